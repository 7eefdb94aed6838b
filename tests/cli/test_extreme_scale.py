"""Extreme scale: every size a double holds is either analysed exactly up to scaling or
refused as bad input naming the field; never numbers that silently underflow or overflow.

A mechanism's coordinates multiplied by s scale its positions, velocities and
accelerations by s and leave angles, ω and ε unchanged.  Before the size range
(``geometry.SIZE_RANGE``), the four-bar × 1e-116 gave joint B's velocity exactly 0 with
exit 0 and no warning, 1e120 called every frame singular and 1e160 "no assembly".
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from mjstruct.cli.main import main
from mjstruct.kinematics.geometry import REACH, SIZE_RANGE
from project_paths import EXAMPLES

#: a plain four-bar, a slider-crank (a prismatic joint) and a closure group
NAMES = ("four-bar", "slider-crank", "zhivago")
FRAMES = 12


def _transformed(name: str, scale: float, offset: complex = 0j) -> dict[str, Any]:
    data = json.loads((EXAMPLES / f"{name}.json").read_text())
    for item in [*data["joints"], *data.get("points", [])]:
        x, y = item["at"]
        item["at"] = [x * scale + offset.real, y * scale + offset.imag]
    return data


def _run(capsys, tmp_path: Path, data: dict[str, Any], scale: float) -> tuple[int, Any, str]:
    path = tmp_path / "m.json"
    path.write_text(json.dumps(data))
    # --full-checks: the constraint Jacobian's rank too (it mixed units before)
    argv = ["kinematics", str(path), "--frames", str(FRAMES), "--full-checks", "--json"]
    status = main(argv)
    out, err = capsys.readouterr()
    return status, json.loads(out) if status == 0 else None, err


def _values(table: dict[str, dict[str, list[float | None]]], key: str) -> np.ndarray:
    return np.array(
        [[np.nan if v is None else v for v in item[key]] for item in table.values()], float
    )


def _disagreement(got: Any, ref: Any, scale: float, offset: complex = 0j) -> float:
    """Largest difference to the unit run, relative to the size (lengths over s)."""
    worst = 0.0
    shift = {"x": offset.real, "y": offset.imag}
    for table in ("joints", "points"):
        for key in ("x", "y", "vx", "vy", "ax", "ay"):
            a = (_values(got[table], key) - shift.get(key, 0.0)) / scale
            b = _values(ref[table], key)
            assert (np.isnan(a) == np.isnan(b)).all(), (table, key)
            worst = max(worst, float(np.nanmax(np.abs(a - b), initial=0.0)))
    for key in ("angle", "omega", "eps"):
        a, b = _values(got["links"], key), _values(ref["links"], key)
        assert (np.isnan(a) == np.isnan(b)).all(), key
        worst = max(worst, float(np.nanmax(np.abs(a - b), initial=0.0)))
    return worst


@pytest.mark.parametrize("name", NAMES)
def test_every_scale_is_exact_up_to_scaling_or_refused(name, tmp_path, capsys) -> None:
    status, ref, err = _run(capsys, tmp_path, _transformed(name, 1.0), 1.0)
    assert status == 0, err
    assert ref["checks"]["jacobian"]["rank"], "the rank is checked"
    size = max(
        abs(complex(*a["at"]) - complex(*b["at"]))
        for a in _transformed(name, 1.0)["joints"]
        for b in _transformed(name, 1.0)["joints"]
    )
    lo, hi = SIZE_RANGE
    seen = {"analysed": 0, "refused": 0}
    for exponent in [*range(-300, 301, 30), -51, -50, 49, 50, 51]:
        scale = 10.0**exponent
        status, got, err = _run(capsys, tmp_path, _transformed(name, scale), scale)
        if lo <= size * scale <= hi:
            assert status == 0, (exponent, err)
            # each coordinate is rounded once by the scaling: 1e-13 of the size
            assert _disagreement(got, ref, scale) < 1e-12, exponent
            assert got["warnings"] == ref["warnings"], exponent
            assert got["checks"]["jacobian"]["rank"] == ref["checks"]["jacobian"]["rank"]
            seen["analysed"] += 1
        else:
            assert (status, got) == (2, None), exponent
            assert err.startswith("mjstruct kinematics: joints.at: the mechanism's size ")
            assert err.count("\n") == 1
            seen["refused"] += 1
    assert seen["analysed"] >= 5 and seen["refused"] >= 17


@pytest.mark.parametrize("name", ["four-bar", "slider-crank"])
def test_far_from_the_origin_is_exact_to_its_rounding_or_refused(name, tmp_path, capsys) -> None:
    status, ref, err = _run(capsys, tmp_path, _transformed(name, 1.0), 1.0)
    assert status == 0, err
    for exponent in (3, 6, 8, 9, 12, 200):
        offset = 10.0**exponent * (1 - 1j)
        data = _transformed(name, 1.0, offset)
        status, got, err = _run(capsys, tmp_path, data, 1.0)
        reach = max(abs(complex(*j["at"])) for j in data["joints"])
        if reach <= REACH * 1.0:  # the examples' size is about 1
            assert status == 0, err
            # coordinates carry eps × distance: measured at most 4 eps × distance
            assert _disagreement(got, ref, 1.0, offset) < 1e-15 * (1 + abs(offset))
            assert got["checks"]["jacobian"]["rank"] == ref["checks"]["jacobian"]["rank"]
        else:
            # too far (or so far that every centre rounds to one point)
            assert status == 2 and err.count("\n") == 1
            assert err.startswith("mjstruct kinematics: joints[0].at: ") or "coincide" in err


def test_a_point_far_beyond_the_mechanism_is_bad_input(tmp_path, capsys) -> None:
    # before: --json failed writing inf (internal error), the text said "max error inf"
    data = _transformed("four-bar", 1.0)
    data["points"][0]["at"] = [1e200, 1e200]
    for flag in ("--json", "--no-checks"):
        path = tmp_path / "poi.json"
        path.write_text(json.dumps(data))
        status = main(["kinematics", str(path), "--frames", "8", flag])
        out, err = capsys.readouterr()
        assert (status, out) == (2, "")
        assert err.startswith("mjstruct kinematics: points[0].at: (1e+200, 1e+200) lies ")
        assert err.count("\n") == 1


def test_the_range_keeps_the_triangles_cubes_normal() -> None:
    # the triangle steps multiply three lengths, with analogs up to 1e12 sizes for the
    # shortest side allowed (1e-12 of the size): the range keeps a factor 1e30 from
    # underflow and overflow at either end, farther points (REACH) included
    lo, hi = SIZE_RANGE
    tiny = (1e-12 * lo) ** 2 * lo
    huge = 1e12 * (REACH * hi) ** 3
    assert tiny > 1e30 * np.finfo(float).tiny and huge < np.finfo(float).max / 1e30
    assert math.isclose(lo * hi, 1.0)


def test_a_guide_direction_of_any_length_is_the_same_guide(tmp_path, capsys) -> None:
    # before: an axis (1e308, 1e308) had an infinite length and became (0, 0), giving
    # a 'singular frame' and nulls; (5e-324, 5e-324) kept a length of 1.41
    def sweep(axis: list[float]) -> Any:
        data = _transformed("slider-crank", 1.0)
        for joint in data["joints"]:
            if joint.get("type") == "P":
                joint["axis"] = axis
        status, got, err = _run(capsys, tmp_path, data, 1.0)
        assert status == 0, err
        return got

    ref = sweep([1.0, 0.25])
    for factor in (1e308, 1e200, 1e-300, 5e-324 / 0.25):
        got = sweep([factor, factor * 0.25])
        assert _disagreement(got, ref, 1.0) < 1e-14, factor
        assert got["warnings"] == ref["warnings"]
