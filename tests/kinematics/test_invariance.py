"""The kinematics of a mechanism do not depend on its unit or where it sits: the same
mechanism scaled by 1e-9 … 1e9 or moved by up to 1e6 times its size assembles on the
same frames, warns of the same kinds of event, keeps its mobility and reproduces its
positions (undone the transform) to a stated relative accuracy."""

from __future__ import annotations

import re
from functools import cache

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.kinematics.solver import KinematicsResult, kinematic_analysis
from mjstruct.mechanism import Mechanism

#: generic geometry (no change point exactly on the frame grid)
GENERIC = ["four-bar", "slider-crank", "class-iv-seed003", "zhivago", "kin-radial-engine-5"]
#: special geometry: change points where two branches meet exactly (MS1, MS5)
SPECIAL = ["fourbar-ms1", "fourbar-ms5"]
FRAMES = 72


def transformed(name: str, scale: float, offset: float) -> Mechanism:
    """The example with every coordinate x ↦ scale·x + offset·size (both axes)."""
    data = mechanism_to_dict(read_mechanism(example_path(name)))
    size = _base(name).geometry.scale
    for item in [*data["joints"], *data.get("points", [])]:
        x, y = item["at"]
        item["at"] = [scale * x + offset * size * scale, scale * y - offset * size * scale]
    return mechanism_from_dict(data)


@cache
def _base(name: str) -> KinematicsResult:
    return kinematic_analysis(read_mechanism(example_path(name)), frames=FRAMES, checks="full")


def _kinds(r: KinematicsResult) -> list[str]:
    """The warnings with their numbers removed: what happened, not where."""
    return sorted(re.sub(r"[-+0-9.e]+", "#", w) for w in r.warnings)


def _compare(name: str, scale: float, offset: float) -> float:
    """Check frames, warnings and mobility; return the worst position error / size."""
    base = _base(name)
    r = kinematic_analysis(
        transformed(name, scale, offset), frames=FRAMES, stroke=scale, checks="full"
    )
    assert np.array_equal(r.placed, base.placed) and np.array_equal(r.valid, base.valid)
    assert _kinds(r) == _kinds(base)
    for key in ("dof", "redundant_constraints", "near_singular_frames", "near_singular_kinds"):
        assert r.checks["jacobian"][key] == base.checks["jacobian"][key], key
    size = base.geometry.scale
    shift = offset * size * scale * (1 - 1j)
    worst = 0.0
    for j, v in base.joints.items():
        z = (r.joints[j]["x"] + 1j * r.joints[j]["y"] - shift) / scale
        zb = v["x"] + 1j * v["y"]
        worst = max(worst, float(np.abs(z - zb)[base.placed].max()) / size)
        # analogs scale with the unit and do not move with the offset (to 1e-12·(1 + D))
        ok = base.valid
        sv = (r.joints[j]["sx"][ok] + 1j * r.joints[j]["sy"][ok]) / scale
        sb = v["sx"][ok] + 1j * v["sy"][ok]
        assert sb.size == 0 or np.abs(sv - sb).max() <= 1e-12 * (1 + offset) * (
            1 + float(np.abs(sb).max())
        )
    return worst


@pytest.mark.parametrize("name", GENERIC)
@pytest.mark.parametrize("scale", [1e-9, 1e-6, 1e6, 1e9])
def test_scale_changes_nothing(name, scale):
    # scaling rounds each coordinate once (relative 1.1e-16): positions agree to 1e-13
    assert _compare(name, scale, 0.0) < 1e-13


@pytest.mark.parametrize("name", GENERIC)
@pytest.mark.parametrize("offset", [1e3, 1e6])
def test_offset_changes_nothing_but_rounding(name, offset):
    # coordinates at an offset D (in sizes) carry rounding of D·eps relative to the
    # size: positions agree to 1e-14·(1 + D) (measured at most 5 eps·D)
    assert _compare(name, 1.0, offset) < 1e-14 * (1 + offset)
    assert _compare(name, 1e6, offset) < 1e-14 * (1 + offset)


@pytest.mark.parametrize("name", SPECIAL)
@pytest.mark.parametrize("scale", [2.0**-30, 2.0**30])
def test_special_geometry_survives_exact_scaling(name, scale):
    # a parallelogram or a hinged square stays one exactly only under scales that are
    # powers of two (any other scale or offset rounds its lengths apart by about eps:
    # its change points become near branch points of a slightly different linkage)
    assert _compare(name, scale, 0.0) < 1e-15
