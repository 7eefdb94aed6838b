"""The motion step of a dynamic analysis: q, q̇ and q̈ over the frames, one way of driving each.

Owns :class:`DrivenMotion` and the three ways a mechanism is driven:

* :func:`constant_speed`: every driver at constant speed over one cycle (inverse
  dynamics); an unknown parameter is solved for steady motion;
* :func:`free_run`: one driver, free motion under the loads from a speed at the
  reference (the energy integral of :mod:`mjstruct.dynamics.equation`);
* :func:`prescribed`: driver values, speeds and accelerations given.

Each returns the frames kept, their speeds and accelerations, the parameters and the
kinematic solution of the frames when it was computed (the coefficients and the
reactions reuse it: one solution per analysis).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.dynamics.inputs import read_inputs
>>> model, data = read_inputs(read_mechanism(example_path("slider-crank-seed000-dynamics")))
>>> run = constant_speed(model, data, 2.0, 12)
>>> run.mode, run.q.shape, float(run.qdot[0, 0])
('speed', (12, 1), 2.0)
>>> round(run.parameters["p"] * 9 / 3.141592653589793, 9)     # p = 10π/9
10.0
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.data import DynamicsData
from mjstruct.dynamics.equation import (
    PathForce,
    coefficients,
    free_motion,
    generalised_force,
    steady_parameter,
)
from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.typing import FloatArray

__all__ = ["DrivenMotion", "constant_speed", "free_run", "moving_links", "prescribed"]


@dataclass(frozen=True)
class DrivenMotion:
    """The motion of the drivers over the frames, with what was solved on the way.

    Attributes
    ----------
    mode : ``"speed"``, ``"free"`` or ``"prescribed"``.
    q, qdot, qddot : driver values, speeds and accelerations (frames kept × drivers).
    parameters : every parameter's value (the unknown solved).
    kinematics : the kinematic solution (order 2, unit rates) of all the frames of the
        cycle (one driver; free motion: also the frames after a stop), or None.
    VW : the reduced inertia and its W term on the frames of ``kinematics`` when the
        motion needed them (free motion), else None.
    cycle_work, integration_error : the cycle work of the loads and its error
        estimate (when a work integral was computed).
    warnings : what the user must know about the motion.
    """

    mode: str
    q: FloatArray
    qdot: FloatArray
    qddot: FloatArray
    parameters: dict[str, float]
    kinematics: Motion | None = None
    VW: tuple[FloatArray, FloatArray] | None = None
    cycle_work: float | None = None
    integration_error: float | None = None
    warnings: tuple[str, ...] = ()

    @property
    def frames_motion(self) -> Motion | None:
        """``kinematics`` when it covers exactly the frames kept (for the reactions)."""
        mo = self.kinematics
        return mo if mo is not None and mo.q.shape[0] == self.q.shape[0] else None


def moving_links(model: KinematicModel) -> tuple[str, ...]:
    """The links of the mechanism but the frame, in file order."""
    return tuple(x for x in model.mechanism.links if x != model.frame)


def constant_speed(
    model: KinematicModel,
    data: DynamicsData,
    speed: float,
    frames: int,
    method: str = "gauss",
    n: int = 10,
    harmonics: int | None = None,
) -> DrivenMotion:
    """Every driver at ``speed`` over one cycle in ``frames`` frames.

    With one driver the frames' kinematics is solved once (order 2): it serves the
    coefficients, the reactions and, as the start of its Gauss rounds, the steady
    parameter.

    Raises
    ------
    MechanismError
        naming ``speed``, or ``parameters.<unknown>`` when steady motion cannot be
        solved (the mechanism does not turn a full cycle, the work does not depend on
        the unknown).
    """
    if not np.isfinite(speed) or speed == 0:
        raise MechanismError(f"speed: must be a finite nonzero number, got {speed}")
    qs = model.sweep(frames, speed)
    mo = model.motion(qs, order=2) if len(model.drivers) == 1 else None
    path = PathForce(model, data, float(np.sign(speed)))
    if mo is not None and mo.valid.all():
        path = path.with_table(mo)
    cycle: float | None = None
    err: float | None = None
    if data.unknown is not None:
        if mo is not None and not mo.valid.all():
            raise MechanismError(
                f"parameters.{data.unknown}: steady motion needs a full cycle, and the "
                "mechanism does not assemble at q = "
                f"{float(qs[np.argmax(~mo.valid), 0]):.9g} (give {data.unknown} a value)"
            )
        try:
            params, cycle, err = steady_parameter(path, speed, method, n, harmonics)
        except NumericalError as exc:
            if "does not assemble" not in str(exc):
                raise
            raise MechanismError(
                f"parameters.{data.unknown}: steady motion needs a full cycle, and {exc} "
                f"(give {data.unknown} a value)"
            ) from None
    else:
        params = data.parameter_values()
    return DrivenMotion(
        "speed",
        qs,
        np.full(qs.shape, float(speed)),
        np.zeros(qs.shape),
        params,
        kinematics=mo,
        cycle_work=cycle,
        integration_error=err,
    )


def free_run(
    model: KinematicModel,
    data: DynamicsData,
    qdot0: float,
    frames: int,
    method: str = "gauss",
    n: int = 10,
    harmonics: int | None = None,
) -> DrivenMotion:
    """One driver moving freely under the loads from speed ``qdot0`` at the reference.

    The frames run over one cycle in the direction of ``qdot0``; where q̇² would turn
    negative the motion stops (the frames after it are dropped, a warning says where).

    Raises
    ------
    MechanismError
        naming ``qdot0`` (several drivers, not finite, the mechanism does not turn a
        full cycle) or ``inertia`` (a reduced inertia that vanishes).
    """
    D = len(model.drivers)
    if D != 1:
        raise MechanismError(f"qdot0: free motion needs one driver, the mechanism has {D}")
    if not np.isfinite(qdot0):
        raise MechanismError("qdot0: must be a finite number")
    s = -1.0 if qdot0 < 0 else 1.0
    u = 2 * np.pi * np.arange(frames) / frames
    path = PathForce(model, data, s)
    qs = path.q(u)
    mo = model.motion(qs, order=2)
    path = path.with_table(mo)  # the Gauss rounds start from the frames' closure
    if not mo.valid.all():
        bad = float(qs[np.argmax(~mo.valid), 0])
        raise MechanismError(
            f"qdot0: the mechanism does not assemble over the cycle (q = {bad:.9g}); "
            "free motion needs a full cycle"
        )
    links = moving_links(model)
    V, W = coefficients(mo, data, links)
    if not (V > 0).all():
        raise MechanismError(
            "inertia: the reduced inertia V is zero somewhere; free motion needs masses that move"
        )

    def at_frames(params: Mapping[str, float], qdot: FloatArray) -> FloatArray:
        k = len(qdot)
        mo_k = mo if k == frames else model.motion(qs[:k], order=1)
        Q_k: FloatArray = generalised_force(mo_k, data, links, qs[:k, 0], qdot, [params])[0]
        return Q_k

    fm = free_motion(path, u, V, W, float(qdot0), method, n, harmonics, at_frames)
    k = fm.kept
    warnings: tuple[str, ...] = ()
    if fm.stop is not None:
        warnings = (
            f"the motion stops at q = {fm.stop:.9g}: q̇² would turn negative there "
            f"(the lists end at the last feasible frame, q = {qs[k - 1, 0]:.9g})",
        )
    return DrivenMotion(
        "free",
        qs[:k],
        fm.qdot[:, None],
        fm.qddot[:, None],
        fm.parameters,
        kinematics=mo,
        VW=(V, W),
        cycle_work=fm.cycle_work,
        integration_error=fm.error,
        warnings=warnings,
    )


def prescribed(
    model: KinematicModel,
    data: DynamicsData,
    q: npt.ArrayLike,
    qdot: npt.ArrayLike | None,
    qddot: npt.ArrayLike | None,
    solve: bool = False,
) -> DrivenMotion:
    """Driver values ``q`` with speeds ``qdot`` and accelerations ``qddot`` (default 0).

    ``solve``: also solve the frames' kinematics (one driver), for the coefficients.

    Raises
    ------
    MechanismError
        naming ``q``, ``qdot`` or ``parameters.<unknown>`` (a prescribed motion needs
        every parameter's value).
    """
    qa = model.driver_values(q)
    F, D = qa.shape
    if qdot is None:
        raise MechanismError("qdot: a prescribed motion needs the driver speeds")
    qd = np.broadcast_to(np.asarray(qdot, float).reshape(-1, D), (F, D)).copy()
    qdd = (
        np.zeros((F, D))
        if qddot is None
        else np.broadcast_to(np.asarray(qddot, float).reshape(-1, D), (F, D)).copy()
    )
    if not (np.isfinite(qd).all() and np.isfinite(qdd).all()):
        raise MechanismError("qdot: speeds and accelerations must be finite")
    if data.unknown is not None:
        raise MechanismError(
            f"parameters.{data.unknown}: a prescribed motion needs its value (pass parameters=)"
        )
    mo = model.motion(qa, order=2) if solve and D == 1 else None
    return DrivenMotion("prescribed", qa, qd, qdd, data.parameter_values(), kinematics=mo)
