"""Gear pairs in the mechanism file: read, checked (bad input names the field), kept by
every writer, GraphML edges."""

from __future__ import annotations

import copy
import json

import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.exchange.graph_formats import (
    mechanism_from_graph,
    mechanism_from_graphml,
    mechanism_to_graph,
    mechanism_to_graphml,
)
from mjstruct.gear_pairs import gear_pairs
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, mechanism_to_toml, parse_mechanism

PLANETARY = json.loads(example_path("planetary-simple").read_text())


def _with(change) -> dict:
    data = copy.deepcopy(PLANETARY)
    change(data["gears"])
    return data


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda g: g[0].update(links=["1", "1"]), r"\[0\]\.links: a gear pair joins two links"),
        (lambda g: g[0].update(links=["1", "9"]), r"gears\[0\]\.links: unknown link '9'"),
        (lambda g: g[0].update(teeth=[20, 0]), r"gears\[0\]\.teeth: .*positive integers, got 0"),
        (lambda g: g[0].update(teeth=[20.5, 40]), r"gears\[0\]\.teeth: .*positive integers"),
        (lambda g: g[0].update(teeth=[20]), r"gears\[0\]\.teeth: expected a list of 2"),
        (lambda g: g[1].update(type="bevel"), r"gears\[1\]\.type: unknown gear pair type"),
        (lambda g: g[0].update(module=-1), r"gears\[0\]\.module: expected a positive number"),
        (lambda g: g[0].update(teeth=[20, 50]), r"gears\[0\]: the gears do not mesh: .* needs 35"),
        (lambda g: g[1].update(teeth=[40, 90]), r"\[1\]: the gears do not mesh: .*\|r1 - r2\|"),
        (lambda g: g[0].update(radii=[10, 21]), r"gears\[0\]\.radii: .* differ from module"),
        (lambda g: g[0].update(centres=["P", "O"]), r"\[0\]\.centres: joint 'P' is not on link"),
        (lambda g: g[0].update(spin=1), r"gears\[0\]\.spin: unknown key"),
        (lambda g: g[1].update(id="g12"), r"gears\[1\]\.id: duplicate gear pair id"),
        (lambda g: g.append(7), r"gears\[2\]: must be an object"),
    ],
)  # fmt: skip
def test_bad_gear_pairs_name_the_field(change, message):
    with pytest.raises(MechanismError, match=message):
        mechanism_from_dict(_with(change))


def test_bad_gear_file_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(_with(lambda g: g[0].update(teeth=[20, 50]))))
    assert main(["analyze", str(bad)]) == 2
    err = capsys.readouterr().err
    assert (
        err.startswith("mjstruct analyze: gears[0]: the gears do not mesh")
        and err.count("\n") == 1
    )


def test_radii_alone_and_rack():
    data = copy.deepcopy(PLANETARY)
    for g in data["gears"]:
        g["radii"] = [g["module"] * z / 2 for z in g.pop("teeth")]
        del g["module"]
    assert [p.radii for p in gear_pairs(mechanism_from_dict(data))] == [(10, 20), (20, 50)]
    rack = {
        "frame": "0",
        "joints": [{"id": "O", "links": ["0", "1"], "at": [0, 0]},
                   {"id": "S", "links": ["0", "2"], "type": "P", "at": [0, -10], "axis": [1, 0]}],
        "gears": [{"id": "r", "links": ["1", "2"], "type": "rack", "teeth": [20], "module": 1,
                   "centres": ["O"], "line": {"at": [5, -10], "axis": [1, 0]}}],
    }  # fmt: skip
    assert gear_pairs(mechanism_from_dict(rack))[0].radii == (10.0,)
    rack["gears"][0]["line"]["at"] = [5, -11]
    with pytest.raises(
        MechanismError, match=r"gears\[0\]: the gears do not mesh: .* needs 10 \(r\)"
    ):
        mechanism_from_dict(rack)


@pytest.mark.parametrize("name", ["planetary-simple", "planetary-2aa", "geared-five-bar"])
def test_writers_keep_the_gears(name):
    from mjstruct.io import read_mechanism

    m = read_mechanism(example_path(name))
    again = mechanism_from_dict(json.loads(json.dumps(mechanism_to_dict(m))))
    assert again == m and gear_pairs(again) == gear_pairs(m)
    assert gear_pairs(parse_mechanism(mechanism_to_toml(m), toml=True)) == gear_pairs(m)
    back = mechanism_from_graphml(mechanism_to_graphml(m))
    assert back == m and gear_pairs(back) == gear_pairs(m)


def test_graphml_gear_edges_carry_the_pair_type():
    from mjstruct.io import read_mechanism

    m = read_mechanism(example_path("planetary-simple"))
    g = mechanism_to_graph(m)
    edges = {
        d["gear_id"]: (sorted((u, v)), d["gear_type"])
        for u, v, d in g.edges(data=True)
        if d.get("pair") == "gear"
    }
    assert edges == {
        "g12": (["link:1", "link:2"], "external"),
        "g20": (["link:0", "link:2"], "internal"),
    }
    del g.graph["extra"]  # a graph tool's file: the pairs come from the edges
    pairs = {p.id: (set(p.links), p.kind) for p in gear_pairs(mechanism_from_graph(g))}
    assert pairs == {"g12": ({"1", "2"}, "external"), "g20": ({"0", "2"}, "internal")}


def test_convert_to_graphml_and_back(tmp_path):
    out = tmp_path / "p.graphml"
    assert main(["convert", str(example_path("planetary-2aa")), "-o", str(out)]) == 0
    text = out.read_text()
    assert 'attr.name="gear_type"' in text and ">internal<" not in text
    back = tmp_path / "p.json"
    assert main(["convert", str(out), "-o", str(back)]) == 0
    assert (
        json.loads(back.read_text())["gears"]
        == json.loads(example_path("planetary-2aa").read_text())["gears"]
    )
