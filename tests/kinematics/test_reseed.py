"""Closure sweeps past an infeasible stretch, and paths that do not start at the reference."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.singular.analysis import singular_analysis


def _triad(prismatic_c: bool) -> KinematicModel:
    d = json.loads(example_path("triad-class-iii").read_text(encoding="utf-8"))
    if prismatic_c:
        for j in d["joints"]:
            if j["id"] == "C":
                j["type"], j["axis"] = "P", [1.0, 1.5]
    return KinematicModel.build(mechanism_from_dict(d))


def _xy(r, i):  # type: ignore[no-untyped-def]
    return np.array([[v["x"][i], v["y"][i]] for v in r.joints.values()])


@pytest.fixture(scope="module")
def sweeps():  # type: ignore[no-untyped-def]
    model = _triad(prismatic_c=True)
    return (
        kinematic_analysis(model, frames=360, speed=1.0),
        kinematic_analysis(model, frames=360, speed=-1.0),
    )


def test_a_slider_triad_finds_every_frame_of_its_branch_both_ways(sweeps):
    up, down = sweeps
    # the driver rocks: q_ref - 1.415 .. q_ref + 1.502; frame i of one sweep is the
    # configuration of frame 360 - i of the other (the same crank angle)
    for a, b in ((up, down), (down, up)):
        ok = a.valid
        assert ok[0] and ok.sum() == b.valid.sum() == 168
        for i in range(1, 360):
            assert ok[i] == b.valid[360 - i]
            if ok[i]:
                assert np.abs(_xy(a, i) - _xy(b, 360 - i)).max() < 1e-9
    assert up.valid[279:].all() and not up.valid[87:279].any()
    assert up.checks["link_lengths"]["max_error"] < 1e-10
    wording = [w for w in up.warnings if "assemble again" in w]
    assert len(wording) == 1 and "driver turning the other way" in wording[0]


def test_a_triad_reports_its_dead_points_where_the_singular_analysis_puts_them():
    model = _triad(prismatic_c=False)
    r = kinematic_analysis(model, frames=360)
    lower, upper = singular_analysis(model.mechanism).input_range.intervals[0]
    dead = sorted(e.q for e in r.events if e.kind == "dead point")
    # both limits are the closure group's folds (located by bisection to 1e-12); near the
    # lower one the plan's dyad at C passes its own dead point 0.3 deg earlier, where its
    # mode flips (an informational event, not a dead point)
    assert abs(dead[0] - (upper - 2 * np.pi)) < 1e-9
    assert abs(dead[1] - lower) < 1e-9
    # frames 347..359 (crank at 347..359 deg) lie within the input range: they assemble
    assert r.valid[347:].all() and r.valid[:72].all() and not r.valid[72:347].any()


@pytest.mark.parametrize("first", [0.01, 3.0, -3.0])
def test_frames_at_the_reference_always_close_and_the_path_continues_from_it(first):
    model = _triad(prismatic_c=True)
    ref = float(model.q_ref[0])
    alone = kinematic_analysis(model, q=[ref], checks=False)
    r = kinematic_analysis(model, q=[ref + first, ref, ref + 0.01], checks=False)
    assert alone.valid[0] and r.valid[1] and r.valid[2]
    assert np.abs(_xy(r, 1) - _xy(alone, 0)).max() < 1e-12
    # the branch spans q_ref - 1.415 .. q_ref + 1.502: q_ref +- 3 lie outside
    assert r.valid[0] == (first == 0.01)


def test_the_class_iv_example_is_unchanged_by_the_reseeding():
    model = KinematicModel.build(read_mechanism(example_path("class-iv-seed003")))
    r = kinematic_analysis(model, frames=72)
    assert r.valid.all() and r.closure is not None and r.closure.reseeded == ()
