"""At a change point the sweep continues on the branch it was on and says so (issue 11.5)."""

from __future__ import annotations

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.solver import kinematic_analysis


def _xy(r, j):  # type: ignore[no-untyped-def]
    return r.joints[j]["x"] + 1j * r.joints[j]["y"]


def test_ms5_keeps_its_rhombus_through_both_change_points():
    r = kinematic_analysis(read_mechanism(example_path("fourbar-ms5")), frames=360)
    assert r.placed.all()  # frame 300 (A on O2) keeps its positions
    O1, A, B, O2 = (_xy(r, j) for j in ("O1", "A", "B", "O2"))
    assert abs(A[300] - O2[300]) < 1e-12
    # the shape the sweep started with: a rhombus, B = A + (O2 - O1), never B on O1
    assert np.abs(np.abs(B - A) - 1.0).max() < 1e-12
    assert np.abs(B - A - (O2 - O1)).max() < 1e-12
    step = np.abs(np.diff(B))
    assert step.max() < 3 * np.median(step)
    text = "\n".join(r.warnings)
    assert "no assembly" not in text and "not a physical motion" not in text
    cps = [e for e in r.events if e.kind == "change point"]
    assert [e.frame for e in cps] == [120, 300]
    assert all("continues smoothly on its branch" in e.message() for e in cps)
    assert "switched" not in text and "sweep does not return" not in text


def test_ms1_stays_a_parallelogram():
    r = kinematic_analysis(read_mechanism(example_path("fourbar-ms1")), frames=360)
    assert r.placed.all()
    O1, A, B, O2 = (_xy(r, j) for j in ("O1", "A", "B", "O2"))
    assert np.abs(B - A - (O2 - O1)).max() < 1e-12
    assert sum("continues smoothly on its branch" in w for w in r.warnings) == 2


def test_ms4_crosses_its_change_point_and_says_the_cycle_is_two_turns():
    r = kinematic_analysis(read_mechanism(example_path("fourbar-ms4")), frames=360)
    B = _xy(r, "B")
    step = np.abs(np.diff(B))
    assert r.valid.sum() >= 359 and step.max() < 3 * np.median(step)
    assert abs(B[-1] - B[0]) > 0.5  # another circuit after one turn
    assert any("closes only after" in w for w in r.warnings)
    # a crank-rocker returns: no such warning
    r = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=360)
    assert not any("closes only after" in w for w in r.warnings)
