"""The 2AA tooth-number synthesis against a brute force over every Z1..Z4 with the plain
definitions (Willis' ratio of the idler chain, centre distances, the carrier turned by
one satellite pitch, satellite centres placed on the plane), and the ratio limits
against sympy's solution of the continuous conditions."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from mjstruct.errors import MechanismError
from mjstruct.gears.planetary import planetary_ratio_range, planetary_synthesis

Z_LO, Z_HI = 12, 60


def brute_force(
    ratio: float, k: int, t1: float, t2: float, y: float, tol: float, ctol: float
) -> set[tuple[int, int, int, int]]:
    """Every (Z1, Z2, Z3, Z4) in Z_LO..Z_HI meeting the definitions, by exhaustion."""
    z = np.arange(Z_LO, Z_HI + 1)
    z2, z3, z4 = np.meshgrid(z, z, z, indexing="ij")
    theta = 2 * math.pi / k
    out = set()
    for z1 in z:
        # Willis with gear 4 held: w1 - wH = i14^H (w4 - wH), i14^H the chain's
        # product of external meshes (-Z2/Z1)(-Z3/Z2)(-Z4/Z3)
        i14 = (-z2 / z1) * (-z3 / z2) * (-z4 / z3)
        i = 1 - i14
        ok = np.abs(i - ratio) <= tol * ratio + 1e-12
        # centre distances in modules: satellite 2 at a12, satellite 3 at a12 + a23
        a12 = (z1 + z2) / 2
        a23 = t1 * (z2 + z3) / 2
        a34_ref = (z3 + z4) / 2
        ok &= np.abs((a12 + a23) / a34_ref - t2) <= ctol + 1e-12
        # carrier turned by one pitch 2pi/k with gear 4 held: gear 1 turns i 2pi/k,
        # which must be a whole number of its tooth pitches 2pi/Z1
        teeth = i * z1 / k
        ok &= np.abs(teeth - np.round(teeth)) < 1e-9
        # neighbours: centres of two adjacent satellites, tip circles d_a = Z + 2
        for radius, zs in ((a12, z2), (a12 + a23, z3)):
            gap = np.hypot(radius - radius * math.cos(theta), radius * math.sin(theta))
            ok &= gap >= zs + 2 - 1e-9
        ok &= np.abs(z3 - y * z2) < 1
        for a, b, c in zip(*np.nonzero(ok), strict=True):
            out.add((int(z1), int(z[a]), int(z[b]), int(z[c])))
    return out


CASES = [
    (3.0, 3, 1.0, 1.0, 1.0, 0.02, 0.01),
    (2.6, 4, 0.9, 1.1, 0.8, 0.02, 0.02),
    (3.5, 3, 1.1, 0.95, 1.3, 0.03, 0.02),
    (2.4, 5, 1.0, 1.2, 1.0, 0.01, 0.005),
    # beyond the paper's (10), t2 < 1/sin(pi/3) = 1.1547: sets exist all the same
    (3.0, 3, 1.0, 1.18, 1.0, 0.02, 0.01),
]


@pytest.mark.parametrize(("ratio", "k", "t1", "t2", "y", "tol", "ctol"), CASES)
def test_every_set_and_only_those(ratio, k, t1, t2, y, tol, ctol):
    expected = brute_force(ratio, k, t1, t2, y, tol, ctol)
    assert expected, "the case must have sets to compare"
    r = planetary_synthesis(
        ratio, k, t1=t1, t2=t2, y=y, ratio_tolerance=tol, coaxial_tolerance=ctol,
        z_min=Z_LO, z_max=Z_HI,
    )  # fmt: skip
    got = {(s.z1, s.z2, s.z3, s.z4) for s in r.sets}
    assert got == expected
    errors = [abs(s.ratio_error) for s in r.sets]
    assert errors == sorted(errors)


def test_sets_beyond_the_paper_t2_limit_are_real():
    """The paper's (10) bounds t2 by 1/sin(pi/k); a set with t2 above it meets every
    condition (the brute force above confirms it), so (10) is not a necessary limit."""
    r = planetary_synthesis(3.0, 3, t2=1.18, ratio_tolerance=0.02, z_max=Z_HI)
    assert r.range.t2_limit_paper < 1.18 and r.count > 0
    assert all(s.t2_exact > r.range.t2_limit_paper for s in r.sets)


def test_paper_example_bounds():
    """(10) as printed: 1/sin(pi/3) ~ 1.15 for three satellites, above 1.2 for four."""
    assert round(planetary_ratio_range(3).t2_limit_paper, 2) == 1.15
    assert planetary_ratio_range(4).t2_limit_paper > 1.2
    # (7): i > (1 + t2) / t2
    for t2 in (0.8, 1.0, 1.2):
        assert planetary_ratio_range(3, 1.0, t2).lower == pytest.approx((1 + t2) / t2)


def _continuous_limits(k: int, t1: float, t2: float, y: float) -> tuple[float, float | None]:
    """Upper limits of i from the neighbouring conditions without the 2/Z1 terms,
    solved by sympy from the coaxiality and the ratio (not from the paper's algebra)."""
    i, z2 = sp.symbols("i z2", positive=True)
    s = sp.sin(sp.pi / k)
    z1, z4, z3 = 1, i - 1, y * z2  # per unit Z1
    z2i = sp.solve(sp.Eq(z1 + z2 + t1 * (z2 + z3), t2 * (z3 + z4)), z2)[0]
    g2 = ((z1 + z2) * s - z2).subs(z2, z2i)
    g3 = ((z1 + z2 + t1 * (z2 + z3)) * s - z3).subs(z2, z2i)
    lower = 1 + 1 / t2
    roots2 = [float(r) for r in sp.solve(sp.Eq(g2, 0), i) if float(r) > lower]
    roots3 = [float(r) for r in sp.solve(sp.Eq(g3, 0), i) if float(r) > lower]
    assert len(roots2) == 1
    return roots2[0], (min(roots3) if roots3 else None)


@pytest.mark.parametrize(
    ("k", "t1", "t2", "y"),
    [(3, 1.0, 1.0, 1.0), (3, 0.9, 1.1, 0.7), (4, 1.2, 0.8, 2.0), (6, 1.0, 1.0, 3.0),
     (5, 0.8, 0.8, 20.0), (3, 1.0, 1.18, 1.0)],
)  # fmt: skip
def test_ratio_limits_solve_the_continuous_conditions(k, t1, t2, y):
    r = planetary_ratio_range(k, t1, t2, y)
    up2, up3 = _continuous_limits(k, t1, t2, y)
    assert r.upper_2 == pytest.approx(up2, rel=1e-12)
    if up3 is None:
        assert r.upper_3 is None
    else:
        assert r.upper_3 == pytest.approx(up3, rel=1e-12)


def test_no_set_beyond_the_range():
    """Just above the upper limit no tooth numbers exist even with many teeth; just
    below, with enough teeth, they do."""
    r = planetary_ratio_range(3)
    with pytest.raises(MechanismError, match=r"^ratio: .* impossible: \(9\)"):
        planetary_synthesis(r.upper * 1.001, 3, ratio_tolerance=0.0005)
    near = planetary_synthesis(r.upper * 0.97, 3, ratio_tolerance=0.01, z_max=600)
    assert near.count > 0
    # the set's own ratio never passes the limit
    assert all(s.ratio < r.upper for s in near.sets)


def test_paper_generating_equations_give_the_sets():
    """The paper's (3)-(5): Z1 = kN/i, Z4 = Z1 (i - 1), Z2 = (t2 (i-1) - 1) Z1 /
    ((1 + y) t1 + 1 - y t2), Z3 = y Z2 give an exact set for a ratio they fit."""
    k, i, t1, t2, y, n = 3, Fraction(12), Fraction(1), Fraction(1), Fraction(1), 72
    z1 = k * n / i
    z4 = z1 * (i - 1)
    z2 = (t2 * (i - 1) - 1) * z1 / ((1 + y) * t1 + 1 - y * t2)
    z3 = y * z2
    best = planetary_synthesis(12, 3).sets[0]
    assert (best.z1, best.z2, best.z3, best.z4) == (z1, z2, z3, z4) == (18, 90, 90, 198)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"ratio": 3, "satellites": 1}, "satellites"),
        ({"ratio": 3, "t1": 0.0}, "t1"),
        ({"ratio": 3, "t2": float("nan")}, "t2"),
        ({"ratio": 3, "y": -1.0}, "y"),
        ({"ratio": 3, "ratio_tolerance": 2.0}, "ratio_tolerance"),
        ({"ratio": 3, "z_min": 0}, "z_min"),
        ({"ratio": 3, "z_min": 30, "z_max": 20}, "z_max"),
        ({"ratio": 1.5}, "ratio"),
        ({"ratio": "3"}, "ratio"),
    ],
)
def test_bad_input_names_the_field(kwargs, field):
    with pytest.raises(MechanismError, match=rf"^{field}: "):
        planetary_synthesis(**kwargs)
