"""The requirements of a task as margins: numbers that are >= 0 where a design meets them.

Owns the constraint margins the searches rank candidates by and the results report
(``DesignResult.margins``), each computed for a whole population at once:

* ``assembly``: the smallest |sine| at the solved joint of every dyad of the plan over
  the driver values the task needs (the step's Jacobian of the kinematics: zero at a
  dead or change point, where the dyad stops assembling or the branches meet), minus
  the sine of ``transmission_deg`` (for a four-bar the transmission angle); where a
  dyad does not assemble its (negative) discriminant stands in, so that a search sees
  how far off it is;
* ``lengths``: how far every distance between two joints or points of one link stays
  inside ``lengths = [min, max]`` (relative to the mechanism's size);
* ``grashof`` / ``motion``: for a four-bar whose motion type is required, the margins
  of the length conditions of that type (Grashof's s + l <= p + q, the shortest link's
  place), relative to the frame length.

The result itself is judged again by the kinematics over a finer sweep (branch
events, dead points: :mod:`mjstruct.design.verify`); these margins guide the search.

Examples
--------
>>> import numpy as np
>>> lengths = {"a": np.array([0.3, 1.2]), "b": np.array([1.0, 1.0]),
...            "c": np.array([0.9, 0.9]), "d": np.array([1.0, 1.0])}
>>> np.round(fourbar_margin(lengths, "crank-rocker"), 3)   # a crank-rocker, then not
array([ 0.6, -0.3])
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from mjstruct.kinematics.evaluate import Evaluation
from mjstruct.mechanism import Mechanism
from mjstruct.typing import ComplexArray, FloatArray

#: the smallest |sine| at a dyad's joint accepted without a transmission bound: a
#: dead point between two samples of the sweep shows as a dip towards zero
MIN_SINE = 1e-3


def dyad_sine(ev: Evaluation, shape: tuple[int, int]) -> FloatArray:
    """Per frame (reshaped to ``shape``), the smallest |sine| over the plan's dyads;
    where a dyad does not assemble, minus the square root of its discriminant's
    deficit (negative: how far it is from assembling)."""
    out = np.full(shape, np.inf)
    for disc, det in ev.diag.values():
        d = np.asarray(disc, float).reshape(shape)
        s = np.abs(np.asarray(det, float)).reshape(shape)
        with np.errstate(invalid="ignore"):
            value = np.where(d >= 0, s, -np.sqrt(np.maximum(-d, 0.0)))
        value = np.where(np.isfinite(value), value, -1.0)
        out = np.minimum(out, value)
    out[~np.isfinite(out)] = 1.0  # no dyad at all: nothing can fail
    return out


def assembly_margin(
    ev: Evaluation, shape: tuple[int, int], transmission_deg: float | None, columns: slice
) -> FloatArray:
    """Per candidate: the smallest dyad sine over ``columns`` minus the required one."""
    need = MIN_SINE if transmission_deg is None else math.sin(math.radians(transmission_deg))
    need = max(need, MIN_SINE)
    s = dyad_sine(ev, shape)[:, columns]
    out: FloatArray = s.min(axis=1) - need
    return out


def link_pairs(m: Mechanism) -> list[tuple[str, str]]:
    """Every pair of joints or points that share a link (each pair once)."""
    seen: set[tuple[str, str]] = set()
    out = []
    for link in m.links:
        ids = list(m.link_joints[link]) + [p.id for p in m.points if p.link == link]
        for i, a in enumerate(ids):
            for b in ids[i + 1 :]:
                key = (a, b) if a < b else (b, a)
                if key not in seen:
                    seen.add(key)
                    out.append(key)
    return out


def length_margin(
    positions: Mapping[str, ComplexArray],
    pairs: Sequence[tuple[str, str]],
    bounds: tuple[float, float],
    scale: float,
) -> FloatArray:
    """Per candidate: min over pairs of (d - min, max - d), relative to ``scale``.

    A pair of centres that coincide (a multiple joint's ids, a point at a joint) has
    no length to bound and is left out.
    """
    lo, hi = bounds
    first = next(iter(positions.values()))
    out = np.full(first.shape, np.inf)
    for a, b in pairs:
        d = np.abs(positions[a] - positions[b])
        out = np.minimum(out, np.minimum(d - lo, hi - d))
    result: FloatArray = np.where(np.isfinite(out), out, 0.0) / scale
    return result


def fourbar_lengths(m: Mechanism, positions: Mapping[str, ComplexArray]) -> dict[str, FloatArray]:
    """Crank a, coupler b, rocker c and frame d of a hinged four-bar driven at a frame
    joint, per candidate (``positions``: every joint id -> (P,) complex)."""
    frame = m.frame
    driver = m.joint(m.drivers[0])
    crank = next(x for x in driver.links if x != frame)
    other = next(j for j in m.joints if frame in j.links and j.id != driver.id)
    rocker = next(x for x in other.links if x != frame)
    A = next(j for j in m.joints if crank in j.links and j.id != driver.id)
    B = next(j for j in m.joints if rocker in j.links and j.id != other.id)
    P = positions
    return {
        "a": np.abs(P[A.id] - P[driver.id]),
        "b": np.abs(P[B.id] - P[A.id]),
        "c": np.abs(P[other.id] - P[B.id]),
        "d": np.abs(P[other.id] - P[driver.id]),
    }


def fourbar_margin(lengths: Mapping[str, FloatArray], motion: str) -> FloatArray:
    """Per candidate, the margin of the length conditions of a four-bar motion type,
    relative to the frame d: crank-rocker (crank a shortest, Grashof), double-crank
    (frame shortest, Grashof), double-rocker (coupler shortest and Grashof, or not
    Grashof)."""
    a, b, c, d = (np.asarray(lengths[k], float) for k in "abcd")
    total = a + b + c + d
    longest = np.maximum.reduce([a, b, c, d])
    shortest = np.minimum.reduce([a, b, c, d])
    grashof = total - 2.0 * (shortest + longest)  # p + q - (s + l), doubled
    if motion == "crank-rocker":
        place = np.minimum.reduce([b, c, d]) - a
        out = np.minimum(grashof, place)
    elif motion == "double-crank":
        place = np.minimum.reduce([a, b, c]) - d
        out = np.minimum(grashof, place)
    else:
        coupler = np.minimum(grashof, np.minimum.reduce([a, c, d]) - b)
        out = np.maximum(coupler, -grashof)
    result: FloatArray = out / d
    return result
