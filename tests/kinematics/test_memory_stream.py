"""The memory estimate per output path, and the CSV table streamed in chunks."""

from __future__ import annotations

import csv
import json
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.cli.output import dumps
from mjstruct.io import read_mechanism
from mjstruct.kinematics import memory
from mjstruct.kinematics.memory import sweep_bytes
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.report import write_csv, write_csv_chunks
from mjstruct.kinematics.solver import kinematic_analysis, sweep_chunks
from mjstruct.testing import shared_crank


def _peak(fn) -> int:  # type: ignore[no-untyped-def]
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("case", ["crank34", "class-iv-seed003"])
def test_the_estimate_of_each_output_path_is_within_half_again_of_the_measured_peak(case):
    if case == "crank34":
        model = KinematicModel.build(shared_crank(16))
    else:
        model = KinematicModel.build(read_mechanism(example_path(case)))
    F = 1500
    paths = {
        # the checks that word no warning run when read: the estimate covers them
        "result": (lambda: kinematic_analysis(model, frames=F).checks, "result", True),
        "bare": (lambda: kinematic_analysis(model, frames=F, checks=False), "result", False),
        "json": (lambda: dumps(kinematic_analysis(model, frames=F).to_dict()), "json", True),
    }
    for name, (fn, output, checks) in paths.items():
        peak = _peak(fn)
        est = sweep_bytes(model, F, output=output, checks=checks)
        assert peak / 1.5 <= est <= 1.5 * peak, (name, est, peak)


def test_the_csv_estimate_does_not_grow_with_the_frames_and_1000_links_fit_by_default():
    model = KinematicModel.build(read_mechanism(example_path("four-bar")))
    assert sweep_bytes(model, 10**9, "csv") == sweep_bytes(model, 10**5, "csv")
    assert sweep_bytes(model, 10**9, "csv") < 2**25
    # 1000 links, 3600 frames, default checks (measured peak 0.32 GB by tracemalloc)
    big = KinematicModel.build(shared_crank(499))
    assert len(big.mechanism.links) == 1000
    assert 0.32e9 < sweep_bytes(big, 3600) < 0.6e9 < memory.DEFAULT_MAX_MEMORY
    # the full checks build sparse entries (dense matrices only within their budget):
    # 12 MB measured at 1000 links, whatever the frames; linear in the size
    extra = sweep_bytes(big, 3600, checks="full") - sweep_bytes(big, 3600)
    assert 12e6 < extra < 4 * memory.MEMORY_BUDGET


def _rows(path: Path) -> list[list[str]]:
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.reader(f))


@pytest.mark.parametrize("name", ["fourbar-ms1", "class-iv-seed003", "slider-crank"])
def test_chunks_give_the_table_and_warnings_of_one_sweep(tmp_path, name):
    # MS1 switches branch at its change points (the chunks must carry the modes),
    # the class-IV closes by continuation, the slider-crank is the plain case
    model = KinematicModel.build(read_mechanism(example_path(name)))
    whole = kinematic_analysis(model, frames=360, speed=0.5)
    write_csv(whole, tmp_path / "one.csv")
    parts = list(sweep_chunks(model, 360, speed=0.5, chunk=70))
    assert [p.valid.size for p in parts] == [70] * 5 + [10]
    summary = write_csv_chunks(iter(parts), tmp_path / "many.csv")
    one, many = _rows(tmp_path / "one.csv"), _rows(tmp_path / "many.csv")
    assert one[0] == many[0] and len(one) == len(many) == 361
    a = np.array([[float(x) if x else np.nan for x in r] for r in one[1:]])
    b = np.array([[float(x) if x else np.nan for x in r] for r in many[1:]])
    assert (np.isnan(a) == np.isnan(b)).all()
    assert np.nanmax(np.abs(a - b)) <= 1e-9 * max(1.0, np.nanmax(np.abs(a)))
    assert summary.frames == 360 and summary.valid == int(whole.valid.sum())
    events = [e.message() for e in whole.events]
    assert [w for w in summary.warnings if w in events] == events
    assert summary.near_singular == whole.checks["jacobian"]["near_singular_frames"]


def test_cli_streams_a_csv_beyond_the_memory_limit_of_the_whole_sweep(
    tmp_path, capsys, monkeypatch
):
    f = str(example_path("four-bar"))
    model = KinematicModel.build(read_mechanism(example_path("four-bar")))
    monkeypatch.setattr(memory, "CHUNK_FRAMES", 1000)
    limit = sweep_bytes(model, 2000)  # the whole 5000-frame result would not fit
    out = tmp_path / "t.csv"
    assert main(["kinematics", f, "--frames", "5000", "--max-memory", str(limit)]) == 2
    capsys.readouterr()
    args = ["kinematics", f, "--frames", "5000", "--max-memory", str(limit), "--csv", str(out)]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "5000 frames" in text and "in 5 chunk(s)" in text
    assert "frames assembled: 5000/5000" in text
    rows = _rows(out)
    assert len(rows) == 5001
    q = np.array([float(r[0]) for r in rows[1:]])
    assert np.allclose(np.diff(q), 2 * np.pi / 5000, rtol=1e-9)
    assert [p.name for p in tmp_path.iterdir()] == ["t.csv"]  # no temporary file left


def test_an_interrupted_table_leaves_the_old_file_and_no_temporary(tmp_path):
    model = KinematicModel.build(read_mechanism(example_path("four-bar")))
    out = tmp_path / "t.csv"
    out.write_text("old\n", encoding="utf-8")

    def chunks():  # type: ignore[no-untyped-def]
        yield kinematic_analysis(model, frames=10)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_csv_chunks(chunks(), out)
    assert out.read_text(encoding="utf-8") == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["t.csv"]
    # the in-memory writer goes through the same temporary file and rename
    write_csv(kinematic_analysis(model, frames=10), out)
    assert len(_rows(out)) == 11


def test_json_output_is_refused_on_its_own_estimate(capsys):
    f = str(example_path("four-bar"))
    model = KinematicModel.build(read_mechanism(example_path("four-bar")))
    limit = sweep_bytes(model, 3000)  # the result fits, its JSON text would not
    assert main(["kinematics", f, "--frames", "3000", "--max-memory", str(limit)]) == 0
    capsys.readouterr()
    assert main(["kinematics", f, "--frames", "3000", "--max-memory", str(limit), "--json"]) == 2
    err = capsys.readouterr().err
    fits = memory.frames_that_fit(model, limit, "json")
    assert f"at most {fits} frames fit" in err and 300 < fits < 3000
    assert json is not None


@pytest.mark.parametrize("checks", [True, "full"])
def test_a_result_is_freed_when_dropped_without_the_cyclic_collector(checks):
    # a deferred check that held its own result made a reference cycle: a large
    # sweep's arrays stayed until the cyclic collector ran, and the peak of repeated
    # calls doubled (1.5 -> 2.6 GB at 4000 links x 3600 frames)
    import gc
    import weakref

    model = KinematicModel.build(read_mechanism(example_path("class-iv-seed003")))
    gc.collect()
    gc.disable()
    try:
        r = kinematic_analysis(model, frames=36, checks=checks)
        alive = weakref.ref(r)
        del r
        assert alive() is None
    finally:
        gc.enable()
