"""Geometry of a mechanism at its reference configuration, read and checked.

Owns the link shapes: every joint centre ``at`` (one reference configuration fixes
the distances on each link, ternary and multiple-joint links included), the guide
direction ``axis`` of each prismatic joint, points of interest, and the
*characteristic angle* of each link (the direction of the vector from the
link's first to its second joint centre; a slider uses its guide; the frame is the
x axis).  Positions are complex numbers ``x + iy`` throughout the plug-in.

References
----------
.. [1] A. N. Panasenko, "Practical implementation…" (in Russian; the available copy
   gives only this beginning of the title), Systems. Methods. Technologies,
   no. 2 (66), pp. 32–42, 2025. [Panasenko 2025] in docs/references.md.

Examples
--------
>>> from mjstruct.io import mechanism_from_dict
>>> m = mechanism_from_dict({"frame": 0, "drivers": ["O1"], "joints": [
...     {"id": "O1", "links": [0, 1], "at": [0, 0]},
...     {"id": "A", "links": [1, 2], "at": [0, 1]},
...     {"id": "B", "links": [2, 3], "at": [2, 1]},
...     {"id": "O2", "links": [3, 0], "at": [2, 0]}]})
>>> g = read_geometry(m)
>>> g.centres["B"], round(g.char_angle["1"], 6), g.driver_ref["O1"] == g.char_angle["1"]
((2+1j), 1.570796, True)
"""

from __future__ import annotations

import cmath
import itertools
import math
from dataclasses import dataclass

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.kinematics.tolerances import COINCIDE
from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.structure.drivers import validate_drivers

__all__ = ["COINCIDE", "Geometry", "geometry_of", "read_geometry"]


#: hull vertices from which the pairwise distances are taken in numpy blocks
HULL_VECTORISED = 64

#: the sizes analysed (largest distance between two joint centres, in the file's unit).
#: The triangle steps form products of three lengths (and of analogs up to 1e12 times
#: the size for the shortest side COINCIDE allows), which must stay normal doubles:
#: measured exact up to scaling from 1e-100 to 1e80 (the shipped examples, 24 frames),
#: wrong from 1e-108 (velocities underflow to 0) and 1e85 (closure groups); this range
#: keeps a factor 1e30 in the cube from either end (tests/cli/test_extreme_scale.py)
SIZE_RANGE = (1e-50, 1e50)
#: joint centres and points at most this many sizes from the origin: coordinates
#: carry eps × (distance / size) of the mechanism, so farther ones keep fewer than 8
#: digits of it (measured: 3e-8 of the size at 1e8, 2e-1 at 1e15)
REACH = 1e8


def diameter(points: list[complex]) -> float:
    """The largest distance between two of ``points`` (0 for fewer than two).

    The farthest pair lies on the convex hull, so only the hull's vertices (Andrew's
    monotone chain, O(n log n)) are compared pairwise: the same value as all pairs,
    without their n² cost on mechanisms of a thousand links.  A large hull (points on
    a circle) is screened in numpy first (:func:`_farthest`).

    >>> diameter([0j, 1 + 0j, 0.5 + 0.2j, 1j])
    1.4142135623730951
    """
    if len(points) <= 12:  # a few points: every pair, cheaper than the hull
        return max((abs(a - b) for a, b in itertools.combinations(points, 2)), default=0.0)
    pts = sorted(set(points), key=lambda z: (z.real, z.imag))
    if len(pts) < 3:
        return max((abs(a - b) for a in pts for b in pts), default=0.0)

    def cross(o: complex, a: complex, b: complex) -> float:
        return (a - o).real * (b - o).imag - (a - o).imag * (b - o).real

    lower: list[complex] = []
    upper: list[complex] = []
    for z in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], z) <= 0:
            lower.pop()
        lower.append(z)
    for z in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], z) <= 0:
            upper.pop()
        upper.append(z)
    hull = lower[:-1] + upper[:-1]
    if len(hull) < HULL_VECTORISED:
        return max(abs(a - b) for a in hull for b in hull)
    return _farthest(hull)


def _farthest(hull: list[complex]) -> float:
    """Largest ``abs(a - b)`` over pairs of ``hull``, bit for bit as pairwise in Python.

    numpy's squared distances (in blocks of rows, one pass; each block against the
    columns from its first row on, so every pair once or twice, not twice) find the
    pairs within a relative 1e-9 of the largest; their Python ``abs`` decides (numpy's
    complex ``abs`` may differ from Python's in the last bit).
    """
    x = np.array([z.real for z in hull])
    y = np.array([z.imag for z in hull])
    rows = max(1, min(64, 2**20 // len(hull)))
    top, near = 0.0, []
    for k in range(0, len(hull), rows):
        dx = x[k : k + rows, None] - x[None, k:]
        dy = y[k : k + rows, None] - y[None, k:]
        sq = dx * dx + dy * dy
        top = max(top, float(sq.max()))
        i, j = np.nonzero(sq >= top * (1.0 - 1e-9))
        near.append((k, i, j, sq[i, j]))
    if not math.isfinite(top):  # overflowed squares: all pairs, as for a small hull
        return max(abs(a - b) for a in hull for b in hull)
    best = 0.0
    for k, i, j, v in near:
        keep = v >= top * (1.0 - 1e-9)
        for a, b in zip(i[keep].tolist(), j[keep].tolist(), strict=True):
            best = max(best, abs(hull[k + a] - hull[k + b]))
    return best


def unit_direction(x: float, y: float) -> complex:
    """The unit vector along (x, y), for any nonzero components a double holds.

    Divided by the larger component first: ``abs`` of (1e308, 1e308) overflows and
    of (5e-324, 5e-324) rounds, which made a zero or a longer-than-unit guide.

    >>> unit_direction(1e308, 1e308) == unit_direction(5e-324, 5e-324) == unit_direction(1, 1)
    True
    """
    m = max(abs(x), abs(y))
    a = complex(x / m, y / m)
    return a / abs(a)


def first_close_pair(
    ids: list[str], centres: dict[str, complex], tol: float
) -> tuple[str, str] | None:
    """The first pair (in the order of ``ids``) of centres at most ``tol`` apart, or None.

    Centres are binned in squares of side ``tol``: a close pair lies in one square or
    two neighbouring ones, and squares hold a few centres when no pair is close, so a
    link of many joints (the frame of a large mechanism) costs O(n), not n² pairs.

    >>> first_close_pair(["a", "b", "c"], {"a": 0j, "b": 1 + 0j, "c": 1 + 1e-13j}, 1e-12)
    ('b', 'c')
    """
    if len(ids) < 16 or not all(cmath.isfinite(centres[a]) for a in ids):
        for i, a in enumerate(ids):
            for b in ids[i + 1 :]:
                if abs(centres[a] - centres[b]) <= tol:
                    return a, b
        return None
    cells: dict[tuple[int, int], list[int]] = {}
    for k, a in enumerate(ids):
        z = centres[a]
        cells.setdefault((math.floor(z.real / tol), math.floor(z.imag / tol)), []).append(k)
    best: tuple[int, int] | None = None
    for (cx, cy), here in cells.items():
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for k in here:
                    for q in cells.get((cx + dx, cy + dy), ()):
                        close = k < q and abs(centres[ids[k]] - centres[ids[q]]) <= tol
                        if close and (best is None or (k, q) < best):
                            best = (k, q)
    return None if best is None else (ids[best[0]], ids[best[1]])


def _check_extent(m: Mechanism, centres: dict[str, complex], scale: float) -> None:
    """Refuse a size outside :data:`SIZE_RANGE` or a coordinate beyond :data:`REACH`
    sizes from the origin, naming the field: never numbers that underflow, overflow
    or keep no digits of the mechanism."""
    lo, hi = SIZE_RANGE
    if not lo <= scale <= hi:
        raise MechanismError(
            f"joints.at: the mechanism's size (the largest distance between two joint "
            f"centres) is {scale:.3g}; sizes from {lo:g} to {hi:g} are analysed (write "
            "the coordinates in a unit nearer the mechanism's size)"
        )
    far = REACH * scale
    places = [(f"joints[{k}].at", centres[j.id]) for k, j in enumerate(m.joints)]
    places += [(f"points[{k}].at", complex(*p.at)) for k, p in enumerate(m.points)]
    for where, z in places:
        if not abs(z) <= far:  # also catches a distance that overflows
            raise MechanismError(
                f"{where}: ({z.real:.6g}, {z.imag:.6g}) lies {abs(z) / scale:.3g} sizes "
                f"(the largest distance between joint centres, {scale:.3g}) from the origin; "
                f"at most {REACH:g} (farther, coordinates keep fewer than 8 digits of the "
                "mechanism: put the origin near it)"
            )


@dataclass(frozen=True)
class Geometry:
    """Reference configuration of a mechanism (complex coordinates).

    Attributes
    ----------
    centres : joint id -> reference centre (for a prismatic joint: a point carried by
        its second listed link, reported as that joint's position).
    axes : prismatic joint id -> unit guide direction at the reference configuration.
    points : point id -> (link, reference position).
    char_angle : link -> characteristic angle at the reference configuration.
    char_joints : link -> the two joints whose centres define that angle (or ``()``).
    driver_ref : driver joint -> its coordinate at the reference configuration
        (relative angle for a revolute driver; 0 for a prismatic slide).
    scale : the largest distance between two joint centres (the length unit of tolerances).
    """

    centres: dict[str, complex]
    axes: dict[str, complex]
    points: dict[str, tuple[str, complex]]
    char_angle: dict[str, float]
    char_joints: dict[str, tuple[str, ...]]
    driver_ref: dict[str, float]
    scale: float


def read_geometry(m: Mechanism, drivers: tuple[str, ...] | None = None) -> Geometry:
    """Read and check the geometry keys of ``m`` (``at``, ``axis``, ``points``).

    Raises
    ------
    MechanismError
        a joint without ``at``, a prismatic joint without ``axis`` or with more than two
        links, all joints at one point, two revolute joints of one link at one point
        (a zero-length side), a driver that is not a joint of the mechanism.
    """
    expect_mechanism(m)
    return geometry_of(m, validate_drivers(m, drivers, balance=False))


def geometry_of(m: Mechanism, drivers: tuple[str, ...]) -> Geometry:
    """:func:`read_geometry` of a mechanism whose ``drivers`` are already checked.

    For entry points that check their inputs once (:meth:`KinematicModel.build
    <mjstruct.kinematics.model.KinematicModel.build>`): ``m`` is a :class:`Mechanism`
    and ``drivers`` came from :func:`~mjstruct.structure.drivers.validate_drivers`;
    only the geometry keys are read and checked here.
    """
    if m.frame is None:
        raise MechanismError("frame: kinematics needs a frame link")
    centres: dict[str, complex] = {}
    axes: dict[str, complex] = {}
    for k, j in enumerate(m.joints):
        if j.at is None:
            raise MechanismError(
                f"joints[{k}].at: missing for joint {j.id!r} (kinematics needs every joint centre)"
            )
        centres[j.id] = complex(*j.at)
        if j.kind == "P":
            if j.axis is None:
                raise MechanismError(f"joints[{k}].axis: missing for prismatic joint {j.id!r}")
            if len(j.links) != 2:
                raise MechanismError(
                    f"joints[{k}].links: prismatic joint {j.id!r} must join exactly two links"
                )
            axes[j.id] = unit_direction(*j.axis)
    scale = diameter(list(centres.values()))
    if scale <= 0.0:
        raise MechanismError("joints.at: all joint centres coincide; the mechanism has no size")
    _check_extent(m, centres, scale)
    tol = COINCIDE * scale
    char_angle: dict[str, float] = {}
    char_joints: dict[str, tuple[str, ...]] = {}
    link_joints = m.link_joints
    for link in m.links:
        revolute = [jid for jid in link_joints[link] if jid not in axes]
        close = first_close_pair(revolute, centres, tol) if len(revolute) > 1 else None
        if close is not None:
            ja, jb = close
            index = next(k for k, j in enumerate(m.joints) if j.id == jb)
            raise MechanismError(
                f"joints[{index}].at: joints {ja!r} and {jb!r} of link {link!r} are "
                "at one point (a zero-length side; join them as one multiple joint)"
            )
        if link == m.frame:
            char_angle[link], char_joints[link] = 0.0, ()
            continue
        pair = next(
            (
                (a, b)
                for i, a in enumerate(revolute)
                for b in revolute[i + 1 :]
                if abs(centres[b] - centres[a]) > tol
            ),
            None,
        )
        if pair is not None:
            char_angle[link] = cmath.phase(centres[pair[1]] - centres[pair[0]])
            char_joints[link] = pair
            continue
        slide = [jid for jid in link_joints[link] if jid in axes]
        char_angle[link] = cmath.phase(axes[slide[0]]) if slide else 0.0
        char_joints[link] = ()

    points: dict[str, tuple[str, complex]] = {}
    for p in m.points:
        if p.id in points or p.id in centres:
            raise MechanismError(
                f"points: id {p.id!r} is used twice (points and joints share ids)"
            )
        points[p.id] = (p.link, complex(*p.at))

    driver_ref: dict[str, float] = {}
    for d in drivers:
        j = m.joint(d)
        if j.kind == "P":
            driver_ref[d] = 0.0
        else:
            driver_ref[d] = char_angle[j.links[1]] - char_angle[j.links[0]]
    return Geometry(centres, axes, points, char_angle, char_joints, driver_ref, scale)
