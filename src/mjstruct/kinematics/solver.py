"""Kinematic analysis of a mechanism over a sweep of its drivers (the plug-in's entry).

Owns :func:`kinematic_analysis`, the orchestration: build (or take) the
:class:`~mjstruct.kinematics.model.KinematicModel`, solve its motion over the sweep
(closure, branch tracking, exact evaluation), collect the
:class:`~mjstruct.kinematics.result.KinematicsResult`, word the warnings (branch points,
parallel guides, infeasible runs) and run the checks of
:mod:`mjstruct.kinematics.checks`.

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

import dataclasses
from collections.abc import Iterable, Iterator, Sequence

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError
from mjstruct.kinematics.branches import fill_change_frames
from mjstruct.kinematics.checks import Checks, checks_level, plan_determinant, run_checks
from mjstruct.kinematics.closure import Closure
from mjstruct.kinematics.continuity import closure_walls
from mjstruct.kinematics.jacobian import poses_at
from mjstruct.kinematics.memory import CHUNK_FRAMES, LEAD_FRAMES, check_sweep_memory
from mjstruct.kinematics.model import KinematicModel, Motion, model_of
from mjstruct.kinematics.reach import reached_frames, sign_walls
from mjstruct.kinematics.result import KinematicsResult, collect
from mjstruct.kinematics.sweep_warnings import denormal_outputs, sweep_warnings
from mjstruct.kinematics.tolerances import CLOSURE_TOL, NEAR_SINGULAR
from mjstruct.mechanism import Mechanism
from mjstruct.structure.assur import Decomposition

__all__ = ["NEAR_SINGULAR", "KinematicsResult", "kinematic_analysis", "sweep_chunks"]

FloatArray = npt.NDArray[np.float64]


def kinematic_analysis(
    model: KinematicModel | Mechanism,
    drivers: Iterable[str] | None = None,
    frames: int = 360,
    speed: float = 1.0,
    q: Sequence[float] | npt.ArrayLike | None = None,
    stroke: float = 1.0,
    decomposition: Decomposition | None = None,
    tol: float = CLOSURE_TOL,
    checks: Checks = True,
    max_memory: int | None = None,
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
    checks : True (default): the checks that cost O(frames) — near-singular frames from
        the plan's group determinants, the closure equations' residuals, and, when
        ``result.checks`` is read, link lengths and analogs against differences;
        ``"full"``: also the constraint Jacobian's rank and determinant (dense
        matrices on a few frames, :func:`~mjstruct.kinematics.jacobian.check_jacobian`);
        False: none.
    max_memory : refuse sweeps whose estimated memory exceeds this many bytes
        (default: ``MJSTRUCT_MAX_MEMORY_BYTES`` or 2 GiB; see
        :mod:`mjstruct.kinematics.memory`).
    """
    from mjstruct.errors import expect_ids, expect_instance, expect_int, expect_number

    expect_instance(model, "model", (KinematicModel, Mechanism), "a Mechanism or KinematicModel")
    expect_ids(drivers, "drivers")
    frames = expect_int(frames, "frames", 1)
    speed = expect_number(speed, "speed", finite=False)
    stroke = expect_number(stroke, "stroke", finite=False)
    tol = expect_number(tol, "tol", finite=False)
    checks = checks_level(checks)
    if isinstance(model, KinematicModel):
        if drivers is not None or decomposition is not None:
            raise MechanismError(
                "drivers: give drivers and decomposition when building the model, not here"
            )
        km = model
    elif decomposition is None:
        km = model_of(model, drivers)  # planned once per mechanism and drivers
    else:
        km = KinematicModel.build(model, drivers, decomposition)
    if not np.isfinite(speed) or speed == 0:
        raise MechanismError(f"speed: must be a finite nonzero number, got {speed}")
    if q is None:
        if frames < 1:
            raise MechanismError(f"frames: must be >= 1, got {frames}")
        _check_stroke(stroke)
        check_sweep_memory(km, frames, max_memory, checks=checks)
        qa = km.sweep(frames, speed, stroke)
    else:
        qa = km.driver_values(q)
        check_sweep_memory(km, qa.shape[0], max_memory, checks=checks)
    _check_speed(km, speed)
    result, motion = _analyse(km, qa, speed, tol, sweep=q is None)
    result.warnings = sweep_warnings(result, motion)
    if q is None:
        result.warnings += _open_cycle(result, km)
    result.warnings += denormal_outputs(result, km)
    if checks:
        with np.errstate(all="ignore"):
            run_checks(result, motion, full=checks == "full")
    return result


def _open_cycle(r: KinematicsResult, km: KinematicModel) -> list[str]:
    """A one-turn sweep whose end does not lead back to its start (MS4 changes circuit
    at its change point: its period is two turns)."""
    kinds = [km.mechanism.joint(d).kind for d in km.drivers]
    F = r.q.shape[0]
    if F < 8 or any(k != "R" for k in kinds) or not r.placed[[0, F - 2, F - 1]].all():
        return []
    xs = r.joints.values_at(np.array([0, F - 2, F - 1])).T
    # the configuration one step past the last frame (q_ref + one turn), extrapolated;
    # its error is far below one step's motion, another circuit is a finite distance away
    pred = 2 * xs[2] - xs[1]
    step = np.abs(xs[2] - xs[1]).max()
    gap = float(np.abs(pred - xs[0]).max())
    if not np.isfinite(gap) or gap <= max(10 * step, 1e-9 * km.scale):
        return []
    return [
        f"the sweep does not return to its start after one turn (the end differs from the "
        f"start by up to {gap:.3g}): the motion closes only after more turns (a change "
        "point crossed onto the other circuit closes it after two)"
    ]


#: the largest |stroke| of a prismatic sweep: its square (in the triangles) and its
#: multiples stay far from overflowing a double
MAX_STROKE = 1e100


def _check_stroke(stroke: float) -> None:
    if not np.isfinite(stroke) or not abs(stroke) <= MAX_STROKE:
        raise MechanismError(
            f"stroke: must be a finite number of at most {MAX_STROKE:g} in size, got {stroke:g}"
        )


def _check_speed(km: KinematicModel, speed: float) -> None:
    if not np.isfinite(float(speed) * float(speed) * km.scale):
        raise MechanismError(f"speed: {speed:g} overflows the accelerations (W² × size)")


def _analyse(
    km: KinematicModel, qa: FloatArray, speed: float, tol: float, sweep: bool = False
) -> tuple[KinematicsResult, Motion]:
    """The motion on ``qa`` and its tables (no warnings, no checks)."""
    motion = km.motion(qa, order=2, tol=tol)
    # a frame exactly at a change point where a dyad is undefined (MS5: A on O2) still
    # has its configuration: the branch's limit from both sides
    with np.errstate(all="ignore"):
        events = fill_change_frames(km, motion.q, motion.events, motion.evaluation)
    if events != list(motion.events):
        motion = dataclasses.replace(motion, events=tuple(events))
    # frames near a singular position may carry infinite analogs: they are not valid
    # (reported), and their arithmetic must not warn
    with np.errstate(all="ignore"):
        result = collect(motion, speed)
    _not_reached(result, km, motion, sweep)
    _check_overflow(result)
    return result, motion


def _not_reached(
    r: KinematicsResult, km: KinematicModel, motion: Motion, sweep: bool = False
) -> None:
    """Frames that assemble but that no continuous motion from the reference reaches:
    taken out of the tables into ``another_assembly`` (one driver; in place).

    ``sweep``: ``r.q`` is a one-turn (or one-stroke) sweep from the reference, whose
    consecutive frames are neighbours: a change of sign of the mechanism's Jacobian
    between two of them is a fold the motion cannot pass.
    """
    if r.q.shape[1] != 1:
        return
    turns = km.mechanism.joint(km.drivers[0]).kind == "R"
    walls = None
    # without closure unknowns every frame is solved on its own in the dyads' modes: a
    # dyad's fold leaves a gap of frames that do not assemble; only a closure can hop
    # over a fold, and a line-line dyad's pin run off to infinity between two frames
    lines = any(st.step_kind.guides is not None for st in km.plan.steps)
    if sweep and r.q.shape[0] > 2 and (r.closure is not None or lines):
        with np.errstate(all="ignore"):
            sign, _ = plan_determinant(motion)
        quiet = np.zeros(r.q.shape[0], bool)
        for e in r.events:
            if e.kind in ("change point", "mode flip", "singular frame"):
                quiet[max(e.frame - 1, 0) : e.frame + 2] = True
        turn = 2 * np.pi * np.sign(r.q[-1, 0] - r.q[0, 0]) if turns else None
        walls = sign_walls(r.q, sign, r.placed, quiet, turn)
        if r.closure is not None:
            c = r.closure
            closed = (c.t, c.t1, c.converged)
            more = closure_walls(km, r.q, closed, c.jumps, dict(c.modes), c.tol, turn)
            walls = np.concatenate([walls, more])
    if r.placed.all() and (walls is None or walls.size == 0):
        return
    blocked = ~r.placed
    reached = reached_frames(r.q, float(km.q_ref[0]), blocked, turns, walls)
    other = r.placed & ~reached
    if not other.any():
        return
    r.another_assembly = other
    r.valid = r.valid & reached
    r.assembled = r.placed & reached
    # the branch points of another assembly are not the motion's
    r.events = [e for e in r.events if not other[e.frame]]


def sweep_chunks(
    model: KinematicModel,
    frames: int,
    speed: float = 1.0,
    stroke: float = 1.0,
    tol: float = CLOSURE_TOL,
    checks: Checks = True,
    chunk: int = CHUNK_FRAMES,
    max_memory: int | None = None,
) -> Iterator[KinematicsResult]:
    """The sweep of :func:`kinematic_analysis` solved ``chunk`` frames at a time.

    Each chunk is solved on a path that leads in from the reference (at most
    :data:`~mjstruct.kinematics.memory.LEAD_FRAMES` frames of the sweep before it,
    evenly thinned, and the last four at full resolution), so that the branch
    tracking, the closure continuation and the angles' unwrapping carry over from the
    frames before; only the chunk's own frames are kept.  Each result holds its
    chunk's frames, the warnings and branch events in them (frame numbers of the
    whole sweep) and its checks; memory stays bounded whatever ``frames``.

    Raises
    ------
    MechanismError
        bad ``frames``, ``speed`` or ``chunk``, or a chunk beyond the memory limit.
    """
    if frames < 1:
        raise MechanismError(f"frames: must be >= 1, got {frames}")
    if chunk < 1:
        raise MechanismError(f"chunk: must be >= 1, got {chunk}")
    checks = checks_level(checks)
    if not np.isfinite(speed) or speed == 0:
        raise MechanismError(f"speed: must be a finite nonzero number, got {speed}")
    _check_stroke(stroke)
    check_sweep_memory(model, frames, max_memory, output="csv", checks=checks)
    _check_speed(model, speed)
    # each driver's reference and span, as in KinematicModel.sweep
    ref = np.array([model.geometry.driver_ref[d] for d in model.drivers])
    kinds = [model.mechanism.joint(d).kind for d in model.drivers]
    span = np.sign(speed) * np.array([2 * np.pi if k == "R" else stroke for k in kinds])
    for a in range(0, frames, chunk):
        b = min(a + chunk, frames)
        thin = max(1, -(-a // LEAD_FRAMES))
        lead = np.unique(np.concatenate([np.arange(0, a, thin), np.arange(max(0, a - 4), a)]))
        idx = np.concatenate([lead, np.arange(a, b)])
        # the same arithmetic as KinematicModel.sweep: equal to its frames bit for bit
        qa = ref[None, :] + span[None, :] * idx[:, None] / frames
        result, motion = _analyse(model, qa, speed, tol)
        n = lead.size
        if n:
            result, motion = _tail(result, n), _tail_motion(motion, n, idx)
        result.warnings = sweep_warnings(result, motion, offset=a)
        if checks:
            with np.errstate(all="ignore"):
                run_checks(result, motion, full=checks == "full")
        yield result


def _tail(r: KinematicsResult, n: int) -> KinematicsResult:
    """``r`` from its frame ``n`` on (views of its tables, no copy)."""

    return dataclasses.replace(
        r,
        q=r.q[n:],
        valid=r.valid[n:],
        joints=r.joints.frames_from(n),
        points=r.points.frames_from(n),
        links=r.links.frames_from(n),
        events=[],
        closure=None if r.closure is None else _tail_closure(r.closure, n),
        assembled=None if r.assembled is None else r.assembled[n:],
        partial=None if r.partial is None else r.partial[n:],
        another_assembly=None if r.another_assembly is None else r.another_assembly[n:],
        _motion=None,
        _error=None,
    )


def _tail_closure(c: Closure, n: int) -> Closure:
    return dataclasses.replace(
        c,
        t=c.t[n:],
        t1=c.t1[n:],
        t2=c.t2[n:],
        error=c.error[n:],
        converged=c.converged[n:],
        jumps=tuple(i - n for i in c.jumps if i >= n),
        modes={k: v[n:] for k, v in c.modes.items()},
        jacobian=None if c.jacobian is None else c.jacobian[n:],
    )


def _tail_motion(motion: Motion, n: int, idx: npt.NDArray[np.int_]) -> Motion:
    """``motion`` from its frame ``n`` on; its events renumbered to the sweep's frames."""
    ev = motion.evaluation
    keep = np.arange(n, motion.q.shape[0])
    sub = dataclasses.replace(
        ev,
        poses=poses_at(ev.poses, keep),
        residuals=[[x[n:] for x in jet] for jet in ev.residuals],
        diag={k: (d[n:], s[n:]) for k, (d, s) in ev.diag.items()},
        solved={j: [x[n:] for x in jet] for j, jet in ev.solved.items()},
    )
    events = tuple(
        dataclasses.replace(e, frame=int(idx[e.frame])) for e in motion.events if e.frame >= n
    )
    return dataclasses.replace(
        motion,
        q=motion.q[n:],
        evaluation=sub,
        valid=motion.valid[n:],
        closure=None if motion.closure is None else _tail_closure(motion.closure, n),
        events=events,
    )


def _check_overflow(r: KinematicsResult) -> None:
    """Refuse a speed whose velocities or accelerations overflow where the analogs do not."""
    if abs(r.speed) <= 1.0:
        # the rates are the analogs times W and W² (or the analogs themselves): no
        # larger in size, so a finite analog has a finite rate
        return
    v = r.valid
    pairs = (("vx", "sx"), ("vy", "sy"), ("ax", "kx"), ("ay", "ky"))
    for table, keys in ((r.joints, pairs), (r.points, pairs), (r.links, _LINK_RATES)):
        for rate, analog in keys:
            _overflow(table.column(rate)[:, v], table.column(analog)[:, v], r.speed)


_LINK_RATES = (("omega", "sigma"), ("eps", "kappa"))


def _overflow(rate: FloatArray, analog: FloatArray, speed: float) -> None:
    if (~np.isfinite(rate) & np.isfinite(analog)).any():
        raise MechanismError(
            f"speed: {speed:g} overflows the velocities or accelerations (largest analog "
            f"{float(np.abs(analog[np.isfinite(analog)]).max()):.3g})"
        )
