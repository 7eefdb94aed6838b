"""The dynamics at any size the kinematics accepts: a scaled mechanism, scaled answers.

Every length × s, every moment of inertia × s², gravity × s, every force × s and every
couple × s² (through the parameters that carry them) leave q, q̇ and q̈ unchanged and
scale V, W, Q and the work by s², the forces (reactions, a slider's drive, a force
parameter) by s and the moments (a crank's drive, a slider's moment, a couple
parameter) by s²; the warnings stay the same.  The oracle is this law applied to the
unscaled run (itself checked against closed forms in test_dynamics.py), and, for the
slider-crank, the closed form p = 10π/9 × s.  Before: the slider-crank's q̇ was 41 %
off at s = 1e-30 (every link's default centre of mass fell on its first joint) and
p 8e-6 off at s = 1e10 (the unknown's rate found as a difference of cycle works),
with "singular position" warnings at every frame (the link equations mixed force and
moment units).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import pytest

from mjstruct.cli.main import main
from mjstruct.dynamics import dynamic_analysis
from mjstruct.dynamics.result import DynamicsResult
from mjstruct.dynamics.time import motion_in_time
from mjstruct.errors import MechanismError, NumericalError
from mjstruct.io import mechanism_from_dict
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from project_paths import EXAMPLES

#: every 15 decades over the sizes the kinematics accepts (1e-50 … 1e50)
SCALES = [10.0**e for e in range(-45, 46, 15) if e != 0]

#: the measured worst relative error of an output over SCALES is 7.5e-14 (Zhivago's
#: p: its closure converges to its own tolerance, not to the last digit)
RTOL = 1e-12

SLIDER = "slider-crank-seed000-dynamics"
ZHIVAGO = "zhivago-dynamics"

#: per example, the power of s each parameter carries (M, p: a couple or a force)
POWERS = {SLIDER: {"M": 2, "p": 1}, ZHIVAGO: {"M": 2, "p": 2}}


def example(name: str) -> dict[str, Any]:
    d: dict[str, Any] = json.loads((EXAMPLES / f"{name}.json").read_text())
    return d


def scaled(d: Mapping[str, Any], s: float, powers: Mapping[str, float]) -> dict[str, Any]:
    """The file ``d`` with every length × s (and the rest by the scaling law)."""
    out: dict[str, Any] = json.loads(json.dumps(d))
    for j in out["joints"]:
        j["at"] = [c * s for c in j["at"]]
    for spec in out.get("inertia", {}).values():
        if "J" in spec:
            spec["J"] *= s * s
        if "com" in spec:
            spec["com"] = [c * s for c in spec["com"]]
    if "gravity" in out:
        out["gravity"] = [g * s for g in out["gravity"]]
    for k, v in out.get("parameters", {}).items():
        if v is not None:
            out["parameters"][k] = v * s ** powers[k]
    for load in out.get("loads", []):
        if "at" in load:
            load["at"] = [c * s for c in load["at"]]
    return out


def outputs(
    r: DynamicsResult, powers: Mapping[str, float], m: Mechanism
) -> dict[str, tuple[Any, float]]:
    """Every numeric output of ``r`` (a run of ``m``) with the power of s it carries."""
    kinds = {j.id: j.kind for j in m.joints}
    out: dict[str, tuple[Any, float]] = {
        "q": (r.q, 0),
        "qdot": (r.qdot, 0),
        "qddot": (r.qddot, 0),
        "condition": (r.condition, 0),
        "accuracy": (r.accuracy, 0),
        "balance": (r.balance, 0),
        "V": (r.V, 2),
        "W": (r.W, 2),
        "Q": (r.Q, 2),
    }
    out |= {f"parameters.{k}": (v, powers[k]) for k, v in r.parameters.items()}
    for d, v in (r.driving or {}).items():
        out[f"driving.{d}"] = (v, 2 if kinds[d] == "R" else 1)
    for j, per in (r.reactions or {}).items():
        for link, comps in per.items():
            for c, v in comps.items():
                out[f"reactions.{j}.{link}.{c}"] = (v, 2 if c == "m" else 1)
    return {k: v for k, v in out.items() if v[0] is not None}


def assert_scaled(
    ref: DynamicsResult, r: DynamicsResult, s: float, powers: Mapping[str, float], m: Mechanism
) -> None:
    """``r`` (a run of ``m`` scaled by s) is ``ref`` (of ``m``) by the scaling law."""
    a, b = outputs(ref, powers, m), outputs(r, powers, m)
    assert a.keys() == b.keys()
    for key, (x, p) in a.items():
        xa = np.asarray(x, float)
        ya = np.asarray(b[key][0], float) / s**p
        assert xa.shape == ya.shape, key
        assert (np.isnan(xa) == np.isnan(ya)).all(), key
        big = np.nanmax(np.abs(xa)) if np.isfinite(xa).any() else 0.0
        if key == "accuracy":
            # an error estimate: it includes the closure's achieved residual, which
            # rounds differently at each scale: the same to a factor of ten
            assert np.nanmax(ya / xa, initial=1.0) <= 10, (key, s)
            assert np.nanmax(xa / ya, initial=1.0) <= 10, (key, s)
            continue
        # condition: an estimate from the solve, equal to its own round-off
        tol = 1e-9 if key == "condition" else RTOL
        assert np.nanmax(np.abs(ya - xa), initial=0.0) <= tol * big, (key, s)
    assert r.warnings == ref.warnings, s
    if ref.check is not None:
        assert r.check is not None and max(ref.check, r.check) < 1e-12


MODES = {
    "speed": {"speed": 2.0, "frames": 36},
    "free": {"qdot0": 20.0, "frames": 36},
    "prescribed": {
        "q": np.linspace(0.1, 2.0, 7),
        "qdot": np.linspace(1.0, 2.0, 7),
        "qddot": 0.3,
        "parameters": {"p": 0.5},
    },
}


@pytest.mark.parametrize("name", [SLIDER, ZHIVAGO])
@pytest.mark.parametrize("mode", list(MODES))
def test_a_scaled_mechanism_gives_the_scaled_answers(name: str, mode: str) -> None:
    d, powers = example(name), POWERS[name]
    m = mechanism_from_dict(d)
    ref = dynamic_analysis(m, **MODES[mode])
    for s in SCALES:
        kw = dict(MODES[mode])
        if "parameters" in kw:
            kw["parameters"] = {"p": 0.5 * s ** powers["p"]}
        r = dynamic_analysis(mechanism_from_dict(scaled(d, s, powers)), **kw)
        assert_scaled(ref, r, s, powers, m)


def test_the_steady_parameter_keeps_its_digits_in_any_unit() -> None:
    # p = 10π/9 in closed form (test_dynamics.py): one unit of p is 1e-46 of the
    # couple's work at s = 1e45, and 1e44 times it at s = 1e-45
    d = example(SLIDER)
    # and the ends of the accepted sizes, 1e-50 … 1e50 (the size is 3)
    for s in [*SCALES, 1e10, 3.4e-51, 3.3e49]:
        m = mechanism_from_dict(scaled(d, s, POWERS[SLIDER]))
        for kw in ({"speed": 2.0}, {"qdot0": 10.0}):
            r = dynamic_analysis(m, frames=12, outputs=["motion"], **kw)
            assert r.parameters["p"] == pytest.approx(10 * math.pi / 9 * s, rel=2e-15)


def test_free_motion_that_stops_stops_at_the_same_q() -> None:
    # from q̇₀ = 1 the slider-crank stops at q = 0.0592 (a warning names it)
    d = example(SLIDER)
    m = mechanism_from_dict(d)
    ref = dynamic_analysis(m, qdot0=1.0, frames=36)
    assert ref.warnings and ref.warnings[0].startswith("the motion stops at q = 0.059157")
    for s in SCALES:
        r = dynamic_analysis(
            mechanism_from_dict(scaled(d, s, POWERS[SLIDER])), qdot0=1.0, frames=36
        )
        assert_scaled(ref, r, s, POWERS[SLIDER], m)


def test_a_cycle_work_independent_of_the_unknown_is_refused_at_every_scale() -> None:
    # backwards from q = 0 the force is 10p all the way and the slider returns: the
    # cycle work of p is 0 (rounding), whatever the unit
    d = example(SLIDER)
    for s in [1.0, *SCALES]:
        m = mechanism_from_dict(scaled(d, s, POWERS[SLIDER]))
        with pytest.raises(MechanismError, match=r"^parameters\.p: .* does not depend on p"):
            dynamic_analysis(m, qdot0=-15.0, frames=12)


def speed_dependent(d: dict[str, Any]) -> dict[str, Any]:
    """The slider-crank with a viscous couple −c q̇ on the crank (free motion by ODE)."""
    d["parameters"] |= {"c": 0.01, "p": 3.49}
    d["loads"].append({"link": "1", "moment": "-c*qdot"})
    return d


def test_speed_dependent_free_motion_scales() -> None:
    d, powers = speed_dependent(example(SLIDER)), {"M": 2, "p": 1, "c": 2}
    m = mechanism_from_dict(d)
    ref = dynamic_analysis(m, qdot0=10.0, frames=12)
    # the energy's absolute tolerance was 1e-14 (a unit): at s = 1e-45 E is 1e-88
    r = dynamic_analysis(mechanism_from_dict(scaled(d, 1e-45, powers)), qdot0=10.0, frames=12)
    assert_scaled(ref, r, 1e-45, powers, m)


def nonlinear(d: dict[str, Any]) -> dict[str, Any]:
    """The slider-crank whose unknown enters as p|p| (the secant method's case)."""
    d["loads"][1]["force"][0] = "-p*Abs(p)*Piecewise((10, q < pi), (1, True))"
    return d


def test_an_unknown_entering_nonlinearly_scales_or_is_refused() -> None:
    # p|p| is a force: p scales with √s.  Its derivative at 0 is 0, so the secant
    # starts from one unit of p: it finds p where that unit is within about 1e15 of
    # the answer, and says it found none beyond (never a wrong value)
    d, powers = nonlinear(example(SLIDER)), {"M": 2, "p": 0.5}
    m = mechanism_from_dict(d)
    ref = dynamic_analysis(m, qdot0=10.0, frames=12)
    assert ref.parameters["p"] == pytest.approx(math.sqrt(10 * math.pi / 9), rel=1e-14)
    for s in (1e-15, 1e15):
        r = dynamic_analysis(mechanism_from_dict(scaled(d, s, powers)), qdot0=10.0, frames=12)
        assert_scaled(ref, r, s, powers, m)
    for s in (1e-45, 1e45):
        with pytest.raises(NumericalError, match=r"^parameters\.p: no value makes"):
            dynamic_analysis(mechanism_from_dict(scaled(d, s, powers)), qdot0=10.0, frames=12)


def slider_driven(d: dict[str, Any]) -> dict[str, Any]:
    """The slider-crank driven by its slider, crank at 90°: a spring and a damper on it."""
    d["drivers"] = ["O4"]
    d["joints"][1]["at"] = [0.0, 1.0]
    d["joints"][2]["at"] = d["joints"][3]["at"] = [math.sqrt(3.0), 0.0]
    d["parameters"] = {"k": 3.0, "c": 0.5, "M": 0.2}
    d["loads"] = [
        {"link": "3", "force": ["-k*q - c*qdot", "0"]},
        {"link": "1", "moment": "-M"},
    ]
    return d


def test_a_slider_driver_scales_prescribed_and_in_time() -> None:
    # q of a prismatic driver is a length: it scales too (the spring constant k and
    # the damping c do not, M is a couple)
    d, powers = slider_driven(example(SLIDER)), {"k": 0, "c": 0, "M": 2}
    m = mechanism_from_dict(d)
    slide = -np.linspace(0.05, 0.5, 6)  # x from 1.68 to 1.23: it assembles
    ref = dynamic_analysis(m, q=slide, qdot=-1.0, qddot=0.5)
    t_ref = motion_in_time(m, 2.0, qdot0=0.3, frames=5, estimate=False)
    assert t_ref.stopped == "rest"
    for s in (1e-45, 1e45):
        ms = mechanism_from_dict(scaled(d, s, powers))
        r = dynamic_analysis(ms, q=slide * s, qdot=-s, qddot=0.5 * s)
        for key in ("driving.O4", "reactions.O4.3.y", "reactions.A.2.x", "reactions.O4.3.m"):
            x, p = outputs(ref, powers, m)[key]
            y = outputs(r, powers, m)[key][0] / s**p
            assert np.isfinite(x).all() and np.isfinite(y).all(), key
            assert np.abs(y - x).max() <= RTOL * max(np.abs(x).max(), 1e-300), key
        assert r.warnings == ref.warnings
        t = motion_in_time(ms, 2.0, qdot0=0.3 * s, frames=5, estimate=False)
        # the same steps of the solver up to its own step-size rounding: within its
        # tolerance (1e-8)
        assert np.abs(t.q / s - t_ref.q).max() <= 1e-7 * np.abs(t_ref.q).max()
        assert np.abs(t.t - t_ref.t).max() <= 1e-7 * t_ref.t[-1] and t.stopped == "rest"


def test_motion_in_time_scales_to_its_tolerance() -> None:
    # a run-up under a motor's line and a viscous slider (the doctest of
    # mjstruct.dynamics.time): q, q̇ unchanged, V, Q and the work × s²; the explicit
    # solver's step sizes follow round-off (an error estimate that is a difference of
    # near-equal stages), so agreement is to the tolerance, not to the last digit
    d = example(SLIDER)
    d["parameters"] = {"a": 40.0, "b": 5.0}
    d["loads"] = [
        {"link": "1", "moment": "a*(1 - qdot/20)"},
        {"link": "3", "force": ["-b*qdot", "0"]},
    ]
    powers = {"a": 2, "b": 1}
    ref = motion_in_time(mechanism_from_dict(d), 3.0, frames=7, estimate=False)
    for s in (1e-45, 1e45):
        r = motion_in_time(
            mechanism_from_dict(scaled(d, s, powers)), 3.0, frames=7, estimate=False
        )
        for key, p in (("q", 0), ("qdot", 0), ("qddot", 0), ("V", 2), ("Q", 2), ("work", 2)):
            x, y = getattr(ref, key), getattr(r, key) / s**p
            assert np.abs(y - x).max() <= 1e-6 * np.abs(x).max(), key
        assert r.warnings == ref.warnings and r.solver == ref.solver
        assert r.energy_residual == pytest.approx(ref.energy_residual, rel=0.5)


def test_the_command_prints_the_scaled_answers(tmp_path: Any, capsys: Any) -> None:
    d = example(SLIDER)
    outs = []
    for s in (1.0, 1e-30):
        f = tmp_path / f"m{s:g}.json"
        f.write_text(json.dumps(scaled(d, s, POWERS[SLIDER])))
        assert main(["dynamics", str(f), "--qdot0", "10", "--frames", "12", "--json"]) == 0
        outs.append(json.loads(capsys.readouterr().out))
    one, tiny = outs
    assert tiny["warnings"] == one["warnings"] == []
    assert tiny["qdot"] == pytest.approx(one["qdot"], rel=1e-14)
    assert np.array(tiny["V"]) / 1e-60 == pytest.approx(one["V"], rel=1e-14)
    assert tiny["condition"] == pytest.approx(one["condition"], rel=1e-9)


def test_the_joint_loads_of_a_model_built_once_scale() -> None:
    # the library call with a model built beforehand (the benchmark's way)
    d = example(ZHIVAGO)
    m = mechanism_from_dict(d)
    ref = dynamic_analysis(m, speed=1.0, frames=12, model=KinematicModel.build(m))
    ms = mechanism_from_dict(scaled(d, 1e40, POWERS[ZHIVAGO]))
    r = dynamic_analysis(ms, speed=1.0, frames=12, model=KinematicModel.build(ms))
    assert_scaled(ref, r, 1e40, POWERS[ZHIVAGO], m)
