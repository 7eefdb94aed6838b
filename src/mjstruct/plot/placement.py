"""Where a label goes: the freest direction around a point, and how far along it.

Owns the rule that a label is set clear of what meets at its point: the bars, plates,
guides and arrows leaving a joint occupy directions, the label takes the direction
farthest from all of them (up and to the right when several are as free), just
outside the pin, and its text box is pushed out along that direction until it no
longer covers the point.  Pure geometry on complex numbers, no drawing.

Examples
--------
>>> d = free_direction(np.array([1, 1j]))          # bars to the right and upwards
>>> round(float(np.degrees(np.angle(d))))           # the label goes down-left
-135
>>> round(float(np.degrees(np.angle(free_direction(np.zeros(0, complex))))))
45
>>> clearance(1j, "B", 8.0)                         # straight up: half the text height + gap
(0.0, 6.0)
"""

from __future__ import annotations

import numpy as np

from mjstruct.typing import ComplexArray

#: candidate directions (degrees), in the order ties are broken: up-right first
_PREFERENCE = (45, 135, -45, -135, 90, 0, 180, -90, 22.5, 67.5, 112.5, 157.5, -22.5, -67.5,
               -112.5, -157.5)  # fmt: skip
_CANDIDATES = np.exp(1j * np.radians(np.array(_PREFERENCE, float)))
#: a label keeps its side while nothing comes nearer than this (radians)
KEEP = float(np.radians(40.0))
#: gap (points) between a label's text box and what it labels
GAP = 2.0


def free_direction(occupied: ComplexArray, keep: complex | None = None) -> complex:
    """The unit direction farthest (in angle) from every direction in ``occupied``.

    ``occupied`` holds nonzero complex numbers (only their directions count); zeros and
    non-finite values are ignored.  Without any, the label goes up and to the right.
    ``keep``: the direction used so far (an animation's previous frame), kept while it
    stays :data:`KEEP` clear of everything, so that labels do not hop between frames.
    """
    occ = np.asarray(occupied, complex)
    occ = occ[np.isfinite(occ) & (np.abs(occ) > 0)]
    if occ.size == 0:
        return complex(_CANDIDATES[0]) if keep is None else keep
    u = occ / np.abs(occ)
    if keep is not None and np.abs(np.angle(keep * np.conj(u))).min() >= KEEP:
        return keep
    # angle between each candidate and its nearest occupied direction
    gap = np.abs(np.angle(_CANDIDATES[:, None] * np.conj(u)[None, :])).min(axis=1)
    # a little preference for the earlier candidates, so that ties keep the usual place
    score = gap - 1e-3 * np.arange(len(_CANDIDATES))
    return complex(_CANDIDATES[int(np.argmax(score))])


def clearance(direction: complex, text: str, fontsize: float) -> tuple[float, float]:
    """Offset (points) from a point to the centre of a text box that lies beyond it in
    ``direction``: the box (about 0.6 em a character by 1 em) no longer covers the
    point and keeps :data:`GAP` from it."""
    half_w = 0.3 * fontsize * max(1, len(text)) + 1.0
    half_h = 0.5 * fontsize
    ux, uy = direction.real, direction.imag
    reach = min(
        half_w / abs(ux) if abs(ux) > 1e-9 else np.inf,
        half_h / abs(uy) if abs(uy) > 1e-9 else np.inf,
    )
    s = float(reach) + GAP
    return (round(ux * s, 6) + 0.0, round(uy * s, 6) + 0.0)
