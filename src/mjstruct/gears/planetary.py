"""Tooth numbers of the 2AA planetary train with a double satellite chain.

The scheme (docs/gears.md): central gear 1 and central gear 4 on the main axis; on the
carrier H, k sets of two satellites 2 and 3 placed one behind the other on a radius
("radially far"); the meshes 1–2, 2–3 and 3–4 are all external. With gear 4 held,
Willis' equation gives the ratio from gear 1 to the carrier, ``i = 1 + Z4/Z1``.

A tooth-number set Z1..Z4 is admissible when it meets the paper's four conditions:

- ratio: ``|1 + Z4/Z1 - i| <= ratio_tolerance * i``;
- coaxiality (2) with the meshing-angle factors ``t = a_w / a`` (working over
  reference centre distance): ``Z1 + Z2 + t1 (Z2 + Z3) = t2 (Z3 + Z4)``, met when the
  t2 that makes it exact is within ``coaxial_tolerance`` of the given t2;
- assembly (3): ``(Z1 + Z4) / k`` is an integer;
- neighbouring (8): adjacent satellites' tip circles clear each other,
  ``(Z1 + Z2) sin(pi/k) >= Z2 + 2`` and ``2 a_34 sin(pi/k) >= Z3 + 2`` with the working
  centre distance ``2 a_34 = Z1 + Z2 + t1 (Z2 + Z3)`` (in modules);

plus ``Z3 = y Z2`` to the nearest tooth (``|Z3 - y Z2| < 1``), the paper's (4).

References
----------
[Kavetsky & Geresh] in docs/references.md: the scheme, the conditions (1)-(4), (8),
the generating equations (3)-(5) and the ratio limits (7), (9), (11).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from mjstruct.errors import MechanismError, expect_int, expect_number

#: the paper's recommended smallest tooth number (of gear 1; used here for every gear)
Z_MIN = 18
_EPS = 1e-9  # equalities in tooth units: sums of a few hundred teeth times t


@dataclass(frozen=True)
class ToothSet:
    """One admissible set of tooth numbers, with how well it meets each condition.

    ``ratio_error`` is relative, ``(ratio - required) / required``; ``t2_exact`` is the
    factor t2 that makes the coaxiality exact with the given t1; the two neighbouring
    margins are the gaps (in modules) between adjacent satellites' tip circles.
    """

    z1: int
    z2: int
    z3: int
    z4: int
    ratio: float
    ratio_error: float
    t2_exact: float
    assembly_number: int
    neighbour_margin_2: float
    neighbour_margin_3: float

    def as_dict(self) -> dict[str, float | int]:
        """The set as the JSON output writes it (docs/contract.md)."""
        return {
            "Z1": self.z1,
            "Z2": self.z2,
            "Z3": self.z3,
            "Z4": self.z4,
            "ratio": self.ratio,
            "ratio_error": self.ratio_error,
            "t2_exact": self.t2_exact,
            "assembly_number": self.assembly_number,
            "neighbour_margin_2": self.neighbour_margin_2,
            "neighbour_margin_3": self.neighbour_margin_3,
        }


@dataclass(frozen=True)
class RatioRange:
    """The admissible ratios ``lower < i < upper`` for given k, t1, t2 and y.

    ``lower`` is the paper's (7) (Z2 > 0); ``upper_2`` its (9) (neighbouring of the
    satellites 2); ``upper_3`` its (11) (neighbouring of the satellites 3), None where
    that condition bounds no ratio. Both upper limits drop the ``2/Z1`` term of the
    neighbouring condition, as the paper does, so they are limits no set can pass.
    ``t2_limit_paper`` is the paper's (10), ``1/sin(pi/k)``: above it the neighbouring
    of the satellites 3 can no longer fail (docs/gears.md says why it is not a limit).
    """

    satellites: int
    t1: float
    t2: float
    y: float
    lower: float
    upper_2: float
    upper_3: float | None
    t2_limit_paper: float

    @property
    def upper(self) -> float:
        """The smaller of the two upper limits."""
        return self.upper_2 if self.upper_3 is None else min(self.upper_2, self.upper_3)

    def failed_condition(self, ratio: float) -> str | None:
        """Which of (7), (9), (11) excludes ``ratio``; None when none does."""
        if ratio <= self.lower:
            return f"(7) needs ratio > 1 + 1/t2 = {self.lower:.6g} (else Z2 <= 0)"
        if ratio >= self.upper_2:
            return (
                f"(9) needs ratio < {self.upper_2:.6g} "
                f"(neighbouring of the satellites 2 with k = {self.satellites})"
            )
        if self.upper_3 is not None and ratio >= self.upper_3:
            return (
                f"(11) needs ratio < {self.upper_3:.6g} "
                f"(neighbouring of the satellites 3 with k = {self.satellites})"
            )
        return None

    def as_dict(self) -> dict[str, float | None]:
        return {
            "lower": self.lower,
            "upper": self.upper,
            "upper_2": self.upper_2,
            "upper_3": self.upper_3,
            "t2_limit_paper": self.t2_limit_paper,
        }


@dataclass(frozen=True)
class PlanetarySynthesis:
    """Every admissible tooth-number set (``count`` of them), best ``sets`` first."""

    ratio: float
    satellites: int
    t1: float
    t2: float
    y: float
    ratio_tolerance: float
    coaxial_tolerance: float
    z_min: int
    z_max: int
    range: RatioRange
    sets: tuple[ToothSet, ...]

    @property
    def count(self) -> int:
        return len(self.sets)


def planetary_ratio_range(
    satellites: int, t1: float = 1.0, t2: float = 1.0, y: float = 1.0
) -> RatioRange:
    """The paper's admissible ratio range (7), (9), (11) of the 2AA scheme.

    Examples
    --------
    >>> r = planetary_ratio_range(3)
    >>> round(r.lower, 6), round(r.upper, 4), r.upper_3, round(r.t2_limit_paper, 4)
    (2.0, 14.9282, None, 1.1547)
    >>> r.failed_condition(16.0)[:3]
    '(9)'
    """
    k, t1, t2, y = _checked_parameters(satellites, t1, t2, y)
    s = math.sin(math.pi / k)
    d = (1 + y) * t1 + 1 - y * t2  # denominator of (5), positive (checked)
    lower = 1 + 1 / t2
    upper_2 = ((1 + t2) + (1 + y) * (t1 - t2) * s) / (t2 * (1 - s))
    # (8b) over Z1 without 2/Z1: t2 u [s d - y c] >= -y c, u = i - 1, c = 1 - t2 s
    c = 1 - t2 * s
    b = s * d - y * c
    upper_3 = 1 + y * c / (t2 * (-b)) if c > 0 and b < 0 else None
    return RatioRange(k, t1, t2, y, lower, upper_2, upper_3, 1 / s)


def planetary_synthesis(
    ratio: float,
    satellites: int = 3,
    *,
    t1: float = 1.0,
    t2: float = 1.0,
    y: float = 1.0,
    ratio_tolerance: float = 0.01,
    coaxial_tolerance: float = 0.01,
    z_min: int = Z_MIN,
    z_max: int = 300,
) -> PlanetarySynthesis:
    """Every tooth-number set Z1..Z4 of the 2AA train within ``z_min..z_max``, by ratio error.

    Parameters
    ----------
    ratio : float
        The required ratio ``i = omega_1 / omega_H`` with gear 4 held.
    satellites : int
        The number k of satellite sets on the carrier (at least 2).
    t1, t2 : float
        Meshing-angle factors ``a_w / a = cos(alpha) / cos(alpha_w)`` of the meshes 2–3
        and 3–4 (the mesh 1–2 is uncorrected); the paper takes them in 0.8..1.2.
    y : float
        ``Z3 / Z2``; Z3 is y·Z2 to the nearest tooth.
    ratio_tolerance : float
        The largest relative ratio error.
    coaxial_tolerance : float
        The largest difference between the given t2 and the one that makes the
        coaxiality (2) exact.
    z_min, z_max : int
        Limits of every tooth number.

    Raises
    ------
    MechanismError
        Bad parameters (the message names it), or a ratio that no set can reach: the
        message says which of the conditions (7), (9), (11) fails.

    Examples
    --------
    >>> r = planetary_synthesis(12, 3)
    >>> s = r.sets[0]
    >>> (s.z1, s.z2, s.z3, s.z4), s.ratio_error
    ((18, 90, 90, 198), 0.0)
    """
    rng = planetary_ratio_range(satellites, t1, t2, y)
    k, t1, t2, y = rng.satellites, rng.t1, rng.t2, rng.y
    ratio = expect_number(ratio, "ratio")
    tol = expect_number(ratio_tolerance, "ratio_tolerance")
    ctol = expect_number(coaxial_tolerance, "coaxial_tolerance")
    if not 0 <= tol < 1:
        raise MechanismError(f"ratio_tolerance: must be in [0, 1), got {tol}")
    if ctol < 0:
        raise MechanismError(f"coaxial_tolerance: must be >= 0, got {ctol}")
    z_min = expect_int(z_min, "z_min", 1)
    z_max = expect_int(z_max, "z_max", z_min)
    if z_max > 2000:
        raise MechanismError(f"z_max: at most 2000 teeth, got {z_max}")
    # the range applies to the set's own ratio: refuse when the whole window is outside
    high, low = ratio * (1 + tol), ratio * (1 - tol)
    failed = rng.failed_condition(high) if high <= rng.lower else None
    failed = rng.failed_condition(low) if low >= rng.upper else failed
    if failed is not None:
        raise MechanismError(f"ratio: {ratio:g} is impossible: {failed}")
    sets = _search(ratio, k, t1, t2, y, tol, ctol, z_min, z_max)
    return PlanetarySynthesis(ratio, k, t1, t2, y, tol, ctol, z_min, z_max, rng, sets)


def _checked_parameters(
    satellites: int, t1: float, t2: float, y: float
) -> tuple[int, float, float, float]:
    k = expect_int(satellites, "satellites", 2)
    values = []
    for name, v in (("t1", t1), ("t2", t2), ("y", y)):
        x = expect_number(v, name)
        if x <= 0:
            raise MechanismError(f"{name}: must be > 0, got {x:g}")
        values.append(x)
    t1, t2, y = values
    if (1 + y) * t1 + 1 - y * t2 <= 0:
        raise MechanismError(
            f"y: (1 + y)·t1 + 1 - y·t2 = {(1 + y) * t1 + 1 - y * t2:.6g} must be > 0 "
            "(the denominator of the paper's (5))"
        )
    return k, t1, t2, y


def _search(
    ratio: float,
    k: int,
    t1: float,
    t2: float,
    y: float,
    tol: float,
    ctol: float,
    z_min: int,
    z_max: int,
) -> tuple[ToothSet, ...]:
    """Z1 and Z4 by the ratio and assembly, Z3 from Z2 by (4); Z2 over its whole range."""
    s = math.sin(math.pi / k)
    z2 = np.arange(z_min, z_max + 1, dtype=np.int64)
    z3 = np.concatenate([np.floor(y * z2), np.ceil(y * z2)]).astype(np.int64)
    z2 = np.concatenate([z2, z2])
    keep = (np.abs(z3 - y * z2) < 1) & (z3 >= z_min) & (z3 <= z_max)
    pairs = np.unique(np.stack([z2[keep], z3[keep]], axis=1), axis=0)
    z2, z3 = pairs[:, 0], pairs[:, 1]
    found: list[ToothSet] = []
    for z1 in range(z_min, z_max + 1):
        lo = math.ceil(z1 * (ratio * (1 - tol) - 1) - _EPS)
        hi = math.floor(z1 * (ratio * (1 + tol) - 1) + _EPS)
        for z4 in range(max(lo, z_min), min(hi, z_max) + 1):
            if (z1 + z4) % k:
                continue  # assembly
            span = z1 + z2 + t1 * (z2 + z3)  # 2 a_12 + 2 a_23 = 2 a_34, in modules
            t2_exact = span / (z3 + z4)
            margin_2 = (z1 + z2) * s - (z2 + 2)
            margin_3 = span * s - (z3 + 2)
            ok = (np.abs(t2_exact - t2) <= ctol + _EPS) & (margin_2 >= -_EPS)
            ok &= margin_3 >= -_EPS
            r = 1 + z4 / z1
            for j in np.flatnonzero(ok):
                found.append(
                    ToothSet(
                        z1,
                        int(z2[j]),
                        int(z3[j]),
                        z4,
                        r,
                        (r - ratio) / ratio,
                        float(t2_exact[j]),
                        (z1 + z4) // k,
                        float(margin_2[j]),
                        float(margin_3[j]),
                    )
                )
    found.sort(key=lambda t: (abs(t.ratio_error), abs(t.t2_exact - t2), t.z1, t.z2, t.z3, t.z4))
    return tuple(found)


def two_aa_mechanism(
    s: ToothSet, satellites: int, t1: float = 1.0, module: float = 1.0
) -> dict[str, Any]:
    """The mechanism file (a dict, docs/contract.md) of a 2AA train with the tooth
    numbers ``s``: gear 4 in the frame "0", gear 1 and the carrier "H" on the main axis
    O, ``satellites`` sets of satellites "2<j>", "3<j>" on one radius each. The meshes
    are given by their teeth and working pitch radii (a_w Z_i / (Z_i + Z_j)), so the
    file's mesh check holds with the meshing-angle factors t1 and ``s.t2_exact``.

    >>> from mjstruct.io import mechanism_from_dict
    >>> best = planetary_synthesis(12, 3).sets[0]
    >>> m = mechanism_from_dict(two_aa_mechanism(best, 3))
    >>> m.n, len(m.extra["gears"])
    (9, 9)
    """
    k = expect_int(satellites, "satellites", 2)
    a12 = module * (s.z1 + s.z2) / 2
    a23 = t1 * module * (s.z2 + s.z3) / 2
    a34 = a12 + a23

    def mesh(
        gid: str, links: list[str], z: tuple[int, int], a: float, centres: list[str]
    ) -> dict[str, Any]:
        radii = [a * z[0] / (z[0] + z[1]), a * z[1] / (z[0] + z[1])]
        return {"id": gid, "links": links, "teeth": list(z), "radii": radii, "centres": centres}

    joints: list[dict[str, Any]] = [{"id": "O", "links": ["0", "1", "H"], "at": [0.0, 0.0]}]
    gears = []
    for j in range(k):
        c, sn = math.cos(2 * math.pi * j / k), math.sin(2 * math.pi * j / k)
        joints.append({"id": f"S2{j}", "links": ["H", f"2{j}"], "at": [a12 * c, a12 * sn]})
        joints.append({"id": f"S3{j}", "links": ["H", f"3{j}"], "at": [a34 * c, a34 * sn]})
        gears += [
            mesh(f"g12-{j}", ["1", f"2{j}"], (s.z1, s.z2), a12, ["O", f"S2{j}"]),
            mesh(f"g23-{j}", [f"2{j}", f"3{j}"], (s.z2, s.z3), a23, [f"S2{j}", f"S3{j}"]),
            mesh(f"g34-{j}", [f"3{j}", "0"], (s.z3, s.z4), a34, [f"S3{j}", "O"]),
        ]
    return {
        "name": f"2AA planetary train: Z = {s.z1}, {s.z2}, {s.z3}, {s.z4}, k = {k}, "
        f"ratio 1 to H {s.ratio:.6g}",
        "frame": "0",
        "joints": joints,
        "drivers": ["O"],
        "gears": gears,
    }
