"""Forward dynamics in time of a mechanism with any number of drivers and force elements.

Owns :func:`forward_dynamics` and its result :class:`ForwardMotion`: the initial-value
problem ``M(q) q̈ + h(q, q̇) = Q(q, q̇)`` of :mod:`mjstruct.dynamics.lagrange` solved by
scipy's ``solve_ivp`` from ``(q0, q̇0)``, every driver a free generalised coordinate
(an actuator acts only through a ``motor`` element).

The state is ``(q, q̇, w)`` with ``w = ∫ Q_work · q̇ dt`` the work of the forces without
a potential (the file's loads, dampers, motors), carried along without steering the
steps: ``T + U − T(0) − U(0) − w`` (U the energy of gravity and the springs) is then a
residual that measures the steps taken; in free motion without dampers it is the
conservation of energy.

Stiffness: the Jacobian of ``(q̇, q̈)`` at the initial state, by central differences;
the stiffness ratio is ``S = ρ · t_end``, ρ its spectral radius (the fastest rate: a
spring's angular frequency, a damper's inverse time constant), the number of the
fastest time constants in the run.  ``auto`` chooses Radau, and says so, when a
*decaying* rate (an eigenvalue whose real part dominates: a stiff spring with a strong
damper, a steep motor line) gives ``S >`` :data:`STIFF_RATIO`, or when a *vibration*
(an imaginary part dominates: a stiff spring) does at a loose tolerance
(``rtol >=`` :data:`LOOSE_RTOL`), where its small amplitude may be stepped over; a fast
vibration at a tighter tolerance must be resolved by any method, DOP853 does it faster
and the run says so.  The rule and the threshold are measured by
``benchmarks/forward_dynamics_energy.py``.

Events: the speed of each driver changing sign (``turn``, recorded, the run goes on)
and the mechanism leaving its assembly (``assembly``: the run ends there, the lists
too).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> r = forward_dynamics(read_mechanism(example_path("five-bar-springs-dynamics")), 0.2,
...                      frames=5, estimate=False)
>>> r.solver, r.q.shape, r.energy_residual < 1e-6
('DOP853', (5, 2), True)
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mjstruct.dynamics.analysis import dynamic_analysis
from mjstruct.dynamics.data import DynamicsData
from mjstruct.dynamics.inputs import read_inputs
from mjstruct.dynamics.lagrange import motion_terms
from mjstruct.dynamics.matrices import check_dimensions
from mjstruct.dynamics.result import DynamicsResult
from mjstruct.dynamics.time import (
    MAX_EVALUATIONS,
    REFERENCE_FACTOR,
    TIGHTEST,
    check_run,
)
from mjstruct.errors import MechanismError, NumericalError, expect_int
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from mjstruct.typing import FloatArray

__all__ = ["LOOSE_RTOL", "STIFF_RATIO", "ForwardMotion", "auto_method", "forward_dynamics"]

#: stiffness ratio (a rate × t_end) above which ``auto`` integrates implicitly (Radau)
STIFF_RATIO = 200.0

#: the loosest tolerances, from which a fast vibration is stepped over implicitly
LOOSE_RTOL = 1e-4

#: relative step of the central differences of the stiffness test
JACOBIAN_STEP = 1e-6


@dataclass(frozen=True)
class ForwardMotion:
    """q(t) of a mechanism with D drivers, what the solver did and how accurate it is.

    Attributes
    ----------
    name : the mechanism's name.
    drivers : the generalised coordinates (driver joints).
    t : output times; ``q``, ``qdot``, ``qddot``: the motion at them (times × D).
    kinetic, potential : the kinetic energy and the energy of gravity and the springs.
    work : the work of the loads, dampers and motors from t = 0.
    parameters : every parameter's value.
    solver : the scipy method used; ``steps``, ``rhs_evaluations``,
        ``jacobian_evaluations``, ``lu_decompositions`` its counts.
    stiffness_ratio : ``ρ · t_end`` at the initial state.
    decay_rate, vibration_rate : the fastest rates (1/s) at the initial state whose
        eigenvalue's real part dominates (a decay or growth) and whose imaginary part
        does (a vibration, rad/s): what ``auto`` reads.
    error, error_qdot : largest difference in q and q̇ against a run at a 100× tighter
        tolerance (None when not estimated).
    energy_residual : largest ``|T + U − T(0) − U(0) − work|`` over the output times,
        relative to the largest kinetic energy, change of U or work met.
    stopped : ``"t_end"`` or ``"assembly"`` (the lists end where it left its assembly).
    events : ``(t, kind, driver)``: ``turn`` where a driver's speed changes sign.
    loads : the inverse dynamics along the motion at the output times (joint
        reactions; ``driving`` is what the actuators would have to add beyond the
        motors, zero up to round-off when the link equations agree with Lagrange's),
        or None when not asked for.
    warnings : what the user must know.
    """

    name: str
    drivers: tuple[str, ...]
    t: FloatArray
    q: FloatArray
    qdot: FloatArray
    qddot: FloatArray
    kinetic: FloatArray
    potential: FloatArray
    work: FloatArray
    parameters: dict[str, float]
    solver: str
    steps: int
    rhs_evaluations: int
    jacobian_evaluations: int
    lu_decompositions: int
    stiffness_ratio: float
    decay_rate: float
    vibration_rate: float
    error: float | None
    error_qdot: float | None
    energy_residual: float
    stopped: str
    events: tuple[tuple[float, str, str], ...] = ()
    loads: DynamicsResult | None = None
    warnings: tuple[str, ...] = ()


class _System:
    """The first-order system ``y' = (q̇, q̈, Q_work · q̇)`` with its evaluation budget."""

    def __init__(
        self,
        model: KinematicModel,
        data: DynamicsData,
        params: Mapping[str, float],
        budget: int,
        progress: Callable[[int, int], None] | None = None,
        t_end: float = 1.0,
    ) -> None:
        self.model, self.data, self.params = model, data, params
        self.D = len(model.drivers)
        self.left = self.total = budget
        self.progress, self.t_end = progress, t_end
        #: the part of the progress scale (percent) this run covers, and where it is
        self.scale, self.shown = (0, 100), -1

    def terms(self, y: FloatArray) -> tuple[FloatArray, float, bool]:
        """q̈, the power of the working forces, and whether the state has a motion
        (NaN where it does not assemble: the solver then rejects the step)."""
        D = self.D
        if not np.isfinite(y[: 2 * D]).all():  # (the work may be probed at inf: unused)
            return np.full(D, np.nan), np.nan, False
        t = motion_terms(self.model, self.data, self.params, y[None, :D], y[None, D : 2 * D])
        if not t.valid[0]:
            return np.full(D, np.nan), np.nan, False
        qdd = t.acceleration()[0]
        return qdd, float(t.Q_work[0] @ y[D : 2 * D]), bool(np.isfinite(qdd).all())

    def __call__(self, t: float, y: FloatArray) -> FloatArray:
        self.left -= 1
        if self.left < 0:
            raise _Spent(t)
        if self.progress is not None:
            lo, hi = self.scale
            done = lo + int((hi - lo) * min(t / self.t_end, 1.0))
            if done > self.shown:
                self.shown = done
                self.progress(done, 100)
        D = self.D
        qdd, power, _ = self.terms(y)
        return np.concatenate([y[D : 2 * D], qdd, [power]])

    def stiffness(self, y0: FloatArray) -> tuple[float, float]:
        """The fastest rates of ∂(q̇, q̈)/∂(q, q̇) at ``y0`` (central differences): the
        largest |λ| of its eigenvalues whose real part dominates (a decay or a growth),
        and of those whose imaginary part dominates (a vibration)."""
        D = self.D
        J = np.zeros((2 * D, 2 * D))
        J[:D, D:] = np.eye(D)
        unit = np.array([self.model.scale if self.slide(i) else 1.0 for i in range(D)] * 2)
        for k in range(2 * D):
            h = JACOBIAN_STEP * (abs(y0[k]) + unit[k])
            up, down = y0.copy(), y0.copy()
            up[k] += h
            down[k] -= h
            a, _, ok_a = self.terms(up)
            b, _, ok_b = self.terms(down)
            with np.errstate(all="ignore"):
                J[D:, k] = (a - b) / (2 * h)
            if not (ok_a and ok_b and np.isfinite(J[D:, k]).all()):
                return 0.0, 0.0
        lam = np.linalg.eigvals(J)
        real = np.abs(lam.real) >= np.abs(lam.imag)
        return (
            float(np.abs(lam[real]).max(initial=0.0)),
            float(np.abs(lam[~real]).max(initial=0.0)),
        )

    def slide(self, i: int) -> bool:
        return self.model.mechanism.joint(self.model.drivers[i]).kind == "P"


class _Spent(Exception):
    def __init__(self, t: float) -> None:
        super().__init__(t)
        self.t = t


def _solve(
    system: _System,
    t_end: float,
    y0: FloatArray,
    method: str,
    rtol: float,
    atol: FloatArray,
) -> Any:
    from scipy.integrate import solve_ivp

    D = system.D
    events = []
    for i in range(D):

        def turn(t: float, y: FloatArray, i: int = i) -> float:
            return float(y[D + i])

        events.append(turn)
    try:
        with np.errstate(all="ignore"):
            sol = solve_ivp(
                system,
                (0.0, t_end),
                y0,
                method=method,
                rtol=rtol,
                atol=atol,
                dense_output=True,
                events=events,
            )
    except _Spent as spent:
        raise MechanismError(
            f"max_evaluations: the run used its {system.total} right-hand-side evaluations "
            f"by t = {spent.t:.6g} of {t_end:.6g} (a shorter t_end, a looser tolerance, or a "
            "larger max_evaluations)"
        ) from None
    if sol.status == -1 and (sol.sol is None or len(sol.t) < 2):
        raise NumericalError(f"the {method} integration failed at t = 0: {sol.message}")
    return sol


def auto_method(decay: float, vibration: float, omega: float, rtol: float) -> tuple[str, str]:
    """``auto``'s method from the stiffness ratios of the fastest decay and vibration,
    and what to say about it (see the module docstring)."""
    if decay > STIFF_RATIO:
        return "Radau", (
            f"stiff: a rate of {decay:.3g} decay times in the run (more than "
            f"{STIFF_RATIO:g}): implicit Radau"
        )
    if vibration > STIFF_RATIO and rtol >= LOOSE_RTOL:
        return "Radau", (
            f"stiff: a vibration of {omega:.3g} rad/s, {vibration:.3g} radians in the run "
            f"(more than {STIFF_RATIO:g}), at rtol {rtol:g}: implicit Radau steps over it"
        )
    if vibration > STIFF_RATIO:
        return "DOP853", (
            f"stiff: a vibration of {omega:.3g} rad/s, {vibration:.3g} radians in the run "
            f"(more than {STIFF_RATIO:g}); at rtol {rtol:g} every method must resolve it and "
            f"DOP853 does so faster than Radau; rtol >= {LOOSE_RTOL:g} steps over it (Radau)"
        )
    return "DOP853", ""


def _vector(
    value: float | Sequence[float] | None, D: int, name: str, default: FloatArray
) -> FloatArray:
    if value is None:
        return default.copy()
    arr = np.atleast_1d(np.asarray(value, dtype=float)).reshape(-1)
    if arr.size == 1 and D > 1:
        raise MechanismError(f"{name}: give one value per driver ({D}), got one")
    if arr.size != D:
        raise MechanismError(f"{name}: give one value per driver ({D}), got {arr.size}")
    if not np.isfinite(arr).all():
        raise MechanismError(f"{name}: must be finite numbers")
    return arr


def forward_dynamics(
    mechanism: Mechanism,
    t_end: float,
    *,
    q0: float | Sequence[float] | None = None,
    qdot0: float | Sequence[float] | None = None,
    frames: int = 201,
    method: str = "auto",
    rtol: float = 1e-8,
    atol: float | None = None,
    parameters: Mapping[str, float] | None = None,
    estimate: bool = True,
    drivers: Iterable[str] | None = None,
    max_evaluations: int = MAX_EVALUATIONS,
    reactions: bool = True,
    progress: Callable[[int, int], None] | None = None,
) -> ForwardMotion:
    """Integrate ``M(q) q̈ + h(q, q̇) = Q(q, q̇)`` from ``(q0, qdot0)`` over ``[0, t_end]``.

    Parameters
    ----------
    mechanism : a mechanism with geometry and dynamics keys (``inertia``, ``loads``,
        ``elements``, ...); any number of drivers.
    t_end : the end time (> 0).
    q0, qdot0 : one value per driver (default: the reference configuration, at rest).
    frames : output times, equally spaced over ``[0, t_end]`` (>= 2).
    method : ``auto`` (DOP853, or Radau by the stiffness rule of the module docstring:
        :func:`auto_method`), or one of ``RK45``, ``DOP853``, ``Radau``, ``BDF``, ``LSODA``.
    rtol, atol : the solver's tolerances (``atol`` in the drivers' units; default
        ``rtol`` × a radian, or × the mechanism's size for a slide).
    parameters : values overriding the file's; every parameter needs a value.
    estimate : also run at a 100× tighter tolerance and report the difference.
    drivers : the generalised coordinates (default: the file's drivers).
    max_evaluations : right-hand-side evaluations the runs may take.
    reactions : also solve the link equations at the output times (:attr:`ForwardMotion.loads`).
    progress : called as ``progress(done, 100)`` while the runs go on (the percentage of
        t_end reached; the error estimate's run is the second half).

    Raises
    ------
    MechanismError
        bad input naming the parameter or field.
    NumericalError
        the solver fails at the start.
    """
    check_run(t_end, frames, method, rtol, atol)
    max_evaluations = expect_int(max_evaluations, "max_evaluations", 1)
    model, data = read_inputs(mechanism, drivers, parameters=parameters)
    D = len(model.drivers)
    if D == 0:
        raise MechanismError("drivers: forward dynamics needs at least one driver")
    if data.unknown is not None:
        raise MechanismError(
            f"parameters.{data.unknown}: forward dynamics needs its value (pass parameters=)"
        )
    params = data.parameter_values()
    start = _vector(q0, D, "q0", model.q_ref)
    speed = _vector(qdot0, D, "qdot0", np.zeros(D))
    for v in speed:
        data.check_speed("qdot0", float(v))
    system = _System(model, data, params, max_evaluations, progress, float(t_end))
    system.scale = (0, 50 if estimate else 100)
    y0 = np.concatenate([start, speed, [0.0]])
    first = motion_terms(model, data, params, start[None], speed[None])
    if not first.valid[0]:
        raise MechanismError(f"q0: the mechanism does not assemble at q0 = {list(start)}")
    if not np.linalg.eigvalsh(first.M[0]).min() > 1e-14 * max(np.abs(first.M[0]).max(), 1e-300):
        raise MechanismError(
            "inertia: the mass matrix is singular at q0; every driver needs masses that move"
        )
    warnings: list[str] = []
    decay, vibration = system.stiffness(y0)
    stiffness = max(decay, vibration) * float(t_end)
    chosen = method
    if method == "auto":
        chosen, note = auto_method(decay * float(t_end), vibration * float(t_end), vibration, rtol)
        if note:
            warnings.append(note)
    unit = np.array([model.scale if system.slide(i) else 1.0 for i in range(D)] * 2)
    a = rtol * unit if atol is None else np.full(2 * D, float(atol))
    atol_vec = np.concatenate([a, [np.inf]])
    sol = _solve(system, float(t_end), y0, chosen, rtol, atol_vec)
    t_stop = float(sol.t[-1])
    times = np.linspace(0.0, float(t_end), int(frames))
    stopped = "t_end"
    if sol.status == -1:
        stopped = "assembly"
        times = np.append(times[times < t_stop], t_stop)
        warnings.append(
            f"the mechanism leaves its assembly (or the solver cannot go on) near t = "
            f"{t_stop:.9g}: the lists end there ({sol.message})"
        )
    Y = sol.sol(times)
    Y[:, 0] = y0
    Y[:, -1] = sol.y[:, -1]
    q, qd, work = Y[:D].T.copy(), Y[D : 2 * D].T.copy(), Y[2 * D].copy()
    terms = motion_terms(model, data, params, q, qd)
    qdd = terms.acceleration()
    T, U = terms.kinetic, terms.potential
    finite = np.isfinite(qdd).all(axis=1) & np.isfinite(q).all(axis=1) & np.isfinite(T + U)
    if stopped == "assembly" and not finite.all():
        # the last output time sits on the dead position the run could not pass
        k = max(int(np.argmin(finite)), 1)
        times, q, qd, qdd, work, T, U = (x[:k] for x in (times, q, qd, qdd, work, T, U))
    resid = np.abs(T + U - T[0] - U[0] - work)
    scale = max(float(np.max(T)), float(np.max(np.abs(U - U[0]))), float(np.max(np.abs(work))))
    energy_residual = float(resid.max() / max(scale, 1e-300))
    events = tuple(
        (float(te), "turn", model.drivers[i])
        for i, ts in enumerate(sol.t_events)
        for te in ts
        if 0 < te < t_stop
    )
    err_q = err_qd = None
    if estimate:
        fine = max(rtol / REFERENCE_FACTOR, TIGHTEST)
        try:
            system.scale = (50, 100)
            ref = _solve(system, float(t_end), y0, chosen, fine, atol_vec / REFERENCE_FACTOR)
            inside = times <= min(t_stop, float(ref.t[-1]))
            Yr = ref.sol(times[inside])
            Yr[:, 0] = y0
            err_q = float(np.max(np.abs(Yr[:D].T - q[inside])))
            err_qd = float(np.max(np.abs(Yr[D : 2 * D].T - qd[inside])))
        except NumericalError as exc:
            warnings.append(f"no error estimate: the reference run failed ({exc})")
    if not (np.isfinite(q).all() and np.isfinite(qd).all() and np.isfinite(qdd).all()):
        raise NumericalError("the integration produced non-finite values")
    if progress is not None and system.shown < 100:
        progress(100, 100)  # a run that ended early (assembly) still completes its bar
    loads = None
    if reactions and model.mechanism.joints:
        try:
            check_dimensions(model)
        except MechanismError as exc:
            warnings.append(f"no joint reactions: {exc}")
        else:
            loads = dynamic_analysis(
                model.mechanism, q=q, qdot=qd, qddot=qdd, model=model, parameters=params
            )
            warnings += loads.warnings
    return ForwardMotion(
        name=model.mechanism.name,
        drivers=model.drivers,
        t=times,
        q=q,
        qdot=qd,
        qddot=qdd,
        kinetic=T,
        potential=U,
        work=work,
        parameters=dict(params),
        solver=chosen,
        steps=len(sol.t) - 1,
        rhs_evaluations=int(sol.nfev),
        jacobian_evaluations=int(sol.njev),
        lu_decompositions=int(sol.nlu),
        stiffness_ratio=stiffness,
        decay_rate=decay,
        vibration_rate=vibration,
        error=err_q,
        error_qdot=err_qd,
        energy_residual=energy_residual,
        stopped=stopped,
        events=events,
        loads=loads,
        warnings=tuple(warnings),
    )
