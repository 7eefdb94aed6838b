"""The dynamics entry point: :func:`dynamic_analysis`, its steps run in order.

Owns the order of the steps of one analysis and what each is given; the steps live in
their own modules: read the data (:mod:`~mjstruct.dynamics.inputs`, checked once),
the motion (:mod:`~mjstruct.dynamics.motion`: constant driver speed, free one-DOF
motion under the loads from a speed ``qdot0``, or a prescribed q(t)), the
coefficients V, W, Q (:mod:`~mjstruct.dynamics.equation`), the forces and the
reactions (:mod:`~mjstruct.dynamics.joint_loads`), the result
(:mod:`~mjstruct.dynamics.result`).  Only the outputs asked for are computed.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> r = dynamic_analysis(read_mechanism(example_path("slider-crank-seed000-dynamics")),
...                      qdot0=10.0, frames=36)
>>> round(r.parameters["p"] * 9 / 3.141592653589793, 9)     # p = 10π/9
10.0
>>> round(r.balance, 4), r.check < 1e-9
(0.2632, True)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection, Iterable, Mapping

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.data import DynamicsData
from mjstruct.dynamics.equation import METHODS, coefficients, generalised_force
from mjstruct.dynamics.inputs import read_inputs
from mjstruct.dynamics.joint_loads import joint_loads, link_loads
from mjstruct.dynamics.matrices import check_dimensions, link_motion
from mjstruct.dynamics.memory import check_analysis_memory
from mjstruct.dynamics.motion import (
    DrivenMotion,
    constant_speed,
    free_run,
    moving_links,
    prescribed,
)
from mjstruct.dynamics.result import OUTPUTS, DynamicsResult
from mjstruct.errors import MechanismError, expect_ids, expect_int, expect_number
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from mjstruct.typing import FloatArray

__all__ = ["OUTPUTS", "DynamicsResult", "dynamic_analysis"]


def dynamic_analysis(
    mechanism: Mechanism,
    *,
    speed: float | None = None,
    qdot0: float | None = None,
    q: npt.ArrayLike | None = None,
    qdot: npt.ArrayLike | None = None,
    qddot: npt.ArrayLike | None = None,
    frames: int = 360,
    drivers: Iterable[str] | None = None,
    outputs: Collection[str] = OUTPUTS,
    joints: Collection[str] | None = None,
    parameters: Mapping[str, float] | None = None,
    method: str = "gauss",
    n: int = 10,
    harmonics: int | None = None,
    model: KinematicModel | None = None,
    max_memory: int | None = None,
) -> DynamicsResult:
    """Dynamics of a mechanism with geometry and the dynamics keys (``inertia``, ``loads``, ...).

    Exactly one way of driving it:

    * ``speed=W``: every driver moves at constant speed W over one cycle in ``frames``
      frames (inverse dynamics: reactions and the actuators' loads);
    * ``qdot0=W0``: one driver, free motion under the loads from speed W0 at the
      reference (V, W, Q, q̇, q̈, balance, the unknown parameter, reactions);
    * ``q``, ``qdot``, ``qddot``: a prescribed motion (frames × drivers arrays).

    Parameters
    ----------
    mechanism : the mechanism (``Mechanism.extra`` holds the dynamics keys).
    outputs : any of :data:`OUTPUTS`; the rest is skipped.
    joints : report reactions at these joints only (default all).
    parameters : values overriding the file's (the unknown included).
    method, n, harmonics : the work integral's method (see
        :mod:`mjstruct.dynamics.equation`).
    model : a kinematic model of ``mechanism`` to reuse (its drivers are the
        analysis's: ``drivers`` must then be None or the same).
    max_memory : refuse a run whose estimated memory
        (:func:`mjstruct.dynamics.memory.analysis_bytes`) is above this many bytes
        (default ``MJSTRUCT_MAX_MEMORY_BYTES`` or 2 GiB).

    Raises
    ------
    MechanismError
        bad dynamics data (the message names the field) or bad arguments (named).

    Notes
    -----
    The function is ``dynamic_analysis`` because ``mjstruct.dynamics`` is the
    subpackage.
    """
    frames, wanted = _checked_arguments(speed, qdot0, q, frames, method, outputs)
    model, data = read_inputs(mechanism, drivers, model, parameters)
    if joints is not None:
        expect_ids(joints, "joints")
        known = {j.id for j in mechanism.joints}
        for jid in joints:
            if jid not in known:
                raise MechanismError(f"joints: {jid!r} is not a joint id")
    D = len(model.drivers)
    if D == 0:
        raise MechanismError("drivers: dynamics needs at least one driver")
    # a prescribed path's length is its frame count
    check_analysis_memory(model, frames if q is None else int(np.size(q)) // D, max_memory)
    need_forces = bool(wanted & {"reactions", "driving", "check"})
    if need_forces:
        check_dimensions(model)
    data.check_speed("speed", speed)
    data.check_speed("qdot0", qdot0)
    if qdot0 is not None and (D > 1 or data.elements):
        why = f"{D} drivers" if D > 1 else "force elements"
        raise MechanismError(
            f"qdot0: free motion of a mechanism with {why} is integrated in time "
            "(forward_dynamics; mjstruct dynamics FILE --time T --qdot0 W1,W2)"
        )
    if data.elements and data.unknown is not None and speed is not None:
        raise MechanismError(
            f"parameters.{data.unknown}: steady motion does not take the work of force "
            "elements; give its value"
        )

    if speed is not None:
        run = constant_speed(model, data, speed, frames, method, n, harmonics)
    elif qdot0 is not None:
        run = free_run(model, data, qdot0, frames, method, n, harmonics)
    else:
        assert q is not None
        run = prescribed(model, data, q, qdot, qddot, solve="coefficients" in wanted)
    result = DynamicsResult(
        mechanism.name,
        run.mode,
        model.drivers,
        run.q,
        run.qdot,
        run.qddot,
        parameters=run.parameters,
        cycle_work=run.cycle_work,
        integration_error=run.integration_error,
    )
    if run.kinematics is not None and (run.mode == "free" or "coefficients" in wanted):
        V, W, Q = _coefficients(run, data, moving_links(model))
        result = dataclasses.replace(result, V=V, W=W, Q=Q, balance=_balance(V))
    warnings = run.warnings
    if need_forces:
        lm = link_motion(model, data.inertia, run.q, run.qdot, run.qddot, motion=run.frames_motion)
        loads = link_loads(data, lm, run.parameters, lm.q[:, 0], run.qdot[:, 0])
        out = joint_loads(model, lm, loads, wanted, joints, free=run.mode == "free")
        warnings += out.warnings
        result = dataclasses.replace(
            result,
            driving=out.driving,
            reactions=out.reactions,
            residual=out.residual,
            check=out.check,
            condition=out.condition,
            accuracy=out.accuracy,
        )
    return dataclasses.replace(result, warnings=warnings)


def _checked_arguments(
    speed: float | None,
    qdot0: float | None,
    q: npt.ArrayLike | None,
    frames: int,
    method: str,
    outputs: Collection[str],
) -> tuple[int, set[str]]:
    """Check the arguments that need no mechanism; the frames and the outputs asked for."""
    if sum(x is not None for x in (speed, qdot0, q)) != 1:
        raise MechanismError("speed: give exactly one of speed, qdot0 and q")
    for value, name in ((speed, "speed"), (qdot0, "qdot0")):
        if value is not None:
            expect_number(value, name)
    frames = expect_int(frames, "frames", 1)
    if method not in METHODS:
        raise MechanismError(
            f"method: unknown integration method {method!r} (one of {', '.join(METHODS)})"
        )
    wanted = set(outputs)
    unknown_out = wanted - set(OUTPUTS)
    if unknown_out:
        raise MechanismError(
            f"outputs: unknown output {sorted(unknown_out)[0]!r} (one of {', '.join(OUTPUTS)})"
        )
    return frames, wanted


def _coefficients(
    run: DrivenMotion, data: DynamicsData, links: tuple[str, ...]
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The coefficients step: V, W and Q on the frames kept.

    Q is computed on all the frames the kinematics solved (after a stop, at speed 0)
    and cut to the frames kept.
    """
    mo = run.kinematics
    assert mo is not None
    V, W = run.VW if run.VW is not None else coefficients(mo, data, links)
    k, total = run.q.shape[0], mo.q.shape[0]
    qdot = run.qdot[:, 0] if k == total else np.concatenate([run.qdot[:, 0], np.zeros(total - k)])
    Q = generalised_force(mo, data, links, mo.q[:, 0], qdot, [run.parameters])[0]
    return V[:k], W[:k], Q[:k]


def _balance(V: FloatArray) -> float | None:
    ok = V[np.isfinite(V)]
    return float(ok.min() / ok.max()) if ok.size and ok.max() > 0 else None
