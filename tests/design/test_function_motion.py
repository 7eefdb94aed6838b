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
from mjstruct.io import mechanism_to_dict, read_mechanism
from project_paths import EXAMPLES

FAST = {"population": 5, "generations": 8, "restarts": 1}


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
            "timing_offset": True, "angle_offset": True, "solver": FAST}  # fmt: skip
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
            "solver": {"population": 4, "generations": 1, "restarts": 1}}  # fmt: skip
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
