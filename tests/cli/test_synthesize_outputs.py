"""``mjstruct synthesize``'s outputs never replace its inputs or each other, and every
check runs before anything is written (issue 37 A3-A6)."""

from __future__ import annotations

import json
import shutil
import tomllib
from pathlib import Path

import pytest

from mjstruct.cli.main import main
from mjstruct.io import parse_mechanism
from project_paths import EXAMPLES

SMALL = {"population": 4, "generations": 3, "restarts": 1, "samples": 16}


def _task(folder: Path, name: str = "T.json") -> Path:
    shutil.copy(EXAMPLES / "four-bar.json", folder / "four-bar.json")
    task = {"task": "path", "mechanism": "four-bar.json", "point": "M",
            "targets": [[0.5, 1.1], [0.3, 1.1], [0.1, 0.9]], "timing": [1.0, 1.5, 2.0],
            "solver": SMALL}  # fmt: skip
    path = folder / name
    path.write_text(json.dumps(task))
    return path


def _run(capsys, argv):
    status = main([str(a) for a in argv])
    _, err = capsys.readouterr()
    return status, err


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir()}


@pytest.mark.parametrize(
    ("outputs", "message"),
    [
        (["-o", "{task}"], "-o: {task} is the input file"),  # A3
        (["-o", "{folder}/four-bar.json"], "-o: {folder}/four-bar.json is the task's mechanism"),
        (["-o", "o.json", "--history", "{task}"], "--history: {task} is the input file"),  # A4
        (
            ["-o", "o.json", "--history", "{folder}/c.svg", "--targets-chart", "{folder}/c.svg"],
            "--targets-chart: {folder}/c.svg is also the output of --history",
        ),
    ],
)
def test_an_output_onto_an_input_or_another_output_is_refused(tmp_path, capsys, outputs, message):
    name = "task.svg" if "{task}" in " ".join(outputs[2:]) else "T.json"
    task = _task(tmp_path, name)
    before = _snapshot(tmp_path)
    argv = [a.format(task=task, folder=tmp_path) for a in outputs]
    argv = [str(tmp_path / a) if a in ("o.json",) else a for a in argv]
    status, err = _run(capsys, ["synthesize", task, *argv])
    assert status == 2, err
    assert message.format(task=task, folder=tmp_path) in err
    assert _snapshot(tmp_path) == before  # nothing written, nothing replaced


def test_two_outputs_onto_one_file_through_a_link_are_refused(tmp_path, capsys):
    task = _task(tmp_path)
    (tmp_path / "d.svg").symlink_to(tmp_path / "c.svg")
    status, err = _run(capsys, ["synthesize", task, "-o", tmp_path / "o.json",
                                "--history", tmp_path / "c.svg",
                                "--targets-chart", tmp_path / "d.svg"])  # fmt: skip
    assert status == 2 and "is also the output of --history" in err


def test_fourbar_ms_with_a_targets_chart_writes_nothing_and_names_the_flag(tmp_path, capsys):
    task = tmp_path / "ms.json"
    task.write_text(json.dumps({"task": "fourbar-ms", "ms": "MS4"}))
    out, history, chart = tmp_path / "o.json", tmp_path / "h.svg", tmp_path / "t.svg"
    status, err = _run(capsys, ["synthesize", task, "-o", out, "--history", history,
                                "--targets-chart", chart])  # fmt: skip
    assert status == 2 and err.startswith("mjstruct synthesize: --targets-chart: ")
    assert not out.exists() and not history.exists() and not chart.exists()  # A5
    status, err = _run(capsys, ["synthesize", task, "-o", out, "--history", history])
    assert status == 0 and out.exists() and history.exists()


def test_all_outputs_are_written_together(tmp_path, capsys):
    task = _task(tmp_path)
    out, history, chart = tmp_path / "o.toml", tmp_path / "h.svg", tmp_path / "t.png"
    status, err = _run(capsys, ["synthesize", task, "-o", out, "--history", history,
                                "--targets-chart", chart])  # fmt: skip
    assert status == 0, err
    assert parse_mechanism(out.read_text(), toml=True).name
    assert history.read_bytes().startswith(b"<?xml") and chart.read_bytes()[:4] == b"\x89PNG"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporaries


@pytest.mark.parametrize("name", ["a\x7fb", "tab\there", "esc\x1bbel\x07nul\x00"])
def test_control_characters_are_escaped_in_toml(tmp_path, capsys, name):
    # A6: a name with DEL was written raw, and the TOML could not be read back
    m = json.loads((EXAMPLES / "four-bar.json").read_text())
    m["name"] = name
    m["joints"][1]["id"] = "A" + name
    m["drivers"] = ["O1"]
    src = tmp_path / "m.json"
    src.write_text(json.dumps(m))
    out = tmp_path / "m.toml"
    status, err = _run(capsys, ["convert", src, "-o", out])
    assert status == 0, err
    text = out.read_text(encoding="utf-8")
    assert "\x7f" not in text and "\x1b" not in text
    tomllib.loads(text)
    back = parse_mechanism(text, toml=True)
    assert back.name == name and back.joints[1].id == "A" + name


def test_a_lone_surrogate_is_bad_input_not_a_crash(tmp_path, capsys):
    src = tmp_path / "m.json"
    text = (EXAMPLES / "four-bar.json").read_text().replace('"four-bar"', '"x\\ud800"', 1)
    src.write_text(text)
    status, err = _run(capsys, ["convert", src, "-o", tmp_path / "m.toml"])
    assert status == 2 and "name: holds a lone UTF-16 surrogate" in err


def _cpu(pid: int) -> float:
    import os

    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return sum(int(x) for x in fields[11:13]) / os.sysconf("SC_CLK_TCK")


def test_sigint_stops_a_large_population_at_once_with_one_worker(tmp_path):
    # B8: one evaluation over the whole screened population (2 000 001 candidates x 72
    # frames) held the interrupt for 0.9-3.9 s of CPU (measured signalled at 4-10 s);
    # chunks of 50 000 frames let it land within 0.1-0.2 s
    import resource
    import signal
    import subprocess
    import sys
    import time

    from project_paths import ROOT

    task = _task(tmp_path)
    data = json.loads(task.read_text())
    data.pop("timing")
    data["solver"] = {"population": 20_000, "restarts": 1}
    task.write_text(json.dumps(data))
    env = {**__import__("os").environ, "PYTHONPATH": str(ROOT / "src")}
    out = tmp_path / "o.json"
    proc = subprocess.Popen([sys.executable, "-m", "mjstruct", "synthesize", str(task), "-o",
                             str(out)], stderr=subprocess.PIPE, env=env)  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while _cpu(proc.pid) < 8.0:  # past the imports, into the screening
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
        used = _cpu(proc.pid)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    total = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    assert proc.returncode == 130 and err.decode().endswith("mjstruct: interrupted\n")
    assert total - used < 1.0, (total, used)
    assert not out.exists()
