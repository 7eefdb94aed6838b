"""Singular positions that lie exactly on a station of the traced curve: the reference
configuration (every branch's start and closing station) and the closure step."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.singular.analysis import _sign_changes, singular_analysis

TWO_PI = 2 * math.pi


def _mod(a: float, b: float) -> float:
    return abs(math.remainder(a - b, TWO_PI))


def _fourbar(O1, A, B, O2):
    return mechanism_from_dict(
        {
            "frame": "0",
            "drivers": ["O1"],
            "joints": [
                {"id": "O1", "links": ["0", "1"], "at": list(O1)},
                {"id": "A", "links": ["1", "2"], "at": list(A)},
                {"id": "B", "links": ["2", "3"], "at": list(B)},
                {"id": "O2", "links": ["3", "0"], "at": list(O2)},
            ],
        }
    )


def test_sign_changes_at_start_and_closing_station():
    # the closing station repeats the first; a root exactly there, with round-off
    # (0 at the start, 1e-40 at the closing copy) between opposite signs
    comp = np.array([0.0, -0.1, -0.2, 0.3, 0.2, 1e-40])
    assert _sign_changes(comp) == [(0, True), (2, False)]
    # a sign change across the closure step (last interior station to the closing one)
    comp = np.array([0.1, 0.2, -0.3, -0.1, 0.1])
    assert _sign_changes(comp) == [(1, False), (3, False)]
    # a zero between equal signs is a touch, not a root; a run of zeros gives its middle
    assert _sign_changes(np.array([0.0, 0.1, 0.2, 0.1, 0.0])) == []
    assert _sign_changes(np.array([0.1, 0.0, 0.0, 0.0, -0.1, -0.2, 0.1])) == [
        (2, True),
        (5, False),
    ]


def test_slider_crank_dead_point_at_its_reference_is_listed():
    # crank (1) and connecting rod (2) in line at q_ref: the slider's dead point; the
    # other one is half a turn later (crank folded back on the rod)
    m = read_mechanism(example_path("slider-crank-seed000-dynamics"))
    r = singular_analysis(m)
    ext = [p for p in r.singular if p.kind == "output_extreme"]
    q_ref = 0.0  # O1 (0, 0) -> A (1, 0): the crank along x
    assert sorted(round(_mod(p.q, q_ref), 9) for p in ext) == [0.0, round(math.pi, 9)]
    assert all(p.collinear == ("O1", "A", "B") for p in ext)
    # the same mechanism with its reference elsewhere lists the same two positions
    other = singular_analysis(read_mechanism(example_path("slider-crank")))
    assert sorted(round(_mod(p.q, 0.0), 9) for p in other.singular) == [0.0, round(math.pi, 9)]


@pytest.mark.parametrize("kind", ["output_extreme", "input_limit"])
def test_reference_on_a_singular_position_agrees_with_a_nudged_reference(kind):
    if kind == "output_extreme":  # O1, A, B in line at the reference
        pts = [(0, 0), (1, 0), (3, 0), (3, -1.5)]
    else:  # A, B, O2 in line (coupler stretched along the output)
        pts = [(0, 0), (0, 1), (2, 1), (3, 1)]
    exact = singular_analysis(_fourbar(*pts))
    q_ref = cmath.phase(complex(*pts[1]))
    at_ref = [p for p in exact.singular if p.kind == kind and _mod(p.q, q_ref) < 1e-12]
    assert len(at_ref) == 1
    # moving O2 by 1e-7 takes the position off the reference: the same list, to O(1e-7)
    nudged_pts = [*pts[:3], (pts[3][0], pts[3][1] + 1e-7)]
    nudged = singular_analysis(_fourbar(*nudged_pts))
    assert sorted(p.kind for p in exact.singular) == sorted(p.kind for p in nudged.singular)
    assert len(exact.singular) == len(nudged.singular)
    for p in exact.singular:
        assert min(_mod(p.q, o.q) for o in nudged.singular if o.kind == p.kind) < 1e-5


@pytest.mark.parametrize("name", ["fourbar-ms2", "fourbar-ms5", "slider-crank", "four-bar"])
def test_numbers_are_python_floats(name):
    r = singular_analysis(read_mechanism(example_path(name)))
    assert r.singular
    for p in r.singular:
        assert type(p.q) is float and type(p.output_angle) is float
    for a, b in r.input_range.intervals:
        assert type(a) is float and type(b) is float
    for arc in r.fold_arcs:
        assert type(arc.q_from) is float and type(arc.q_to) is float
