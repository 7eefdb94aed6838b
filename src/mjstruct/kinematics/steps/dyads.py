"""Dyads with two assembly modes: RRR, RRP and RPR (circle intersections).

Owns, for each of the three kinds, the planning rule that finds it, its evaluation
over all frames (the triangle solvers of :mod:`mjstruct.kinematics.triangles`, exact
σ and κ), the assembly mode K = ±1 that reproduces the reference configuration, and
its triangle count (RRR: one general triangle; RRP and RPR: one right triangle, plus
the triangles that find the dyad's base side across the placed cluster).

References
----------
.. [1] A. N. Panasenko, "Practical implementation…" (in Russian; the available copy
   gives only this beginning of the title), Systems. Methods. Technologies,
   no. 2 (66), pp. 32–42, 2025. [Panasenko 2025] in docs/references.md.

Examples
--------
>>> from mjstruct.kinematics.steps.base import Step
>>> from mjstruct.kinematics.geometry import Geometry
>>> g = Geometry({"A": 0j, "B": 1 + 1j, "C": 2 + 0j}, {}, {}, {}, {}, {}, 2.0)
>>> STEP_RRR.reference_mode(Step("RRR", ("1", "2"), joint="B", inputs=("A", "C")), g)
1
"""

from __future__ import annotations

from typing import overload

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.geometry import Geometry
from mjstruct.kinematics.steps.base import (
    PlanRule,
    PlanState,
    Run,
    Step,
    StepKind,
    other_link,
    reads_base_and_first_input,
    reads_inputs,
    register,
    register_rule,
)
from mjstruct.kinematics.triangles import (
    Pose,
    circle_circle,
    circle_line,
    guide_pair,
    rotation_between,
)
from mjstruct.typing import FloatArray


@overload
def side(x: float) -> int: ...
@overload
def side(x: FloatArray) -> npt.NDArray[np.int8]: ...
def side(x: float | FloatArray) -> int | npt.NDArray[np.int8]:
    """+1 where ``x >= 0``, else -1: an assembly mode from a signed quantity.

    Per-frame geometry (each frame its own reference configuration, arrays of centres
    instead of numbers: the design plug-in's population) gives one mode per frame.
    """
    if isinstance(x, np.ndarray):
        return np.where(x >= 0, 1, -1).astype(np.int8)
    return 1 if x >= 0 else -1


def mode_rrr(z1: complex, z2: complex, zX: complex) -> int:
    """Assembly mode of a dyad RRR: the side of P1P2 the joint is on."""
    return side(((zX - z1) * (z2 - z1).conjugate()).imag)


def mode_rrp(z1: complex, zX: complex, axis: complex) -> int:
    """Assembly mode of a dyad RRP: which way along the guide the joint lies from P1."""
    return side(((zX - z1) * axis.conjugate()).real)


def mode_rpr(z1: complex, z2: complex, axis: complex) -> int:
    """Mode of a dyad RPR: whether P1P2 runs along the guide (+1) or against it (-1)."""
    return side(((z2 - z1) * axis.conjugate()).real)


# -- RRR ------------------------------------------------------------------------------


def _ref_rrr(s: Step, geom: Geometry) -> int:
    C = geom.centres
    return mode_rrr(C[s.inputs[0]], C[s.inputs[1]], C[s.joint])


def _eval_rrr(s: Step, k: int, run: Run) -> None:
    C = run.geometry.centres
    b, c = s.links
    P1, P2 = run.centre(s.inputs[0]), run.centre(s.inputs[1])
    zX, z1, z2 = C[s.joint], C[s.inputs[0]], C[s.inputs[1]]
    mode = run.mode(k, mode_rrr(z1, z2, zX))
    low = run.lower_point(s.joint, k)
    X, disc, det = circle_circle(P1, P2, abs(zX - z1), abs(zX - z2), mode, run.order, low)
    run.diag[k] = (disc, det)
    rb, wb = rotation_between(P1, X, z1, zX, run.lower_pose(b))
    rc, wc = rotation_between(P2, X, z2, zX, run.lower_pose(c))
    run.place(b, Pose(zX, X, rb, wb))
    run.place(c, Pose(zX, X, rc, wc))
    run.first[s.joint] = b
    run.solved[s.joint] = X


STEP_RRR = register(
    StepKind(
        "RRR",
        "dyad RRR: links {links[0]}, {links[1]} from centres {inputs[0]}, {inputs[1]} "
        "meet at {joint} (one general triangle)",
        _eval_rrr,
        triangle="general",
        reference_mode=_ref_rrr,
        reads=reads_inputs,
    )
)


# -- RRP ------------------------------------------------------------------------------


def _ref_rrp(s: Step, geom: Geometry) -> int:
    C = geom.centres
    return mode_rrp(C[s.inputs[0]], C[s.joint], geom.axes[s.inputs[1]])


def _eval_rrp(s: Step, k: int, run: Run) -> None:
    C, geom = run.geometry.centres, run.geometry
    b, c = s.links
    guide = s.inputs[1]
    base = run.poses[s.base]
    zX, z1 = C[s.joint], C[s.inputs[0]]
    P1 = run.centre(s.inputs[0])
    L = base.carry(zX)
    n = base.vector(1j * geom.axes[guide])
    mode = run.mode(k, mode_rrp(z1, zX, geom.axes[guide]))
    X, disc, det = circle_line(P1, abs(zX - z1), L, n, mode, run.order)
    run.diag[k] = (disc, det)
    rb, wb = rotation_between(P1, X, z1, zX)
    run.place(b, Pose(zX, X, rb, wb))
    run.place(c, Pose(zX, X, base.r, list(base.w)))
    run.first[s.joint] = b
    run.solved[s.joint] = X


register(
    StepKind(
        "RRP",
        "dyad RRP: link {links[0]} from centre {inputs[0]} meets slider {links[1]} at "
        "{joint} on the guide {inputs[1]} of link {base} (one right triangle)",
        _eval_rrp,
        triangle="right",
        reference_mode=_ref_rrp,
        reads=reads_base_and_first_input,
    )
)


# -- RPR ------------------------------------------------------------------------------


def _ref_rpr(s: Step, geom: Geometry) -> int:
    C = geom.centres
    return mode_rpr(C[s.inputs[0]], C[s.inputs[1]], geom.axes[s.joint])


def _eval_rpr(s: Step, k: int, run: Run) -> None:
    C = run.geometry.centres
    b, c = s.links
    z1, z2 = C[s.inputs[0]], C[s.inputs[1]]
    P1, P2 = run.centre(s.inputs[0]), run.centre(s.inputs[1])
    axis = run.geometry.axes[s.joint]
    mode = run.mode(k, mode_rpr(z1, z2, axis))
    r, w, disc, det = guide_pair(P1, P2, z1, z2, axis, mode, run.order)
    run.diag[k] = (disc, det)
    run.place(b, Pose(z1, P1, r, w))
    run.place(c, Pose(z2, P2, r, list(w)))


register(
    StepKind(
        "RPR",
        "dyad RPR: links {links[0]}, {links[1]} from centres {inputs[0]}, {inputs[1]} "
        "slide on each other at {joint} (one right triangle)",
        _eval_rpr,
        triangle="right",
        reference_mode=_ref_rpr,
        reads=reads_inputs,
    )
)


# -- planning -------------------------------------------------------------------------


def line_diagonal(st: PlanState, joint: str, base: str) -> int:
    """Triangles to find the distance from a known centre to a guide on link ``base``."""
    on_base = st.known_on(base)
    if joint in on_base:
        return 0
    return st.nearest(joint, on_base)


def _free_links(st: PlanState, jid: str) -> list[str]:
    """The links of joint ``jid`` that may be placed now, in the joint's order."""
    links, allowed = st.topo.links_of[jid], st.allowed
    if allowed is not None and len(allowed) < len(links):
        # a multiple joint of many links met while one small group is open
        pos = st.topo.position(jid)
        free = [x for x in allowed if x in pos and x not in st.placed]
        return sorted(free, key=pos.__getitem__)
    placed = st.placed
    if allowed is None:
        return [x for x in links if x not in placed]
    return [x for x in links if x not in placed and x in allowed]


def _plan_revolute_dyad(st: PlanState, jid: str) -> bool:
    """At an unknown revolute joint: a dyad RRR, else a dyad RRP (in file order)."""
    m = st.m
    # every branch below needs a link with exactly one known centre at the joint
    if jid in st.known or not st.ones[jid]:
        return False
    cands = _free_links(st, jid)
    for ib, b in enumerate(cands):
        kb = st.known_on(b)
        if len(kb) != 1 or st.coincide(kb[0], jid):
            continue
        for c in cands[ib + 1 :]:
            kc = st.known_on(c)
            if len(kc) != 1 or st.coincide(kc[0], jid) or st.coincide(kb[0], kc[0]):
                continue
            diagonal, checks = st.paths(kb[0], kc[0])
            step = st.add(
                Step("RRR", (b, c), joint=jid, inputs=(kb[0], kc[0]), diagonal=diagonal,
                     checks=checks)
            )  # fmt: skip
            st.place(b, step, (kb[0], jid))
            st.place(c, step, (kc[0], jid))
            return True
        # RRP: b has a known centre, its partner c slides on a placed link
        for c in cands:
            if c == b or st.count[c]:
                continue
            guides = [
                g
                for g in st.topo.guides[c]
                for other in m.joint(g).links
                if other != c and other in st.placed
            ]
            if not guides:
                continue
            guide = guides[0]
            base = other_link(m, guide, c)
            step = st.add(
                Step("RRP", (b, c), joint=jid, inputs=(kb[0], guide), base=base,
                     diagonal=line_diagonal(st, kb[0], base))
            )  # fmt: skip
            st.place(b, step, (kb[0], jid))
            st.place(c, step, (jid, guide))
            return True
    return False


def _plan_rpr(st: PlanState, jid: str) -> bool:
    """At a guide pair: two links, one known centre each, sliding on each other."""
    if jid in st.topo.driver_set:
        return False
    b, c = st.m.joint(jid).links
    if not st.free(b) or not st.free(c):
        return False
    kb, kc = st.known_on(b), st.known_on(c)
    if len(kb) != 1 or len(kc) != 1 or st.coincide(kb[0], kc[0]):
        return False
    diagonal, checks = st.paths(kb[0], kc[0])
    step = st.add(
        Step("RPR", (b, c), joint=jid, inputs=(kb[0], kc[0]), diagonal=diagonal, checks=checks)
    )
    st.place(b, step, (*kb, jid))
    st.place(c, step, (*kc, jid))
    return True


register_rule(PlanRule("revolute dyads", "R", 30, _plan_revolute_dyad))
# a driven slide is no guide pair of a dyad
register_rule(PlanRule("RPR", "P", 40, _plan_rpr, lambda t, j: j not in t.driver_set))
