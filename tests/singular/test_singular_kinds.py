"""The kinematics report names each near-singular frame by its kind of singular position
(input limit, output extreme, change point) and says the sweep keeps its branch."""

from __future__ import annotations

import math

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.singular.analysis import singular_analysis


def test_ms1_parallelogram_flags_its_two_change_points_by_kind():
    m = read_mechanism(example_path("fourbar-ms1"))
    r = kinematic_analysis(m, frames=360)
    j = r.checks["jacobian"]
    # q runs from the reference 60° over a full turn: the crank along the frame line
    # at 180° and 360° (frames 120 and 300); the latter's analogs are indeterminate
    assert j["near_singular_frames"] == [120, 300]
    assert j["near_singular_kinds"] == ["change_point", "change_point"]
    assert all(abs(math.sin(r.q[i, 0])) < 1e-12 for i in (120, 300))
    warning = next(w for w in r.warnings if w.startswith("near-singular Jacobian"))
    assert "change point at q = 3.14159265 (frame 120)" in warning
    assert "change point at q = 6.28318531 (frame 300)" in warning
    # at each change point the sweep continues on its branch, and says so: still the
    # parallelogram (coupler parallel to the frame) on every frame with positions
    assert sum("the sweep continues smoothly on its branch" in w for w in r.warnings) == 2
    A = r.joints["A"]["x"] + 1j * r.joints["A"]["y"]
    B = r.joints["B"]["x"] + 1j * r.joints["B"]["y"]
    assert r.placed.all()
    assert np.abs(B - A - 1.0).max() < 1e-12


def test_ms5_hinged_square_names_its_change_point():
    m = read_mechanism(example_path("fourbar-ms5"))
    r = kinematic_analysis(m, frames=360)
    j = r.checks["jacobian"]
    # frame 300 (A on O2) is a change point too, with its positions (was null)
    assert j["near_singular_frames"] == [120, 300]
    assert j["near_singular_kinds"] == ["change_point", "change_point"]
    assert any("change point at q = 3.14159265 (frame 120)" in w for w in r.warnings)
    assert any("change point at q = 6.28318531 (frame 300)" in w for w in r.warnings)
    # the kinds agree with the singular analysis located to 1e-9 in q
    a = singular_analysis(m)
    qs = [p.q for p in a.singular if p.kind == "change_point"]
    for i in (120, 300):
        assert min(abs(math.remainder(r.q[i, 0] - q, 2 * math.pi)) for q in qs) < 1e-9


def test_kinds_are_computed_only_for_flagged_frames():
    r = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=36)
    j = r.checks["jacobian"]
    assert j["near_singular_frames"] == [] and j["near_singular_kinds"] == []
    # MS2: its change points are flagged (the output extremes are not near-singular)
    r2 = kinematic_analysis(read_mechanism(example_path("fourbar-ms2")), frames=360)
    assert r2.checks["jacobian"]["near_singular_kinds"] == ["change_point", "change_point"]
