"""Motion in time (mjstruct.dynamics.time): run-up, run-down, stiffness, accuracy."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.dynamics.data import read_dynamics
from mjstruct.dynamics.equation import PathForce, coefficients, free_motion, generalised_force
from mjstruct.dynamics.time import motion_in_time, time_json, time_report
from mjstruct.dynamics.time_terms import reduced_equation
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism


def slider_crank(
    loads: list[dict[str, Any]], parameters: dict[str, Any] | None = None, **extra: Any
) -> Mechanism:
    """The seed-000 slider-crank (L2/L1 = 2, masses of uniform rods) with other loads."""
    d = mechanism_to_dict(read_mechanism(example_path("slider-crank-seed000-dynamics")))
    d["loads"] = loads
    d["parameters"] = parameters or {}
    d.update(extra)
    return mechanism_from_dict(d)


def motor(M0: float, w0: float, c: float = 5.0) -> Mechanism:
    """A motor's torque–speed line on the crank, a viscous resistance on the slider."""
    return slider_crank(
        [
            {"link": "1", "moment": f"{M0}*(1 - qdot/{w0})"},
            {"link": "3", "force": [f"-{c}*qdot", "0"]},
        ]
    )


def test_stiff_run_up_is_solved_implicitly_in_few_steps() -> None:
    # a steep characteristic: dq̈/dq̇ ≈ −M0/(ω0 V) ≈ −1e6 /s, over 2 s
    m = motor(4e7, 20.0)
    r = motion_in_time(m, 2.0, rtol=1e-6, estimate=False, frames=41)
    assert r.stiffness_ratio >= 1e6
    assert r.solver == "Radau"
    # an explicit method would need about S/3 steps for stability alone
    assert r.steps < 1000 < r.stiffness_ratio / 3
    assert r.jacobian_evaluations > 0
    ref = motion_in_time(m, 2.0, rtol=1e-11, method="Radau", estimate=False, frames=41)
    assert np.max(np.abs(r.q - ref.q)) < 1e-4
    assert np.max(np.abs(r.qdot - ref.qdot)) < 1e-3
    # the speed settles near the motor's no-load speed (the resistance is tiny by comparison)
    assert abs(r.qdot[-1] - 20.0) < 0.01


def test_error_estimate_tracks_the_true_error() -> None:
    m = motor(400.0, 20.0)
    r = motion_in_time(m, 2.0, rtol=1e-6, frames=21)
    ref = motion_in_time(m, 2.0, rtol=1e-12, estimate=False, frames=21)
    true = float(np.max(np.abs(r.q - ref.q)))
    assert r.error is not None and r.error_qdot is not None
    assert r.solver == "DOP853"
    # the difference against a 100× tighter run is the coarse run's error, to a factor
    assert true / 3 < r.error < true * 3


def test_energy_balance_against_an_independent_quadrature() -> None:
    m = motor(40.0, 20.0)
    r = motion_in_time(m, 1.5, rtol=1e-10, frames=6001, estimate=False)
    assert r.energy_residual < 1e-7
    # work of the loads from the kinematics' own generalised force (H4's), trapezoid rule
    model = KinematicModel.build(m)
    data = read_dynamics(m)
    links = tuple(x for x in m.links if x != model.frame)
    mo = model.motion(r.q[:, None], order=2)
    Q = generalised_force(mo, data, links, r.q, r.qdot, [{}])[0]
    V, _ = coefficients(mo, data, links)
    power = Q * r.qdot
    work = np.concatenate([[0.0], np.cumsum((power[1:] + power[:-1]) / 2 * np.diff(r.t))])
    T = V * r.qdot**2 / 2
    assert np.max(np.abs(T - T[0] - work)) < 1e-5 * np.max(T)
    assert np.allclose(r.V, V, rtol=1e-9)


def test_free_motion_agrees_with_the_energy_integral() -> None:
    # loads independent of q̇: q̇(q) from q̇² = (2A + V0 q̇0²)/V (H4's route) and from q(t)
    m = read_mechanism(example_path("slider-crank-seed000-dynamics"))
    r = motion_in_time(m, 0.5, qdot0=12.0, rtol=1e-11, frames=40, estimate=False)
    assert any("parameters.p" in w for w in r.warnings)
    assert r.parameters["p"] == pytest.approx(10 * np.pi / 9, rel=1e-9)
    model = KinematicModel.build(m)
    data = read_dynamics(m)
    links = tuple(x for x in m.links if x != model.frame)
    u = r.q - model.q_ref[0]
    keep = u < 2 * np.pi
    assert keep.sum() > 10
    V, W = coefficients(model.motion(r.q[keep, None], order=2), data, links)
    fm = free_motion(PathForce(model, data, 1.0), u[keep], V, W, 12.0)
    assert fm.parameters["p"] == pytest.approx(r.parameters["p"], rel=1e-12)
    assert np.allclose(fm.qdot, r.qdot[keep], rtol=1e-8, atol=0)
    assert np.allclose(fm.qddot, r.qddot[keep], rtol=1e-6, atol=1e-6)


def test_run_down_to_rest_under_dry_friction() -> None:
    # a constant friction couple on the crank: T0 = Mc · (angle travelled to rest)
    m = slider_crank([{"link": "1", "moment": "-Mc*sign(qdot)"}], {"Mc": 3.0})
    r = motion_in_time(m, 10.0, qdot0=8.0, rtol=1e-10, estimate=False)
    assert r.stopped == "rest"
    assert r.t[-1] < 10.0
    assert abs(r.qdot[-1]) < 1e-9
    assert np.all(np.diff(r.t) > 0)
    T0 = r.V[0] * 8.0**2 / 2
    assert r.q[-1] - r.q[0] == pytest.approx(T0 / 3.0, rel=1e-8)
    assert any("comes to rest" in w for w in r.warnings)


def test_run_down_with_smooth_friction_slows_to_rest() -> None:
    # viscous plus regularised dry friction: steep at q̇ ≈ 0, the run ends stiff
    m = slider_crank(
        [{"link": "1", "moment": "-0.5*qdot - 2*tanh(qdot/0.0001)"}],
    )
    r = motion_in_time(m, 20.0, qdot0=6.0, rtol=1e-8, frames=101)
    assert r.stiffness_ratio > 1e5
    # not stiff at the start: explicit until the rest of the run is, then implicit
    assert r.solver == "DOP853+Radau"
    assert any("turns stiff" in w for w in r.warnings)
    assert abs(r.qdot[-1]) < 1e-6
    assert np.all(np.diff(r.work) <= 1e-9)  # friction only takes energy away
    assert r.error is not None and r.error < 1e-5


def test_table_against_exact_kinematics() -> None:
    m = motor(40.0, 20.0)
    a = motion_in_time(m, 0.6, rtol=1e-10, estimate=False, frames=11)
    b = motion_in_time(m, 0.6, rtol=1e-10, estimate=False, frames=11, table=None)
    assert a.coefficients == "table" and b.coefficients == "exact"
    assert a.table_error is not None and a.table_error < 1e-10
    assert np.allclose(a.q, b.q, rtol=0, atol=1e-8)
    assert np.allclose(a.qdot, b.qdot, rtol=0, atol=1e-7)


def test_jacobian_matches_differences() -> None:
    m = slider_crank(
        [
            {"link": "1", "moment": "400*(1 - qdot/20)"},
            {
                "link": "2",
                "force": ["3*sin(q)*qdot**2", "Piecewise((1, q < 2), (2 + q*qdot, True))"],
            },
        ],
        gravity=[0.0, -9.81],
    )
    model = KinematicModel.build(m)
    eq = reduced_equation(model, read_dynamics(m), {})
    for q, qd in [(0.3, 5.0), (2.5, 19.0), (4.0, -3.0)]:
        _, _, a, _ = eq.partials([q], [qd])
        h = 1e-6
        dq = (eq.acceleration([q + h], [qd])[0] - eq.acceleration([q - h], [qd])[0]) / (2 * h)
        dqd = (eq.acceleration([q], [qd + h])[0] - eq.acceleration([q], [qd - h])[0]) / (2 * h)
        assert a[0, 0] == pytest.approx(float(dq[0]), rel=1e-6)
        assert a[1, 0] == pytest.approx(float(dqd[0]), rel=1e-6)
        assert eq.rate(q, qd)[0] == pytest.approx(
            float(eq.acceleration([q], [qd])[0][0]), rel=1e-13
        )


def test_json_and_report() -> None:
    r = motion_in_time(motor(40.0, 20.0), 0.5, frames=5)
    d = time_json(r)
    assert set(d) >= {"t", "q", "qdot", "qddot", "solver", "steps", "error", "stiffness_ratio"}
    assert len(d["t"]) == len(d["qddot"]) == 5
    text = json.dumps(d, allow_nan=False)
    assert "NaN" not in text
    rep = time_report(r)
    assert "DOP853" in rep and "qddot" in rep and "stiffness ratio" in rep


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"t_end": 0.0}, "t_end"),
        ({"t_end": -1.0}, "t_end"),
        ({"t_end": float("nan")}, "t_end"),
        ({"t_end": float("inf")}, "t_end"),
        ({"t_end": 1.0, "frames": 1}, "frames"),
        ({"t_end": 1.0, "method": "Euler"}, "method"),
        ({"t_end": 1.0, "qdot0": float("nan")}, "qdot0"),
        ({"t_end": 1.0, "rtol": 0.0}, "rtol"),
        ({"t_end": 1.0, "parameters": {"nope": 1.0}}, "parameters"),
        ({"t_end": 1.0, "max_evaluations": 0}, "max_evaluations"),
        # a run far longer than its evaluation budget is refused with the time it reached
        ({"t_end": 1e6, "max_evaluations": 2000}, "max_evaluations"),
    ],
)
def test_bad_input_names_the_parameter(kwargs: dict[str, Any], field: str) -> None:
    with pytest.raises(MechanismError, match=f"^{field}"):
        motion_in_time(motor(40.0, 20.0), **kwargs)


def test_two_drivers_refused() -> None:
    m = read_mechanism(example_path("kin-five-bar"))
    with pytest.raises(MechanismError, match=r"^drivers: .*exactly one driver"):
        motion_in_time(m, 1.0)


def test_unknown_parameter_with_speed_dependent_load_refused() -> None:
    m = slider_crank([{"link": "1", "moment": "p*(1 - qdot/20)"}], {"p": None})
    with pytest.raises(MechanismError, match=r"^parameters\.p"):
        motion_in_time(m, 1.0)
