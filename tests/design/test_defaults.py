"""Defaults and honest reports: the default transmission bound, a design variable on
its box's bound named, ``change_point: true`` of the four-bar matrix synthesis."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fourbar_oracle import coupler_point
from mjstruct.cli.main import main
from mjstruct.design.api import synthesize
from mjstruct.design.fourbar_ms import synthesize_fourbar_ms
from mjstruct.design.task import DEFAULT_TRANSMISSION_DEG, task_from_dict
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from project_paths import EXAMPLES

FAST = {"restarts": 1, "screen": 1000, "local_starts": 3}


def _task(**extra):
    m = read_mechanism(EXAMPLES / "four-bar.json")
    q = KinematicModel.build(m).q_ref[0] + np.linspace(0, 2 * math.pi, 8, endpoint=False)
    d = mechanism_to_dict(m)
    targets = [[z.real, z.imag] for z in (coupler_point(d, float(v)) for v in q)]
    return {"task": "path", "mechanism": d, "point": "M", "targets": targets,
            "solver": FAST, **extra}  # fmt: skip


def _min_transmission(d, frames=720):
    """The smallest angle between coupler A->B and rocker O2->B over a turn (oracle)."""
    at = {j["id"]: complex(*j["at"]) for j in d["joints"]}
    q0 = math.atan2((at["A"] - at["O1"]).imag, (at["A"] - at["O1"]).real)
    least = 90.0
    for q in q0 + np.linspace(0, 2 * math.pi, frames, endpoint=False):
        A, B = coupler_point(d, float(q), "A"), coupler_point(d, float(q), "B")
        u, v = B - A, B - at["O2"]
        s = abs((u.conjugate() * v).imag) / (abs(u) * abs(v))
        least = min(least, math.degrees(math.asin(min(1.0, s))))
    return least


def test_every_task_has_the_default_transmission_bound_and_zero_switches_it_off():
    assert task_from_dict(_task()).transmission_deg == DEFAULT_TRANSMISSION_DEG == 20.0
    assert task_from_dict(_task(transmission_deg=0)).transmission_deg == 0.0
    r = synthesize(_task(), seed=1)
    d = mechanism_to_dict(r.mechanism)
    assert r.feasible and _min_transmission(d) >= DEFAULT_TRANSMISSION_DEG - 0.05
    assert r.details["min_transmission_deg"] >= DEFAULT_TRANSMISSION_DEG - 1e-9


def test_a_variable_on_its_box_bound_is_named(tmp_path, capsys):
    # the targets of the example's path, its crank pivot kept 0.2 to the right of where
    # the answer has it and O2 fixed (without it a cognate fits exactly inside the box):
    # the search presses O1 against the box's left side
    task = _task(region={"O1": [[0.2, -0.5], [0.6, 0.5]]}, transmission_deg=0, fixed=["O2"])
    r = synthesize(task, seed=0)
    assert "O1.x (lower)" in r.details["on_bound"]
    assert not any(name.startswith(("A.", "B.", "M.")) for name in r.details["on_bound"])
    path = tmp_path / "task.json"
    path.write_text(json.dumps(task))
    assert main(["synthesize", str(path), "-o", str(tmp_path / "o.json")]) == 0
    assert "on a bound of its box" in capsys.readouterr().out


def test_change_point_true_takes_the_line_that_meets_the_requirements():
    # MS4's swing on 4.2 (the test of the named line gives MS4 back): any line may serve
    # a swing; the answer meets it and names the lines that could
    r = synthesize_fourbar_ms({"task": "fourbar-ms", "change_point": True, "swing_deg": 141.06})
    assert r.objective < 1e-6 and r.details["requirement"]["change_point"] in ("4.1", "4.2", "4.3")
    assert set(r.details["lines_tried"]) <= {"4.1", "4.2", "4.3"}
    assert abs(r.details["swing_deg"] - 141.06) < 1e-6
    with pytest.raises(MechanismError, match=r"^change_point: no line of system \(4\) meets"):
        synthesize_fourbar_ms(
            {"task": "fourbar-ms", "change_point": True, "swing_deg": 359, "time_ratio": 5}
        )


def _rotated(d, angle):
    r = complex(math.cos(angle), math.sin(angle))
    out = json.loads(json.dumps(d))
    for j in out["joints"] + out["points"]:
        z = complex(*j["at"]) * r
        j["at"] = [z.real, z.imag]
    return out


@pytest.mark.parametrize("free", [False, True])
def test_timing_from_the_frame_line(free):
    # the example four-bar turned by 0.7 rad: its crank angles measured from O1 -> O2 are
    # the unturned example's world angles; with the frame pivots free the frame's
    # direction is found, with them fixed it is given
    m = mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json"))
    truth = _rotated(m, 0.7)
    rel = KinematicModel.build(read_mechanism(EXAMPLES / "four-bar.json")).q_ref[0] + np.linspace(
        0.0, 1.2, 5
    )
    targets = [coupler_point(truth, float(v) + 0.7) for v in rel]
    start = _rotated(m, 0.7 if not free else 0.0)
    task = {"task": "path", "mechanism": start, "point": "M", "timing": list(rel),
            "timing_from": ["O1", "O2"], "transmission_deg": 0,
            "targets": [[z.real, z.imag] for z in targets],
            "solver": {"restarts": 1, "screen": 2000, "local_starts": 6}}  # fmt: skip
    if not free:
        task["fixed"] = ["O1", "O2"]
    r = synthesize(task, seed=2)
    d = mechanism_to_dict(r.mechanism)
    at = {j["id"]: complex(*j["at"]) for j in d["joints"]}
    frame = math.atan2((at["O2"] - at["O1"]).imag, (at["O2"] - at["O1"]).real)
    assert abs(r.details["frame_angle"] - frame) < 1e-12
    for v, t, q, e in zip(rel, targets, r.details["timing"], r.errors, strict=True):
        assert abs(math.remainder(q - (v + frame), 2 * math.pi)) < 1e-9
        assert abs(abs(coupler_point(d, float(v) + frame) - t) - e) < 1e-9
    assert r.max_error < (1e-3 if free else 1e-7)


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (["O1"], r"^timing_from: expected \[J1, J2\]"),
        (["O1", "A"], r"^timing_from\[1\]: joint 'A' is not on the frame"),
        (["O1", "X"], r"^timing_from\[1\]: 'X' is not a joint"),
        (["O2", "O2"], r"^timing_from: the two joints must differ"),
    ],
)
def test_bad_timing_from_names_the_field(value, message):
    task = _task(timing=[0.1 * k for k in range(8)], timing_from=value)
    with pytest.raises(MechanismError, match=message):
        task_from_dict(task)
    with pytest.raises(MechanismError, match=r"^timing_from: needs a timing list"):
        task_from_dict(_task(timing_from=["O1", "O2"]))


def test_every_shipped_task_reads():
    from mjstruct.design.task import read_task
    from project_paths import ROOT

    files = sorted((ROOT / "catalogs" / "tasks").glob("*.json"))
    assert len(files) >= 7
    for f in files:
        t = read_task(f)
        assert t.kind in ("path", "function", "motion") and len(t.targets) >= 5
    line = read_task(ROOT / "catalogs" / "tasks" / "path-timed5-frame-free.json")
    assert line.timing_from == ("O1", "O2") and not line.timing_offset


def _function_task(**extra):
    from fourbar_oracle import link_angle

    m = read_mechanism(EXAMPLES / "four-bar.json")
    d = mechanism_to_dict(m)
    q = KinematicModel.build(m).q_ref[0] + np.linspace(0.0, 1.6, 6)
    targets = [[float(v), link_angle(d, float(v), "3")] for v in q]
    return d, {"task": "function", "mechanism": d, "output": "3", "targets": targets,
               "fixed": ["O1", "O2"], "transmission_deg": 0,
               "solver": {"restarts": 1, "screen": 500, "local_starts": 2}, **extra}  # fmt: skip


@pytest.mark.parametrize("objective", ["points", "range"])
def test_function_results_report_the_largest_error_over_the_range(objective):
    from scipy.interpolate import CubicSpline

    from fourbar_oracle import link_angle

    _, task = _function_task(objective=objective)
    r = synthesize(task, seed=0)
    assert len(r.errors) == 6 and len(r.details["timing"]) == 6
    d = mechanism_to_dict(r.mechanism)
    q = np.array([t[0] for t in task["targets"]])
    spline = CubicSpline(q, np.unwrap([t[1] for t in task["targets"]]))
    grid = np.linspace(q[0], q[-1], 41)
    worst = max(abs(math.remainder(link_angle(d, float(v), "3") - spline(v), 2 * math.pi))
                for v in grid)  # fmt: skip
    worst = max(worst, max(r.errors))
    assert abs(r.details["max_error_range"] - worst) < 1e-9
    if objective == "points":  # the example itself fits the points exactly
        assert r.max_error < 1e-8 and r.details["max_error_range"] > 1e3 * r.max_error


def test_objective_key_is_checked():
    _, task = _function_task(objective="minimax")
    with pytest.raises(MechanismError, match=r"^objective: expected one of range, points"):
        task_from_dict(task)
    with pytest.raises(MechanismError, match=r"^objective: only for a function task"):
        task_from_dict(_task(objective="points"))
