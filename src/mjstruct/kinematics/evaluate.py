"""Evaluation of a plan over all frames at once: positions and their exact derivatives.

Owns the one code path that runs a :class:`~mjstruct.kinematics.planner.Plan`: every
step is computed for all frames in one go (numpy arrays over frames, no Python loop
per frame), carrying jets ``[value, d/dτ, d²/dτ²]`` along a path parameter τ whose
derivatives of the driver coordinates and closure unknowns are given as seeds.  The
same routine gives positions, analogs, and the Jacobian of the closure equations
(seeds on the unknowns), so Newton and the analogs use the same formulas.

Examples
--------
>>> import numpy as np
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.geometry import read_geometry
>>> from mjstruct.kinematics.planner import plan_kinematics
>>> m = read_mechanism(example_path("four-bar"))
>>> g = read_geometry(m); p = plan_kinematics(m, geometry=g)
>>> ev = evaluate(p, g, m, np.array([[g.driver_ref["O1"]]]), order=0)
>>> bool(abs(ev.centre("B")[0][0] - g.centres["B"]) < 1e-12)   # reproduces the file
True
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from mjstruct.kinematics.geometry import Geometry
from mjstruct.kinematics.planner import Plan
from mjstruct.kinematics.triangles import (
    Jet,
    Pose,
    circle_circle,
    circle_line,
    distance_residual,
    guide_pair,
    line_line,
    rotation_between,
)
from mjstruct.mechanism import Mechanism


@dataclass
class Evaluation:
    """Poses of all links over the frames, residual jets and per-step diagnostics.

    ``diag[k] = (disc, det)`` for each dyad step k: the discriminant (h²/r², negative
    where the dyad does not assemble) and the signed sine at the solved joint (the
    step's Jacobian; zero at a dead or change point).
    """

    m: Mechanism
    geom: Geometry
    order: int
    poses: dict[str, Pose]
    residuals: list[Jet] = field(default_factory=list)
    diag: dict[int, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    first: dict[str, str] = field(default_factory=dict)
    solved: dict[str, Jet] = field(default_factory=dict)

    def centre(self, joint: str) -> Jet:
        """Jet of a joint centre (prismatic: the point carried by its second link)."""
        if joint in self.solved:
            return self.solved[joint]
        j = self.m.joint(joint)
        link = j.links[1] if j.kind == "P" else self.first[joint]
        return self.poses[link].point(self.geom.centres[joint])

    def residual_matrix(self, k: int = 0) -> np.ndarray:
        """Derivative ``k`` of the closure equations, shape (frames, equations)."""
        return np.stack([r[k] for r in self.residuals], axis=-1)


def _frames(q: np.ndarray) -> int:
    return int(q.shape[0])


def evaluate(
    plan: Plan,
    geom: Geometry,
    m: Mechanism,
    q: np.ndarray,
    order: int = 2,
    rates: np.ndarray | None = None,
    t: np.ndarray | None = None,
    t1: np.ndarray | None = None,
    t2: np.ndarray | None = None,
    K: Mapping[int, np.ndarray | int] | None = None,
    upto: int | None = None,
) -> Evaluation:
    """Run the plan on driver coordinates ``q`` (frames × drivers).

    Parameters
    ----------
    order : 0 positions, 1 with first derivatives, 2 with second derivatives.
    rates : dq_i/dτ for each driver (default 1: analogs with respect to q).
    t, t1, t2 : closure unknowns (frames × unknowns) and their derivatives.
    K : assembly mode per dyad step (±1, scalar or per frame); missing: chosen to
        reproduce the reference configuration (see :func:`reference_modes`).
    upto : stop after this many steps (for refining branch points).
    """
    F = _frames(q)
    zero_c = np.zeros(F, complex)
    zero_r = np.zeros(F)
    rate = np.ones(q.shape[1]) if rates is None else np.asarray(rates, float)
    if t is None:
        t = np.zeros((F, plan.unknowns))
    if t1 is None:
        t1 = np.zeros((F, plan.unknowns))
    if t2 is None:
        t2 = np.zeros((F, plan.unknowns))
    modes = K if K is not None else {}
    ev = Evaluation(m, geom, order, {})
    poses, first, C = ev.poses, ev.first, geom.centres

    def place(link: str, pose: Pose) -> None:
        poses[link] = pose
        for jid in m.link_joints[link]:
            first.setdefault(jid, link)

    def centre(jid: str) -> Jet:
        if jid in ev.solved:
            return ev.solved[jid]
        return poses[first[jid]].point(C[jid])

    steps = plan.steps if upto is None else plan.steps[:upto]
    for k, s in enumerate(steps):
        if s.kind == "reference":
            w = [zero_r] * order
            place(s.links[0], Pose(0j, [zero_c] * (order + 1), np.ones(F, complex), w))
        elif s.kind in ("driver-R", "driver-P"):
            joint = m.joint(s.joint)
            base, driven = poses[s.base], s.links[0]
            sign = 1.0 if driven == joint.links[1] else -1.0
            dq = sign * (q[:, s.index] - geom.driver_ref[s.joint])
            dq1 = sign * rate[s.index]
            if s.kind == "driver-R":
                r = base.r * np.exp(1j * dq)
                w = [base.w[0] + dq1, *base.w[1:]] if order else []
                place(driven, Pose(C[s.joint], centre(s.joint), r, w))
            else:
                A = base.point(C[s.joint])
                u = base.vector(geom.axes[s.joint])
                X = [A[0] + dq * u[0]]
                if order >= 1:
                    X.append(A[1] + dq1 * u[0] + dq * u[1])
                if order >= 2:
                    X.append(A[2] + 2 * dq1 * u[1] + dq * u[2])
                place(driven, Pose(C[s.joint], X, base.r, list(base.w)))
        elif s.kind == "assume":
            i = s.index
            w = [t1[:, i], t2[:, i]][:order]
            place(s.links[0], Pose(C[s.joint], centre(s.joint), np.exp(1j * t[:, i]), w))
        elif s.kind == "RRR":
            b, c = s.links
            P1, P2 = centre(s.inputs[0]), centre(s.inputs[1])
            zX, z1, z2 = C[s.joint], C[s.inputs[0]], C[s.inputs[1]]
            X, disc, det = circle_circle(
                P1, P2, abs(zX - z1), abs(zX - z2), modes.get(k, _mode_rrr(z1, z2, zX)), order
            )
            ev.diag[k] = (disc, det)
            rb, wb = rotation_between(P1, X, z1, zX)
            rc, wc = rotation_between(P2, X, z2, zX)
            place(b, Pose(zX, X, rb, wb))
            place(c, Pose(zX, X, rc, wc))
            first[s.joint] = b
            ev.solved[s.joint] = X
        elif s.kind == "RRP":
            b, c = s.links
            guide = s.inputs[1]
            base = poses[s.base]
            zX, z1 = C[s.joint], C[s.inputs[0]]
            P1 = centre(s.inputs[0])
            L = base.point(zX)
            n = base.vector(1j * geom.axes[guide])
            mode = modes.get(k, _mode_rrp(z1, zX, geom.axes[guide]))
            X, disc, det = circle_line(P1, abs(zX - z1), L, n, mode, order)
            ev.diag[k] = (disc, det)
            rb, wb = rotation_between(P1, X, z1, zX)
            place(b, Pose(zX, X, rb, wb))
            place(c, Pose(zX, X, base.r, list(base.w)))
            first[s.joint] = b
            ev.solved[s.joint] = X
        elif s.kind == "RPR":
            b, c = s.links
            z1, z2 = C[s.inputs[0]], C[s.inputs[1]]
            P1, P2 = centre(s.inputs[0]), centre(s.inputs[1])
            axis = geom.axes[s.joint]
            mode = modes.get(k, _mode_rpr(z1, z2, axis))
            r, w, disc, det = guide_pair(P1, P2, z1, z2, axis, mode, order)
            ev.diag[k] = (disc, det)
            place(b, Pose(z1, P1, r, w))
            place(c, Pose(z2, P2, r, list(w)))
        elif s.kind == "PRP":
            # two sliders, each on a guide of a placed link, pinned together at X
            b, c = s.links
            zX = C[s.joint]
            pb, pc = (poses[_other(m, g, x)] for g, x in zip(s.inputs, s.links, strict=True))
            X, disc, det = line_line(
                pb.point(zX),
                pb.vector(1j * geom.axes[s.inputs[0]]),
                pc.point(zX),
                pc.vector(1j * geom.axes[s.inputs[1]]),
                order,
            )
            ev.diag[k] = (disc, det)
            place(b, Pose(zX, X, pb.r, list(pb.w)))
            place(c, Pose(zX, X, pc.r, list(pc.w)))
            first[s.joint] = b
            ev.solved[s.joint] = X
        elif s.kind == "RPP":
            # link b (known centre) slides in c, which slides on a guide of link `base`:
            # both keep base's rotation; c's image of the inner joint's point is on both
            # guides (the one carried by b, the one carried by base)
            b, c = s.links
            base = poses[s.base]
            zJ, z1 = C[s.joint], C[s.inputs[0]]
            place(b, Pose(z1, centre(s.inputs[0]), base.r, list(base.w)))
            X, disc, det = line_line(
                poses[b].point(zJ),
                base.vector(1j * geom.axes[s.joint]),
                base.point(zJ),
                base.vector(1j * geom.axes[s.inputs[1]]),
                order,
            )
            ev.diag[k] = (disc, det)
            place(c, Pose(zJ, X, base.r, list(base.w)))
        elif s.kind == "place":
            P, Q = centre(s.inputs[0]), centre(s.inputs[1])
            r, w = rotation_between(P, Q, C[s.inputs[0]], C[s.inputs[1]])
            place(s.links[0], Pose(C[s.inputs[0]], P, r, w))
        elif s.kind == "close-distance":
            P, Q = centre(s.inputs[0]), centre(s.inputs[1])
            ev.residuals.append(distance_residual(P, Q, abs(C[s.inputs[1]] - C[s.inputs[0]])))
        elif s.kind == "close-point":
            a, b = s.links
            Xa, Xb = poses[a].point(C[s.joint]), poses[b].point(C[s.joint])
            diff = [Xa[i] - Xb[i] for i in range(order + 1)]
            ev.residuals.append([d.real for d in diff])
            ev.residuals.append([d.imag for d in diff])
        else:  # pragma: no cover - the planner makes no other kinds
            raise ValueError(f"unknown step kind {s.kind!r}")
    if plan.reference != plan.frame and plan.frame in poses and upto is None:
        _to_frame(ev, plan.frame)
    return ev


def _other(m: Mechanism, joint: str, link: str) -> str:
    """The other link of a two-link joint."""
    return next(x for x in m.joint(joint).links if x != link)


def reference_mode(plan: Plan, geom: Geometry, k: int) -> int:
    """Assembly mode (±1) of dyad step k that reproduces the reference configuration."""
    s, C = plan.steps[k], geom.centres
    if s.kind == "RRR":
        return _mode_rrr(C[s.inputs[0]], C[s.inputs[1]], C[s.joint])
    if s.kind == "RPR":
        return _mode_rpr(C[s.inputs[0]], C[s.inputs[1]], geom.axes[s.joint])
    return _mode_rrp(C[s.inputs[0]], C[s.joint], geom.axes[s.inputs[1]])


def _mode_rpr(z1: complex, z2: complex, axis: complex) -> int:
    """Mode of a dyad RPR: whether P1P2 runs along the guide (+1) or against it (-1)."""
    return 1 if ((z2 - z1) * axis.conjugate()).real >= 0 else -1


def _mode_rrr(z1: complex, z2: complex, zX: complex) -> int:
    """Assembly mode of a dyad at the reference: the side of P1P2 the joint is on."""
    return 1 if ((zX - z1) * (z2 - z1).conjugate()).imag >= 0 else -1


def _mode_rrp(z1: complex, zX: complex, axis: complex) -> int:
    """Assembly mode of a dyad RRP: which way along the guide the joint lies from P1."""
    return 1 if ((zX - z1) * axis.conjugate()).real >= 0 else -1


def _to_frame(ev: Evaluation, frame: str) -> None:
    """Carry every pose from the reference link's coordinates to the frame's."""
    ev.solved.clear()  # solved centres were in the reference link's coordinates
    f = ev.poses[frame]
    c = f.r.conjugate()
    cw: Jet = [c]
    if ev.order >= 1:
        cw.append(-1j * f.w[0] * c)
    if ev.order >= 2:
        cw.append((-1j * f.w[1] - f.w[0] ** 2) * c)
    for link, p in list(ev.poses.items()):
        Y = [p.A[i] - f.A[i] for i in range(ev.order + 1)]
        A = [f.zA + c * Y[0]]
        if ev.order >= 1:
            A.append(cw[1] * Y[0] + c * Y[1])
        if ev.order >= 2:
            A.append(cw[2] * Y[0] + 2 * cw[1] * Y[1] + c * Y[2])
        w = [p.w[i] - f.w[i] for i in range(ev.order)]
        ev.poses[link] = Pose(p.zA, A, p.r * c, w)
