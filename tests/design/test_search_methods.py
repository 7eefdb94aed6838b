"""The global stages (screened multistart, differential evolution): a starting design
is never lost, the anytime budget, the solver keys and flags."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

from fourbar_oracle import coupler_point
from mjstruct.cli.main import main
from mjstruct.design.api import synthesize
from mjstruct.design.multistart import basins
from mjstruct.io import mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from project_paths import EXAMPLES

#: searches too small to find the answer on their own
TINY = {
    "multistart": {"method": "multistart", "screen": 4, "local_starts": 1, "restarts": 1},
    "de": {"method": "de", "population": 4, "generations": 1, "restarts": 1},
}


def _timed_task(solver: dict[str, object]) -> tuple[dict[str, object], float]:
    """Timed targets of the example four-bar, a start 0.02 off it, joints free in a box
    far larger than the mechanism; and the start's own RMS error by the oracle."""
    m = read_mechanism(EXAMPLES / "four-bar.json")
    q = KinematicModel.build(m).q_ref[0] + np.linspace(0.0, 1.5, 5)
    truth = mechanism_to_dict(m)
    targets = [coupler_point(truth, float(v)) for v in q]
    start = mechanism_to_dict(m)
    rng = np.random.default_rng(5)
    for j in start["joints"] + start["points"]:
        j["at"] = [v + 0.02 * rng.standard_normal() for v in j["at"]]
    e0 = math.sqrt(
        np.mean(
            [abs(coupler_point(start, float(v)) - t) ** 2 for v, t in zip(q, targets, strict=True)]
        )
    )
    box = [[-30.0, -30.0], [30.0, 30.0]]
    task = {"task": "path", "mechanism": start, "point": "M",
            "targets": [[t.real, t.imag] for t in targets], "timing": list(q),
            "region": {k: box for k in ("O1", "A", "B", "O2", "M")}, "solver": solver}  # fmt: skip
    return task, e0


@pytest.mark.parametrize("method", sorted(TINY))
def test_the_result_is_never_worse_than_the_start(method):
    task, e0 = _timed_task(TINY[method])
    r = synthesize(task, seed=3)
    assert r.feasible and r.objective <= e0 + 1e-12
    d = mechanism_to_dict(r.mechanism)  # the oracle agrees with the reported errors
    for v, t, e in zip(task["timing"], task["targets"], r.errors, strict=True):
        assert abs(abs(coupler_point(d, float(v)) - complex(*t)) - e) < 1e-9


def test_multistart_recovers_the_known_four_bar():
    task, _ = _timed_task({"screen": 2000, "local_starts": 4, "restarts": 1})
    r = synthesize(task, seed=1)
    assert r.feasible and r.max_error < 1e-8


def test_basins_keep_one_start_per_neighbourhood():
    rng = np.random.default_rng(0)
    X = rng.random((400, 3))
    key = rng.random(400)
    kept = basins(X, key, np.zeros(3), np.ones(3), 50)
    assert kept[0] == int(np.argmin(key)) and len(kept) == 50
    U = X[kept]
    gaps = np.max(np.abs(U[:, None, :] - U[None, :, :]), axis=2) + 2 * np.eye(len(kept))
    assert gaps.min() > 0.05
    assert key[kept[1]] == min(k for i, k in enumerate(key) if i != kept[0]
                               and np.max(np.abs(X[i] - X[kept[0]])) > 0.05)  # fmt: skip


def test_budget_returns_the_best_so_far_with_its_history():
    task, e0 = _timed_task({"restarts": 1, "screen": 500, "local_starts": 2})
    r = synthesize(task, seed=0, budget=1.0)
    assert r.feasible and r.objective <= e0
    best = [f for _, _, f in r.history]
    assert all(b <= a for a, b in itertools.pairwise(best))
    assert [k for k, _, _ in r.history] == sorted(k for k, _, _ in r.history)
    assert r.details["restarts"] >= 1


@pytest.mark.parametrize(
    ("argv", "solver", "message"),
    [
        (["--budget", "0"], None, "--budget: must be a positive number"),
        (["--budget", "nan"], None, "--budget: must be a positive number"),
        ([], {"method": "cmaes"}, "solver.method: unknown method 'cmaes'"),
        ([], {"screen": 0}, "solver.screen: must be in [1, 100000]"),
        ([], {"local_starts": 1.5}, "solver.local_starts: expected a whole number"),
    ],
)
def test_bad_budget_and_solver_keys_exit_2(tmp_path, capsys, argv, solver, message):
    task, _ = _timed_task({"restarts": 1} if solver is None else solver)
    path = tmp_path / "task.json"
    path.write_text(json.dumps(task))
    out = tmp_path / "out.json"
    assert main(["synthesize", str(path), "-o", str(out), *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"mjstruct synthesize: {message}") and err.count("\n") == 1
    assert not out.exists()


def test_budget_flag_writes_history_in_json(tmp_path, capsys):
    task, _ = _timed_task({"restarts": 1, "screen": 300, "local_starts": 2})
    path = tmp_path / "task.json"
    path.write_text(json.dumps(task))
    out = tmp_path / "out.json"
    assert main(["synthesize", str(path), "-o", str(out), "--budget", "2", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["feasible"] and len(d["history"]) >= 2
    assert all(len(h) == 3 and h[0] >= 0 and h[1] >= 0 for h in d["history"])


def test_many_untimed_targets_are_solved_on_a_thinned_set_then_all():
    from mjstruct.design.path import path_problem
    from mjstruct.design.task import task_from_dict

    m = read_mechanism(EXAMPLES / "four-bar.json")
    d = mechanism_to_dict(m)
    q = KinematicModel.build(m).q_ref[0] + np.linspace(0, 2 * math.pi, 120, endpoint=False)
    targets = [[z.real + 0.3, z.imag - 0.1] for z in (coupler_point(d, float(v)) for v in q)]
    task = {"task": "path", "mechanism": d, "point": "M", "targets": targets,
            "solver": {"restarts": 1, "screen": 300, "local_starts": 2}}  # fmt: skip
    p = path_problem(task_from_dict(task))
    c = p.coarse()
    assert c.targets == 32 and p.targets == 120 and p.coarse() is not p
    assert np.allclose(c.positions, p.positions[p.matched])
    assert p.screen_frames == c.samples == 4 * 32  # the screen's cost: no 120 in it
    r = synthesize(task, seed=0)
    assert len(r.errors) == 120 and r.max_error < 1e-8  # the example, moved, exactly
    moved = mechanism_to_dict(r.mechanism)
    for v, t in zip(r.details["timing"], targets, strict=True):
        assert abs(coupler_point(moved, float(v)) - complex(*t)) < 1e-8


def test_budget_is_refused_with_atlas(tmp_path, capsys):
    task, _ = _timed_task({"restarts": 1})
    path = tmp_path / "task.json"
    path.write_text(json.dumps(task))
    argv = ["synthesize", str(path), "-o", str(tmp_path / "o.json"), "--atlas", "4"]
    assert main([*argv, "--budget", "5"]) == 2
    assert capsys.readouterr().err.startswith("mjstruct synthesize: --budget: not used with")
