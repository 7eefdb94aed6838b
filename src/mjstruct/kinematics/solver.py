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

from collections.abc import Iterable, Sequence

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError
from mjstruct.kinematics.checks import run_checks
from mjstruct.kinematics.evaluate import Evaluation
from mjstruct.kinematics.memory import check_sweep_memory
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.planner import Plan
from mjstruct.kinematics.result import KinematicsResult, collect
from mjstruct.kinematics.tolerances import CLOSURE_TOL, NEAR_SINGULAR
from mjstruct.mechanism import Mechanism
from mjstruct.structure.assur import Decomposition

__all__ = ["NEAR_SINGULAR", "KinematicsResult", "kinematic_analysis"]

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
    checks: bool = True,
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
    checks : run the checks (link lengths, analogs vs differences, Jacobian).
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
    if q is None:
        if frames < 1:
            raise MechanismError(f"frames: must be >= 1, got {frames}")
        check_sweep_memory(km, frames, max_memory)
        qa = km.sweep(frames, speed, stroke)
    else:
        qa = km.driver_values(q)
        check_sweep_memory(km, qa.shape[0], max_memory)
    if not np.isfinite(float(speed) * float(speed) * km.scale):
        raise MechanismError(f"speed: {speed:g} overflows the accelerations (W² × size)")
    motion = km.motion(qa, order=2, tol=tol)
    # frames near a singular position may carry infinite analogs: they are not valid
    # (reported), and their arithmetic must not warn
    with np.errstate(all="ignore"):
        result = collect(motion, speed)
    _check_overflow(result)
    warnings = list(motion.warnings)
    warnings += [e.message() for e in motion.events]
    warnings += _parallel_guides(km.plan, motion.evaluation, qa)
    warnings += _infeasible(result)
    result.warnings = warnings
    if checks:
        with np.errstate(all="ignore"):
            run_checks(result, motion)
    return result


def _check_overflow(r: KinematicsResult) -> None:
    """Refuse a speed whose velocities or accelerations overflow where the analogs do not."""
    v = r.valid
    for table in (r.joints, r.points):
        for values in table.values():
            for rate, analog in (("vx", "sx"), ("vy", "sy"), ("ax", "kx"), ("ay", "ky")):
                _overflow(values[rate][v], values[analog][v], r.speed)
    for values in r.links.values():
        _overflow(values["omega"][v], values["sigma"][v], r.speed)
        _overflow(values["eps"][v], values["kappa"][v], r.speed)


def _overflow(rate: FloatArray, analog: FloatArray, speed: float) -> None:
    if (~np.isfinite(rate) & np.isfinite(analog)).any():
        raise MechanismError(
            f"speed: {speed:g} overflows the velocities or accelerations (largest analog "
            f"{float(np.abs(analog[np.isfinite(analog)]).max()):.3g})"
        )


def _parallel_guides(plan: Plan, ev: Evaluation, q: FloatArray) -> list[str]:
    """Frames where the two guides of a line-intersection dyad are parallel."""
    out = []
    for k, s in enumerate(plan.steps):
        guides_of = s.step_kind.guides
        if guides_of is not None and k in ev.diag:
            bad = ev.diag[k][0] < 0
            if bad.any():
                guides = guides_of(s)
                out.append(
                    f"dyad {s.kind} (step {k + 1}): guides {guides[0]} and {guides[1]} are "
                    f"parallel at {int(bad.sum())} frame(s), first q = "
                    f"{q[np.argmax(bad), 0]:.9g}: no intersection, values are null"
                )
    return out


def _infeasible(r: KinematicsResult) -> list[str]:
    """Runs of frames that do not assemble, with their q range; singular frames."""
    out = _runs(r, ~r.placed, "no assembly for q in [{a}, {b}] (frames {i}..{j}); values are null")
    out += _runs(
        r,
        r.placed & ~r.valid,
        "singular position for q in [{a}, {b}] (frames {i}..{j}): the Jacobian with the drivers "
        "fixed is singular; positions are given, velocities and accelerations are not (null)",
    )
    bad = np.concatenate([[False], ~r.placed, [False]])
    ends = np.flatnonzero(~bad[1:] & bad[:-1]) - 1
    after = [int(j) + 1 for j in ends if j + 1 < r.valid.size]
    # only steps with an assembly mode (circle intersections, closures) can carry the
    # wrong branch across a gap; line-line dyads (PRP, RPP) have a single solution
    has_modes = any(s.step_kind.has_modes or s.is_closure for s in r.plan.steps)
    if after and has_modes:
        # the motion cannot physically cross an infeasible interval: say so
        out.append(
            f"frames from {after[0]} on assemble again after an infeasible interval: found "
            "by continuation across the gap (same assembly modes), not a physical motion"
        )
    return out


def _runs(r: KinematicsResult, mask: npt.NDArray[np.bool_], text: str) -> list[str]:
    """``text`` for each run of frames in ``mask`` (``{a}``, ``{b}``: its q range)."""
    edge = np.concatenate([[False], mask, [False]])
    starts = np.flatnonzero(edge[1:] & ~edge[:-1])
    ends = np.flatnonzero(~edge[1:] & edge[:-1]) - 1
    return [
        text.format(a=f"{r.q[i, 0]:.9g}", b=f"{r.q[j, 0]:.9g}", i=i, j=j)
        for i, j in zip(starts, ends, strict=True)
    ]
