"""The ``fourbar`` block: which link its swing and time ratio describe (``output_link``,
whatever ``--output`` is), the time ratio against an independent closed form, and the
reason a crank-rocker's time ratio is null."""

from __future__ import annotations

import json
import math

import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.io import read_mechanism
from mjstruct.singular.analysis import singular_analysis


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


def _time_ratio_by_o1_triangle(P1: float, P2: float, P3: float) -> float:
    """Crank-rocker time ratio from the triangle O1 O2 B (frame 1) at the two dead
    points: stretched |O1 B| = P1 + P2 (input along O1 B), folded |O1 B| = P2 - P1
    (input opposite O1 B); B on the same side of the frame line at both."""
    s, f = P1 + P2, P2 - P1
    a_s = math.acos((1 + s * s - P3 * P3) / (2 * s))
    a_f = math.acos((1 + f * f - P3 * P3) / (2 * f))
    stroke = (a_f + math.pi - a_s) % (2 * math.pi)
    return max(stroke, 2 * math.pi - stroke) / min(stroke, 2 * math.pi - stroke)


@pytest.mark.parametrize("P", [(0.5, 1.0, 1.5), (0.5, 1.5, 1.0), (0.3, 1.1, 0.9), (0.4, 1.2, 1.3)])
def test_time_ratio_against_the_o1_triangle(P):
    from mjstruct.singular.fourbar import fourbar_theory

    fb = fourbar_theory(*P)
    assert fb.motion == "crank-rocker"
    assert fb.time_ratio == pytest.approx(_time_ratio_by_o1_triangle(*P), rel=1e-10)


def test_ms4_time_ratio_from_the_model_and_the_closed_form():
    r = singular_analysis(read_mechanism(example_path("fourbar-ms4")))
    expected = _time_ratio_by_o1_triangle(0.5, 1.0, 1.5)
    # the same number from the located positions: the stretched extreme of one circuit
    # and the folded one, which for MS4 is its change point (all four in line)
    (cp,) = [p for p in r.singular if p.kind == "change_point"]
    ext = [p for p in r.singular if p.kind == "output_extreme"]
    stroke = min(abs(math.remainder(p.q - cp.q, 2 * math.pi)) for p in ext)
    assert (2 * math.pi - stroke) / stroke == pytest.approx(expected, rel=1e-9)
    assert r.fourbar.time_ratio == pytest.approx(expected, rel=1e-10)
    assert expected == pytest.approx(4.104, abs=5e-4)


def test_ms2_null_time_ratio_says_why():
    r = singular_analysis(read_mechanism(example_path("fourbar-ms2")))
    assert r.fourbar.motion == "crank-rocker" and r.fourbar.time_ratio is None
    (w,) = [w for w in r.warnings if w.startswith("fourbar: time_ratio")]
    assert "B sits on O1" in w
    # and a crank-rocker with a time ratio has no such warning
    r4 = singular_analysis(read_mechanism(example_path("fourbar-ms4")))
    assert not any(w.startswith("fourbar: time_ratio") for w in r4.warnings)


def test_change_point_fourbar_angles_survive_rounding_of_the_lengths():
    from mjstruct.singular.fourbar import fourbar_singular_angles, fourbar_theory

    # MS4's lengths as read back from its file (a few ulps off): the change point's
    # folded extreme must not split into two extremes 1e-8 rad either side of it
    exact, read = (0.5, 1.0, 1.5), (0.4999999999999997, 1.0000000000000004, 1.5000000000000002)
    a, b = fourbar_singular_angles(*exact), fourbar_singular_angles(*read)
    assert len(a.output_extremes) == len(b.output_extremes) == 2
    assert b.output_extremes == pytest.approx(a.output_extremes, abs=1e-12)
    assert fourbar_theory(*read).time_ratio == pytest.approx(
        fourbar_theory(*exact).time_ratio, rel=1e-12
    )
