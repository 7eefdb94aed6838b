"""Dynamics plug-in: data checks, the equation of motion, steady motion, the CLI.

The seed-000 slider-crank (L2/L1 = 2, L1 = 1, uniform rods of mass ∝ length, slider
half the rod's mass, horizontal plane, resisting couple M = 10 on the crank, a
driving force on the slider of 10p along its motion on the first half-turn and p
against it on the second) must give p = 10π/9 and min V / max V ≈ 0.26.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import sympy as sp

from mjstruct.dynamics import dynamic_analysis
from mjstruct.dynamics.data import read_dynamics
from mjstruct.dynamics.equation import PathForce, work_integral
from mjstruct.dynamics.expressions import parse_expression
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from project_paths import EXAMPLES

SEED = EXAMPLES / "slider-crank-seed000-dynamics.json"


def seed_dict() -> dict[str, Any]:
    data: dict[str, Any] = json.loads(SEED.read_text())
    return data


def closed_form_VW(qv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """V and W of the seed's slider-crank from its closed-form positions, by sympy."""
    q = sp.Symbol("q", real=True)
    L1, L2 = 1, 2
    phi = sp.asin(-L1 * sp.sin(q) / L2)  # rod angle (B on the x axis, to the right)
    A = (L1 * sp.cos(q), L1 * sp.sin(q))
    c1 = (A[0] / 2, A[1] / 2)
    c2 = (A[0] + L2 / 2 * sp.cos(phi), A[1] + L2 / 2 * sp.sin(phi))
    c3 = (A[0] + L2 * sp.cos(phi), sp.Integer(0))
    m1, m2, m3 = 1, 2, 1
    J1, J2 = sp.Rational(1, 12), sp.Rational(2 * 4, 12)
    coords = [(m1, c1[0]), (m1, c1[1]), (m2, c2[0]), (m2, c2[1]), (m3, c3[0]), (J1, q), (J2, phi)]
    V = sum(k * sp.diff(s, q) ** 2 for k, s in coords)
    W = sum(k * sp.diff(s, q) * sp.diff(s, q, 2) for k, s in coords)
    fV, fW = sp.lambdify(q, V, "numpy"), sp.lambdify(q, W, "numpy")
    return np.asarray(fV(qv), float), np.asarray(fW(qv), float)


@pytest.fixture(scope="module")
def seed_free():
    return dynamic_analysis(read_mechanism(SEED), qdot0=10.0, frames=72)


def test_seed_parameter_is_ten_pi_over_nine(seed_free):
    assert seed_free.parameters["p"] == pytest.approx(10 * math.pi / 9, rel=1e-12)
    assert seed_free.cycle_work == pytest.approx(0.0, abs=1e-9)
    assert seed_free.integration_error < 1e-9


def test_seed_degree_of_balance(seed_free):
    # the seed prints 0.3 (rounded); the dense closed form gives the exact figure
    V, _ = closed_form_VW(np.linspace(0, 2 * np.pi, 20001))
    assert V.min() / V.max() == pytest.approx(0.2632, abs=5e-4)
    assert seed_free.balance == pytest.approx(V.min() / V.max(), rel=1e-3)
    assert round(seed_free.balance, 1) == 0.3


def test_V_and_W_match_symbolic_differentiation(seed_free):
    V, W = closed_form_VW(seed_free.q[:, 0])
    assert np.abs(seed_free.V - V).max() < 1e-12 * V.max()
    assert np.abs(seed_free.W - W).max() < 1e-12 * np.abs(W).max()


def test_free_motion_satisfies_the_energy_equation(seed_free):
    r = seed_free
    q = r.q[:, 0]
    # A(q) in closed form: couple −10 q plus the slider force's work (x_B(0) − x_B(q)) · (±p)
    p = r.parameters["p"]
    phi = np.arcsin(-np.sin(q) / 2)
    xB = np.cos(q) + 2 * np.cos(phi)
    work_force = np.where(q < np.pi, 10 * p * (3 - xB), 10 * p * 2 - p * (xB - 1))
    A = -10 * q + work_force
    V, _ = closed_form_VW(q)
    qdot = np.sqrt((2 * A + V[0] * 100) / V)
    assert np.abs(r.qdot[:, 0] - qdot).max() < 1e-10
    # the equation of motion V q̈ + W q̇² = Q holds at every frame
    lhs = r.V * r.qddot[:, 0] + r.W * r.qdot[:, 0] ** 2
    assert np.abs(lhs - r.Q).max() < 1e-9 * np.abs(r.Q).max()
    assert r.check < 1e-12


def test_motion_stops_where_qdot_squared_turns_negative():
    r = dynamic_analysis(read_mechanism(SEED), qdot0=1.0, frames=360)
    assert len(r.q) < 360 and np.isfinite(r.qdot).all()
    (warning,) = r.warnings
    assert "stops at q =" in warning
    q_stop = float(warning.split("stops at q = ")[1].split(":")[0])
    assert r.q[-1, 0] < q_stop < r.q[-1, 0] + 2 * np.pi / 360
    # at the stop, 2A + V0 q̇0² = 0: the closed-form energy confirms the root
    p = r.parameters["p"]
    xB = np.cos(q_stop) + 2 * np.cos(np.arcsin(-np.sin(q_stop) / 2))
    A = -10 * q_stop + 10 * p * (3 - xB)
    V0 = closed_form_VW(np.array([0.0]))[0][0]
    assert abs(2 * A + V0) < 1e-9
    json.dumps(r.to_dict(), allow_nan=False)


@pytest.mark.parametrize("frames", [4, 36])
def test_a_stop_between_frames_is_found(frames):
    # with q̇0 = 1 the energy dips below zero at q = 0.059 and would be positive again
    # at the next frames: the stop must not be missed on coarse frames
    r = dynamic_analysis(read_mechanism(SEED), qdot0=1.0, frames=frames)
    assert len(r.q) == 1 and "stops at q = 0.059157" in r.warnings[0]


def test_at_rest_and_pushed_backwards_it_does_not_move():
    r = dynamic_analysis(read_mechanism(SEED), qdot0=0.0, frames=8)
    assert len(r.q) == 1 and r.qdot[0, 0] == 0.0 and "stops at q = 0:" in r.warnings[0]


@pytest.mark.parametrize(
    ("method", "n", "tol"), [("trapezoid", 12, 1e-3), ("fft", 12, 1e-3), ("adaptive", 10, 1e-9)]
)
def test_integration_methods_converge_to_the_exact_parameter(method, n, tol):
    r = dynamic_analysis(read_mechanism(SEED), qdot0=10.0, frames=16, method=method, n=n)
    assert r.parameters["p"] == pytest.approx(10 * math.pi / 9, rel=tol)


def test_fft_check_measures_the_fit_error():
    m = read_mechanism(SEED)
    # 36 frames fall between the 2^n samples, where the fit departs from the force
    coarse = dynamic_analysis(m, qdot0=10.0, frames=36, method="fft", n=5)
    fine = dynamic_analysis(m, qdot0=10.0, frames=36, method="fft", n=11)
    exact = dynamic_analysis(m, qdot0=10.0, frames=36)
    assert exact.check < 1e-13
    assert coarse.check > 1e-3 > fine.check
    assert fine.check > 1e-12  # a fitted force is never exact at the jump


def test_work_integral_methods_on_a_known_function():
    f = lambda u: np.stack([1 + np.cos(u) ** 2, np.where(u < 1.0, 2.0, 0.0)])  # noqa: E731
    targets = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    exact0 = targets + targets / 2 + np.sin(2 * targets) / 4
    exact1 = 2 * np.minimum(targets, 1.0)
    g = work_integral(f, 2 * np.pi, targets, "gauss", breaks=np.array([1.0]))
    assert np.abs(g.A[0] - exact0).max() < 1e-13
    assert np.abs(g.A[1] - exact1).max() < 1e-13
    assert g.cycle == pytest.approx([3 * np.pi, 2.0], rel=1e-14)
    ff = work_integral(f, 2 * np.pi, targets, "fft", n=6)
    assert np.abs(ff.A[0] - exact0).max() < 1e-13  # a trigonometric polynomial is exact
    t = work_integral(f, 2 * np.pi, targets, "trapezoid", n=10)
    assert np.abs(t.A[1] - exact1).max() < 1e-2


def test_speed_dependent_load_is_integrated_as_an_ode():
    d = seed_dict()
    d["parameters"]["p"] = 10 * math.pi / 9
    d["loads"].append({"link": "1", "moment": "-0.05*qdot"})  # viscous friction at O1
    m = mechanism_from_dict(d)
    r = dynamic_analysis(m, qdot0=10.0, frames=24)
    # damping takes energy out: the cycle ends slower than it began
    assert r.cycle_work < 0
    lhs = r.V * r.qddot[:, 0] + r.W * r.qdot[:, 0] ** 2
    assert np.abs(lhs - r.Q).max() < 1e-9 * np.abs(r.Q).max()
    # the ODE's energy against a direct quadrature of the damping along that motion
    free = dynamic_analysis(
        mechanism_from_dict({**seed_dict(), "parameters": d["parameters"]}), qdot0=10.0, frames=24
    )
    assert (r.qdot[1:, 0] < free.qdot[1:, 0]).all()


def test_steady_parameter_with_energy_change():
    d = seed_dict()
    d["energy_change"] = 5.0
    r = dynamic_analysis(mechanism_from_dict(d), qdot0=10.0, frames=8)
    assert r.parameters["p"] == pytest.approx((20 * math.pi + 5.0) / 18, rel=1e-12)


def test_only_what_is_asked_is_computed():
    m = read_mechanism(SEED)
    r = dynamic_analysis(m, speed=1.0, frames=12, outputs=["coefficients"])
    assert r.V is not None and r.reactions is None and r.driving is None and r.check is None
    r = dynamic_analysis(m, speed=1.0, frames=12, outputs=["reactions"], joints=["A"])
    assert list(r.reactions) == ["A"] and r.V is None


def test_path_force_gives_V_W_Q_anywhere():
    m = read_mechanism(SEED)
    model = KinematicModel.build(m)
    path = PathForce(model, read_dynamics(m), 1.0)
    u = np.array([2.0, 0.5, 1.0])  # unsorted on purpose
    V, W = path.coefficients(u)
    Vc, Wc = closed_form_VW(u)
    assert np.allclose(V, Vc, atol=1e-13) and np.allclose(W, Wc, atol=1e-13)
    Q = path.force(u, 0.0, [read_dynamics(m).parameter_values(p=0.0)])[0]
    assert np.allclose(Q, -10.0)


# -- bad input ----------------------------------------------------------------------


def bad(mutate, match):
    d = seed_dict()
    mutate(d)
    with pytest.raises(MechanismError, match=match):
        dynamic_analysis(mechanism_from_dict(d), qdot0=1.0, frames=8)


def test_negative_mass_and_inertia_are_bad_input():
    bad(lambda d: d["inertia"]["1"].update(mass=-1.0), r"^inertia\.1\.mass: must be >= 0")
    bad(lambda d: d["inertia"]["2"].update(J=-0.1), r"^inertia\.2\.J: must be >= 0")
    bad(lambda d: d["inertia"].update({"9": {"mass": 1}}), r"^inertia\.9: unknown link '9'")


def test_loads_on_unknown_link_or_frame_are_bad_input():
    bad(
        lambda d: d["loads"].append({"link": "7", "moment": 1}), r"^loads\[2\]\.link: unknown link"
    )
    bad(lambda d: d["loads"].append({"link": "0", "moment": 1}), r"^loads\[2\]\.link: .*frame")


def test_expressions_are_checked():
    bad(lambda d: d["loads"][0].update(moment="-M*("), r"^loads\[0\]\.moment: cannot parse")
    bad(lambda d: d["loads"][0].update(moment="-K"), r"^loads\[0\]\.moment: 'K' is not a known")
    bad(
        lambda d: d["loads"][0].update(moment="__import__('os').system('true')"),
        r"^loads\[0\]\.moment: \"__import__\('os'\).system\" is not a known function",
    )
    bad(lambda d: d["loads"][0].update(moment="(1).__class__"), r"^loads\[0\]\.moment: Attribute")
    bad(lambda d: d["loads"][0].update(moment="9**9**9"), r"^loads\[0\]\.moment: it builds exact")
    bad(lambda d: d["loads"][0].update(moment="q < 1"), r"^loads\[0\]\.moment: .*condition")


def test_parameters_are_checked():
    bad(lambda d: d["parameters"].update(M=None), r"^parameters: two unknown parameters")
    bad(lambda d: d["parameters"].update(q=1.0), r"^parameters\.q: 'q' is reserved")
    bad(lambda d: d.update(gravity=[0, "x"]), r"^gravity\[1\]: must be a number")


def test_dynamics_needs_geometry():
    d = seed_dict()
    del d["joints"][1]["at"]
    # read once, by the kinematics' geometry (the model the dynamics runs on)
    with pytest.raises(MechanismError, match=r"^joints\[1\]\.at: missing for joint 'A'"):
        dynamic_analysis(mechanism_from_dict(d), speed=1.0, frames=4)


def test_parse_expression_builds_sympy_without_eval():
    e = parse_expression("Piecewise((1, 0 < q < pi), (-1, True)) + Max(qdot, 2)", set(), "x")
    assert e.free_symbols == {sp.Symbol("q", real=True), sp.Symbol("qdot", real=True)}
    q, qd = sp.Symbol("q", real=True), sp.Symbol("qdot", real=True)
    assert float(e.subs({q: 1.0, qd: 3.0})) == 4.0
    assert parse_expression(2, set(), "x") == 2


# -- CLI ------------------------------------------------------------------------------


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "mjstruct.cli.main", "dynamics", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_cli_free_motion_json_is_the_contract(tmp_path):
    out = tmp_path / "t.csv"
    p = run_cli(str(SEED), "--qdot0", "10", "--frames", "12", "--json", "--csv", str(out))
    assert p.returncode == 0, p.stderr
    obj = json.loads(p.stdout)
    for key in (
        "q",
        "V",
        "W",
        "Q",
        "qdot",
        "qddot",
        "balance",
        "parameters",
        "driving",
        "reactions",
        "check",
        "warnings",
    ):
        assert key in obj
    assert obj["parameters"]["p"] == pytest.approx(10 * math.pi / 9)
    assert obj["driving"]["O1"] == [0.0] * 12
    assert set(obj["reactions"]["O4"]["3"]) == {"x", "y", "m"}
    assert out.read_text().splitlines()[0].startswith("q,qdot,qddot,V,W,Q")


def test_cli_text_report_and_bad_input(tmp_path):
    p = run_cli(str(SEED), "--speed", "2", "--frames", "36")
    assert p.returncode == 0 and "check (excluded equation" in p.stdout and "p " in p.stdout
    d = seed_dict()
    d["inertia"]["1"]["mass"] = -2
    f = tmp_path / "bad.json"
    f.write_text(json.dumps(d))
    csv = tmp_path / "never.csv"
    p = run_cli(str(f), "--speed", "1", "--csv", str(csv))
    assert p.returncode == 2 and not csv.exists()
    assert p.stderr.count("\n") == 1 and "inertia.1.mass" in p.stderr
    p = run_cli(str(SEED), "--speed", "0")
    assert p.returncode == 2 and "--speed" in p.stderr
    p = run_cli(str(SEED))
    assert p.returncode == 2


@pytest.mark.parametrize("mode", [{"qdot0": 20.0}, {"speed": 20.0}, {"speed": -20.0}])
def test_one_kinematic_solution_per_analysis(monkeypatch, mode):
    # the frames' closure is solved once; the Gauss rounds of the steady parameter
    # start from it (no fresh continuation), the reactions reuse it, and no SVD runs
    m = read_mechanism(EXAMPLES / "zhivago-dynamics.json")
    model = KinematicModel.build(m)
    ref = dynamic_analysis(m, frames=36, model=model, method="adaptive", **mode)
    calls = []
    original = KinematicModel.motion

    def counted(self, *a, **k):
        calls.append(1)
        return original(self, *a, **k)

    def no_svd(*a, **k):
        raise AssertionError("an SVD per frame")

    monkeypatch.setattr(KinematicModel, "motion", counted)
    monkeypatch.setattr(np.linalg, "cond", no_svd)
    monkeypatch.setattr(np.linalg, "svd", no_svd)
    r = dynamic_analysis(m, frames=36, model=model, **mode)
    assert len(calls) == 1
    # the same results as the independent adaptive quadrature on fresh closures
    assert r.parameters["p"] == pytest.approx(ref.parameters["p"], rel=1e-10, abs=1e-9)
    big = max(
        np.abs(c).max() for per in ref.reactions.values() for x in per.values() for c in x.values()
    )
    for j, per in ref.reactions.items():
        for link, comps in per.items():
            for c, v in comps.items():
                assert np.abs(r.reactions[j][link][c] - v).max() < 1e-9 * big


def _bad_file(tmp_path, change) -> str:
    d = seed_dict()
    change(d)
    f = tmp_path / "bad.json"
    f.write_text(json.dumps(d))
    return str(f)


@pytest.mark.parametrize("text", ["1/0", "log(q-q)", "M/(q-q)", "log(0)", "1/(2*q - q - q)"])
def test_non_finite_load_expression_is_refused_at_parse_time(tmp_path, text):
    def change(d):
        d["loads"][0]["moment"] = text

    p = run_cli(_bad_file(tmp_path, change), "--speed", "1", "--json")
    assert p.returncode == 2, p.stderr
    assert p.stderr.count("\n") == 1 and "loads[0].moment" in p.stderr
    assert "not finite" in p.stderr and "internal error" not in p.stderr


@pytest.mark.parametrize(
    "args, flag",
    [
        (["--qdot0", "1e200"], "--qdot0"),
        (["--speed", "1e308"], "--speed"),
        (["--speed=-1e155"], "--speed"),
    ],
)
def test_overflowing_speeds_are_bad_input(args, flag):
    p = run_cli(str(SEED), *args, "--frames", "12", "--json")
    assert p.returncode == 2 and p.stdout == ""
    assert p.stderr.startswith(f"mjstruct dynamics: {flag}:") or f"{flag}:" in p.stderr
    assert "overflows" in p.stderr and p.stderr.count("\n") == 1


def test_steady_parameter_of_a_mechanism_that_does_not_turn_round_is_bad_input(tmp_path):
    def change(d):  # L2 = L1/2: the crank cannot make a full turn
        d["joints"][2]["at"] = [1.5, 0.0]
        d["joints"][3]["at"] = [1.5, 0.0]

    f = _bad_file(tmp_path, change)
    for mode in (["--speed", "1"], ["--speed", "-1"]):
        p = run_cli(f, *mode, "--frames", "36", "--json")
        assert p.returncode == 2, p.stderr
        assert p.stderr.count("\n") == 1 and "parameters.p" in p.stderr
        assert "does not assemble" in p.stderr
    # with p given, the frames that assemble are solved, the rest null, no numpy warning
    d = json.loads(Path(f).read_text())
    d["parameters"]["p"] = 1.0
    Path(f).write_text(json.dumps(d))
    p = run_cli(f, "--speed", "1", "--frames", "36", "--json")
    assert p.returncode == 0 and p.stderr == ""
    obj = json.loads(p.stdout)
    assert any("does not assemble" in w for w in obj["warnings"])
    assert None in obj["driving"]["O1"]


def _motor_file(tmp_path) -> str:
    def change(d):
        d["loads"] = [
            {"link": "1", "moment": "40*(1 - qdot/20)"},
            {"link": "3", "force": ["-5*qdot", "0"]},
        ]
        d["parameters"] = {}

    return _bad_file(tmp_path, change)


def test_time_honours_an_explicit_frames(tmp_path):
    f = _motor_file(tmp_path)
    p = run_cli(f, "--time", "0.05", "--json")
    assert p.returncode == 0, p.stderr
    assert len(json.loads(p.stdout)["t"]) == 201  # the default output times
    p = run_cli(f, "--time", "0.05", "--frames", "360", "--json")
    assert p.returncode == 0, p.stderr
    assert len(json.loads(p.stdout)["t"]) == 360


def test_time_errors_name_the_flags(tmp_path):
    f = _motor_file(tmp_path)
    p = run_cli(f, "--time", "-1")
    assert p.returncode == 2 and "--time" in p.stderr and "t_end" not in p.stderr
    p = run_cli(f, "--time", "1", "--solver", "X")
    assert p.returncode == 2 and "--solver" in p.stderr and "method" not in p.stderr
    import mjstruct.dynamics.time as time_module

    assert not hasattr(time_module, "FLAGS") and not hasattr(time_module, "time_command")


def test_q_drivers_carries_every_driver(tmp_path):
    d = json.loads((EXAMPLES / "kin-five-bar.json").read_text())
    d["inertia"] = {"1": {"mass": 1.0}, "2": {"mass": 2.0}, "3": {"mass": 1.5}, "4": {"mass": 1}}
    f = tmp_path / "five.json"
    f.write_text(json.dumps(d))
    p = run_cli(str(f), "--speed", "2", "--frames", "8", "--json")
    assert p.returncode == 0, p.stderr
    obj = json.loads(p.stdout)
    model = KinematicModel.build(read_mechanism(f))
    assert list(obj["q_drivers"]) == list(model.drivers) == ["O1", "O2"]
    for i, jid in enumerate(model.drivers):
        expected = model.q_ref[i] + 2 * np.pi * np.arange(8) / 8
        assert np.allclose(obj["q_drivers"][jid], expected, rtol=0, atol=1e-15)
    assert obj["q"] == obj["q_drivers"]["O1"]


def test_a_model_of_another_mechanism_or_other_drivers_is_refused():
    seed = read_mechanism(SEED)
    other = read_mechanism(EXAMPLES / "zhivago-dynamics.json")
    with pytest.raises(MechanismError, match=r"^model: "):
        dynamic_analysis(seed, speed=1.0, frames=8, model=KinematicModel.build(other))
    with pytest.raises(MechanismError, match=r"^drivers: "):
        dynamic_analysis(
            seed, speed=1.0, frames=8, drivers=["O4"], model=KinematicModel.build(seed)
        )
    # the same drivers as the model's are fine
    r = dynamic_analysis(
        seed, speed=1.0, frames=8, drivers=["O1"], model=KinematicModel.build(seed)
    )
    assert r.drivers == ("O1",)


@pytest.mark.parametrize("name", ["fourbar-ms1", "fourbar-ms5"])
def test_change_point_frames_print_no_numpy_warning(name: str) -> None:
    """Frames at a change point have no analogs (NaN, reported): no RuntimeWarning."""
    r = run_cli(str(SEED.parent / f"{name}.json"), "--speed", "1", "--frames", "36", "--json")
    assert r.returncode == 0, r.stderr
    assert "Warning" not in r.stderr, r.stderr
    out = json.loads(r.stdout)
    assert len(out["q"]) == 36


@pytest.mark.parametrize(
    ("name", "kwargs"), [("zhivago", {"speed": 1.0}), ("slider", {"qdot0": 10.0})]
)
def test_memory_estimate_is_close_to_the_measured_peak(
    name: str, kwargs: dict[str, float]
) -> None:
    """The estimate that guards --frames is within 1.5× of a tracemalloc peak."""
    import tracemalloc

    from mjstruct.dynamics.memory import analysis_bytes

    path = EXAMPLES / "zhivago-dynamics.json" if name == "zhivago" else SEED
    m = read_mechanism(path)
    dynamic_analysis(m, frames=64, **kwargs)  # imports and caches out of the measurement
    frames = 3000
    tracemalloc.start()
    try:
        dynamic_analysis(m, frames=frames, **kwargs)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    estimate = analysis_bytes(KinematicModel.build(m), frames)
    assert peak / 1.5 < estimate < peak * 1.5, (estimate, peak)


def test_cli_refuses_frames_beyond_the_memory_limit() -> None:
    r = run_cli(str(SEED), "--speed", "1", "--frames", "100000", "--max-memory", "1000000")
    assert r.returncode == 2
    line = r.stderr.strip()
    assert "\n" not in line and line.startswith("mjstruct dynamics: --frames:")
    fits = int(line.rsplit("at most ", 1)[1].split()[0])
    ok = run_cli(str(SEED), "--speed", "1", "--frames", str(fits), "--max-memory", "1000000")
    assert ok.returncode == 0, ok.stderr


def test_cli_run_in_time_beyond_its_evaluation_budget_is_refused() -> None:
    r = run_cli(str(SEED), "--time", "1e9", "--max-evaluations", "3000")
    assert r.returncode == 2
    assert "--max-evaluations" in r.stderr and "by t = " in r.stderr
