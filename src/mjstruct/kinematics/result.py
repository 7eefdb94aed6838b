"""The result of a kinematic analysis: tables over the frames, the JSON object, the table.

Owns :class:`KinematicsResult` (positions, analogs σ = ds/dq and κ = dσ/dq,
velocities ``v = σ q̇`` and accelerations ``a = κ q̇² + σ q̈`` at constant driver
speed, the branch points, warnings and checks) and :func:`collect`, which builds its
tables from a solved :class:`~mjstruct.kinematics.model.Motion`.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("four-bar")))
>>> r = collect(model.motion(model.sweep(frames=8)), speed=2.0)
>>> names, data = r.table()
>>> names[:3], data.shape
(['q', 'O1.x', 'O1.y'], (8, 43))
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from mjstruct import display
from mjstruct.kinematics.branches import BranchEvent
from mjstruct.kinematics.closure import Closure
from mjstruct.kinematics.geometry import Geometry
from mjstruct.kinematics.jacobian import JacobianCheck
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.kinematics.planner import Plan
from mjstruct.kinematics.triangles import Jet
from mjstruct.mechanism import Mechanism

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


@dataclass
class KinematicsResult:
    """Positions, analogs, velocities and accelerations over the frames, with the report.

    ``q`` (frames × drivers); ``valid`` frames that assemble; ``joints`` / ``points``:
    id -> {x, y, vx, vy, ax, ay, sx, sy, kx, ky} arrays (s: velocity analogs, k:
    acceleration analogs); ``links``: id -> {angle, omega, eps, sigma, kappa};
    ``checks``: the checks by name (those that word no warning are computed when
    ``checks`` is first read, see :meth:`check_on_demand`).
    """

    model: KinematicModel
    q: FloatArray
    speed: float
    valid: BoolArray
    joints: dict[str, dict[str, FloatArray]]
    points: dict[str, dict[str, FloatArray]]
    links: dict[str, dict[str, FloatArray]]
    events: list[BranchEvent]
    warnings: list[str]
    _checks: dict[str, Any]
    closure: Closure | None = None
    jacobian: JacobianCheck | None = field(default=None, repr=False)
    #: frames whose positions exist (``valid`` ones, and singular frames where only the
    #: velocities and accelerations are infinite); default: ``valid``
    assembled: BoolArray | None = None
    #: frames where only some groups assemble (a later group does not): there each
    #: joint, point and link is given where its own values exist (finite), the items
    #: of the groups that do not assemble are null; default: none
    partial: BoolArray | None = None
    _on_demand: Callable[[], dict[str, Any]] | None = field(default=None, repr=False)

    @property
    def checks(self) -> dict[str, Any]:
        """The checks by name (their JSON object); deferred ones are computed here."""
        if self._on_demand is not None:
            compute, self._on_demand = self._on_demand, None
            # the deferred checks come first, in the order the report gives them
            self._checks = {**compute(), **self._checks}
        return self._checks

    def check_on_demand(self, compute: Callable[[], dict[str, Any]]) -> None:
        """Defer checks that word no warning until :attr:`checks` is read.

        ``compute`` returns them by name; a result passed over (positions read, checks
        never looked at) does not pay for them.
        """
        if self._on_demand is not None:
            earlier = self._on_demand
            self._on_demand = lambda: {**earlier(), **compute()}
        else:
            self._on_demand = compute

    @property
    def placed(self) -> BoolArray:
        """Frames with positions: ``assembled`` (``valid`` when not given)."""
        return self.valid if self.assembled is None else self.assembled

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

    def _repr_svg_(self) -> str | None:
        """Notebook picture (drawn by the renderer of :mod:`mjstruct.display`)."""
        return display.svg(self)

    def to_dict(self) -> dict[str, Any]:
        """The contract's JSON object (nulls where a frame does not assemble)."""

        placed, valid = self.placed, self.valid
        if self.partial is not None:
            # the items of the groups that assemble keep their (finite) values
            placed, valid = placed | self.partial, valid | self.partial

        def lst(a: FloatArray, key: str) -> list[float | None]:
            mask = placed if key in _POSITIONS else valid
            return [
                float(x) if ok and np.isfinite(x) else None for x, ok in zip(a, mask, strict=True)
            ]

        keys_p = ("x", "y", "vx", "vy", "ax", "ay")
        keys_l = ("angle", "omega", "eps")
        q = self.q[:, 0] if self.q.shape[1] == 1 else self.q
        q_out: list[Any] = [float(x) for x in q] if q.ndim == 1 else q.tolist()
        return {
            "name": self.mechanism.name,
            "drivers": list(self.plan.drivers),
            "speed": self.speed,
            "q": q_out,
            "joints": {j: {k: lst(v[k], k) for k in keys_p} for j, v in self.joints.items()},
            "links": {x: {k: lst(v[k], k) for k in keys_l} for x, v in self.links.items()},
            "points": {p: {k: lst(v[k], k) for k in keys_p} for p, v in self.points.items()},
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

    def table(self) -> tuple[list[str], FloatArray]:
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
        nq = self.q.shape[1]
        position = np.array([n.rsplit(".", 1)[-1] in _POSITIONS for n in names[nq:]])
        placed, valid = self.placed, self.valid
        if self.partial is not None:
            placed, valid = placed | self.partial, valid | self.partial
            # a partly assembled frame keeps the finite values of the groups that assemble
            rows = data[self.partial]
            rows[~np.isfinite(rows)] = np.nan
            data[self.partial] = rows
        data[np.ix_(~placed, np.flatnonzero(position) + nq)] = np.nan
        data[np.ix_(~valid, np.flatnonzero(~position) + nq)] = np.nan
        return names, data


def unwrap_rows(p: FloatArray) -> FloatArray:
    """``np.unwrap(p, axis=1)`` bit for bit, the modulo taken only at the jumps.

    The same arithmetic as numpy's (period 2π, jumps of at least π corrected, the
    ambiguous boundary kept positive); a sweep's angles jump at a few frames, so the
    modulo over every difference, most of numpy's time, is left out.

    >>> p = np.array([[0.0, 3.0, -3.0, -0.5, 3.1]])
    >>> bool((unwrap_rows(p) == np.unwrap(p, axis=1)).all())
    True
    """
    period = 2 * np.pi
    high = period / 2
    low = -high
    dd = np.diff(p, axis=1)
    rows, cols = np.nonzero(np.abs(dd) >= high)
    # numpy adds a zero correction before any jump (-0.0 becomes 0.0), none to column 0
    up: FloatArray = np.empty_like(p)
    up[:, 0] = p[:, 0]
    np.add(p[:, 1:], 0.0, out=up[:, 1:])
    if rows.size == 0:
        return up
    d = dd[rows, cols]
    dmod = np.mod(d - low, period) + low
    np.copyto(dmod, high, where=(dmod == low) & (d > 0))
    ph = dmod - d
    if rows.size > MANY_JUMPS:
        full = np.zeros_like(dd)
        full[rows, cols] = ph
        up[:, 1:] = p[:, 1:] + full.cumsum(axis=1)
        return up
    # the running correction is constant between jumps: add it segment by segment (the
    # same sums as numpy's cumulative sum, whose zeros add nothing)
    n = p.shape[1]
    for row in np.unique(rows):
        at = rows == row
        where, total = cols[at] + 1, ph[at].cumsum()
        for k, a in enumerate(where):
            b = where[k + 1] if k + 1 < where.size else n
            np.add(p[row, a:b], total[k], out=up[row, a:b])
    return up


#: above this many jumps in all :func:`unwrap_rows` corrects with one cumulative sum
MANY_JUMPS = 64


#: the table's position columns (given on every assembled frame, singular ones too)
_POSITIONS = frozenset({"x", "y", "angle"})


def collect(motion: Motion, speed: float) -> KinematicsResult:
    """The result's tables from a solved motion: positions, analogs, velocities and
    accelerations at constant driver speed ``speed`` (frames with a non-finite value
    are not valid)."""
    km, ev, q = motion.model, motion.evaluation, motion.q
    m, geom = km.mechanism, km.geometry
    if motion.order < 2:
        raise ValueError("collect: the motion must carry second derivatives (order 2)")
    W = float(speed)
    W2 = W * W
    # every centre and point is a function of the link poses, whose finiteness the
    # motion's ``valid`` already holds; at unit speed velocities are the analogs
    valid = motion.valid.copy()
    # a singular frame (a dead point of the drivers) has positions but infinite
    # derivatives: it assembles, though it is not valid
    # (a frame that breaks a redundant constraint has finite derivatives: not assembled)
    partial = None
    if valid.all():
        assembled = valid.copy()  # every frame valid: every frame assembles
    else:
        pos_ok, der_ok = np.ones_like(valid), np.ones_like(valid)
        for pose in ev.poses.values():
            pos_ok &= np.isfinite(pose.r + pose.A[0])
            der_ok &= np.isfinite(sum(pose.A[1:]) + sum(pose.w))
        if motion.closure is not None:
            pos_ok &= motion.closure.converged
        assembled = valid | (pos_ok & ~der_ok)
        # some link has no position there: its group (and those after it) does not
        # assemble, the others do (a frame that breaks a redundant constraint has every
        # position: nothing moves there)
        partial = ~pos_ok if (~pos_ok).any() else None

    def scaled(a: FloatArray, k: float) -> FloatArray:
        return a if k == 1.0 else a * k

    def pack(X: Jet) -> dict[str, FloatArray]:
        sx, sy, kx, ky = X[1].real, X[1].imag, X[2].real, X[2].imag
        return {
            "x": X[0].real, "y": X[0].imag,
            "vx": scaled(sx, W), "vy": scaled(sy, W),
            "ax": scaled(kx, W2), "ay": scaled(ky, W2),
            "sx": sx, "sy": sy, "kx": kx, "ky": ky,
        }  # fmt: skip

    joints = {j.id: pack(ev.centre(j.id)) for j in m.joints}
    points = {pid: pack(ev.poses[link].point(z)) for pid, (link, z) in geom.points.items()}
    links: dict[str, dict[str, FloatArray]] = {}
    moving = {x: i for i, x in enumerate(x for x in m.links if x != m.frame)}
    # the angles of every moving link at once (one unwrap over the rows: the same
    # values as row by row); a row with gaps is unwrapped over its finite frames
    angles = np.angle(np.stack([ev.poses[x].r for x in moving])) if moving else np.zeros((0, 0))
    if valid.all():
        # every rotation is finite: every row unwraps whole, without a masked copy
        whole = np.ones(len(moving), dtype=bool)
        angles = unwrap_rows(angles) if moving else angles
    else:
        whole = np.asarray(np.isfinite(angles).all(axis=1), dtype=bool)
        if whole.any():
            angles[whole] = unwrap_rows(angles[whole])
    for link in m.links:
        p = ev.poses[link]
        if link not in moving:
            theta = np.zeros(q.shape[0])
        else:
            theta = angles[moving[link]]
            ok = np.isfinite(theta)
            if not whole[moving[link]] and ok.any():
                theta[ok] = unwrap_rows(theta[ok][None, :])[0]
        links[link] = {
            "angle": theta + geom.char_angle[link],
            "omega": scaled(p.w[0], W),
            "eps": scaled(p.w[1], W2),
            "sigma": p.w[0],
            "kappa": p.w[1],
        }
    return KinematicsResult(
        km,
        q,
        W,
        valid,
        joints,
        points,
        links,
        list(motion.events),
        [],
        {},
        motion.closure,
        assembled=assembled,
        partial=partial,
    )
