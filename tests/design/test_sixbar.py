"""Path, function and motion synthesis of a Watt six-bar, from the API and from the
command: a known six-bar recovered from a perturbed start, the result checked by an
independent full-system continuation (tests/full_system_continuation.py: every link a
rigid body, no plan, no triangle step); the same task and seed give the same file."""

from __future__ import annotations

import cmath
import functools
import json
import math

import numpy as np
import pytest

from full_system_continuation import FullSystem, reach
from mjstruct.cli.main import main
from mjstruct.design.api import synthesize
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism

#: a Watt I six-bar whose crank O1 -> A turns fully: the four-bar O1 A B O2, the
#: ternary rocker 3 (O2, B, C) driving the dyad C D O3; P is a point of link 5 (C, D)
WATT = {
    "name": "watt-test",
    "frame": "0",
    "drivers": ["O1"],
    "joints": [
        {"id": "O1", "links": ["0", "1"], "at": [0.0, 0.0]},
        {"id": "A", "links": ["1", "2"], "at": [0.162091, 0.252441]},
        {"id": "B", "links": ["2", "3"], "at": [0.998858, 0.799999]},
        {"id": "O2", "links": ["0", "3"], "at": [1.0, 0.0]},
        {"id": "C", "links": ["3", "5"], "at": [0.653912, 0.631366]},
        {"id": "D", "links": ["5", "4"], "at": [1.354194, 0.244577]},
        {"id": "O3", "links": ["0", "4"], "at": [1.6, 0.9]},
    ],
    "points": [{"id": "P", "link": "5", "at": [1.1, 0.6]}],
}
Q = 1.0 + np.linspace(0.0, 2.4, 6)  # the driver values of the targets (q_ref = 1)
FAST = {"population": 4, "generations": 3, "restarts": 1, "screen": 1000, "local_starts": 4}
FRAME = ["O1", "O2", "O3"]


def _oracle(d, q):
    """Positions of P and the angles of links 4 and 5 of the file ``d`` at ``q``
    (the full-system continuation from its reference)."""
    m = mechanism_from_dict(d)
    got = reach(FullSystem(m), q)
    assert sorted(got) == list(range(len(q)))
    at = {j["id"]: complex(*j["at"]) for j in d["joints"]}
    P0 = complex(*d["points"][0]["at"])
    out = []
    for i in range(len(q)):
        J = got[i].joints
        turn = (J["D"] - J["C"]) / (at["D"] - at["C"])  # link 5's rotation (unit)
        P = J["C"] + turn * (P0 - at["C"])
        # the contract's angle of a link: its first joint to its second, in file order
        out.append((P, cmath.phase(J["O3"] - J["D"]), cmath.phase(J["D"] - J["C"])))
    return out


@functools.cache
def _truth() -> tuple:
    return tuple(_oracle(WATT, Q))


def _task(kind: str) -> dict:
    truth = _truth()
    start = json.loads(json.dumps(WATT))
    rng = np.random.default_rng(7)
    for j in start["joints"] + start["points"]:
        if j["id"] not in FRAME:
            j["at"] = [v + 0.01 * rng.standard_normal() for v in j["at"]]
    task = {"task": kind, "mechanism": start, "fixed": FRAME, "solver": FAST}
    if kind == "path":
        task |= {"point": "P", "targets": [[p.real, p.imag] for p, _, _ in truth],
                 "timing": list(Q)}  # fmt: skip
    elif kind == "function":
        task |= {
            "output": "4",
            "targets": [[q, a4] for q, (_, a4, _) in zip(Q, truth, strict=True)],
            "objective": "points",  # the known six-bar meets the points exactly
        }
    else:
        task |= {"point": "P", "targets": [[p.real, p.imag, a5] for p, _, a5 in truth],
                 "timing": list(Q)}  # fmt: skip
    return task


def _check(kind: str, d: dict, targets: list) -> None:
    """The design ``d`` meets the targets at its own timing, by the oracle."""
    timing = d["synthesis"]["timing"]
    assert np.allclose(timing, Q, atol=1e-9)
    for (P, a4, a5), t in zip(_oracle(d, np.array(timing)), targets, strict=True):
        if kind == "function":
            assert abs(math.remainder(a4 - t[1], 2 * math.pi)) < 1e-7
        else:
            assert abs(P - complex(t[0], t[1])) < 1e-7
        if kind == "motion":
            assert abs(math.remainder(a5 - t[2], 2 * math.pi)) < 1e-7


@pytest.mark.parametrize("kind", ["path", "function", "motion"])
def test_six_bar_from_the_api(kind):
    task = _task(kind)
    r = synthesize(task, seed=1)
    assert r.feasible and r.max_error < 1e-8
    d = mechanism_to_dict(r.mechanism)
    assert {j["id"]: j["at"] for j in d["joints"] if j["id"] in FRAME} == {
        j["id"]: j["at"] for j in WATT["joints"] if j["id"] in FRAME
    }
    _check(kind, d, task["targets"])


@pytest.mark.parametrize("kind", ["path", "function", "motion"])
def test_six_bar_from_the_command(tmp_path, capsys, kind):
    path = tmp_path / "task.json"
    path.write_text(json.dumps(_task(kind)))
    out = tmp_path / "six.json"
    assert main(["synthesize", str(path), "-o", str(out), "--seed", "2", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["task"] == kind and report["feasible"] and report["max_error"] < 1e-8
    m = read_mechanism(out)
    assert len(m.links) == 6 and m.extra["synthesis"]["task"] == kind
    _check(kind, mechanism_to_dict(m), _task(kind)["targets"])
    if kind == "path":  # the same task and seed: the same bytes
        again = tmp_path / "again.json"
        assert main(["synthesize", str(path), "-o", str(again), "--seed", "2"]) == 0
        assert again.read_bytes() == out.read_bytes()
