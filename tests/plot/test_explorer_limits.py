"""The explorer's limits: a frame count beyond the memory limit and a driver value that
is not finite are bad input naming the parameter (issue 37 B12)."""

from __future__ import annotations

import math

import pytest

from mjstruct.errors import MechanismError
from mjstruct.io import read_mechanism
from mjstruct.plot.explorer_view import ExplorerView
from project_paths import EXAMPLES


def test_frames_beyond_the_memory_limit_are_refused_before_the_sweep():
    m = read_mechanism(EXAMPLES / "four-bar.json")
    with pytest.raises(MechanismError, match=r"^frames: 1000000000 frames need about .* fit"):
        ExplorerView(m, frames=10**9)  # was a bare MemoryError


@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan, "left"])
def test_a_driver_value_that_is_not_finite_is_named(value):
    view = ExplorerView(read_mechanism(EXAMPLES / "four-bar.json"), frames=8)
    with pytest.raises(MechanismError, match=r"^value: "):
        view.set_driver(value)  # was "cannot convert float NaN to integer"
    view.set_driver(90.0)
    assert view.k == view.frame_of(90.0)
