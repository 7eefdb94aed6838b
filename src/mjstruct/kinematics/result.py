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

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from mjstruct import display
from mjstruct.kinematics.accuracy import ErrorEstimate, error_estimate
from mjstruct.kinematics.branches import BranchEvent
from mjstruct.kinematics.closure import Closure
from mjstruct.kinematics.evaluate import Evaluation
from mjstruct.kinematics.geometry import Geometry
from mjstruct.kinematics.jacobian import JacobianCheck
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.kinematics.planner import Plan
from mjstruct.mechanism import Mechanism
from mjstruct.output_numbers import json_list, json_number

FloatArray = npt.NDArray[np.float64]
ComplexArray = npt.NDArray[np.complex128]
BoolArray = npt.NDArray[np.bool_]
#: an item's (or every item's stacked) value, first and second derivative
Jets = tuple[npt.NDArray[Any], ...]


@dataclass
class KinematicsResult:
    """Positions, analogs, velocities and accelerations over the frames, with the report.

    ``q`` (frames × drivers); ``valid`` frames that assemble; ``joints`` / ``points``:
    id -> {x, y, vx, vy, ax, ay, sx, sy, kx, ky} arrays (s: velocity analogs, k:
    acceleration analogs); ``links``: id -> {angle, omega, eps, sigma, kappa} (each a
    :class:`Table`: stacked arrays, rows read as views);
    ``checks``: the checks by name (those that word no warning are computed when
    ``checks`` is first read, see :meth:`check_on_demand`).
    """

    model: KinematicModel
    q: FloatArray
    speed: float
    valid: BoolArray
    joints: Table
    points: Table
    links: Table
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
    #: frames that assemble but that no continuous motion from the reference reaches
    #: (past an interval that does not assemble, either way round): another assembly,
    #: null in the tables, their positions in :meth:`another_assembly_dict`; default: none
    another_assembly: BoolArray | None = None
    #: the motion the tables come from (for the error estimates, made when read)
    _motion: Motion | None = field(default=None, repr=False)
    _error: ErrorEstimate | None = field(default=None, repr=False)
    _on_demand: Callable[[KinematicsResult], dict[str, Any]] | None = field(
        default=None, repr=False
    )

    @property
    def checks(self) -> dict[str, Any]:
        """The checks by name (their JSON object); deferred ones are computed here."""
        if self._on_demand is not None:
            compute, self._on_demand = self._on_demand, None
            # the deferred checks come first, in the order the report gives them
            self._checks = {**compute(self), **self._checks}
        return self._checks

    def check_on_demand(self, compute: Callable[[KinematicsResult], dict[str, Any]]) -> None:
        """Defer checks that word no warning until :attr:`checks` is read.

        ``compute(result)`` returns them by name; a result passed over (positions read,
        checks never looked at) does not pay for them.  It is given the result when
        called rather than holding it (a function holding its result would make a
        reference cycle, and a result of a large sweep would stay in memory until the
        cyclic garbage collector runs).
        """
        if self._on_demand is not None:
            earlier = self._on_demand
            self._on_demand = lambda r: {**earlier(r), **compute(r)}
        else:
            self._on_demand = compute

    @property
    def error(self) -> ErrorEstimate | None:
        """Per frame, estimates of the largest error of the positions, velocities and
        accelerations (from the residual and the conditioning of the plan's groups;
        :mod:`~mjstruct.kinematics.accuracy`); None without the motion (a streamed
        chunk).  Made when first read."""
        if self._error is None and self._motion is not None:
            self._error = self._estimate(self._motion)
        return self._error

    def _estimate(self, motion: Motion) -> ErrorEstimate:
        S = np.zeros(self.q.shape[0])
        K = np.zeros(self.q.shape[0])
        with np.errstate(invalid="ignore"):
            for table in (self.joints, self.points):
                if len(table):
                    jets = table.stacks()
                    S = np.fmax(S, np.abs(jets[1]).max(axis=0))
                    K = np.fmax(K, np.abs(jets[2]).max(axis=0))
        return error_estimate(motion, self.speed, S, K, self.valid)

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
                    "q": json_number(e.q),
                    "frame": e.frame,
                    "joint": e.joint,
                    "kind": e.kind,
                    "sine": json_number(e.sine),
                    "mode": e.action,
                }
                for e in self.events
            ],
            "checks": self.checks,
            "closure": None if self.closure is None else self._closure_dict(),
            "another_assembly": self.another_assembly_dict(),
            "error": self._error_dict(),
        }

    def _error_dict(self) -> dict[str, list[float | None]] | None:
        e = self.error
        if e is None:
            return None
        return {
            "position": json_list(e.position),
            "velocity": json_list(e.velocity),
            "acceleration": json_list(e.acceleration),
            "conditioning": json_list(e.conditioning),
        }

    def another_assembly_dict(self) -> dict[str, Any] | None:
        """The frames of another assembly (not reached from the reference) and the joint
        centres there, or None when every frame that assembles is reached."""
        other = self.another_assembly
        if other is None or not other.any():
            return None
        idx = np.flatnonzero(other)
        xy = self.joints.values_at(idx)
        return {
            "frames": [int(i) for i in idx],
            "note": "assembled, but not reached by a continuous motion from the reference",
            "joints": {
                j: {"x": json_list(xy[k].real), "y": json_list(xy[k].imag)}
                for k, j in enumerate(self.joints)
            },
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


#: the keys of a joint's or point's row: stack, part, power of the speed
POINT_KEYS: dict[str, tuple[int, str, int]] = {
    "x": (0, "real", 0), "y": (0, "imag", 0),
    "vx": (1, "real", 1), "vy": (1, "imag", 1),
    "ax": (2, "real", 2), "ay": (2, "imag", 2),
    "sx": (1, "real", 0), "sy": (1, "imag", 0),
    "kx": (2, "real", 0), "ky": (2, "imag", 0),
}  # fmt: skip
#: the keys of a link's row: stack, part (none: real), power of the speed
LINK_KEYS: dict[str, tuple[int, str, int]] = {
    "angle": (0, "", 0),
    "omega": (1, "", 1),
    "eps": (2, "", 2),
    "sigma": (1, "", 0),
    "kappa": (2, "", 0),
}


class Table(Mapping[str, Mapping[str, FloatArray]]):
    """Items by id (joints, points or links) -> their arrays over the frames.

    Each item has a jet of three arrays over the frames: for joints and points the
    complex position, σ and κ (``x`` is the real part of the first, ``sx`` of the
    second…), for links the angle, σ and κ.  ``table[id]`` is that item's row, a
    mapping of views built when read; velocities and accelerations are the analogs
    times the speed W and W², computed when read (the same arithmetic as scaling each
    array).  The jets themselves are made when first needed: one item's when its row
    is read, every item's at once, stacked items × frames, when a whole
    :meth:`column` is (the JSON object, the table, the checks), so a result whose
    tables are never read does not pay for them.

    >>> P = np.array([[1 + 2j, 3 + 4j]])
    >>> t = Table.of_stacks(("B",), (P, 2 * P, 3 * P), POINT_KEYS, 2.0)
    >>> t["B"]["y"].tolist(), t["B"]["vx"].tolist(), list(t["B"])[:4]
    ([2.0, 4.0], [4.0, 12.0], ['x', 'y', 'vx', 'vy'])
    >>> t.column("ax").tolist()
    [[12.0, 36.0]]
    """

    __slots__ = ("_all", "_at", "_index", "_keys", "_one", "_rows", "_stacks", "ids", "speed")

    def __init__(
        self,
        ids: tuple[str, ...],
        keys: dict[str, tuple[int, str, int]],
        speed: float,
        one: Callable[[int], Jets],
        every: Callable[[], Jets],
        at: Callable[[npt.NDArray[np.intp]], npt.NDArray[Any]] | None = None,
    ) -> None:
        self.ids = ids
        self._index = {x: k for k, x in enumerate(ids)}
        self._keys = keys
        self.speed = speed
        self._one, self._all, self._at = one, every, at
        self._rows: dict[int, Jets] = {}
        self._stacks: Jets | None = None

    @classmethod
    def of_stacks(
        cls,
        ids: tuple[str, ...],
        stacks: Jets,
        keys: dict[str, tuple[int, str, int]],
        speed: float,
    ) -> Table:
        """A table of jets already stacked (items × frames each)."""
        return cls(ids, keys, speed, lambda i: tuple(a[i] for a in stacks), lambda: stacks)

    def keys_of_rows(self) -> tuple[str, ...]:
        """The keys every row has."""
        return tuple(self._keys)

    def _jets(self, i: int) -> Jets:
        if self._stacks is not None:
            return tuple(a[i] for a in self._stacks)
        got = self._rows.get(i)
        if got is None:
            # frames near a singular position may carry infinite analogs (not valid,
            # reported): their arithmetic must not warn
            with np.errstate(all="ignore"):
                got = self._rows[i] = self._one(i)
        return got

    def stacks(self) -> Jets:
        """The three jets of every item, items × frames each (made once)."""
        if self._stacks is None:
            with np.errstate(all="ignore"):
                self._stacks = self._all()
            self._rows.clear()
        return self._stacks

    def _scaled(self, a: npt.NDArray[Any], key: str) -> FloatArray:
        _, part, power = self._keys[key]
        if part:
            a = getattr(a, part)
        if power and self.speed != 1.0:
            with np.errstate(all="ignore"):
                a = a * (self.speed if power == 1 else self.speed * self.speed)
        return a

    def column(self, key: str) -> FloatArray:
        """``key`` of every item, items × frames (in :attr:`ids` order)."""
        return self._scaled(self.stacks()[self._keys[key][0]], key)

    def value(self, ident: str, key: str) -> FloatArray:
        """``key`` of one item over the frames (``table[ident][key]``)."""
        return self._scaled(self._jets(self._index[ident])[self._keys[key][0]], key)

    def values_at(self, frames: npt.NDArray[np.intp]) -> npt.NDArray[Any]:
        """Every item's value (first jet: complex position, or angle) at a few frames,
        items × frames, without making the whole jets when they are not made yet."""
        if self._stacks is None and self._at is not None:
            with np.errstate(all="ignore"):
                return self._at(frames)
        return self.stacks()[0][:, frames]

    def __getitem__(self, ident: str) -> Mapping[str, FloatArray]:
        if ident not in self._index:
            raise KeyError(ident)
        return _Row(self, ident)

    def __iter__(self) -> Iterator[str]:
        return iter(self.ids)

    def __len__(self) -> int:
        return len(self.ids)

    def __contains__(self, ident: object) -> bool:
        return ident in self._index

    def frames_from(self, n: int) -> Table:
        """The same table from frame ``n`` on (views, no copy)."""
        return Table(
            self.ids,
            self._keys,
            self.speed,
            lambda i: tuple(a[n:] for a in self._jets(i)),
            lambda: tuple(a[:, n:] for a in self.stacks()),
        )


class _Row(Mapping[str, FloatArray]):
    """One item's arrays over the frames, by key (read from its table)."""

    __slots__ = ("_ident", "_table")

    def __init__(self, table: Table, ident: str) -> None:
        self._table, self._ident = table, ident

    def __getitem__(self, key: str) -> FloatArray:
        return self._table.value(self._ident, key)

    def __iter__(self) -> Iterator[str]:
        return iter(self._table._keys)

    def __len__(self) -> int:
        return len(self._table._keys)


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
    are not valid).

    The tables are stacked arrays (items × frames, one per jet of the joints, of the
    points, of the links' angles and rates); a row is a view, and the velocities and
    accelerations are scaled from the analogs when read (:class:`Table`).
    """
    km, ev, q = motion.model, motion.evaluation, motion.q
    m, geom = km.mechanism, km.geometry
    if motion.order < 2:
        raise ValueError("collect: the motion must carry second derivatives (order 2)")
    W = float(speed)
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

    joint_ids = tuple(j.id for j in m.joints)
    items: list[tuple[str | None, complex, str]] = [
        (ev.carrier(j), geom.centres[j], j) for j in joint_ids
    ]
    nj = len(items)
    items += [(link, z, pid) for pid, (link, z) in geom.points.items()]
    joints = _point_table(ev, joint_ids, items[:nj], W)
    points = _point_table(ev, tuple(geom.points), items[nj:], W)
    links = _link_table(ev, tuple(m.links), m.frame, geom.char_angle, bool(valid.all()), W)
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
        _motion=motion,
    )


def _point_table(
    ev: Evaluation, ids: tuple[str, ...], items: list[tuple[str | None, complex, str]], W: float
) -> Table:
    """Joints or points: each one's jet from the pose that carries it (or as solved)."""

    def one(i: int) -> Jets:
        link, z, joint = items[i]
        jet = ev.solved[joint] if link is None else ev.poses[link].point(z)
        return tuple(jet[:3])

    def every() -> Jets:
        return tuple(ev.stacked(items))

    def at(frames: npt.NDArray[np.intp]) -> npt.NDArray[Any]:
        # the first jet of Pose.point on those frames only (the same arithmetic)
        out = np.empty((len(items), frames.size), complex)
        for i, (link, z, joint) in enumerate(items):
            if link is None:
                out[i] = ev.solved[joint][0][frames]
                continue
            p = ev.poses[link]
            out[i] = p.A[0][frames] if z == p.zA else p.A[0][frames] + p.r[frames] * (z - p.zA)
        return out

    return Table(ids, POINT_KEYS, W, one, every, at)


def _link_table(
    ev: Evaluation,
    ids: tuple[str, ...],
    frame: str | None,
    char_angle: Mapping[str, float],
    all_valid: bool,
    W: float,
) -> Table:
    """Links: the angle (unwrapped over the frames, from the reference's characteristic
    angle), σ and κ of each from its pose."""
    poses = ev.poses

    def angle_of(x: str) -> FloatArray:
        if x == frame:
            return np.zeros(poses[x].r.shape[-1]) + char_angle[x]
        theta = np.angle(poses[x].r)[None, :]
        if all_valid or np.isfinite(theta).all():
            theta = unwrap_rows(theta)
        else:
            ok = np.isfinite(theta[0])
            if ok.any():
                theta[0, ok] = unwrap_rows(theta[:, ok])[0]
        out: FloatArray = theta[0] + char_angle[x]
        return out

    def one(i: int) -> Jets:
        x = ids[i]
        return angle_of(x), poses[x].w[0], poses[x].w[1]

    def every() -> Jets:
        F = poses[ids[0]].r.shape[-1]
        angle = np.zeros((len(ids), F))
        rows = [k for k, x in enumerate(ids) if x != frame]
        if rows:
            # the angles of every moving link at once (one unwrap over the rows: the
            # same values as row by row); a row with gaps unwraps over its finite frames
            angles = np.angle(np.stack([poses[ids[k]].r for k in rows]))
            if all_valid:
                angles = unwrap_rows(angles)
            else:
                whole = np.isfinite(angles).all(axis=1)
                if whole.any():
                    angles[whole] = unwrap_rows(angles[whole])
                for k in np.flatnonzero(~whole):
                    theta = angles[k]
                    ok = np.isfinite(theta)
                    if ok.any():
                        theta[ok] = unwrap_rows(theta[ok][None, :])[0]
            angle[rows] = angles
        angle += np.array([char_angle[x] for x in ids])[:, None]
        sigma = np.stack([poses[x].w[0] for x in ids])
        kappa = np.stack([poses[x].w[1] for x in ids])
        return angle, sigma, kappa

    return Table(ids, LINK_KEYS, W, one, every)
