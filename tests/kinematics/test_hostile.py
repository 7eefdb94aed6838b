"""Hostile input to ``mjstruct kinematics``: over-driven choices, singular references,
tolerances below the floor, overflowing speeds and sweeps too large for memory."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.io import read_mechanism
from mjstruct.kinematics.memory import MEMORY_ENV, frames_that_fit, sweep_bytes
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.kinematics.tolerances import TOL_FLOOR


def _refused(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    assert main(argv) == 2
    cap = capsys.readouterr()
    assert cap.out == "" and cap.err.count("\n") == 1 and "Traceback" not in cap.err
    return cap.err


@pytest.mark.parametrize(
    ("example", "drivers", "fixed"),
    [
        ("four-bar", "O1,B", "B"),
        ("slider-crank", "O1,B", "B"),
        ("slider-crank", "O1,A", "A"),
        ("kin-radial-engine-5", "O,B1", "B1"),
        ("scotch-yoke", "O,J", "J"),
    ],
)
def test_over_driven_choices_are_refused_naming_the_driver(example, drivers, fixed, capsys):
    err = _refused(["kinematics", str(example_path(example)), "--drivers", drivers], capsys)
    assert "--drivers" in err and "over-constrained" in err and f"{fixed} already fixed" in err


def test_a_driver_named_twice_is_refused(capsys):
    err = _refused(["kinematics", str(example_path("four-bar")), "--drivers", "O1,O1"], capsys)
    assert "--drivers" in err and "listed twice" in err


def test_special_geometry_keeps_its_real_mobility():
    # the MS1 parallelogram: one driver, as its Jacobian says (not refused)
    r = kinematic_analysis(read_mechanism(example_path("fourbar-ms1")), frames=8, checks=False)
    assert r.valid.any()


def test_scotch_yoke_driven_at_the_yoke_assembles_at_its_reference(capsys):
    # driven at G the reference is a dead point (crank along the slide): positions exist,
    # velocities are infinite; the report must neither crash nor call it "no assembly"
    f = str(example_path("scotch-yoke"))
    assert main(["kinematics", f, "--drivers", "G", "--frames", "8"]) == 0
    text = capsys.readouterr().out
    assert "frames assembled: 1/8 (1 singular: positions only)" in text
    assert "singular position for q in [0, 0] (frames 0..0)" in text
    d = json.loads(
        _run(capsys, ["kinematics", f, "--drivers", "G", "--speed", "-1", "--stroke", "0.2"])
    )
    a = d["joints"]["A"]
    assert a["x"][0] == pytest.approx(0.1) and a["vx"][0] is None
    # away from the dead point the crank follows the yoke: x_A = 0.1 + q
    q = np.array(d["q"][1:])
    assert np.allclose(a["x"][1:], 0.1 + q, atol=1e-15)
    assert all(v is not None for v in a["vx"][1:])


def _run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    assert main([*argv, "--frames", "8", "--json"]) == 0
    return capsys.readouterr().out


def test_tolerance_below_the_floor_is_refused(capsys):
    f = str(example_path("zhivago"))
    err = _refused(["kinematics", f, "--tol", "1e-30"], capsys)
    assert err.startswith("mjstruct kinematics: --tol:") and "1e-15" in err
    m = read_mechanism(example_path("zhivago"))
    with pytest.raises(MechanismError, match=r"^tol: must be in \[1e-15, 1\)"):
        kinematic_analysis(m, frames=4, tol=1e-16)
    # the floor itself closes every frame
    r = kinematic_analysis(m, frames=36, tol=TOL_FLOOR, checks=False)
    assert r.closure is not None and r.closure.converged.all()


@pytest.mark.parametrize("speed", ["1e308", "1e160", "inf", "nan"])
def test_overflowing_speeds_are_bad_input(speed, capsys):
    err = _refused(["kinematics", str(example_path("four-bar")), f"--speed={speed}"], capsys)
    assert "--speed" in err


def test_accelerations_that_overflow_where_w2_does_not_are_refused():
    # W² × size is finite but W² × κ is not (the yoke near its dead point, κ ≈ 35 against
    # a size of 0.35): refused by the library naming ``speed``
    m = read_mechanism(example_path("scotch-yoke"))
    model = KinematicModel.build(m, ["G"])
    assert np.isfinite(4e153**2 * model.scale)
    with pytest.raises(MechanismError, match=r"^speed: .* overflows the velocities or acc"):
        kinematic_analysis(model, frames=8, speed=-4e153, stroke=0.2, checks=False)
    r = kinematic_analysis(model, frames=8, speed=-4e152, stroke=0.2, checks=False)
    assert np.isfinite(r.joints["A"]["ay"][1:]).all()


def test_sweeps_beyond_the_memory_limit_are_refused_with_the_largest_that_fits(
    capsys, monkeypatch
):
    f = str(example_path("four-bar"))
    err = _refused(["kinematics", f, "--frames", "10000000"], capsys)
    model = KinematicModel.build(read_mechanism(example_path("four-bar")))
    fits = frames_that_fit(model, 2**31)
    assert "--frames: 10000000 frames need about" in err and f"at most {fits} frames fit" in err
    # the flag and the environment variable lower (or raise) the limit
    err = _refused(["kinematics", f, "--frames", "100", "--max-memory", "1000"], capsys)
    assert "at most 0 frames fit" in err
    monkeypatch.setenv(MEMORY_ENV, str(sweep_bytes(model, 50)))
    assert "at most 50 frames fit" in _refused(["kinematics", f, "--frames", "51"], capsys)
    assert main(["kinematics", f, "--frames", "50"]) == 0
    capsys.readouterr()
    monkeypatch.setenv(MEMORY_ENV, "lots")
    assert MEMORY_ENV in _refused(["kinematics", f, "--frames", "5"], capsys)


def test_the_memory_estimate_bounds_the_measured_peak():
    import tracemalloc

    m = read_mechanism(example_path("class-iv-seed003"))
    model = KinematicModel.build(m)
    tracemalloc.start()
    try:
        r = kinematic_analysis(model, frames=2000)
        text = json.dumps(r.to_dict())
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert text and peak <= sweep_bytes(model, 2000, output="json") <= 3 * peak
