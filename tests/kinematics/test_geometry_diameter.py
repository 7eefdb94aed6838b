"""The mechanism's size (the unit of every kinematics tolerance) from the convex hull."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from mjstruct.kinematics.geometry import diameter

coordinate = st.one_of(
    st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False),
    st.integers(-3, 3).map(float),  # duplicates and collinear points on a small grid
)
points = st.lists(st.builds(complex, coordinate, coordinate), max_size=40)


@settings(max_examples=300, derandomize=True, deadline=None)
@given(points)
def test_diameter_is_the_largest_pairwise_distance(pts: list[complex]) -> None:
    assert diameter(pts) == max((abs(a - b) for a in pts for b in pts), default=0.0)
