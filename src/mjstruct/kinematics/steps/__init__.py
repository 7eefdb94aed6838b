"""The step kinds of a kinematic plan, one module per family.

Owns the registry :data:`STEP_KINDS` (name -> :class:`StepKind`: description,
evaluation with exact σ and κ, reference assembly mode, triangle class, closure
equations) and :data:`PLAN_RULES` (how the planner finds each family's steps).

* :mod:`~mjstruct.kinematics.steps.base`: the contract (Step, StepKind, PlanRule,
  the planner's state, the evaluation's run);
* :mod:`~mjstruct.kinematics.steps.drivers`: reference, driver-R, driver-P, assume;
* :mod:`~mjstruct.kinematics.steps.closures`: place, close-distance, close-point;
* :mod:`~mjstruct.kinematics.steps.dyads`: RRR, RRP, RPR (two assembly modes);
* :mod:`~mjstruct.kinematics.steps.line_dyads`: PRP, RPP (line–line intersections);
* :mod:`~mjstruct.kinematics.steps.gears`: gear (a link turned by Willis' equations
  from the drivers), gear-link (by its mate's turn relative to the carrier).

A new step kind goes into the module of its family (or a new module imported here):
a :class:`StepKind` passed to :func:`register`, and a :class:`PlanRule` passed to
:func:`register_rule` if the planner is to find it.

Examples
--------
>>> [r.name for r in PLAN_RULES]
['drivers', 'gears', 'gear links', 'place', 'revolute dyads', 'RPR', 'PRP', 'RPP']
>>> sorted(STEP_KINDS)[:4]
['PRP', 'RPP', 'RPR', 'RRP']
"""

from mjstruct.kinematics.steps import closures, drivers, dyads, gears, line_dyads
from mjstruct.kinematics.steps.base import (
    PLAN_RULES,
    STEP_KINDS,
    PlanRule,
    PlanState,
    Run,
    Step,
    StepKind,
    Topology,
    other_link,
    register,
    register_rule,
)

__all__ = [
    "PLAN_RULES",
    "STEP_KINDS",
    "PlanRule",
    "PlanState",
    "Run",
    "Step",
    "StepKind",
    "Topology",
    "closures",
    "drivers",
    "dyads",
    "gears",
    "line_dyads",
    "other_link",
    "register",
    "register_rule",
]
