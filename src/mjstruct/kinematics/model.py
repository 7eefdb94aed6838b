"""The kinematic model: a mechanism, its reference geometry and its plan, frozen together.

Owns :class:`KinematicModel` (what the solver, the closure, the branch tracking, the
checks, the dynamics and the drawings all take) and :class:`Motion`, the solved
position functions of a model over a set of driver values: the poses of every link as
jets ``[value, d/dτ, d²/dτ²]``, which frames assemble, the closure unknowns and the
branch points met.  A model is built once (reading the geometry and planning are the
costly parts) and then solved on as many driver values as needed.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> model = KinematicModel.build(read_mechanism(example_path("four-bar")))
>>> model.drivers, model.frame
(('O1',), '0')
>>> motion = model.motion(model.sweep(frames=4))
>>> bool(motion.valid.all()), len(motion.q)
(True, 4)
>>> x = motion.centre("B")[0]          # centre of joint B over the four frames
>>> bool(abs(x[0] - model.geometry.centres["B"]) < 1e-12)   # frame 0 is the reference
True
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from contextlib import nullcontext
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError, expect_ids
from mjstruct.kinematics.branches import BranchEvent, track_branches
from mjstruct.kinematics.closure import Closure, close
from mjstruct.kinematics.evaluate import Evaluation, evaluate, reference_mode
from mjstruct.kinematics.geometry import Geometry, geometry_of
from mjstruct.kinematics.jacobian import one_blas_thread
from mjstruct.kinematics.planner import Plan, plan_checked
from mjstruct.kinematics.steps.base import Modes
from mjstruct.kinematics.tolerances import CLOSURE_TOL, REDUNDANT_HOLDS, TOL_FLOOR
from mjstruct.kinematics.triangles import Jet
from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.structure.assur import Decomposition
from mjstruct.structure.drivers import validate_drivers

__all__ = ["CLOSURE_TOL", "KinematicModel", "Motion"]

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


@dataclass(frozen=True)
class KinematicModel:
    """A mechanism with its reference geometry and the plan of its position analysis.

    Build it with :meth:`build`; the three parts are read-only and travel together.

    Attributes
    ----------
    mechanism : the link–joint graph (with ``at``/``axis`` geometry).
    geometry : the reference configuration read from the file.
    plan : the triangle steps (and closure unknowns) for the chosen drivers.
    """

    mechanism: Mechanism
    geometry: Geometry
    plan: Plan

    @classmethod
    def build(
        cls,
        mechanism: Mechanism,
        drivers: Iterable[str] | None = None,
        decomposition: Decomposition | None = None,
    ) -> KinematicModel:
        """Read the geometry and plan the analysis for ``drivers`` (default: the file's).

        Parameters
        ----------
        mechanism : a mechanism whose joints carry ``at`` (and ``axis`` for sliders).
        drivers : joint ids of the generalised coordinates.
        decomposition : an Assur decomposition to follow (default: computed).

        Raises
        ------
        MechanismError
            not a mechanism, missing geometry, or drivers that do not determine it.

        Notes
        -----
        This is where a mechanism and its drivers are checked, once: the model is the
        validated object that the kinematics, the dynamics and the drawings take, and
        they trust it.
        """
        expect_mechanism(mechanism, "mechanism")
        expect_ids(drivers, "drivers")
        drv = validate_drivers(mechanism, drivers, balance=False)
        return cls.from_geometry(mechanism, geometry_of(mechanism, drv), decomposition)

    @classmethod
    def from_geometry(
        cls,
        mechanism: Mechanism,
        geometry: Geometry,
        decomposition: Decomposition | None = None,
    ) -> KinematicModel:
        """Plan a mechanism whose geometry is read and checked (no second check).

        ``geometry`` is :func:`~mjstruct.kinematics.geometry.geometry_of` the mechanism
        for checked drivers (its ``driver_ref`` keys, in order, are the drivers): for an
        entry point that has already checked its inputs (the dynamics reads its data
        between the geometry and the plan).
        """
        drv = tuple(geometry.driver_ref)
        plan = plan_checked(mechanism, drv, geometry, decomposition)
        return cls(mechanism, geometry, plan)

    @cached_property
    def step_dependencies(self) -> tuple[tuple[int, ...], ...]:
        """For each step of the plan, the steps its evaluation needs (itself included).

        From what each step kind reads (:attr:`~mjstruct.kinematics.steps.StepKind.reads`):
        the steps that placed the links and first carried the joint centres it reads,
        and theirs in turn.  Evaluating one step with only these
        (``evaluate(..., only=...)``) costs what its own group costs, not the plan's
        prefix.
        """
        m = self.mechanism
        placed_by: dict[str, int] = {}
        carried_by: dict[str, int] = {}
        out: list[frozenset[int]] = []
        for k, s in enumerate(self.plan.steps):
            kind = s.step_kind
            if kind.reads is None:
                need: frozenset[int] = frozenset(range(k + 1))
            else:
                links, joints = kind.reads(s, m)
                direct = {placed_by[x] for x in links if x in placed_by}
                direct |= {carried_by[j] for j in joints if j in carried_by}
                need = frozenset({k}.union(direct, *(out[i] for i in direct)))
            out.append(need)
            if kind.equations == 0:
                for x in s.links:
                    placed_by.setdefault(x, k)
                    for j in m.link_joints[x]:
                        carried_by.setdefault(j, k)
        return tuple(tuple(sorted(d)) for d in out)

    def first_links(self, only: tuple[int, ...] | None, upto: int | None) -> dict[str, str]:
        """Joint -> the first link placed that carries it, for evaluations of the steps
        ``only`` (or the first ``upto``, or all), as found so far.

        The placement order of a set of steps is the plan's, so what one evaluation
        finds holds for the next (an evaluation found each anew: a tenth of the cost of
        evaluating a few stations).  Filled by the evaluations themselves.
        """
        memo: dict[tuple[tuple[int, ...] | None, int | None], dict[str, str]]
        memo = self.__dict__.setdefault("_first_links", {})
        return memo.setdefault((only, upto), {})

    def _same_modes(self, a: Modes | None, b: Modes | None) -> bool:
        """Whether two sets of assembly modes are the same on every frame (a step
        missing: the reference configuration's mode)."""
        a, b = a or {}, b or {}
        for k in set(a) | set(b):
            ref = reference_mode(self.plan, self.geometry, k)
            if not np.all(np.asarray(a.get(k, ref)) == np.asarray(b.get(k, ref))):
                return False
        return True

    @property
    def drivers(self) -> tuple[str, ...]:
        """The driver joints (generalised coordinates), in order."""
        return self.plan.drivers

    @property
    def frame(self) -> str:
        """The frame link."""
        return self.plan.frame

    @property
    def scale(self) -> float:
        """The mechanism's size: the largest distance between two joint centres."""
        return self.geometry.scale

    @property
    def q_ref(self) -> FloatArray:
        """Driver coordinates at the reference configuration."""
        return np.array([self.geometry.driver_ref[d] for d in self.drivers])

    def sweep(self, frames: int, speed: float = 1.0, stroke: float = 1.0) -> FloatArray:
        """Driver values (frames × drivers) over one cycle from the reference.

        A revolute driver turns a full turn, a prismatic one slides ``stroke``; frames
        are equally spaced with the end point excluded, in the direction of ``speed``.
        """
        if frames < 1:
            raise MechanismError(f"frames: must be >= 1, got {frames}")
        if not np.isfinite(speed) or speed == 0:
            raise MechanismError(f"speed: must be a finite nonzero number, got {speed}")
        cols = []
        for d in self.drivers:
            span = 2 * np.pi if self.mechanism.joint(d).kind == "R" else stroke
            ref = self.geometry.driver_ref[d]
            cols.append(ref + np.sign(speed) * span * np.arange(frames) / frames)
        return np.column_stack(cols)

    def driver_values(self, q: Sequence[float] | npt.ArrayLike) -> FloatArray:
        """``q`` checked and shaped as frames × drivers."""
        qa = np.asarray(q, float)
        qa = qa[:, None] if qa.ndim == 1 else qa
        if qa.ndim != 2 or qa.shape[1] != len(self.drivers) or qa.shape[0] < 1:
            raise MechanismError(f"q: expected frames × {len(self.drivers)} driver values")
        if not np.isfinite(qa).all():
            raise MechanismError("q: driver values must be finite")
        return qa

    def motion(
        self,
        q: Sequence[float] | npt.ArrayLike,
        order: int = 2,
        rates: Sequence[float] | npt.ArrayLike | None = None,
        tol: float = CLOSURE_TOL,
    ) -> Motion:
        """Solve the position functions on driver values ``q`` (taken as a path).

        Parameters
        ----------
        q : frames × drivers (or one value per frame for one driver).
        order : 0 positions only, 1 with first, 2 with second derivatives.
        rates : dq_i/dτ of each driver along the path (default 1: the derivatives
            are the analogs σ = ds/dq and κ = dσ/dq of a one-driver mechanism).
        tol : closure tolerance (relative to :attr:`scale`) for iterated groups, at
            least ``TOL_FLOOR`` (1e-15: a few rounding units of the size).
        """
        if not TOL_FLOOR <= tol < 1:
            raise MechanismError(
                f"tol: must be in [{TOL_FLOOR:g}, 1) (relative to the mechanism's size), "
                f"got {tol:g}"
            )
        qa = self.driver_values(q)
        rate = np.ones(len(self.drivers)) if rates is None else np.asarray(rates, float)
        plan, geom = self.plan, self.geometry
        warnings: list[str] = []
        sol: Closure | None = None
        t = t1 = t2 = None
        kept: list[tuple[Evaluation, Modes | None]] = []
        if plan.unknowns:
            # trouble is reported per frame below; one BLAS thread for the batched
            # small solves of Newton (threads only add wake-up cost there).  With one
            # closure equation every solve is a division (no BLAS): setting the
            # limit would cost more than the solves (tens of microseconds)
            blas = one_blas_thread() if plan.equations > 1 else nullcontext()
            with np.errstate(all="ignore"), blas:
                sol = close(self, qa, rate, tol=tol, order=order, keep=kept)
            # frames that did not close carry no configuration (null, reported)
            t = np.where(sol.converged[:, None], sol.t, np.nan)
            t1, t2 = sol.t1, sol.t2
            if sol.jumps:
                i = sol.jumps[0]
                warnings.append(
                    f"closure: the unknowns change faster than their derivative allows at "
                    f"{len(sol.jumps)} frame(s), first q = {qa[i, 0]:.9g}: possible jump to "
                    "another branch (a near-singular group or too coarse frames)"
                )
            bad = ~sol.converged
            if bad.any():
                warnings.append(
                    f"closure did not converge to {tol:g} on {int(bad.sum())} frame(s) "
                    f"(first q = {qa[np.argmax(bad), 0]:.9g}); their values are null"
                )
        # the closure's inner dyads take its modes per frame (they flip where a dyad
        # passes its own dead point inside the group)
        K0 = None if sol is None or not sol.modes else sol.modes
        # the closure's evaluation of t'' at these t and t' in these modes: positions
        # and first derivatives as they are
        lower = kept.pop()[0] if kept and self._same_modes(kept[0][1], K0) else None
        with np.errstate(all="ignore"):
            ev = evaluate(
                self, qa, order=order, rates=rate, t=t, t1=t1, t2=t2, K=K0, lower=lower, known=1
            )
            lower = None  # its own arrays of order 2 are not needed any more
            stops = () if sol is None else sol.stops
            K, events = track_branches(self, qa, t, first=ev, modes=K0, stops=stops)
            if any(e.action == "switched" for e in events):
                ev = evaluate(self, qa, order=order, rates=rate, t=t, t1=t1, t2=t2, K=K)
        valid = _finite_frames(ev, qa.shape[0])
        if plan.unknowns == 0 and ev.residuals:
            # redundant constraints: they must hold along the motion, else it stops there
            worst = np.abs(ev.residual_matrix(0)).max(axis=1)
            broken = ~(worst <= REDUNDANT_HOLDS * geom.scale)
            valid &= ~broken
            if broken.any():
                warnings.append(
                    f"redundant constraint violated on {int(broken.sum())} frame(s) (first "
                    f"q = {qa[np.argmax(broken), 0]:.9g}): the mechanism cannot move there"
                )
            else:
                warnings.append(
                    f"redundant constraint(s) hold on all frames (max error {worst.max():.3g})"
                )
        if sol is not None:
            valid &= sol.converged
        return Motion(self, qa, order, ev, valid, sol, tuple(events), tuple(warnings))


def _finite_frames(ev: Evaluation, frames: int) -> BoolArray:
    """Frames where every link's pose and its derivatives are finite."""
    # (links placed by one step share their arrays: each is summed once)
    parts = list(
        {id(x): x for pose in ev.poses.values() for x in (pose.r, *pose.A, *pose.w)}.values()
    )
    # each array's sum is finite when all of it is (an overflowing sum only sends
    # the test down the frame-by-frame path): one reduction per array
    with np.errstate(all="ignore"):
        if np.isfinite(sum(complex(x.sum()) for x in parts)):
            return np.ones(frames, bool)
    valid = np.ones(frames, bool)
    for pose in ev.poses.values():
        # one test per link: a sum is finite only where every part is
        total = pose.r + sum(pose.A) + sum(pose.w)
        valid &= np.isfinite(total)
    return valid


@dataclass(frozen=True)
class Motion:
    """Position functions of a :class:`KinematicModel` solved over driver values.

    Attributes
    ----------
    model : the model solved.
    q : driver values, frames × drivers.
    order : derivatives carried (0, 1 or 2).
    evaluation : the poses of every link (jets over the frames) and step diagnostics.
    valid : frames that assemble (and close).
    closure : the closure unknowns, for plans that iterate.
    events : branch points met.
    warnings : what the user must know about these frames (closure, redundant
        constraints); branch events and infeasible runs are in ``events``/``valid``.
    """

    model: KinematicModel
    q: FloatArray
    order: int
    evaluation: Evaluation
    valid: BoolArray
    closure: Closure | None
    events: tuple[BranchEvent, ...]
    warnings: tuple[str, ...]

    def centre(self, joint: str) -> Jet:
        """Jet of a joint centre, ``x + iy`` (a slider: the point its second link carries)."""
        return self.evaluation.centre(joint)

    def point(self, link: str, at: complex) -> Jet:
        """Jet of the point of ``link`` whose reference position is ``at``."""
        return self.evaluation.poses[link].point(at)

    def angle(self, link: str) -> Jet:
        """Jet of a link's characteristic angle (continued over the frames, not wrapped)."""
        pose = self.evaluation.poses[link]
        n = self.q.shape[0]
        if link == self.model.frame:
            return [np.zeros(n)] + [np.zeros(n)] * self.order
        theta = np.angle(pose.r)
        ok = np.isfinite(theta)
        if ok.any():
            theta[ok] = np.unwrap(theta[ok])
        return [theta + self.model.geometry.char_angle[link], *pose.w[: self.order]]


#: where :func:`model_of` keeps a mechanism's models (in the mechanism's own
#: ``__dict__``, as ``functools.cached_property`` keeps its values: the models live and
#: die with the mechanism, which is frozen)
_MODELS_ATTR = "_kinematic_models"


def model_of(mechanism: Mechanism, drivers: Iterable[str] | None = None) -> KinematicModel:
    """:meth:`KinematicModel.build` once per mechanism and drivers (the plan cached).

    A mechanism is immutable, and so is its model: a second analysis of the same
    mechanism object with the same drivers reuses the model built by the first
    (reading the geometry and planning cost as much as the sweep of a small
    mechanism).  Errors are not cached: a mechanism that cannot be planned raises
    again.

    >>> from mjstruct.io import read_mechanism
    >>> from mjstruct.catalog_files import example_path
    >>> m = read_mechanism(example_path("four-bar"))
    >>> model_of(m) is model_of(m, ["O1"]), model_of(m) is KinematicModel.build(m)
    (True, False)
    """
    given = None if drivers is None else tuple(drivers)
    key = tuple(mechanism.drivers) if given is None else given
    cache = vars(mechanism).setdefault(_MODELS_ATTR, {})
    model = cache.get(key)
    if model is None:
        model = cache[key] = KinematicModel.build(mechanism, given)
    return model  # type: ignore[no-any-return]
