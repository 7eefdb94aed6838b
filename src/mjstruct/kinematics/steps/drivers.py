"""Steps that start a plan or set a coordinate: reference, driver-R, driver-P, assume.

Owns the kinds that place a link from a known coordinate rather than by a triangle:
the *reference* link (fixed in the solving frame), a revolute or prismatic *driver*
(the driven link turns or slides on an already placed one by q), and an *assumed*
angle (a closure unknown t, iterated by :mod:`mjstruct.kinematics.closure`).  None of
them has assembly modes or counts as a triangle.

Examples
--------
>>> from mjstruct.kinematics.steps import STEP_KINDS
>>> STEP_KINDS["driver-R"].triangle is None, STEP_KINDS["assume"].has_modes
(True, False)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mjstruct.kinematics.steps.base import (
    PlanRule,
    PlanState,
    Run,
    Step,
    StepKind,
    register,
    register_rule,
)
from mjstruct.kinematics.triangles import Jet, Pose
from mjstruct.mechanism import Mechanism


def _reference(s: Step, k: int, run: Run) -> None:
    zero_c = np.zeros(run.frames, complex)
    w: Jet = [np.zeros(run.frames)] * run.order
    r = np.ones(run.frames, complex)
    run.place(s.links[0], Pose(0j, [zero_c] * (run.order + 1), r, w, fixed=True))


def _driver(s: Step, k: int, run: Run) -> None:
    C = run.geometry.centres
    joint = run.mechanism.joint(s.joint)
    base, driven = run.poses[s.base], s.links[0]
    sign = 1.0 if driven == joint.links[1] else -1.0
    dq = sign * (run.q[:, s.index] - run.geometry.driver_ref[s.joint])
    dq1 = sign * run.rates[..., s.index]
    if s.kind == "driver-R":
        place_turned(run, driven, s.joint, base, dq, dq1)
        return
    A = base.carry(C[s.joint])
    u = base.vector(run.geometry.axes[s.joint])
    X: Jet = [A[0] + dq * u[0]]
    if run.order >= 1:
        X.append(A[1] + dq1 * u[0] + dq * u[1])
    if run.order >= 2:
        X.append(A[2] + 2 * dq1 * u[1] + dq * u[2])
    run.place(driven, Pose(C[s.joint], X, base.r, list(base.w)))


def place_turned(run: Run, link: str, joint: str, base: Pose, dq: Any, dq1: Any) -> None:
    """Place ``link`` turned about ``joint`` on ``base`` by ``dq`` from the reference,
    at the rate ``dq1`` relative to it (no relative acceleration: constant rates)."""
    low = run.lower_pose(link)
    r = base.r * np.exp(1j * dq) if low is None else low[0]
    w: Jet = [base.w[0] + dq1, *base.w[1:]] if run.order else []
    run.place(link, Pose(run.geometry.centres[joint], run.centre(joint), r, w))


def _assume_slide(s: Step, k: int, run: Run) -> None:
    # like a prismatic driver, with the slide a closure unknown (its second
    # derivative is an unknown's too, not zero as at constant driver speed)
    C = run.geometry.centres
    i = s.index
    base = run.poses[s.base]
    A = base.carry(C[s.joint])
    u = base.vector(run.geometry.axes[s.joint])
    d, d1, d2 = run.t[:, i], run.t1[..., i], run.t2[..., i]
    X: Jet = [A[0] + d * u[0]]
    if run.order >= 1:
        X.append(A[1] + d1 * u[0] + d * u[1])
    if run.order >= 2:
        X.append(A[2] + d2 * u[0] + 2 * d1 * u[1] + d * u[2])
    run.place(s.links[0], Pose(C[s.joint], X, base.r, list(base.w)))


def _assume(s: Step, k: int, run: Run) -> None:
    i = s.index
    w: Jet = [run.t1[..., i], run.t2[..., i]][: run.order]
    C = run.geometry.centres
    low = run.lower_pose(s.links[0])
    r = np.exp(1j * run.t[:, i]) if low is None else low[0]
    run.place(s.links[0], Pose(C[s.joint], run.centre(s.joint), r, w))


def _driver_reads(s: Step, m: Mechanism) -> tuple[tuple[str, ...], tuple[str, ...]]:
    return (s.base,), (s.joint,)


def _base_reads(s: Step, m: Mechanism) -> tuple[tuple[str, ...], tuple[str, ...]]:
    return (s.base,), ()


register(
    StepKind(
        "reference",
        "link {links[0]} is the reference (fixed in the solving frame)",
        _reference,
        reads=lambda s, m: ((), ()),
    )
)
register(
    StepKind(
        "driver-R",
        "joint {joint} turns link {links[0]} about {joint} on link {base} by q{n}",
        _driver,
        reads=_driver_reads,
    )
)
register(
    StepKind(
        "driver-P",
        "joint {joint} slides link {links[0]} along link {base} by q{n}",
        _driver,
        reads=_driver_reads,
    )
)
register(
    StepKind(
        "assume",
        "assume the angle t{n} of link {links[0]} about {joint} (closure unknown)",
        _assume,
        reads=lambda s, m: ((), (s.joint,)),
    )
)
register(
    StepKind(
        "assume-slide",
        "assume the slide t{n} of link {links[0]} along the guide {joint} of link {base} "
        "(closure unknown)",
        _assume_slide,
        reads=_base_reads,
    )
)


def _plan_drivers(st: PlanState, _: str) -> bool:
    """Every driver whose base is placed turns or slides its driven link into place."""
    progress = False
    placed = st.placed
    for i, d, kind, a, b in st.topo.driver_links:
        if a not in placed and b not in placed:
            continue
        for base, driven in ((a, b), (b, a)):
            if base in placed and st.free(driven):
                name = "driver-P" if kind == "P" else "driver-R"
                step = st.add(Step(name, (driven,), joint=d, base=base, index=i))
                st.place(driven, step, (d,))
                progress = True
    return progress


def assume_angle(st: PlanState, link: str, joint: str) -> None:
    """Place ``link`` about its known centre ``joint`` by a new closure unknown."""
    step = st.add(Step("assume", (link,), joint=joint, index=st.unknowns))
    st.unknowns += 1
    st.place(link, step, (joint,))


def assume_slide(st: PlanState, link: str, guide: str) -> None:
    """Place ``link`` on its ``guide`` of a placed link by a new closure unknown."""
    base = next(x for x in st.m.joint(guide).links if x != link)
    step = st.add(Step("assume-slide", (link,), joint=guide, base=base, index=st.unknowns))
    st.unknowns += 1
    st.place(link, step, (guide,))


register_rule(PlanRule("drivers", "drivers", 10, _plan_drivers))
