"""Steps that close loops: place a link by two known centres, and the closure equations.

Owns *place* (a link whose two centres are already known is placed by them) and the
closure kinds it and the planner's bookkeeping create: *close-distance* (the
distance between those two centres must equal the link's side: one equation),
*close-point* (a centre reached along two links must coincide: two equations) and
*close-slide* (two links placed apart must still slide on their common guide: same
rotation, and the second link's point on the first link's guide line: two equations).  The
closure residuals are what Newton drives to zero on the plan's unknowns; with no
unknown they are redundant constraints checked along the motion.

Examples
--------
>>> from mjstruct.kinematics.steps import STEP_KINDS
>>> STEP_KINDS["close-point"].equations, STEP_KINDS["place"].equations
(2, 0)
"""

from __future__ import annotations

from mjstruct.kinematics.steps.base import (
    PlanRule,
    PlanState,
    Run,
    Step,
    StepKind,
    reads_inputs,
    register,
    register_rule,
)
from mjstruct.kinematics.triangles import Jet, Pose, distance_residual, dot, rotation_between


def _eval_place(s: Step, k: int, run: Run) -> None:
    C = run.geometry.centres
    P, Q = run.centre(s.inputs[0]), run.centre(s.inputs[1])
    r, w = rotation_between(P, Q, C[s.inputs[0]], C[s.inputs[1]], run.lower_pose(s.links[0]))
    run.place(s.links[0], Pose(C[s.inputs[0]], P, r, w))


def _eval_close_distance(s: Step, k: int, run: Run) -> None:
    C = run.geometry.centres
    P, Q = run.centre(s.inputs[0]), run.centre(s.inputs[1])
    run.residuals.append(distance_residual(P, Q, abs(C[s.inputs[1]] - C[s.inputs[0]])))


def _eval_close_point(s: Step, k: int, run: Run) -> None:
    a, b = s.links
    z = run.geometry.centres[s.joint]
    Xa, Xb = run.poses[a].carry(z), run.poses[b].carry(z)
    diff: Jet = [Xa[i] - Xb[i] for i in range(run.order + 1)]
    run.residuals.append([d.real for d in diff])
    run.residuals.append([d.imag for d in diff])


def _eval_close_slide(s: Step, k: int, run: Run) -> None:
    geom, order = run.geometry, run.order
    a, b = run.mechanism.joint(s.joint).links
    pa, pb = run.poses[a], run.poses[b]
    z = geom.centres[s.joint]
    n = pa.vector(1j * geom.axes[s.joint])  # the guide's normal, carried by link a
    Xa, Xb = pa.carry(z), pb.carry(z)
    D = [Xb[i] - Xa[i] for i in range(order + 1)]
    offset: Jet = [dot(n[0], D[0])]
    # the relative rotation rho = e^{i phi}, phi = theta_b - theta_a, must stay 1
    rho = pb.r * pa.r.conjugate()
    angle: Jet = [rho.imag]
    if order >= 1:
        offset.append(dot(n[1], D[0]) + dot(n[0], D[1]))
        phi1 = pb.w[0] - pa.w[0]
        angle.append(phi1 * rho.real)
    if order >= 2:
        offset.append(dot(n[2], D[0]) + 2.0 * dot(n[1], D[1]) + dot(n[0], D[2]))
        phi2 = pb.w[1] - pa.w[1]
        angle.append(phi2 * rho.real - phi1 * phi1 * rho.imag)
    run.residuals.append(angle)
    run.residuals.append(offset)


register(
    StepKind(
        "place",
        "link {links[0]} placed by its known centres {inputs[0]}, {inputs[1]}",
        _eval_place,
        reads=reads_inputs,
    )
)
register(
    StepKind(
        "close-distance",
        "closure: |{inputs[0]}{inputs[1]}| on link {links[0]} must equal its length",
        _eval_close_distance,
        equations=1,
        reads=reads_inputs,
    )
)
register(
    StepKind(
        "close-point",
        "closure: centre {joint} from link {links[0]} must coincide with link {links[1]}'s",
        _eval_close_point,
        equations=2,
        reads=lambda s, m: (s.links, ()),
    )
)


def _plan_place(st: PlanState, link: str) -> bool:
    """A link with two known centres is placed by them (its side closes a loop)."""
    if not st.free(link):
        return False
    known = st.known_on(link)
    if len(known) < 2:
        return False
    step = st.add(Step("place", (link,), inputs=(known[0], known[1])))
    st.add(Step("close-distance", (link,), inputs=(known[0], known[1])))
    st.place(link, step, known[:2])
    return True


register(
    StepKind(
        "close-slide",
        "closure: link {links[0]} must slide on link {links[1]} along the guide {joint}",
        _eval_close_slide,
        equations=2,
        reads=lambda s, m: (s.links, ()),
    )
)


# a link is placed by two revolute centres: a link with fewer never is
register_rule(PlanRule("place", "link", 20, _plan_place, lambda t, x: len(t.revolute[x]) > 1))
