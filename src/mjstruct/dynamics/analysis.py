"""The dynamics entry point: :func:`dynamic_analysis` and its result.

Owns the three ways a mechanism is driven — constant driver speed (inverse dynamics,
any number of drivers), free one-DOF motion under the loads from a speed ``qdot0``,
and a prescribed motion q(t) with its speeds and accelerations (API) — and the result
object with its contract JSON.  Only the outputs asked for are computed.

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

from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.data import DynamicsData
from mjstruct.dynamics.equation import (
    METHODS,
    PathForce,
    coefficients,
    free_motion,
    generalised_force,
    steady_parameter,
)
from mjstruct.dynamics.inputs import read_inputs
from mjstruct.dynamics.matrices import LinkMotion, active_forces, check_dimensions, link_motion
from mjstruct.dynamics.memory import check_analysis_memory
from mjstruct.dynamics.reactions import (
    SINGULAR_CONDITION,
    generalised_drive,
    inertia_loads,
    solve_stack,
    stack_loads,
    system_matrix,
    unknowns,
)
from mjstruct.errors import MechanismError, NumericalError, expect_int, expect_number
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from mjstruct.output_numbers import json_list, json_number

FloatArray = npt.NDArray[np.float64]

#: what :func:`dynamic_analysis` can compute
OUTPUTS = ("coefficients", "motion", "reactions", "driving", "check")

#: frames whose system is worse conditioned than this are named in a warning
ILL_CONDITIONED = 1e3

#: machine epsilon: the solve's relative error is up to condition × EPS
EPS = float(np.finfo(float).eps)


@dataclass(frozen=True)
class DynamicsResult:
    """Arrays over the frames of a dynamic analysis (None where not computed).

    Attributes
    ----------
    name : the mechanism's name.
    mode : ``"speed"`` (constant driver speed), ``"free"`` (one-DOF motion from
        ``qdot0``) or ``"prescribed"`` (q(t) given).
    drivers : the driver joints.
    q : driver values, frames × drivers (frames kept).
    qdot, qddot : speeds and accelerations, frames × drivers.
    V, W, Q : reduced inertia, its W term and the generalised force (one driver).
    balance : min V / max V over the frames (one driver).
    parameters : all parameters, the unknown solved.
    cycle_work : work of the loads over one cycle with those parameters.
    integration_error : estimated error of the cycle work (free motion).
    driving : driver joint -> actuator torque or force on its second listed link.
    reactions : joint -> link -> {``x``, ``y`` (and ``m`` for a slider)}: the load the
        joint applies to the link (an MJ: one entry per link, summing to zero).
    residual : per-frame relative residual of the excluded equation.
    check : the largest of ``residual`` (None when no frame was solved).
    condition : per-frame estimate of the condition number κ∞ of the link equations
        (a lower bound within a small factor, from the solve's own factorisation; JSON:
        its largest value); near a singular position the accelerations and reactions
        lose between log10 and 2·log10 of it in digits.  Frames above
        ``SINGULAR_CONDITION`` (1e15) are singular: null loads and a warning.
    accuracy : per-frame estimate of the relative error of the reactions and actuator
        loads from the solve, condition × machine epsilon (JSON: its largest value).
        ``check`` cannot see this loss (the excluded equation is computed from the
        same rounded loads), ``accuracy`` grows with the conditioning.
    warnings : what the user must know.
    """

    name: str
    mode: str
    drivers: tuple[str, ...]
    q: FloatArray
    qdot: FloatArray
    qddot: FloatArray
    V: FloatArray | None = None
    W: FloatArray | None = None
    Q: FloatArray | None = None
    balance: float | None = None
    parameters: dict[str, float] = field(default_factory=dict)
    cycle_work: float | None = None
    integration_error: float | None = None
    driving: dict[str, FloatArray] | None = None
    reactions: dict[str, dict[str, dict[str, FloatArray]]] | None = None
    residual: FloatArray | None = None
    check: float | None = None
    condition: FloatArray | None = None
    accuracy: FloatArray | None = None
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The contract's JSON object (lists; NaN as null)."""
        out: dict[str, Any] = {"q": _list(self.q[:, 0])}
        # q is the first driver's (the contract's); every driver's coordinate here
        out["q_drivers"] = {d: _list(self.q[:, i]) for i, d in enumerate(self.drivers)}
        if self.mode != "speed" and self.V is not None:
            out["V"] = _list(self.V)
            out["W"] = _list(self.W)
            out["Q"] = _list(self.Q)
        if self.mode != "speed":
            out["qdot"] = _list(self.qdot[:, 0])
            out["qddot"] = _list(self.qddot[:, 0])
            out["balance"] = json_number(self.balance)
        if self.parameters or self.mode == "free":
            out["parameters"] = {k: json_number(v) for k, v in self.parameters.items()}
        if self.driving is not None:
            out["driving"] = {k: _list(v) for k, v in self.driving.items()}
        if self.reactions is not None:
            out["reactions"] = {
                j: {link: {c: _list(v) for c, v in comps.items()} for link, comps in per.items()}
                for j, per in self.reactions.items()
            }
        if self.residual is not None:
            out["check"] = json_number(self.check)
        for key, arr in (("condition", self.condition), ("accuracy", self.accuracy)):
            if arr is not None and np.isfinite(arr).any():
                out[key] = json_number(float(arr[np.isfinite(arr)].max()))
        out["warnings"] = list(self.warnings)
        return out


def _list(a: FloatArray | None) -> list[float | None]:
    return [] if a is None else json_list(np.asarray(a, float))


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
    modes = [speed is not None, qdot0 is not None, q is not None]
    if sum(modes) != 1:
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
    model, data = read_inputs(mechanism, drivers, model, parameters)
    D = len(model.drivers)
    if D == 0:
        raise MechanismError("drivers: dynamics needs at least one driver")
    # a prescribed path's length is its frame count
    count = frames if q is None else int(np.size(q)) // D
    check_analysis_memory(model, count, max_memory)
    warnings: list[str] = []
    links = tuple(x for x in mechanism.links if x != model.frame)
    need_forces = bool(wanted & {"reactions", "driving", "check"})
    if need_forces:
        check_dimensions(model)

    for name, w in (("speed", speed), ("qdot0", qdot0)):
        # W² × size must be a float: the accelerations and the kinetic energy hold it
        with np.errstate(all="ignore"):
            big = np.float64(w) * np.float64(w) * model.scale if w is not None else 0.0
        if w is not None and np.isfinite(w) and not np.isfinite(big):
            raise MechanismError(f"{name}: {w:g} overflows the accelerations (W² × size)")
    if speed is not None:
        if not np.isfinite(speed) or speed == 0:
            raise MechanismError(f"speed: must be a finite nonzero number, got {speed}")
        qs = model.sweep(frames, speed)
        D1 = D == 1
        # one kinematic solution of the frames serves the coefficients, the reactions
        # and (as the seed of its Gauss rounds) the steady parameter
        mo = model.motion(qs, order=2) if D1 else None
        path = PathForce(model, data, float(np.sign(speed)))
        if mo is not None and mo.valid.all():
            path = path.with_table(mo)
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
            params, cycle, err = data.parameter_values(), None, None
        qd = np.full(qs.shape, float(speed))
        qdd = np.zeros(qs.shape)
        result = DynamicsResult(
            mechanism.name,
            "speed",
            model.drivers,
            qs,
            qd,
            qdd,
            parameters=params,
            cycle_work=cycle,
            integration_error=err,
        )
        if mo is not None and "coefficients" in wanted:
            V, W = coefficients(mo, data, links)
            Qv = generalised_force(mo, data, links, qs[:, 0], qd[:, 0], [params])[0]
            result = _replace(result, V=V, W=W, Q=Qv, balance=_balance(V))
        if need_forces:
            lm = link_motion(model, data.inertia, qs, qd, None, motion=mo)
            result = _forces(result, model, data, lm, params, wanted, joints, warnings, free=False)
    elif qdot0 is not None:
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
        V, W = coefficients(mo, data, links)
        if not (V > 0).all():
            raise MechanismError(
                "inertia: the reduced inertia V is zero somewhere; "
                "free motion needs masses that move"
            )

        def at_frames(params: Mapping[str, float], qdot: FloatArray) -> FloatArray:
            k = len(qdot)
            mo_k = mo if k == frames else model.motion(qs[:k], order=1)
            Q_k: FloatArray = generalised_force(mo_k, data, links, qs[:k, 0], qdot, [params])[0]
            return Q_k

        fm = free_motion(path, u, V, W, float(qdot0), method, n, harmonics, at_frames)
        k = fm.kept
        if fm.stop is not None:
            warnings.append(
                f"the motion stops at q = {fm.stop:.9g}: q̇² would turn negative there "
                f"(the lists end at the last feasible frame, q = {qs[k - 1, 0]:.9g})"
            )
        qd = fm.qdot[:, None]
        qdd = fm.qddot[:, None]
        Qv = generalised_force(
            mo,
            data,
            links,
            qs[:, 0],
            np.concatenate([fm.qdot, np.zeros(frames - k)]),
            [fm.parameters],
        )[0]
        result = DynamicsResult(
            mechanism.name,
            "free",
            model.drivers,
            qs[:k],
            qd,
            qdd,
            V=V[:k],
            W=W[:k],
            Q=Qv[:k],
            balance=_balance(V[:k]),
            parameters=fm.parameters,
            cycle_work=fm.cycle_work,
            integration_error=fm.error,
        )
        if need_forces:
            lm = link_motion(
                model, data.inertia, qs[:k], qd, qdd, motion=mo if k == frames else None
            )
            result = _forces(
                result, model, data, lm, fm.parameters, wanted, joints, warnings, free=True
            )
    else:
        assert q is not None
        qa = model.driver_values(q)
        F = qa.shape[0]
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
                f"parameters.{data.unknown}: a prescribed motion needs its value "
                "(pass parameters=)"
            )
        params = data.parameter_values()
        result = DynamicsResult(
            mechanism.name, "prescribed", model.drivers, qa, qd, qdd, parameters=params
        )
        mo_p = None
        if D == 1 and "coefficients" in wanted:
            mo_p = model.motion(qa, order=2)
            V, W = coefficients(mo_p, data, links)
            Qv = generalised_force(mo_p, data, links, qa[:, 0], qd[:, 0], [params])[0]
            result = _replace(result, V=V, W=W, Q=Qv, balance=_balance(V))
        if need_forces:
            lm = link_motion(model, data.inertia, qa, qd, qdd, motion=mo_p)
            result = _forces(result, model, data, lm, params, wanted, joints, warnings, free=False)
    return _replace(result, warnings=tuple(warnings) + result.warnings)


def _balance(V: FloatArray) -> float | None:
    ok = V[np.isfinite(V)]
    return float(ok.min() / ok.max()) if ok.size and ok.max() > 0 else None


def _replace(r: DynamicsResult, **kw: Any) -> DynamicsResult:
    import dataclasses

    return dataclasses.replace(r, **kw)


def _forces(
    result: DynamicsResult,
    model: KinematicModel,
    data: DynamicsData,
    lm: LinkMotion,
    params: Mapping[str, float],
    wanted: set[str],
    joints: Collection[str] | None,
    warnings: list[str],
    free: bool,
) -> DynamicsResult:
    """Reactions, actuator loads and the excluded-equation check on the frames of ``lm``."""
    m = model.mechanism
    if joints is not None:
        for jid in joints:
            if jid not in lm.joints:
                raise MechanismError(f"joints: {jid!r} is not a joint id")
    mass = np.array([data.inertia[x].mass for x in lm.links])
    J = np.array([data.inertia[x].J for x in lm.links])
    fa, ma = active_forces(data, lm, params, lm.q[:, 0], result.qdot[:, 0])
    fi, mi = inertia_loads(lm, mass, J)
    force, moment = fa + fi, ma + mi
    cols = unknowns(model)
    A = system_matrix(model, lm, cols)
    S = stack_loads(force, moment)
    ok = lm.valid.copy()
    S = np.where(ok[:, None], S, np.nan)
    x, solved, cond = solve_stack(A, S)
    if (ok & ~solved).any():
        bad = float(lm.q[np.argmax(ok & ~solved), 0])
        warnings.append(
            f"the joint loads are not determined at {int((ok & ~solved).sum())} frame(s) "
            f"(a singular position: condition number above {SINGULAR_CONDITION:.0e}; "
            f"first q = {bad:.9g}); their values are null"
        )
    if (~ok).any():
        warnings.append(
            f"the mechanism does not assemble at {int((~ok).sum())} frame(s) "
            f"(first q = {float(lm.q[np.argmax(~ok), 0]):.9g}); their values are null"
        )
    solved &= ok
    kappa = np.where(ok, cond, np.nan)  # singular frames keep theirs: it says why
    solved_kappa = np.where(solved, cond, np.nan)
    worst = int(np.nanargmax(solved_kappa)) if np.isfinite(solved_kappa).any() else None
    if worst is not None and cond[worst] > ILL_CONDITIONED:
        warnings.append(
            "near-singular position: the link equations' condition number reaches "
            f"{cond[worst]:.3g} at q = {float(lm.q[worst, 0]):.9g}; accelerations and "
            f"reactions there lose {np.log10(cond[worst]):.0f} to "
            f"{2 * np.log10(cond[worst]):.0f} digits"
        )
    ell = model.scale
    drive_cols = [c for c, u in enumerate(cols) if u.kind == "drive"]
    tau_sys = x[:, drive_cols].T  # drivers × frames
    tau_eom = np.zeros_like(tau_sys) if free else generalised_drive(lm, force, moment)
    # the largest load of each frame, moments counted as forces at the mechanism's size
    is_force = np.array(
        [
            u.kind in ("x", "y", "n") or (u.kind == "drive" and m.joint(u.joint).kind == "P")
            for u in cols
        ]
    )
    ax = np.abs(x)
    # np.fmax ignores NaN without the All-NaN warning of np.nanmax (frames not solved)
    with np.errstate(all="ignore"):
        big_f = np.fmax.reduce(np.concatenate([np.abs(fa), np.abs(fi), ax[:, is_force].T]), axis=0)
        big_m = np.fmax.reduce(
            np.concatenate([np.abs(ma), np.abs(mi), ax[:, ~is_force].T]), axis=0
        )
        big = np.fmax(big_f, big_m / ell)
        unit = np.array([ell if m.joint(d).kind == "R" else 1.0 for d in model.drivers])
        rel = np.abs(tau_sys - tau_eom) / (big[None] * unit[:, None])
        rel = np.where(big[None] > 0, rel, np.abs(tau_sys - tau_eom))
    residual = np.where(solved, np.fmax.reduce(rel, axis=0), np.nan)
    check = float(np.nanmax(residual)) if np.isfinite(residual).any() else None

    reactions: dict[str, dict[str, dict[str, FloatArray]]] | None = None
    if "reactions" in wanted:
        reactions = {}
        index = {(u.joint, u.link, u.kind): c for c, u in enumerate(cols)}
        for j in m.joints:
            if joints is not None and j.id not in joints:
                continue
            per: dict[str, dict[str, FloatArray]] = {}
            if j.kind == "R":
                sx = np.zeros(lm.q.shape[0])
                sy = np.zeros(lm.q.shape[0])
                for link in j.links[1:]:
                    rx, ry = x[:, index[(j.id, link, "x")]], x[:, index[(j.id, link, "y")]]
                    per[link] = {"x": rx, "y": ry}
                    sx, sy = sx + rx, sy + ry
                per = {j.links[0]: {"x": -sx, "y": -sy}, **per}
            else:
                nvec = 1j * lm.axis[j.id] * x[:, index[(j.id, j.links[1], "n")]]
                mm = x[:, index[(j.id, j.links[1], "m")]]
                per[j.links[0]] = {"x": -nvec.real, "y": -nvec.imag, "m": -mm}
                per[j.links[1]] = {"x": nvec.real, "y": nvec.imag, "m": mm}
            reactions[j.id] = per
    driving: dict[str, FloatArray] | None = None
    if "driving" in wanted:
        shown = np.zeros_like(tau_sys) if free else np.where(solved[None], tau_sys, np.nan)
        driving = {d: shown[i] for i, d in enumerate(model.drivers)}
    return _replace(
        result,
        driving=driving,
        reactions=reactions,
        residual=residual if "check" in wanted else None,
        check=check if "check" in wanted else None,
        condition=kappa,
        accuracy=solved_kappa * EPS,
    )
