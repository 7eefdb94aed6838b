"""The ``fourbar`` block: which link its swing and time ratio describe (``output_link``,
whatever ``--output`` is), the time ratio against an independent closed form, and the
reason a crank-rocker's time ratio is null."""

from __future__ import annotations

import json

import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main


def _json(capsys, *argv):
    assert main(["singular", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_output_link_names_the_link_of_swing_and_time_ratio(capsys):
    path = str(example_path("fourbar-ms4"))
    default = _json(capsys, path)
    coupler = _json(capsys, path, "--output", "2")
    assert default["output"] == "3" and default["fourbar"]["output_link"] == "3"
    assert coupler["output"] == "2" and coupler["fourbar"]["output_link"] == "3"
    assert coupler["fourbar"]["swing"] == default["fourbar"]["swing"]
    # the swing is that of link 3's extremes, not of the chosen output's
    ext3 = [p["output_angle"] for p in default["singular"] if p["kind"] == "output_extreme"]
    ext2 = [p["output_angle"] for p in coupler["singular"] if p["kind"] == "output_extreme"]
    assert max(ext3) - min(ext3) == pytest.approx(default["fourbar"]["swing"], abs=1e-9)
    assert abs(max(ext2) - min(ext2) - coupler["fourbar"]["swing"]) > 1e-3
    assert any("link 3" in w and "output link 2" in w for w in coupler["warnings"])
    assert not any(w.startswith("fourbar:") for w in default["warnings"])
    assert main(["singular", path, "--output", "2"]) == 0
    assert "output (link 3) swing" in capsys.readouterr().out
