"""Path synthesis: recovering a known four-bar, timed and untimed; the result checked
against an independent closed form; determinism; no feasible design."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fourbar_oracle import coupler_point
from mjstruct.design.api import synthesize
from mjstruct.design.result import SYNTHESIS_KEY
from mjstruct.errors import NumericalError
from mjstruct.io import mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from project_paths import EXAMPLES

FAST = {"restarts": 1, "screen": 1000, "local_starts": 4}


def _known(n: int, span: float):
    """The example four-bar, its point M at n driver values over ``span`` from the
    reference, and a start perturbed from it (the answer is known: error 0)."""
    m = read_mechanism(EXAMPLES / "four-bar.json")
    model = KinematicModel.build(m)
    q = model.q_ref[0] + np.linspace(0.0, span, n, endpoint=False)
    truth = mechanism_to_dict(m)
    targets = [coupler_point(truth, float(v)) for v in q]
    start = mechanism_to_dict(m)
    rng = np.random.default_rng(3)
    for j in start["joints"] + start["points"]:
        j["at"] = [v + 0.01 * rng.standard_normal() for v in j["at"]]
    return start, q, [[z.real, z.imag] for z in targets]


def test_timed_targets_met_exactly_and_the_oracle_agrees():
    start, q, targets = _known(6, 4.0)
    task = {"task": "path", "mechanism": start, "point": "M", "targets": targets,
            "timing": list(q), "solver": FAST}  # fmt: skip
    r = synthesize(task, seed=2)
    assert r.feasible and r.max_error < 1e-8
    d = mechanism_to_dict(r.mechanism)
    for qi, t, e in zip(q, targets, r.errors, strict=True):
        z = coupler_point(d, float(qi))
        assert abs(z - complex(*t)) < 1e-8
        assert abs(abs(z - complex(*t)) - e) < 1e-9
    entry = d[SYNTHESIS_KEY]
    assert entry["point"] == "M" and entry["targets"] == targets
    assert np.allclose(entry["timing"], q) and entry["timed"] is True
    assert r.history and r.evaluations > 0 and r.margins["assembly"] >= 0


def test_timing_offset_is_found():
    start, q, targets = _known(5, 3.0)
    rel = list(q - q[0] + 0.4)  # the offset q[0] - 0.4 is unknown to the search
    task = {"task": "path", "mechanism": start, "point": "M", "targets": targets,
            "timing": rel, "timing_offset": True, "solver": FAST}  # fmt: skip
    r = synthesize(task, seed=1)
    assert r.feasible and r.max_error < 1e-8
    timing = mechanism_to_dict(r.mechanism)[SYNTHESIS_KEY]["timing"]
    offset = np.array(timing) - np.array(rel)
    assert np.allclose(offset, offset[0], atol=1e-9)
    assert math.isclose(math.remainder(offset[0] - (q[0] - 0.4), 2 * math.pi), 0, abs_tol=1e-7)


def test_untimed_targets_are_matched_in_order_along_one_turn():
    start, _q, targets = _known(7, 5.5)
    task = {"task": "path", "mechanism": start, "point": "M", "targets": targets,
            "solver": FAST}  # fmt: skip
    r = synthesize(task, seed=0)
    assert r.feasible and r.max_error < 1e-8
    d = mechanism_to_dict(r.mechanism)
    timing = np.array(d[SYNTHESIS_KEY]["timing"])
    assert d[SYNTHESIS_KEY]["timed"] is False  # the driver values as met, not prescribed
    # met in their order along the cycle: the steps between consecutive targets,
    # taken forward modulo a turn, add up to less than one turn
    steps = np.mod(np.diff(timing), 2 * math.pi)
    assert steps.sum() < 2 * math.pi
    for qi, t in zip(timing, targets, strict=True):
        assert abs(coupler_point(d, float(qi)) - complex(*t)) < 1e-8


def test_same_seed_same_file():
    start, q, targets = _known(5, 3.0)
    task = {
        "task": "path",
        "mechanism": start,
        "point": "M",
        "targets": targets,
        "timing": list(q),
        "solver": {
            "population": 5,
            "generations": 5,
            "restarts": 1,
            "screen": 1000,
            "local_starts": 4,
        },
    }
    a = synthesize(task, seed=4)
    b = synthesize(task, seed=4)
    assert json.dumps(mechanism_to_dict(a.mechanism)) == json.dumps(mechanism_to_dict(b.mechanism))


def test_a_requirement_no_candidate_meets_is_no_feasible_design():
    start, _q, targets = _known(4, 2.0)
    # a crank-rocker whose every joint stays in a box too small for a crank to turn
    box = [[0.0, 0.0], [0.05, 0.05]]
    task = {"task": "path", "mechanism": start, "point": "M", "targets": targets,
            "motion": "crank-rocker", "region": {"O1": box, "O2": [[0.9, 0], [0.95, 0.05]]},
            "transmission_deg": 85.0,
            "solver": {"restarts": 1, "screen": 1000, "local_starts": 4}}  # fmt: skip
    with pytest.raises(NumericalError, match=r"^no feasible design: best constraint violation"):
        synthesize(task, seed=0)


def _central(f, z, h):
    """Central differences of ``f`` (an oracle independent of the problem's Jacobian)."""
    cols = []
    for i in range(len(z)):
        up, dn = z.copy(), z.copy()
        up[i] += h
        dn[i] -= h
        cols.append((f(up) - f(dn)) / (2 * h))
    return np.array(cols).T


@pytest.mark.parametrize(("timed", "lengths"), [(True, None), (False, None), (False, [0.3, 0.6])])
def test_local_jacobian_is_the_derivative_of_the_residuals(timed, lengths):
    # the Jacobian evaluates the targets' frames only when no penalty is active (and
    # the whole range when one is, as with these lengths): both must be the residuals'
    # derivative, whether or not the residuals were just asked at the same point
    from mjstruct.design.path import path_problem
    from mjstruct.design.task import task_from_dict

    start, q, targets = _known(5, 3.0)
    task = {"task": "path", "mechanism": start, "point": "M", "targets": targets}
    if timed:
        task["timing"] = list(q)
    if lengths:
        task["lengths"] = lengths
    p = path_problem(task_from_dict(task))
    z, _, _ = p.local_start(p.start())
    r = p.residuals(z)
    penalties = r[2 * len(targets) :]
    assert (np.abs(penalties) > 0).any() == bool(lengths)
    J = p.jacobian(z)
    want = _central(p.residuals, z, 1e-7)
    assert np.allclose(J, want, atol=1e-5 * np.abs(want).max())
    z2 = z + 1e-3
    assert np.allclose(
        p.jacobian(z2), _central(p.residuals, z2, 1e-7), atol=1e-5 * np.abs(want).max()
    )
