"""Dynamics plug-in: characteristic matrices, equation of motion, joint reactions.

The subpackage is ``mjstruct.dynamics``; its entry point is
:func:`~mjstruct.dynamics.analysis.dynamic_analysis` (not ``dynamics``, which is this
package's name).  Modules: ``expressions`` (safe load expressions), ``data`` (the
file keys), ``matrices`` (incidence, position functions, analogs, inertia and force
matrices), ``equation`` (V, W, Q, work integrals, steady motion, q̇(q), q̈(q)),
``reactions`` (the stacked linear system and its check), ``analysis`` (the entry point
and result), ``report`` (text and CSV).  A time integrator builds on
:class:`~mjstruct.dynamics.equation.PathForce` (V, W, Q at any q).
"""

from __future__ import annotations

from mjstruct.dynamics.analysis import DynamicsResult, dynamic_analysis

__all__ = ["DynamicsResult", "dynamic_analysis"]
