"""Whole-branch fold arcs (MS2's dwell, MS5's locked input) as a structured list."""

from __future__ import annotations

import cmath
import json
import math

import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.io import read_mechanism
from mjstruct.singular.analysis import singular_analysis

TWO_PI = 2 * math.pi


def _mod(a: float, b: float) -> float:
    return abs(math.remainder(a - b, TWO_PI))


def _file_angle(m, a: str, b: str) -> float:
    za, zb = (complex(*m.joint(j).at) for j in (a, b))
    return cmath.phase(zb - za)


def test_ms2_dwell_arcs_are_half_turns_between_its_change_points():
    m = read_mechanism(example_path("fourbar-ms2"))
    r = singular_analysis(m)
    cps = [p.q for p in r.singular if p.kind == "change_point"]
    arcs = r.fold_arcs
    assert arcs and all(a.kind == "output_extreme" for a in arcs)
    # B sits on O1 along the dwell: the output link lies along the frame line O1 O2
    along = _file_angle(m, "O1", "O2")
    total = 0.0
    for a in arcs:
        assert a.joints == ("O1", "B")
        assert a.q_to - a.q_from == pytest.approx(math.pi, abs=1e-9)
        assert min(_mod(a.q_from, c) for c in cps) < 1e-9
        assert min(_mod(a.q_to, c) for c in cps) < 1e-9
        assert min(_mod(a.output_angle, along), _mod(a.output_angle, along + math.pi)) < 1e-9
        assert math.pi / 3 - 1e-12 <= a.q_from < math.pi / 3 + TWO_PI  # [q_ref, q_ref + 2 pi)
        total += a.q_to - a.q_from
    assert total == pytest.approx(TWO_PI, abs=1e-9)  # the dwell branch winds once
    # the warning is kept
    assert sum(w.startswith("fold arc") for w in r.warnings) == 1


def test_ms5_locked_input_arc_at_a_on_o2(capsys):
    m = read_mechanism(example_path("fourbar-ms5"))
    r = singular_analysis(m)
    (locked,) = [a for a in r.fold_arcs if a.kind == "input_limit"]
    # A on O2: the input link points from O1 to O2
    assert locked.q_from == locked.q_to
    assert _mod(locked.q_from, _file_angle(m, "O1", "O2")) < 1e-9
    assert locked.joints == ("A", "O2") and locked.output_angle is None
    assert any(a.kind == "output_extreme" and a.joints == ("O1", "B") for a in r.fold_arcs)
    assert sum(w.startswith("fold arc") for w in r.warnings) == 2
    assert main(["singular", str(example_path("fourbar-ms5")), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert len(d["fold_arcs"]) == len(r.fold_arcs)
    for a in d["fold_arcs"]:
        assert set(a) >= {"q_from", "q_to", "joints", "kind", "output_angle"}
        assert a["q_from"] <= a["q_to"]


def test_no_fold_arcs_without_a_fold():
    r = singular_analysis(read_mechanism(example_path("fourbar-ms4")))
    assert r.fold_arcs == () and r.to_dict()["fold_arcs"] == []
