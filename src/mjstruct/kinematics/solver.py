"""Kinematic analysis of a mechanism over a sweep of its drivers (the plug-in's entry).

Owns :func:`kinematic_analysis`: geometry and plan, closure unknowns (Newton) where the plan
has them, branch tracking, the final exact evaluation (positions, analogs σ = ds/dq,
κ = dσ/dq), velocities and accelerations ``v = σ q̇``, ``a = κ q̇² + σ q̈`` for a
constant driver speed, and the checks (link lengths, analogs against differences of
positions, the constraint Jacobian's rank and determinant).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> r = kinematic_analysis(read_mechanism(example_path("slider-crank")), frames=4, speed=0.5)
>>> [round(float(x), 3) for x in r.joints["B"]["x"]]
[0.386, 0.259, 0.292, 0.435]
>>> r.warnings
[]
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.kinematics.branches import BranchEvent
from mjstruct.kinematics.closure import Closure
from mjstruct.kinematics.evaluate import Evaluation
from mjstruct.kinematics.geometry import Geometry
from mjstruct.kinematics.jacobian import JacobianCheck, check_jacobian
from mjstruct.kinematics.model import CLOSURE_TOL, KinematicModel, Motion
from mjstruct.kinematics.planner import Plan
from mjstruct.mechanism import Mechanism

#: |det| of the driver-fixed Jacobian below this fraction of its largest value is flagged
NEAR_SINGULAR = 1e-3


@dataclass
class KinematicsResult:
    """Positions, analogs, velocities and accelerations over the frames, with the report.

    ``q`` (frames × drivers); ``valid`` frames that assemble; ``joints`` / ``points``:
    id -> {x, y, vx, vy, ax, ay, sx, sy, kx, ky} arrays (s: velocity analogs, k:
    acceleration analogs); ``links``: id -> {angle, omega, eps, sigma, kappa}.
    """

    model: KinematicModel
    q: np.ndarray
    speed: float
    valid: np.ndarray
    joints: dict[str, dict[str, np.ndarray]]
    points: dict[str, dict[str, np.ndarray]]
    links: dict[str, dict[str, np.ndarray]]
    events: list[BranchEvent]
    warnings: list[str]
    checks: dict[str, Any]
    closure: Closure | None = None
    jacobian: JacobianCheck | None = field(default=None, repr=False)

    @property
    def mechanism(self) -> Mechanism:
        """The mechanism analysed."""
        return self.model.mechanism

    @property
    def plan(self) -> Plan:
        """The plan the analysis ran."""
        return self.model.plan

    @property
    def geometry(self) -> Geometry:
        """The reference configuration."""
        return self.model.geometry

    def to_dict(self) -> dict[str, Any]:
        """The contract's JSON object (nulls where a frame does not assemble)."""

        def lst(a: np.ndarray) -> list[float | None]:
            return [
                float(x) if ok and np.isfinite(x) else None
                for x, ok in zip(a, self.valid, strict=True)
            ]

        keys_p = ("x", "y", "vx", "vy", "ax", "ay")
        keys_l = ("angle", "omega", "eps")
        q = self.q[:, 0] if self.q.shape[1] == 1 else self.q
        return {
            "name": self.mechanism.name,
            "drivers": list(self.plan.drivers),
            "speed": self.speed,
            "q": [float(x) for x in q] if q.ndim == 1 else q.tolist(),
            "joints": {j: {k: lst(v[k]) for k in keys_p} for j, v in self.joints.items()},
            "links": {x: {k: lst(v[k]) for k in keys_l} for x, v in self.links.items()},
            "points": {p: {k: lst(v[k]) for k in keys_p} for p, v in self.points.items()},
            "warnings": list(self.warnings),
            "plan": {
                "reference": self.plan.reference,
                "source": self.plan.source,
                "steps": self.plan.describe(),
                "complexity": self.plan.complexity(),
            },
            "branch_points": [
                {
                    "q": e.q,
                    "frame": e.frame,
                    "joint": e.joint,
                    "kind": e.kind,
                    "sine": e.sine,
                    "mode": e.action,
                }
                for e in self.events
            ],
            "checks": self.checks,
            "closure": None if self.closure is None else self._closure_dict(),
        }

    def _closure_dict(self) -> dict[str, Any]:
        cl = self.closure
        assert cl is not None
        ok = cl.converged
        return {
            "unknowns": self.plan.unknowns,
            "tolerance": cl.tol,
            "iterations": cl.iterations,
            "max_error": float(cl.error[ok].max()) if ok.any() else None,
            "frames_closed": int(ok.sum()),
        }

    def table(self) -> tuple[list[str], np.ndarray]:
        """Columns (q, then x y vx vy ax ay per joint and point, angle ω ε per link)."""
        names = [f"q{i + 1}" if self.q.shape[1] > 1 else "q" for i in range(self.q.shape[1])]
        cols = [self.q[:, i] for i in range(self.q.shape[1])]
        for kind in (self.joints, self.points):
            for pid, v in kind.items():
                for k in ("x", "y", "vx", "vy", "ax", "ay"):
                    names.append(f"{pid}.{k}")
                    cols.append(v[k])
        for link, v in self.links.items():
            for k in ("angle", "omega", "eps"):
                names.append(f"{link}.{k}")
                cols.append(v[k])
        data = np.column_stack(cols)
        data[~self.valid, self.q.shape[1] :] = np.nan
        return names, data


def kinematic_analysis(
    model: KinematicModel | Mechanism,
    drivers: Iterable[str] | None = None,
    frames: int = 360,
    speed: float = 1.0,
    q: Sequence[float] | np.ndarray | None = None,
    stroke: float = 1.0,
    decomposition: object | None = None,
    tol: float = CLOSURE_TOL,
    checks: bool = True,
) -> KinematicsResult:
    """Positions, analogs, velocities and accelerations over a driver sweep.

    Parameters
    ----------
    model : a :class:`~mjstruct.kinematics.model.KinematicModel`, or a mechanism to
        build one from (with ``drivers`` and ``decomposition``).
    drivers : generalised coordinates (default: the file's drivers); any joint's
        relative angle or slide, not only a frame joint.  Only with a mechanism.
    frames, speed : ``frames`` frames over one full cycle from the reference
        configuration, every driver at constant speed ``speed`` (rad/s or length/s).
    q : explicit driver values instead (frames, or frames × drivers), taken as a path.
    stroke : the sweep of a prismatic driver.
    decomposition : an Assur decomposition to plan on (only with a mechanism).
    tol : closure tolerance (relative to the mechanism's size) for iterated groups.
    checks : run the checks (link lengths, analogs vs differences, Jacobian).
    """
    if isinstance(model, KinematicModel):
        if drivers is not None or decomposition is not None:
            raise MechanismError(
                "drivers: give drivers and decomposition when building the model, not here"
            )
        km = model
    else:
        km = KinematicModel.build(model, drivers, decomposition)
    if not np.isfinite(speed) or speed == 0:
        raise MechanismError(f"speed: must be a finite nonzero number, got {speed}")
    qa = km.sweep(frames, speed, stroke) if q is None else km.driver_values(q)
    motion = km.motion(qa, order=2, tol=tol)
    result = _collect(motion, speed)
    warnings = list(motion.warnings)
    warnings += [e.message() for e in motion.events]
    warnings += _parallel_guides(km.plan, motion.evaluation, qa)
    warnings += _infeasible(result)
    result.warnings = warnings
    if checks:
        _checks(result, motion.evaluation)
    return result


def _collect(motion: Motion, speed: float) -> KinematicsResult:
    km, ev, q = motion.model, motion.evaluation, motion.q
    m, geom = km.mechanism, km.geometry
    W = float(speed)
    joints: dict[str, dict[str, np.ndarray]] = {}
    valid = motion.valid.copy()

    def pack(X) -> dict[str, np.ndarray]:
        nonlocal valid
        valid &= np.isfinite(X[0]) & np.isfinite(X[1]) & np.isfinite(X[2])
        return {
            "x": X[0].real, "y": X[0].imag,
            "vx": X[1].real * W, "vy": X[1].imag * W,
            "ax": X[2].real * W * W, "ay": X[2].imag * W * W,
            "sx": X[1].real, "sy": X[1].imag, "kx": X[2].real, "ky": X[2].imag,
        }  # fmt: skip

    for j in m.joints:
        joints[j.id] = pack(ev.centre(j.id))
    points = {pid: pack(ev.poses[link].point(z)) for pid, (link, z) in geom.points.items()}
    links: dict[str, dict[str, np.ndarray]] = {}
    for link in m.links:
        p = ev.poses[link]
        if link == m.frame:
            theta = np.zeros(q.shape[0])
        else:
            theta = np.angle(p.r)
            ok = np.isfinite(theta)
            if ok.any():
                theta[ok] = np.unwrap(theta[ok])
        ang = theta + geom.char_angle[link]
        links[link] = {
            "angle": ang,
            "omega": p.w[0] * W,
            "eps": p.w[1] * W * W,
            "sigma": p.w[0],
            "kappa": p.w[1],
        }
        valid &= np.isfinite(p.w[0]) & np.isfinite(p.w[1])
    return KinematicsResult(
        km, q, W, valid, joints, points, links, list(motion.events), [], {}, motion.closure
    )


def _parallel_guides(plan: Plan, ev: Evaluation, q: np.ndarray) -> list[str]:
    """Frames where the two guides of a dyad PRP / RPP are parallel (no intersection)."""
    out = []
    for k, s in enumerate(plan.steps):
        if s.kind in ("PRP", "RPP") and k in ev.diag:
            bad = ev.diag[k][0] < 0
            if bad.any():
                guides = s.inputs if s.kind == "PRP" else (s.joint, s.inputs[1])
                out.append(
                    f"dyad {s.kind} (step {k + 1}): guides {guides[0]} and {guides[1]} are "
                    f"parallel at {int(bad.sum())} frame(s), first q = "
                    f"{q[np.argmax(bad), 0]:.9g}: no intersection, values are null"
                )
    return out


def _infeasible(r: KinematicsResult) -> list[str]:
    """Runs of frames that do not assemble, with their q range."""
    bad = np.concatenate([[False], ~r.valid, [False]])
    starts = np.flatnonzero(bad[1:] & ~bad[:-1])
    ends = np.flatnonzero(~bad[1:] & bad[:-1]) - 1
    out = [
        f"no assembly for q in [{r.q[i, 0]:.9g}, {r.q[j, 0]:.9g}] (frames {i}..{j}); "
        "values are null"
        for i, j in zip(starts, ends, strict=True)
    ]
    after = [int(j) + 1 for j in ends if j + 1 < r.valid.size]
    # only steps with an assembly mode (circle intersections, closures) can carry the
    # wrong branch across a gap; line-line dyads (PRP, RPP) have a single solution
    has_modes = any(s.kind in ("RRR", "RRP", "RPR") or s.is_closure for s in r.plan.steps)
    if after and has_modes:
        # the motion cannot physically cross an infeasible interval: say so
        out.append(
            f"frames from {after[0]} on assemble again after an infeasible interval: found "
            "by continuation across the gap (same assembly modes), not a physical motion"
        )
    return out


def _checks(r: KinematicsResult, ev: Evaluation) -> None:
    m, g, v = r.mechanism, r.geometry, r.valid
    # link lengths: every pair of centres (and points) on one link over the valid frames
    worst = 0.0
    worst_link = ""
    for link in m.links:
        ids = [j for j in m.link_joints[link] if m.joint(j).kind == "R"]
        ids += [p for p, (lk, _) in g.points.items() if lk == link]
        pos = {i: _position(r, i) for i in ids}
        ref = {i: g.centres[i] if i in g.centres else g.points[i][1] for i in ids}
        for a_i, a in enumerate(ids):
            for b in ids[a_i + 1 :]:
                d = np.abs(pos[a][v] - pos[b][v]) - abs(ref[a] - ref[b])
                e = float(np.abs(d).max()) if d.size else 0.0
                if e > worst:
                    worst, worst_link = e, link
    r.checks["link_lengths"] = {"max_error": worst, "link": worst_link or None}
    # analogs against central differences of positions (uniform sweeps only); the
    # five-point stencil (error ~ h^4 x^(5)/30) so that a disagreement means a wrong
    # analog or a branch jump, not the coarseness of the frames
    q = r.q[:, 0]
    F = q.size
    if F >= 7 and r.q.shape[1] == 1 and np.allclose(np.diff(q), q[1] - q[0], rtol=1e-9, atol=0):
        h = q[1] - q[0]
        err, big, at = 0.0, 0.0, None
        ok = v[4:] & v[3:-1] & v[2:-2] & v[1:-3] & v[:-4]
        for data in list(r.joints.values()) + list(r.points.values()):
            for c, s in (("x", "sx"), ("y", "sy")):
                x, sx = data[c], data[s]
                fd = (x[:-4] - 8 * x[1:-3] + 8 * x[3:-1] - x[4:]) / (12 * h)
                if ok.any():
                    dev = np.where(ok, np.abs(fd - sx[2:-2]), 0.0)
                    k = int(dev.argmax())
                    if dev[k] > err:
                        err, at = float(dev[k]), float(q[k + 2])
                    big = max(big, float(np.abs(sx[2:-2])[ok].max()))
        r.checks["analogs_vs_differences"] = {
            "max_error": err,
            "max_analog": big,
            "step": float(h),
            "q_of_max_error": at,
        }
    # constraint Jacobian: rank (mobility refinement) and driver-fixed determinant
    with np.errstate(all="ignore"):
        jc = check_jacobian(m, g, ev.poses, r.plan.drivers)
    r.jacobian = jc
    ranks = sorted({int(x) for x in jc.rank[v] if x >= 0}) if v.any() else []
    dets = np.abs(jc.det)
    top = float(np.nanmax(dets[v])) if v.any() and np.isfinite(dets[v]).any() else float("nan")
    flagged = (
        np.flatnonzero(v & (dets < NEAR_SINGULAR * top)) if np.isfinite(top) else np.zeros(0, int)
    )
    dof = jc.coordinates - (max(ranks) if ranks else 0)
    r.checks["jacobian"] = {
        "equations": jc.equations,
        "coordinates": jc.coordinates,
        "rank": ranks,
        "rank_frames": int((jc.rank[v] >= 0).sum()),
        "redundant_constraints": jc.equations - max(ranks) if ranks else None,
        "dof": dof,
        "min_abs_det": float(np.nanmin(dets[v])) if np.isfinite(dets[v]).any() else None,
        "max_abs_det": top if np.isfinite(top) else None,
        "near_singular_frames": [int(i) for i in flagged],
    }
    if len(flagged):
        r.warnings.append(
            f"near-singular Jacobian (|det| < {NEAR_SINGULAR:g} of its maximum) at "
            f"{len(flagged)} frame(s), first q = {r.q[flagged[0], 0]:.9g}"
        )
    if ranks and max(ranks) < jc.equations:
        r.warnings.append(
            f"constraint Jacobian rank {max(ranks)} < {jc.equations} equations: "
            f"{jc.equations - max(ranks)} redundant constraint(s)"
        )


def _position(r: KinematicsResult, ident: str) -> np.ndarray:
    d = r.joints.get(ident) or r.points[ident]
    return d["x"] + 1j * d["y"]
