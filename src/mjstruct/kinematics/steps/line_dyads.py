"""Dyads with two prismatic pairs: PRP and RPP (line–line intersections).

Owns, for both kinds, the planning rule, the evaluation (the solved point lies on two
guides carried by placed links: linear, one solution, no assembly mode), the guides
whose parallelism leaves the step undefined, and the triangle count (one right
triangle, plus the triangles relating the two guides across the placed cluster).
Parallel guides at the reference configuration are bad input.

Examples
--------
>>> from mjstruct.kinematics.steps.base import Step
>>> STEP_RPP.guides(Step("RPP", ("2", "3"), joint="J", inputs=("A", "G")))
('J', 'G')
"""

from __future__ import annotations

from mjstruct.errors import MechanismError
from mjstruct.kinematics.steps.base import (
    PlanRule,
    PlanState,
    Run,
    Step,
    StepKind,
    other_link,
    reads_base_and_first_input,
    register,
    register_rule,
)
from mjstruct.kinematics.steps.dyads import line_diagonal
from mjstruct.kinematics.tolerances import PARALLEL_REF
from mjstruct.kinematics.triangles import Pose, line_line


def _eval_prp(s: Step, k: int, run: Run) -> None:
    # two sliders, each on a guide of a placed link, pinned together at X
    m, geom = run.mechanism, run.geometry
    b, c = s.links
    zX = geom.centres[s.joint]
    pb, pc = (run.poses[other_link(m, g, x)] for g, x in zip(s.inputs, s.links, strict=True))
    X, disc, det = line_line(
        pb.carry(zX),
        pb.vector(1j * geom.axes[s.inputs[0]]),
        pc.carry(zX),
        pc.vector(1j * geom.axes[s.inputs[1]]),
        run.order,
    )
    run.diag[k] = (disc, det)
    run.place(b, Pose(zX, X, pb.r, list(pb.w)))
    run.place(c, Pose(zX, X, pc.r, list(pc.w)))
    run.first[s.joint] = b
    run.solved[s.joint] = X


def _eval_rpp(s: Step, k: int, run: Run) -> None:
    # link b (known centre) slides in c, which slides on a guide of link `base`: both
    # keep base's rotation; c's image of the inner joint's point is on both guides
    # (the one carried by b, the one carried by base)
    geom = run.geometry
    b, c = s.links
    base = run.poses[s.base]
    zJ, z1 = geom.centres[s.joint], geom.centres[s.inputs[0]]
    run.place(b, Pose(z1, run.centre(s.inputs[0]), base.r, list(base.w)))
    X, disc, det = line_line(
        run.poses[b].carry(zJ),
        base.vector(1j * geom.axes[s.joint]),
        base.carry(zJ),
        base.vector(1j * geom.axes[s.inputs[1]]),
        run.order,
    )
    run.diag[k] = (disc, det)
    run.place(c, Pose(zJ, X, base.r, list(base.w)))


def _guides_prp(s: Step) -> tuple[str, str]:
    return s.inputs[0], s.inputs[1]


def _guides_rpp(s: Step) -> tuple[str, str]:
    return s.joint, s.inputs[1]


STEP_PRP = register(
    StepKind(
        "PRP",
        "dyad PRP: sliders {links[0]}, {links[1]} on the guides {inputs[0]}, {inputs[1]} "
        "meet at {joint} (line–line intersection: one right triangle)",
        _eval_prp,
        triangle="right",
        guides=_guides_prp,
        reads=lambda s, m: (
            tuple(other_link(m, g, x) for g, x in zip(s.inputs, s.links, strict=True)),
            (),
        ),
    )
)
STEP_RPP = register(
    StepKind(
        "RPP",
        "dyad RPP: link {links[0]} from centre {inputs[0]} slides at {joint} in link "
        "{links[1]}, which slides on the guide {inputs[1]} of link {base} (line–line "
        "intersection: one right triangle)",
        _eval_rpp,
        triangle="right",
        guides=_guides_rpp,
        reads=reads_base_and_first_input,
    )
)


# -- planning -------------------------------------------------------------------------


def _guide(st: PlanState, link: str, partner: str) -> str | None:
    """A prismatic joint (not a driver) of ``link`` on a placed link other than ``partner``."""
    for g in st.topo.guides[link]:
        other = other_link(st.m, g, link)
        if other != partner and other in st.placed:
            return g
    return None


def _check_parallel(st: PlanState, kind: str, at: str, g1: str, g2: str) -> None:
    """Bad input when the two guides of a dyad PRP / RPP are parallel at the reference."""
    a1, a2 = st.geom.axes[g1], st.geom.axes[g2]
    if abs((a1.conjugate() * a2).imag) <= PARALLEL_REF:
        k = st.topo.joint_index[g2]
        raise MechanismError(
            f"joints[{k}].axis: guides {g1!r} and {g2!r} of the dyad {kind} at {at!r} are "
            "parallel; their intersection does not exist (the dyad is not determined)"
        )


def _guides_diagonal(st: PlanState, base1: str, base2: str) -> int:
    """Triangles to relate guides on two placed links (0 on one link or a shared centre)."""
    k1, k2 = st.known_on(base1), st.known_on(base2)
    if base1 == base2 or set(k1) & set(k2):
        return 0
    return min((st.nearest(a, k2) for a in k1), default=1) if k2 else 1


def _plan_prp(st: PlanState, jid: str) -> bool:
    """At an unknown revolute joint: two sliders without known centres, each on a guide."""
    # two of the joint's links must have a guide
    if jid in st.known or st.topo.guided[jid] < 2:
        return False
    cands = [x for x in st.m.joint(jid).links if st.free(x) and not st.count[x]]
    for ib, b in enumerate(cands):
        for c in cands[ib + 1 :]:
            gb, gc = _guide(st, b, c), _guide(st, c, b)
            if gb is None or gc is None:
                continue
            _check_parallel(st, "PRP", jid, gb, gc)
            bb, bc = other_link(st.m, gb, b), other_link(st.m, gc, c)
            step = st.add(
                Step("PRP", (b, c), joint=jid, inputs=(gb, gc), base=bb,
                     diagonal=_guides_diagonal(st, bb, bc))
            )  # fmt: skip
            st.place(b, step, (jid, gb))
            st.place(c, step, (jid, gc))
            return True
    return False


def _plan_rpp(st: PlanState, jid: str) -> bool:
    """At a guide pair: b with one known centre slides in c, which slides on a placed link
    (an RPP, or a PPR read from the other end)."""
    if jid in st.topo.driver_set:
        return False
    links = st.m.joint(jid).links
    for b, c in (tuple(links), tuple(links[::-1])):
        if not st.free(b) or not st.free(c) or st.count[c]:
            continue
        kb = st.known_on(b)
        gc = _guide(st, c, b)
        if len(kb) != 1 or gc is None:
            continue
        _check_parallel(st, "RPP", kb[0], jid, gc)
        base = other_link(st.m, gc, c)
        step = st.add(
            Step("RPP", (b, c), joint=jid, inputs=(kb[0], gc), base=base,
                 diagonal=line_diagonal(st, kb[0], base))
        )  # fmt: skip
        st.place(b, step, (*kb, jid))
        st.place(c, step, (jid, gc))
        return True
    return False


# a PRP needs two guided links at its joint; a driven slide is no guide pair of a dyad
register_rule(PlanRule("PRP", "R", 50, _plan_prp, lambda t, j: t.guided[j] > 1))
register_rule(PlanRule("RPP", "P", 60, _plan_rpp, lambda t, j: j not in t.driver_set))
