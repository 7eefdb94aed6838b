"""Kinematics plug-in: triangle-rule position analysis, analogs, branches, singularities.

Entry point: :func:`mjstruct.kinematics.solver.kinematics` (CLI: ``mjstruct kinematics``).
Modules: ``geometry`` (reading ``at``/``axis``/``points``), ``planner`` (triangle steps
on a chosen decomposition), ``triangles`` (vectorised dyads with exact derivatives),
``evaluate`` (running a plan over all frames), ``closure`` (Newton on the fewest
unknowns), ``branches`` (assembly modes, branch points, feasibility), ``jacobian``
(constraint Jacobian rank and determinant), ``solver`` (the analysis and its checks),
``report`` (text and CSV).  Nothing is imported here, so the structural path stays light.
"""
