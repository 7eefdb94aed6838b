"""``mjstruct convert``: formats by suffix or flag, round trips through files, refusals
that leave nothing written."""

from __future__ import annotations

import json
import re

import pytest

from mjstruct.cli.main import main
from mjstruct.io import read_mechanism
from mjstruct.structure.isomorphism import canonical_code
from project_paths import DATA, EXAMPLES

PYSLVS_DATA = DATA / "pyslvs"


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


def test_json_to_pyslvs_to_toml_and_back(capsys, tmp_path):
    src = EXAMPLES / "slider-crank.json"
    status, out, _ = run(capsys, "convert", src, "-o", tmp_path / "sc.pmks", "--json")
    assert status == 0
    summary = json.loads(out)
    assert summary["from"] == "json" and summary["to"] == "pyslvs"
    assert summary["canonical"] == canonical_code(read_mechanism(src))
    assert run(capsys, "convert", tmp_path / "sc.pmks", "-o", tmp_path / "sc.toml")[0] == 0
    assert run(capsys, "convert", tmp_path / "sc.toml", "-o", tmp_path / "sc.json")[0] == 0
    assert read_mechanism(tmp_path / "sc.json") == read_mechanism(src)


def test_node_link_is_named_and_graphml_goes_by_suffix(capsys, tmp_path):
    src = EXAMPLES / "radial-engine-5.json"
    status, out, _ = run(capsys, "convert", src, "--to", "node-link")
    assert status == 0 and "nodes" in json.loads(out)
    (tmp_path / "g.json").write_text(out)
    # a .json object with nodes and no joints reads as node-link
    assert run(capsys, "convert", tmp_path / "g.json", "-o", tmp_path / "g.graphml")[0] == 0
    assert run(capsys, "convert", tmp_path / "g.graphml", "-o", tmp_path / "back.json")[0] == 0
    assert read_mechanism(tmp_path / "back.json") == read_mechanism(src)


def test_pin_slot_refused_with_exit_2_and_nothing_written(capsys, tmp_path):
    out_file = tmp_path / "out.json"
    out_file.write_text("keep me")
    status, out, err = run(capsys, "convert", PYSLVS_DATA / "crank-slider-rp.pmks", "-o", out_file)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and "pin in a slot" in err and "--pin-slot block" in err
    assert out_file.read_text() == "keep me"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.json"]
    status, _, _ = run(
        capsys,
        "convert",
        PYSLVS_DATA / "crank-slider-rp.pmks",
        "-o",
        out_file,
        "--pin-slot",
        "block",
        "--drivers",
        "P0",
    )
    assert status == 0
    m = read_mechanism(out_file)
    assert m.n == 4 and m.drivers == ("P0",)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["watt.json", "-o", "w.pmks"], r"joints\[0\]\.at: missing"),
        (["four-bar.json"], "--to: name the output format"),
        (["four-bar.json", "--to", "pyslvs", "--json"], "--json: needs -o"),
        (["four-bar.json", "-o", "x.txt"], "unknown suffix '.txt'"),
        (["four-bar.json", "-o", "x.pmks", "--drivers", "Z"], "--drivers: 'Z' is not a joint"),
        (["missing.json", "-o", "x.pmks"], "no such file"),
    ],
)
def test_bad_usage_exits_2_with_one_line(capsys, tmp_path, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    args = [str(EXAMPLES / a) if a.endswith(".json") and a != "missing.json" else a for a in argv]
    status, out, err = run(capsys, "convert", *args)
    assert status == 2 and out == ""
    assert err.count("\n") == 1
    assert re.search(message, err)
    assert list(tmp_path.iterdir()) == []


def test_pyslvs_project_in_and_out(capsys, tmp_path):
    status, _, _ = run(
        capsys, "convert", PYSLVS_DATA / "crank-rocker.pyslvs", "-o", tmp_path / "c.json"
    )
    assert status == 0
    m = read_mechanism(tmp_path / "c.json")
    assert m.drivers == ("P0",) and m.frame == "ground"
    src = EXAMPLES / "zhivago-dynamics.json"
    assert run(capsys, "convert", src, "-o", tmp_path / "z.pyslvs")[0] == 0
    assert "input:" in (tmp_path / "z.pyslvs").read_text()
    assert run(capsys, "convert", tmp_path / "z.pyslvs", "-o", tmp_path / "z.json")[0] == 0
    assert read_mechanism(tmp_path / "z.json") == read_mechanism(src)
