"""Synthesis memory: the estimate, the refusal before anything is allocated, and the
population judged in chunks with the answer of one call (issue 37 B7, B8)."""

from __future__ import annotations

import time
import tracemalloc

import numpy as np
import pytest

from mjstruct.cli.main import main
from mjstruct.design.api import load_task, synthesize
from mjstruct.design.memory import assess_in_chunks, chunk_rows, synthesis_bytes
from mjstruct.design.path import path_problem
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_to_dict, read_mechanism
from project_paths import EXAMPLES

TARGETS = [[0.5, 1.1], [0.3, 1.1], [0.1, 0.9]]


def _task(**extra):
    m = mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json"))
    return {"task": "path", "mechanism": m, "point": "M", "targets": TARGETS, **extra}


def _many(n: int) -> list[list[float]]:
    return np.random.default_rng(0).uniform(0, 1, (n, 2)).tolist()


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        ({"solver": {"population": 100_000}}, "solver.population"),  # the documented maximum
        ({"targets": _many(10_000)}, "targets"),
        ({"targets": _many(10_000), "timing": list(np.linspace(0.0, 6.0, 10_000))}, "targets"),
    ],
)
def test_a_search_beyond_the_memory_limit_is_refused_before_allocating(extra, field):
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(MechanismError) as exc:
            synthesize(_task(**extra), seed=0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    message = str(exc.value)
    assert message.startswith(f"{field}: ") and "over the limit of 2.15e+09 bytes" in message
    assert peak < 100e6 and time.perf_counter() - t0 < 30


def test_the_limit_can_be_raised_or_lowered(monkeypatch):
    with pytest.raises(MechanismError, match=r"^solver.population: .* over the limit of 1e\+06"):
        synthesize(_task(), seed=0, max_memory=10**6)
    monkeypatch.setenv("MJSTRUCT_MAX_MEMORY_BYTES", str(10**6))
    with pytest.raises(MechanismError, match="over the limit of 1e"):
        synthesize(_task(), seed=0)
    t = load_task(_task(solver={"population": 100_000}))
    need = sum(synthesis_bytes(path_problem(t), t.solver).values())
    assert 4e9 < need < 1e10  # 10 x 1e6 members x 10 variables of Latin hypercube


def test_the_command_names_its_flag_and_writes_nothing(tmp_path, capsys):
    import json

    task = tmp_path / "t.json"
    task.write_text(json.dumps(_task()))
    out = tmp_path / "o.json"
    status = main(["synthesize", str(task), "-o", str(out), "--max-memory", "1000"])
    err = capsys.readouterr().err
    assert status == 2 and "over the limit of 1e+03 bytes" in err and not out.exists()
    assert main(["synthesize", str(task), "-o", str(out), "--max-memory", "0"]) == 2
    assert "--max-memory: must be a positive" in capsys.readouterr().err


def test_a_population_in_chunks_is_judged_as_in_one_call():
    p = path_problem(load_task(_task(targets=_many(6))))
    lo, hi = p.bounds()
    X = lo + (hi - lo) * np.random.default_rng(1).random((40, len(lo)))
    whole = p._assess(X)
    parts = assess_in_chunks(p._assess, X, 7)
    assert np.array_equal(whole.energy, parts.energy)
    for k, v in whole.margins.items():
        assert np.array_equal(v, parts.margins[k])
    assert chunk_rows(p) * p.samples <= 50_000


def test_an_atlas_of_odd_or_too_many_links_names_the_flag(tmp_path, capsys):
    import json

    task = tmp_path / "t.json"
    task.write_text(json.dumps({"task": "path", "point": "P", "targets": TARGETS}))
    for links, words in (("5", "even number of links"), ("50", "2.4e+68 one-DOF chains")):
        status = main(["synthesize", str(task), "-o", str(tmp_path / "o.json"), "--atlas", links])
        err = capsys.readouterr().err
        assert status == 2 and err.startswith("mjstruct synthesize: --atlas: ") and words in err
