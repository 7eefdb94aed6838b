"""Dynamics plug-in: characteristic matrices, equation of motion, joint reactions.

The subpackage is ``mjstruct.dynamics``; its entry point is
:func:`~mjstruct.dynamics.analysis.dynamic_analysis` (not ``dynamics``, which is this
package's name).  Modules: ``expressions`` (safe load expressions), ``data`` (the
file keys), ``inputs`` (the boundary: everything checked once), ``matrices``
(incidence, position functions, analogs, inertia and force matrices), ``equation`` (V,
W, Q, work integrals, steady motion, q̇(q), q̈(q)), ``motion`` (the three ways of
driving), ``reactions`` (the stacked linear system), ``joint_loads`` (the forces and
reactions steps and the check), ``analysis`` (the entry point: the steps in order),
``result`` (the result and its JSON), ``report`` (text and CSV), ``time`` (motion in
time: run-up and run-down, stiffness test, explicit or implicit integrators) on
``time_terms`` (V, W and the loads' analogs at any q); ``elements`` (the force
elements of the file: springs, dampers, elastic slides, motors) and ``element_loads``
(their loads at the centres of mass), ``lagrange`` (``M(q) q̈ + h = Q`` for any number
of drivers), ``forward`` (its motion in time) and ``forward_report`` (what the command
prints of it).

References
----------
.. [1] A. N. Panasenko, "Practical implementation…" (in Russian; the available copy
   gives only this beginning of the title), Systems. Methods. Technologies,
   no. 2 (66), pp. 32–42, 2025. [Panasenko 2025] in docs/references.md.
"""

from __future__ import annotations

from mjstruct.dynamics.analysis import DynamicsResult, dynamic_analysis

__all__ = ["DynamicsResult", "dynamic_analysis"]
