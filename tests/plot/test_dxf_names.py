"""DXF names from any ids: layers unique (without case), at most 255 characters, free of
the characters DXF forbids and of control characters; TEXT free of control characters
with the original id readable in it (issue 37 B11, C13); and ids holding ``/`` drawn
everywhere (B10)."""

from __future__ import annotations

import json
import re

import ezdxf
import pytest
from ezdxf.lldxf.validator import is_valid_layer_name

from mjstruct.cli.main import main
from mjstruct.plot.dxf import MAX_NAME, dxf_text, layer_names
from project_paths import EXAMPLES

CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def _four_bar(tmp_path, links=None, joints=None):
    m = json.loads((EXAMPLES / "four-bar.json").read_text())
    if links:  # rename links "1", "2", "3"
        for j in m["joints"]:
            j["links"] = [links.get(x, x) for x in j["links"]]
        for p in m.get("points", []):
            p["link"] = links.get(p["link"], p["link"])
    if joints:
        for j in m["joints"]:
            j["id"] = joints.get(j["id"], j["id"])
        m["drivers"] = [joints.get(d, d) for d in m["drivers"]]
    path = tmp_path / "m.json"
    path.write_text(json.dumps(m))
    return path


@pytest.mark.parametrize(
    "links",
    [
        {"1": "Arm", "2": "arm"},  # one DXF layer without case: DXFTableEntryError
        {"1": "a<b", "2": "a>b", "3": "a_b"},
        {"1": "nul\x00", "2": "esc\x1b", "3": "bel\x07"},
        {"1": "x" * 306, "2": "y" * 3005},
        {"1": "x" * 3005, "2": "x" * 3005 + "z"},  # alike in their first 255 characters
    ],
)
def test_layers_are_valid_unique_and_keep_the_id_in_text(tmp_path, capsys, links):
    path = _four_bar(tmp_path, links=links)
    out = tmp_path / "m.dxf"
    assert main(["draw", str(path), "-o", str(out)]) == 0, capsys.readouterr().err
    doc = ezdxf.readfile(out)
    names = [layer.dxf.name for layer in doc.layers]
    assert len({n.lower() for n in names}) == len(names)
    for n in names:
        assert is_valid_layer_name(n) and len(n) <= MAX_NAME and not CONTROL.search(n)
    texts = [t.dxf.text for t in doc.modelspace().query("TEXT")]
    assert not any(CONTROL.search(t) for t in texts)
    mine = layer_names(["1", "2", "3", *links.values()])
    for link in links.values():  # each renamed link: its layer and its id in a TEXT
        assert mine[link] in names
        if mine[link] != "link-" + link:
            assert f"link {dxf_text(link)}" in texts


def test_joint_ids_with_control_characters_are_escaped_in_text(tmp_path, capsys):
    path = _four_bar(tmp_path, joints={"A": "A\x00\x1b\x07", "B": "B\nC"})
    out = tmp_path / "m.dxf"
    assert main(["draw", str(path), "-o", str(out)]) == 0, capsys.readouterr().err
    texts = {t.dxf.text for t in ezdxf.readfile(out).modelspace().query("TEXT")}
    assert {"A\\x00\\x1b\\x07", "B\\x0aC"} <= texts


@pytest.mark.parametrize("command", ["draw", "animate"])
def test_joint_ids_with_a_slash_are_drawn(tmp_path, capsys, command):
    # B10: analyze and kinematics took 'A/B', draw and animate failed with KeyError 'A'
    m = json.loads((EXAMPLES / "slider-crank.json").read_text())
    new = {j["id"]: j["id"] + "/x" for j in m["joints"]}
    for j in m["joints"]:
        j["id"] = new[j["id"]]
    m["drivers"] = [new[d] for d in m["drivers"]]
    path = tmp_path / "m.json"
    path.write_text(json.dumps(m))
    suffix = ".svg" if command == "draw" else ".gif"
    extra = ["--show", "paths,velocity"] if command == "draw" else ["--frames", "4"]
    for source in (path, _four_bar(tmp_path, joints={"A": "A/B"})):
        out = tmp_path / f"o{suffix}"
        status = main([command, str(source), "-o", str(out), *extra])
        assert status == 0, capsys.readouterr().err
        assert out.stat().st_size > 0
    assert main(["draw", str(path), "-o", str(tmp_path / "o.dxf")]) == 0
