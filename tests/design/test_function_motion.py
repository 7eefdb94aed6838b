"""Function synthesis (Freudenstein's start) and motion synthesis (Burmester's start):
known four-bars recovered, checked by an independent closed form."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest

from fourbar_oracle import coupler_point, link_angle
from mjstruct.design.api import synthesize
from mjstruct.design.burmester import burmester_dyads
from mjstruct.design.function import freudenstein, lengths_of
from mjstruct.design.task import DEFAULT_TRANSMISSION_DEG
from mjstruct.io import mechanism_to_dict, read_mechanism
from project_paths import EXAMPLES

FAST = {"restarts": 1, "screen": 3000, "local_starts": 4}


def _wrap(a: float) -> float:
    return math.remainder(a, 2 * math.pi)


@pytest.mark.parametrize(
    ("a", "b", "c", "d"), [(0.3, 1.0, 0.8, 1.0), (0.5, 1.6, 1.1, 1.4), (0.4, 0.9, 1.0, 1.1)]
)
def test_three_precision_points_give_the_lengths_back(a, b, c, d):
    # the output's direction by the law of cosines (open assembly), not by the plug-in
    def psi(phi: float) -> float:
        A = a * cmath.exp(1j * phi)
        e = d - A
        f = abs(e)
        return cmath.phase(-e) - math.acos((c * c + f * f - b * b) / (2 * c * f))

    phis = [0.4, 0.9, 1.5]
    assert np.allclose(lengths_of(freudenstein(phis, [psi(p) for p in phis]), d), (a, b, c))


def _example():
    return read_mechanism(EXAMPLES / "four-bar.json"), mechanism_to_dict(
        read_mechanism(EXAMPLES / "four-bar.json")
    )


def test_function_with_relative_input_and_output_angles():
    m, truth = _example()
    q = 0.6 + np.linspace(0.0, 2.4, 7)
    out = [link_angle(truth, float(v), "3") for v in q]
    start = mechanism_to_dict(m)
    start["joints"][1]["at"] = [0.2, 0.3]
    start["joints"][2]["at"] = [0.9, 0.8]
    task = {"task": "function", "mechanism": start, "output": "3",
            "targets": [[float(v - q[0]), _wrap(o - out[0])] for v, o in zip(q, out, strict=True)],
            "timing_offset": True, "angle_offset": True, "solver": FAST,
            "objective": "points"}  # fmt: skip
    r = synthesize(task, seed=0)
    assert r.feasible and r.max_error < 1e-8
    d = mechanism_to_dict(r.mechanism)
    timing = d["synthesis"]["timing"]
    got = [link_angle(d, float(t), "3") for t in timing]
    rel = [_wrap(g - got[0]) for g in got]
    assert np.allclose(rel, [_wrap(o - out[0]) for o in out], atol=1e-8)
    assert np.allclose(np.diff(timing), np.diff(q), atol=1e-8)


def test_function_from_three_points_is_exact_from_the_start():
    m, truth = _example()
    q = [1.2, 1.9, 2.6]
    task = {"task": "function", "mechanism": mechanism_to_dict(m), "output": "3",
            "targets": [[v, link_angle(truth, v, "3")] for v in q], "fixed": ["O1", "O2"],
            "solver": {"restarts": 1, "screen": 1000, "local_starts": 4},
            "objective": "points", "transmission_deg": 0}  # fmt: skip
    task["mechanism"]["joints"][1]["at"] = [0.1, 0.35]
    r = synthesize(task, seed=0)
    assert r.max_error < 1e-10  # Freudenstein's start already meets the three points


@pytest.mark.parametrize("poses", [4, 5, 7])
def test_motion_poses_of_a_known_coupler(poses):
    m, truth = _example()
    q = 1.047 + np.linspace(0.0, 5.0, poses)
    targets = [
        [coupler_point(truth, v).real, coupler_point(truth, v).imag, link_angle(truth, v, "2")]
        for v in map(float, q)
    ]
    start = mechanism_to_dict(m)
    rng = np.random.default_rng(1)
    for j in start["joints"]:
        j["at"] = [v + 0.15 * rng.standard_normal() for v in j["at"]]
    task = {"task": "motion", "mechanism": start, "point": "M", "targets": targets,
            "solver": FAST}  # fmt: skip
    r = synthesize(task, seed=0)
    assert r.feasible and r.max_error < 1e-8
    d = mechanism_to_dict(r.mechanism)
    for t, goal in zip(d["synthesis"]["timing"], targets, strict=True):
        assert abs(coupler_point(d, t) - complex(goal[0], goal[1])) < 1e-8
        assert abs(_wrap(link_angle(d, t, "2") - goal[2])) < 1e-8


def test_four_pose_dyads_keep_their_length():
    poses = [(0.3 + 0.9j, 0.1), (0.1 + 0.95j, 0.25), (-0.1 + 0.9j, 0.4), (-0.25 + 0.7j, 0.55)]
    dyads = burmester_dyads(poses, size=2.0)
    assert len(dyads) > 10  # a curve of them
    for C, mm in dyads:
        radius = [abs(P + cmath.exp(1j * t) * mm - C) for P, t in poses]
        assert np.ptp(radius) < 1e-9


@pytest.mark.parametrize("name", ["function-log10", "motion-five-poses"])
def test_shipped_four_bar_tasks_from_the_command(tmp_path, capsys, name):
    # the per-target errors the command reports, recomputed from the written file by
    # the closed form at the driver values it reports
    import itertools
    import json

    from mjstruct.cli.main import main
    from project_paths import ROOT

    task = json.loads((ROOT / "catalogs" / "tasks" / f"{name}.json").read_text())
    task["mechanism"] = str(ROOT / "catalogs" / "examples" / "four-bar.json")
    task["solver"] = FAST
    path = tmp_path / "task.json"
    path.write_text(json.dumps(task))
    out = tmp_path / "design.json"
    assert main(["synthesize", str(path), "-o", str(out), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["feasible"] and r["task"] == task["task"] and r["output"] == str(out)
    d = mechanism_to_dict(read_mechanism(out))
    timing = d["synthesis"]["timing"]
    assert d["synthesis"]["timed"] is (task["task"] == "function" or "timing" in task)
    if task["task"] == "function":  # the chart needs the offset the search found
        assert d["synthesis"]["angle_offset"] == r["details"]["angle_offset"]
    assert len(timing) == len(task["targets"]) == len(r["errors"])
    start = [complex(*j["at"]) for j in mechanism_to_dict(_example()[0])["joints"]]
    size = max(abs(a - b) for a, b in itertools.combinations(start, 2))
    for q, goal, err in zip(timing, task["targets"], r["errors"], strict=True):
        if task["task"] == "function":
            off = r["details"]["angle_offset"]
            want = abs(_wrap(link_angle(d, q, "3") - goal[1] - off))
        else:
            dp = abs(coupler_point(d, q) - complex(goal[0], goal[1]))
            want = math.hypot(dp, size * _wrap(link_angle(d, q, "2") - goal[2]))
        assert abs(want - err) < 1e-9
    # close fits even from this small search (rad; motion: the coupler's size ~1), every
    # transmission angle at least the default bound
    assert r["objective"] < (0.03 if task["task"] == "function" else 0.05)
    assert r["details"]["min_transmission_deg"] >= DEFAULT_TRANSMISSION_DEG - 1e-9
