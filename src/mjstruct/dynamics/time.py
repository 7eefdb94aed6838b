"""Motion in time of a one-DOF mechanism: run-up, run-down, q(t) under speed-dependent loads.

Owns :func:`motion_in_time` and its result :class:`TimeMotion`: the initial-value
problem ``V(q) q̈ + W(q) q̇² = Q(q, q̇)`` (coefficients from
:mod:`mjstruct.dynamics.time_terms`) solved by scipy's ``solve_ivp``, the stiffness
test that chooses between an explicit and an implicit method, the analytic Jacobian
given to the implicit one, and the error estimates; also the text and JSON that
``mjstruct dynamics FILE --time T`` prints (:func:`time_report`, :func:`time_json`,
:func:`time_csv`, :func:`time_command`).

The state is ``(q, q̇, w)`` with ``w = ∫ Q q̇ dt`` the work of the loads, carried along
without steering the step size: the energy balance ``V q̇²/2 − T(0) − w`` is then a
residual that measures the steps taken.

Stiffness ratio: ``S = max |∂q̈/∂q̇| · t_end``, the number of the fastest time
constants of the speed (a steep torque–speed line makes ∂q̈/∂q̇ large) in the run.  An
explicit method needs of the order of ``S / 10`` steps for stability alone, whatever
the tolerance.  ``auto`` uses Radau with the Jacobian ``[[0, 1], [∂q̈/∂q, ∂q̈/∂q̇]]``
when the initial state gives ``S >`` :data:`STIFF_RATIO`; otherwise DOP853, watching
``|∂q̈/∂q̇| · (t_end − t)`` at every step and going on with Radau from where it exceeds
:data:`STIFF_RATIO` (a run-down into a steep friction law turns stiff near rest).
The threshold is where the benchmark ``benchmarks/dynamics_run_up.py`` finds the two
methods equally fast.

Examples
--------
>>> from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> d = mechanism_to_dict(read_mechanism(example_path("slider-crank-seed000-dynamics")))
>>> d["loads"] = [{"link": "1", "moment": "40*(1 - qdot/20)"},     # a motor's line
...               {"link": "3", "force": ["-5*qdot", "0"]}]        # viscous resistance
>>> d["parameters"] = {}
>>> m = mechanism_from_dict(d)
>>> r = motion_in_time(m, 3.0, frames=7)
>>> r.solver, len(r.t), r.error < 1e-5, r.energy_residual < 1e-6
('DOP853', 7, True, True)
>>> round(float(r.qdot[0]), 9), bool(r.qdot[-1] > 5)
(0.0, True)
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.data import DynamicsData
from mjstruct.dynamics.equation import PathForce, steady_parameter
from mjstruct.dynamics.inputs import read_inputs
from mjstruct.dynamics.time_terms import (
    TABLE_POINTS,
    ReducedEquation,
    driver_unit,
    reduced_equation,
)
from mjstruct.errors import MechanismError, NumericalError, expect_int
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from mjstruct.output_numbers import json_list, json_number
from mjstruct.output_numbers import text_number as _fmt

FloatArray = npt.NDArray[np.float64]

#: the solvers ``method`` may name (``auto`` chooses by the stiffness ratio)
SOLVERS = ("auto", "RK45", "DOP853", "Radau", "BDF", "LSODA")

#: explicit solvers (no Jacobian)
EXPLICIT = ("RK45", "DOP853")

#: stiffness ratio above which ``auto`` integrates implicitly
STIFF_RATIO = 1e4

#: relative interpolation error the coefficient table is refined to reach
TABLE_TOL = 1e-8

#: the table is refined (doubled) up to this many times its requested size
TABLE_REFINE = 8

#: the reference run's tolerance is this much tighter
REFERENCE_FACTOR = 100.0

#: the tightest tolerance scipy accepts (100 machine epsilons, rounded up)
TIGHTEST = 2.3e-14


@dataclass(frozen=True)
class TimeMotion:
    """q(t) of a one-DOF mechanism, with what the solver did and how accurate it is.

    Attributes
    ----------
    name : the mechanism's name.
    driver : the driver joint (its coordinate is q).
    t, q, qdot, qddot : output times and the motion at them.
    V, Q : reduced inertia and generalised force at the output times.
    work : work of the loads from t = 0 (the integrated ``∫ Q q̇ dt``).
    parameters : every parameter's value.
    solver : the scipy method used.
    steps : accepted steps.
    rhs_evaluations, jacobian_evaluations, lu_decompositions : the solver's counts.
    stiffness_ratio : ``max |∂q̈/∂q̇| · t_end`` over the initial state and the run.
    error : largest difference in q against a run at a 100× tighter tolerance
        (None when not estimated).
    error_qdot : the same for q̇.
    energy_residual : largest ``|V q̇²/2 − T(0) − work|`` over the output times,
        relative to the largest kinetic energy or work met.
    coefficients : ``"table"`` (interpolated V, W, σ) or ``"exact"``.
    table_error : the table's measured relative interpolation error (None: exact).
    table_points : the table's grid points per turn (None: exact).
    stopped : ``"t_end"`` or ``"rest"`` (q̇ reached zero: the lists end there).
    warnings : what the user must know.
    """

    name: str
    driver: str
    t: FloatArray
    q: FloatArray
    qdot: FloatArray
    qddot: FloatArray
    V: FloatArray
    Q: FloatArray
    work: FloatArray
    parameters: dict[str, float]
    solver: str
    steps: int
    rhs_evaluations: int
    jacobian_evaluations: int
    lu_decompositions: int
    stiffness_ratio: float
    error: float | None
    error_qdot: float | None
    energy_residual: float
    coefficients: str
    table_error: float | None
    table_points: int | None
    stopped: str
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class _Segment:
    """One solve_ivp run over part of the time span."""

    sol: Any
    method: str
    steps: int
    nfev: int
    njev: int
    nlu: int
    ended_by: str  # "t_end", "rest" or "stiff"


@dataclass(frozen=True)
class _Path:
    """The segments of a run, evaluated as one dense solution."""

    segments: tuple[_Segment, ...]

    @property
    def t_stop(self) -> float:
        return float(self.segments[-1].sol.t[-1])

    @property
    def y_stop(self) -> FloatArray:
        return np.asarray(self.segments[-1].sol.y[:, -1], float)

    @property
    def states(self) -> FloatArray:
        """The states at every accepted step (3 × points)."""
        return np.concatenate([np.asarray(s.sol.y, float) for s in self.segments], axis=1)

    def __call__(self, times: FloatArray) -> FloatArray:
        out = np.empty((3, times.size))
        lo = -np.inf
        for seg in self.segments:
            hi = float(seg.sol.t[-1])
            sel = (times > lo) & (times <= hi) if lo > -np.inf else times <= hi
            if sel.any():
                out[:, sel] = seg.sol.sol(times[sel])
            lo = hi
        return out


#: right-hand-side evaluations one run may take (``max_evaluations``): a run this long
#: keeps every step for dense output, so its memory and time grow with it
MAX_EVALUATIONS = 500_000


class _Budget:
    """Right-hand-side evaluations left to a run; raises :class:`_Spent` when used up."""

    def __init__(self, evaluations: int) -> None:
        self.left = self.total = evaluations

    def spend(self, t: float) -> None:
        self.left -= 1
        if self.left < 0:
            raise _Spent(t)


class _Spent(Exception):
    """The evaluation budget ran out at time ``t``."""

    def __init__(self, t: float) -> None:
        super().__init__(t)
        self.t = t


def _solve(
    eq: ReducedEquation,
    span: tuple[float, float],
    y0: FloatArray,
    method: str,
    rtol: float,
    atol: FloatArray,
    rest: float,
    watch: bool,
    budget: _Budget,
) -> _Segment:
    """One run from ``span[0]``; ``rest`` is the initial speed's sign (0: no rest event),
    ``watch`` ends the run where the remaining time holds more than
    :data:`STIFF_RATIO` of the fastest time constant (an explicit run turning stiff)."""
    from scipy.integrate import solve_ivp

    t_end = span[1]

    def rhs(t: float, y: FloatArray) -> FloatArray:
        budget.spend(t)
        qdd, Q = eq.rate(float(y[0]), float(y[1]))
        return np.array([y[1], qdd, Q * y[1]])

    def jac(t: float, y: FloatArray) -> FloatArray:
        _, Q, a, dQ = eq.partials(y[:1], y[1:2])
        return np.array(
            [
                [0.0, 1.0, 0.0],
                [a[0, 0], a[1, 0], 0.0],
                [dQ[0, 0] * y[1], Q[0] + dQ[1, 0] * y[1], 0.0],
            ]
        )

    def at_rest(t: float, y: FloatArray) -> float:
        return float(y[1])

    def turns_stiff(t: float, y: FloatArray) -> float:
        b = eq.partials(y[:1], y[1:2])[2][1, 0]
        return float(abs(b) * (t_end - t)) - STIFF_RATIO

    at_rest.terminal = True  # type: ignore[attr-defined]
    at_rest.direction = -rest  # type: ignore[attr-defined]
    turns_stiff.terminal = True  # type: ignore[attr-defined]
    turns_stiff.direction = 1  # type: ignore[attr-defined]
    events = [at_rest] if rest else []
    if watch:
        events.append(turns_stiff)
    kw: dict[str, Any] = {} if method in EXPLICIT else {"jac": jac}
    try:
        with np.errstate(all="ignore"):
            sol = solve_ivp(
                rhs,
                span,
                y0,
                method=method,
                rtol=rtol,
                atol=atol,
                dense_output=True,
                events=events or None,
                **kw,
            )
    except _Spent as spent:
        raise MechanismError(
            f"max_evaluations: the run used its {budget.total} right-hand-side evaluations "
            f"by t = {spent.t:.6g} of {t_end:.6g} (a shorter t_end, a looser tolerance, or a "
            "larger max_evaluations)"
        ) from None
    if sol.status == -1:
        raise NumericalError(
            f"the {method} integration failed at t = {float(sol.t[-1]):.9g}: {sol.message}"
        )
    ended = "t_end"
    if sol.status == 1:
        ended = "rest" if rest and len(sol.t_events[0]) else "stiff"
    return _Segment(sol, method, len(sol.t) - 1, int(sol.nfev), int(sol.njev), int(sol.nlu), ended)


def _integrate(
    eq: ReducedEquation,
    t_end: float,
    y0: FloatArray,
    method: str,
    rtol: float,
    atol: FloatArray,
    stop_at_rest: bool,
    budget: _Budget,
) -> _Path:
    """Solve over ``[0, t_end]``; ``auto`` starts explicitly and goes on with Radau
    from where the rest of the run is stiff."""
    rest = float(np.sign(y0[1])) if stop_at_rest else 0.0
    if method != "auto":
        return _Path((_solve(eq, (0.0, t_end), y0, method, rtol, atol, rest, False, budget),))
    first = _solve(eq, (0.0, t_end), y0, "DOP853", rtol, atol, rest, True, budget)
    if first.ended_by != "stiff":
        return _Path((first,))
    t1 = float(first.sol.t[-1])
    y1 = np.asarray(first.sol.y[:, -1], float)
    return _Path((first, _solve(eq, (t1, t_end), y1, "Radau", rtol, atol, rest, False, budget)))


def check_run(t_end: float, frames: int, method: str, rtol: float, atol: float | None) -> None:
    """Refuse the arguments of a run in time that are not what they must be, naming each
    (``t_end``, ``frames``, ``method``, ``rtol``, ``atol``)."""
    if isinstance(t_end, bool) or not isinstance(t_end, (int, float, np.floating)):
        raise MechanismError("t_end: must be a number")
    if not np.isfinite(t_end) or t_end <= 0:
        raise MechanismError(f"t_end: must be a finite number > 0, got {t_end}")
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or frames < 2:
        raise MechanismError(f"frames: must be an integer >= 2, got {frames}")
    if method not in SOLVERS:
        raise MechanismError(f"method: unknown solver {method!r} (one of {', '.join(SOLVERS)})")
    if not (np.isfinite(rtol) and TIGHTEST <= rtol < 1):
        raise MechanismError(f"rtol: must be in [{TIGHTEST:g}, 1), got {rtol}")
    if atol is not None and not (np.isfinite(atol) and atol > 0):
        raise MechanismError(f"atol: must be a finite number > 0, got {atol}")


def motion_in_time(
    mechanism: Mechanism | KinematicModel,
    t_end: float,
    *,
    q0: float | None = None,
    qdot0: float = 0.0,
    frames: int = 201,
    times: npt.ArrayLike | None = None,
    method: str = "auto",
    rtol: float = 1e-8,
    atol: float | None = None,
    parameters: Mapping[str, float] | None = None,
    table: int | None = TABLE_POINTS,
    estimate: bool = True,
    stop_at_rest: bool = True,
    drivers: Iterable[str] | None = None,
    max_evaluations: int = MAX_EVALUATIONS,
) -> TimeMotion:
    """Integrate ``V q̈ + W q̇² = Q(q, q̇)`` from ``(q0, qdot0)`` over ``[0, t_end]``.

    Parameters
    ----------
    mechanism : a mechanism with geometry and dynamics keys, or its kinematic model;
        exactly one driver.
    t_end : the end time (> 0).
    q0 : the initial driver coordinate (default: the reference configuration's).
    qdot0 : the initial speed (0: a run-up from rest).
    frames : output times, equally spaced over ``[0, t_end]`` (>= 2).
    times : the output times instead (increasing, from 0 to ``t_end``).
    method : ``auto`` (explicit DOP853, or Radau when the stiffness ratio exceeds
        :data:`STIFF_RATIO`, switching to Radau where the rest of the run turns stiff), or
        one of ``RK45``, ``DOP853``, ``Radau``, ``BDF``, ``LSODA``.
    rtol, atol : the solver's tolerances (``atol`` in the units of q and q̇; default
        ``rtol`` × q's unit: a radian for a revolute driver, the mechanism's size for a
        slider; the work rides along without steering the steps).
    parameters : values overriding the file's.  An unknown (``null``) parameter left
        open is solved as for steady motion when no load depends on ``qdot``.
    table : grid points per turn of the interpolated coefficients (doubled, up to
        :data:`TABLE_REFINE` times, until the measured interpolation error is below
        :data:`TABLE_TOL`), or None to solve the
        kinematics at every evaluation (slow for iterated closures, exact).
    estimate : also run at a 100× tighter tolerance and report the difference.
    stop_at_rest : end the run where q̇ first returns to zero (a run-down).
    drivers : the driver joint (default: the file's).
    max_evaluations : right-hand-side evaluations the run (with its error estimate)
        may take; a run that needs more is refused with the time it reached.

    Raises
    ------
    MechanismError
        bad input, naming the parameter (``t_end``, ``frames``, ``drivers``, ...).
    NumericalError
        the mechanism leaves its assembly or the solver fails.
    """
    check_run(t_end, frames, method, rtol, atol)
    if not np.isfinite(qdot0):
        raise MechanismError(f"qdot0: must be finite, got {qdot0}")
    if q0 is not None and not np.isfinite(q0):
        raise MechanismError(f"q0: must be finite, got {q0}")
    max_evaluations = expect_int(max_evaluations, "max_evaluations", 1)
    budget = _Budget(max_evaluations)
    out_times = np.linspace(0.0, float(t_end), int(frames))
    if times is not None:
        out_times = np.asarray(times, float).reshape(-1)
        if not (
            out_times.size >= 2
            and np.isfinite(out_times).all()
            and out_times[0] == 0.0
            and out_times[-1] == t_end
            and (np.diff(out_times) > 0).all()
        ):
            raise MechanismError("times: must increase from 0 to t_end (at least two values)")
    if table is not None and (isinstance(table, bool) or int(table) != table or table < 16):
        raise MechanismError(f"table: must be an integer >= 16 or None, got {table}")
    if isinstance(mechanism, KinematicModel):
        model, data = read_inputs(mechanism.mechanism, drivers, mechanism)
    else:
        model, data = read_inputs(mechanism, drivers)
    data.check_speed("qdot0", qdot0)
    if len(model.drivers) != 1:
        raise MechanismError(
            "drivers: motion in time needs exactly one driver, "
            f"the mechanism has {len(model.drivers)}"
        )
    warnings: list[str] = []
    params = _parameters(model, data, parameters, warnings)
    start = float(model.q_ref[0]) if q0 is None else float(q0)
    try:
        eq = reduced_equation(model, data, params, table)
    except NumericalError as exc:
        if table is None:
            raise
        warnings.append(f"{exc}: the coefficients are solved exactly at every step")
        eq = reduced_equation(model, data, params, None)
    points = table
    # a cubic spline's error falls 16-fold per doubling: refine to the target
    while (
        eq.table_error is not None
        and eq.table_error > TABLE_TOL
        and points is not None
        and table is not None
        and points < TABLE_REFINE * table
    ):
        points *= 2
        eq = reduced_equation(model, data, params, points)
    if eq.table_error is not None and eq.table_error > TABLE_TOL:
        warnings.append(
            f"the interpolated coefficients carry a relative error up to {eq.table_error:.2g} "
            f"(table of {points} points): pass a larger table or table=None"
        )
    V0 = float(eq.terms(np.array([start]))[0][0, 0])
    if not V0 > 0:
        raise MechanismError(
            "inertia: the reduced inertia V is zero at q0; the motion needs masses that move"
        )
    stiffness = _stiffness(eq, start, qdot0, t_end)
    T0 = V0 * qdot0**2 / 2
    # the default absolute tolerance in q's unit: a radian, or the size for a slider
    a = rtol * driver_unit(model) if atol is None else float(atol)
    # the work rides along: it does not steer the steps, so its balance measures them
    atol_vec = np.array([a, a, np.inf])
    y0 = np.array([start, float(qdot0), 0.0])

    chosen = method
    if method == "auto" and stiffness > STIFF_RATIO:
        chosen = "Radau"
    path = _integrate(eq, float(t_end), y0, chosen, rtol, atol_vec, stop_at_rest, budget)
    seg = path.segments
    solver = "+".join(x.method for x in seg)
    if len(seg) > 1:
        warnings.append(
            f"the motion turns stiff at t = {float(seg[0].sol.t[-1]):.9g}: "
            f"{seg[0].method} up to there, {seg[1].method} from there on"
        )
    t_stop = path.t_stop
    stopped = "t_end"
    times = out_times
    if seg[-1].ended_by == "rest":
        stopped = "rest"
        times = np.append(times[times < t_stop], t_stop)
        warnings.append(
            f"the mechanism comes to rest at t = {t_stop:.9g} (q = {float(path.y_stop[0]):.9g}); "
            "the lists end there"
        )
    Y = path(times)
    Y[:, 0] = y0
    Y[:, -1] = path.y_stop  # the run ends at the last output time (t_end or rest)
    q, qd, work = Y[0], Y[1], Y[2]
    qdd, Q, V, _ = eq.acceleration(q, qd)
    along = path.states
    # at most about 2000 of the steps: the ratio is an estimate, kept cheap for long runs
    along = along[:, :: max(1, along.shape[1] // 2000)]
    b_run = eq.partials(along[0], along[1])[2][1]
    stiffness = max(stiffness, float(np.nanmax(np.abs(b_run))) * float(t_end))

    T = V * qd**2 / 2
    resid = np.abs(T - T0 - work)
    size = max(float(np.max(T)), float(np.max(np.abs(work))), T0, 1e-300)
    energy_residual = float(resid.max() / size)

    err_q: float | None = None
    err_qd: float | None = None
    if estimate:
        fine = max(rtol / REFERENCE_FACTOR, TIGHTEST)
        try:
            ref = _integrate(
                eq,
                float(t_end),
                y0,
                chosen,
                fine,
                atol_vec / REFERENCE_FACTOR,
                stop_at_rest,
                budget,
            )
            inside = times <= min(t_stop, ref.t_stop)
            Yr = ref(times[inside])
            err_q = float(np.max(np.abs(Yr[0] - q[inside])))
            err_qd = float(np.max(np.abs(Yr[1] - qd[inside])))
        except NumericalError as exc:
            warnings.append(f"no error estimate: the reference run failed ({exc})")
    if not (np.isfinite(q).all() and np.isfinite(qd).all() and np.isfinite(qdd).all()):
        raise NumericalError("the integration produced non-finite values")
    return TimeMotion(
        name=model.mechanism.name,
        driver=model.drivers[0],
        t=times,
        q=q,
        qdot=qd,
        qddot=qdd,
        V=V,
        Q=Q,
        work=work,
        parameters=params,
        solver=solver,
        steps=sum(x.steps for x in seg),
        rhs_evaluations=sum(x.nfev for x in seg),
        jacobian_evaluations=sum(x.njev for x in seg),
        lu_decompositions=sum(x.nlu for x in seg),
        stiffness_ratio=stiffness,
        error=err_q,
        error_qdot=err_qd,
        energy_residual=energy_residual,
        coefficients=eq.kind,
        table_error=eq.table_error,
        table_points=None if eq.pieces is None else int(eq.pieces.shape[1]),
        stopped=stopped,
        warnings=tuple(warnings),
    )


def _parameters(
    model: KinematicModel,
    data: DynamicsData,
    given: Mapping[str, float] | None,
    warnings: list[str],
) -> dict[str, float]:
    """Every parameter's value: the file's, overridden, the unknown given or solved."""
    fixed = data.with_parameters(given)
    p = fixed.unknown
    if p is None:
        return fixed.parameter_values()
    if data.uses_qdot:
        raise MechanismError(
            f"parameters.{p}: motion in time needs its value when a load depends on qdot "
            "(pass parameters=)"
        )
    solved, _, _ = steady_parameter(PathForce(model, fixed, 1.0), 0.0)
    warnings.append(
        f"parameters.{p} = {solved[p]:.12g}, solved for steady motion "
        f"(cycle work = {data.energy_change:g})"
    )
    return solved


def _stiffness(eq: ReducedEquation, q0: float, qdot0: float, t_end: float) -> float:
    """``max |∂q̈/∂q̇| · t_end`` at the initial speed over one turn of q."""
    qs = q0 + 2 * np.pi * np.arange(64) / 64 if eq.kind == "table" else np.array([q0])
    b = eq.partials(qs, np.full(qs.shape, qdot0))[2][1]
    return float(np.nanmax(np.abs(b))) * t_end


def solver_account(r: Any) -> dict[str, Any]:
    """The JSON keys of a run in time that say what the solver did and how accurate it
    is (``parameters``, ``solver``, ``steps``, ``evaluations``, ``stiffness_ratio``,
    ``error``), for :class:`TimeMotion` and for
    :class:`~mjstruct.dynamics.forward.ForwardMotion`."""
    return {
        "parameters": {k: json_number(v) for k, v in r.parameters.items()},
        "solver": r.solver,
        "steps": r.steps,
        "evaluations": {
            "rhs": r.rhs_evaluations,
            "jacobian": r.jacobian_evaluations,
            "lu": r.lu_decompositions,
        },
        "stiffness_ratio": json_number(r.stiffness_ratio),
        "error": {
            "q": json_number(r.error),
            "qdot": json_number(r.error_qdot),
            "energy": json_number(r.energy_residual),
        },
    }


def solver_text(r: Any) -> list[str]:
    """The report lines of a run in time that give its parameters and what the solver
    did (the text twin of :func:`solver_account`, for both kinds of run)."""
    lines = []
    if r.parameters:
        lines.append(
            "parameters: " + ", ".join(f"{k} = {_fmt(v)}" for k, v in sorted(r.parameters.items()))
        )
    kind = "implicit" if r.solver not in EXPLICIT else "explicit"
    lines.append(
        f"solver {r.solver} ({kind}), stiffness ratio {_fmt(r.stiffness_ratio)}: {r.steps} steps, "
        f"{r.rhs_evaluations} evaluations, {r.jacobian_evaluations} Jacobians, "
        f"{r.lu_decompositions} LU"
    )
    return lines


def accuracy_text(r: Any) -> str:
    """The report line of a run in time that says how accurate it is."""
    acc = f"energy balance residual {_fmt(r.energy_residual)} (relative)"
    if r.error is not None:
        acc = (
            f"error estimate |dq| {_fmt(r.error)}, |dqdot| {_fmt(r.error_qdot)} "
            "(against a run 100x tighter); " + acc
        )
    return acc


def time_json(r: TimeMotion) -> dict[str, Any]:
    """The JSON object of ``mjstruct dynamics FILE --time T`` (no NaN: null)."""
    return {
        "t": json_list(r.t),
        "q": json_list(r.q),
        "qdot": json_list(r.qdot),
        "qddot": json_list(r.qddot),
        "V": json_list(r.V),
        "Q": json_list(r.Q),
        "work": json_list(r.work),
        **solver_account(r),
        "coefficients": r.coefficients,
        "table_error": json_number(r.table_error),
        "table_points": r.table_points,
        "stopped": r.stopped,
        "warnings": list(r.warnings),
    }


def time_report(r: TimeMotion, rows: int = 11) -> str:
    """The text report: the solver's work, the accuracy and a table of ``rows`` times."""
    start = "from rest" if r.qdot[0] == 0 else f"from qdot = {_fmt(float(r.qdot[0]))}"
    lines = [
        f"{r.name or 'mechanism'}: motion in time {start}, driver {r.driver}, "
        f"t = 0 … {_fmt(float(r.t[-1]))}",
    ]
    lines += solver_text(r)
    coeff = (
        f"interpolated on {r.table_points} points a turn (relative error {_fmt(r.table_error)})"
        if r.coefficients == "table"
        else "exact"
    )
    lines.append(f"coefficients V, W, Q: {coeff}")
    lines.append(accuracy_text(r))
    n = len(r.t)
    idx = np.unique(np.linspace(0, n - 1, min(rows, n)).round().astype(int))
    lines.append(f"  {'t':>12}  {'q':>12}  {'qdot':>12}  {'qddot':>12}")
    for i in idx:
        lines.append(
            f"  {_fmt(float(r.t[i])):>12}  {_fmt(float(r.q[i])):>12}  "
            f"{_fmt(float(r.qdot[i])):>12}  {_fmt(float(r.qddot[i])):>12}"
        )
    lines += [f"warning: {w}" for w in r.warnings]
    return "\n".join(lines)


def time_csv(r: TimeMotion) -> str:
    """One row per output time: ``t, q, qdot, qddot, V, Q, work`` (empty where not finite)."""
    cols = [("t", r.t), ("q", r.q), ("qdot", r.qdot), ("qddot", r.qddot)]
    cols += [("V", r.V), ("Q", r.Q), ("work", r.work)]
    lines = [",".join(name for name, _ in cols)]
    for row in zip(*(v for _, v in cols), strict=True):
        lines.append(",".join(repr(float(x)) if np.isfinite(x) else "" for x in row))
    return "\n".join(lines) + "\n"
