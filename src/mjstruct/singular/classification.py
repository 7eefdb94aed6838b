"""The extended classification of singular positions of [Four-bar clearances]: types
I-V, singular traps A-E, useful or harmful.

Owns the paper's table and the rules that put each singular position and fold arc of
:mod:`mjstruct.singular.analysis` in it, and the closed-form classes of a hinged
four-bar from its singularity matrix (:func:`fourbar_classes`).

The table (the paper's "extended classification"; W1, W2 the mobility at the input
and at the output, φ the input angle, θ the angle of the singular zone):

* I, trap A, dead position of the output: W1 = 0, W2 = 0, at one φ0;
* II, trap B, bifurcation of the output's motion: W1 = 1, W2 = 2, φ anywhere,
  θ << 2π;
* III, trap C, the closed chain becomes open (the input turns, the output stands):
  W1 = 1, W2 = 0, φ over a range, θ = 2π;
* IV, trap D, adjacent links at the output block pairwise (the input stands, the
  output turns): W1 = 0, W2 = 1;
* V, trap E, Assur singular point: W1 = 1, W2 = 2, θ0.

Each is useful (П) or harmful (В); the notation is ``type/trap//mark``, e.g.
``II/B//П``.  The rules (exact for a four-bar, whose singular positions are the three
collinearities):

* a change point (branches cross: the input passes, the output may leave on either
  branch) is II/B;
* an output extreme (the output reverses; with clearance it is free within the zone)
  is II/B;
* an input limit with two moving links in line (a dyad stretched or folded: the
  driver's force cannot turn the chain, transmission angle 0) is I/A;
* an input limit with no two moving links in line (a group of class III or higher
  whose legs meet in one point: Assur's singular point) is V/E;
* a fold arc along which the output dwells while the input turns is III/C; one along
  which the input is locked while the output turns is IV/D; a fold arc along which
  neither moves has no type (the table does not apply).

The mark: change points and fold arcs exist only for special lengths (a line of
system (4), two pairs of equal links), so a linkage that has them is built for them:
useful, П, as every example of the paper.  Input limits, output extremes and Assur
points are generic (every linkage near those lengths has them): the paper's singular
traps, harmful, В, unless the design uses them.

References
----------
.. [1] Singular positions and synthesis of hinged multi-joint mechanisms with
   clearances in their revolute pairs (in Russian; eLibrary document code EDN PBGDPR;
   authors, exact title, journal and year not given in the available copy).
   [Four-bar clearances] in docs/references.md.

Examples
--------
>>> fourbar_classes(0.5, 1.0, 1.5)          # MS4: the folding crank-rocker
('II/B//П', 'II/B//В')
>>> fourbar_classes(0.5, 0.5, 1.0)          # MS2: exact dwell
('II/B//П', 'II/B//В', 'III/C//П')
>>> fourbar_classes(1.2, 0.8, 1.5)          # a triple-rocker: dead positions
('I/A//В', 'II/B//В')
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mjstruct.output_numbers import json_number
from mjstruct.singular.clearance import formula3, leading_order_zone, singular_direction
from mjstruct.singular.curve import ClosureEquations
from mjstruct.singular.fourbar import TIE, fourbar_theory
from mjstruct.typing import FloatArray


@dataclass(frozen=True)
class SingularType:
    """One row of the table: the trap and the mobilities of a type."""

    trap: str
    W1: int
    W2: int
    trap_name: str
    cause: str


#: the paper's table, by type
TYPES: dict[str, SingularType] = {
    "I": SingularType(
        "A", 0, 0, "dead position of the output", "the angle of motion exceeds its limit"
    ),
    "II": SingularType(
        "B",
        1,
        2,
        "bifurcation of the output's motion",
        "geometric constraints of the pairs broken within their clearances",
    ),
    "III": SingularType(
        "C",
        1,
        0,
        "closed chain degenerates into an open one: the input turns, the output stands",
        "the axes of adjacent links' joints coincide at the input of the loop",
    ),
    "IV": SingularType(
        "D",
        0,
        1,
        "adjacent links at the output block pairwise: the input stands, the output turns",
        "the axes of adjacent links' joints coincide at the output of the loop",
    ),
    "V": SingularType("E", 1, 2, "Assur singular point", "an Assur singular point forms"),
}

#: the marks, in the paper's letters
USEFUL, HARMFUL = "П", "В"


@dataclass(frozen=True)
class SingularClass:
    """The class of one singular position or fold arc.

    Attributes
    ----------
    type : ``"I"`` ... ``"V"``.
    phi : the input's value (from = to for a position) or range (a fold arc).
    theta : the singular zone's angle (rad): the widest clearance zone there; ``None``
        without a clearance, or where no zone is computed.
    useful : the mark П (True) or В (False).
    reason : what put it in this class, in words.
    """

    type: str
    phi: tuple[float, float]
    theta: float | None
    useful: bool
    reason: str

    @property
    def trap(self) -> str:
        return TYPES[self.type].trap

    @property
    def notation(self) -> str:
        """``type/trap//mark``, e.g. ``II/B//П``."""
        return f"{self.type}/{self.trap}//{USEFUL if self.useful else HARMFUL}"

    def to_dict(self) -> dict[str, Any]:
        t = TYPES[self.type]
        return {
            "type": self.type,
            "trap": t.trap,
            "W1": t.W1,
            "W2": t.W2,
            "phi": [json_number(self.phi[0]), json_number(self.phi[1])],
            "theta": json_number(self.theta),
            "use": "useful" if self.useful else "harmful",
            "notation": self.notation,
            "reason": self.reason,
        }


def classify_position(
    kind: str,
    q: float,
    moving_pairs: Sequence[tuple[str, str]],
    theta: float | None,
    group_class: int | None = None,
) -> SingularClass:
    """The class of a singular position of ``kind`` at input ``q``.

    ``moving_pairs``: the pairs of moving links in line there; ``theta``: its widest
    zone (None without a clearance); ``group_class``: the class of the Assur group
    that is singular at an input limit (:func:`singular_group_class`; None: unknown,
    then a position with no pair in line is taken for an Assur point).

    >>> classify_position("change_point", 0.0, [("1", "2"), ("2", "3")], None).notation
    'II/B//П'
    >>> classify_position("input_limit", 1.2, [], None, group_class=3).notation
    'V/E//В'
    """
    phi = (q, q)
    if kind == "change_point":
        return SingularClass(
            "II",
            phi,
            theta,
            True,
            "change point: the input passes and the output may leave on either branch; "
            "it exists only for special lengths, so the linkage is built for it",
        )
    if kind == "output_extreme":
        return SingularClass(
            "II",
            phi,
            theta,
            False,
            "output extreme: the output reverses while the input turns, and with "
            "clearance it is free within the zone; generic, a trap unless used",
        )
    if kind != "input_limit":
        raise ValueError(f"kind: unknown singular position {kind!r}")
    dyad = group_class == 2 if group_class is not None else bool(moving_pairs)
    if dyad:
        inline = (
            f"links {moving_pairs[0][0]} and {moving_pairs[0][1]} in line"
            if moving_pairs
            else "its dyad in line"
        )
        return SingularClass(
            "I",
            phi,
            theta,
            False,
            f"input limit with {inline} (a class-II group): the driver's force cannot "
            "turn the chain (transmission angle 0), input and output stop; generic",
        )
    klass = "III or higher" if group_class is None else _roman(group_class)
    return SingularClass(
        "V",
        phi,
        theta,
        False,
        f"input limit where a group of class {klass} is singular, its legs meeting in "
        "one point (Assur's singular point); generic",
    )


def _roman(k: int) -> str:
    return {3: "III", 4: "IV", 5: "V", 6: "VI"}.get(k, str(k))


def singular_group_class(
    eq: ClosureEquations, x: FloatArray, classes: Sequence[tuple[tuple[str, ...], int]]
) -> int | None:
    """The class of the first Assur group (solving order) that moves when the input is
    held at ``x``: the group that is singular there.

    ``classes``: each group's links and class, in solving order.  None when no group
    moves (the input is not at a limit).
    """
    v, _ = singular_direction(eq, x, "input")
    size = np.abs(v).max()
    moves = {
        link
        for k, link in enumerate(eq.moving)
        if float(np.abs(v[3 * k : 3 * k + 3]).max()) > MOVES * size
    }
    return next((klass for links, klass in classes if moves & set(links)), None)


#: a link moves along a singular direction when a coordinate of it exceeds this
#: fraction of the largest (round-off of the SVD is about 1e-15)
MOVES = 1e-6


def classify_fold_arc(
    kind: str, q_from: float, q_to: float, theta: float | None
) -> SingularClass | None:
    """The class of a fold arc: III/C for a dwell (``kind`` ``output_extreme``),
    IV/D for a locked input (``input_limit``); ``None`` for any other kind.

    >>> classify_fold_arc("output_extreme", 0.0, 3.14, None).notation
    'III/C//П'
    """
    span = (q_from, q_to)
    if kind == "output_extreme":
        return SingularClass(
            "III",
            span,
            theta,
            True,
            "fold arc: the output stands while the input turns (two joints coincide), "
            "which needs equal links: built for it",
        )
    if kind == "input_limit":
        return SingularClass(
            "IV",
            span,
            theta,
            True,
            "fold arc: the input stands while the output turns (two joints coincide), "
            "which needs equal links: built for it",
        )
    return None


def fold_arc_theta(
    joints: Sequence[str],
    link_joints: Mapping[str, Sequence[str]],
    centres: Mapping[str, complex],
    clearance: float | None,
) -> float | None:
    """The zone angle of a fold arc: formula (3) of the folded pair whose outer pivots
    are the coinciding joints (2π for any clearance > 0: the pivots coincide).

    ``joints``: the coinciding joints; ``link_joints``: each link's joints;
    ``centres``: the joint centres of the reference configuration.  ``None`` without a
    clearance or when no pair of links joins the coinciding joints.
    """
    if clearance is None:
        return None
    coincide = set(joints)
    best: float | None = None
    for a, ja in link_joints.items():
        for b, jb in link_joints.items():
            if a >= b:
                continue
            for shared in set(ja) & set(jb):
                outer = {j for j in ja if j != shared} & coincide
                outer_b = {j for j in jb if j != shared} & coincide
                if outer and outer_b and outer != outer_b:
                    pa, pb = outer.pop(), outer_b.pop()
                    la = abs(centres[pa] - centres[shared])
                    lb = abs(centres[pb] - centres[shared])
                    # the pivots coincide along the arc: the pair is folded and equal
                    psi = formula3(max(la, lb), max(la, lb), clearance, stretched=False)
                    best = psi if best is None else max(best, psi)
    return best


def fourbar_classes(P1: float, P2: float, P3: float) -> tuple[str, ...]:
    """The notations a hinged four-bar of matrix ``[P1 P2 P3]`` has, in closed form.

    From the lengths alone: a change point (a line of system (4)) gives II/B//П; an
    output that rocks has output extremes, II/B//В; an input that does not turn fully
    has dead positions, I/A//В; B on O1 for every input angle (``P1 = P2``,
    ``P3 = 1``) a dwell, III/C//П; A on O2 with the output turning (``P1 = 1``,
    ``P2 = P3``) a locked input, IV/D//П.  A four-bar has no class-III group, so no
    V/E.  The traced analysis gives the same set (tested).
    """
    fb = fourbar_theory(P1, P2, P3)
    out: list[str] = []
    extremes, limits = _plain_extremes_and_limits(P1, P2, P3)
    if limits:
        out.append("I/A//В")
    if fb.system4:
        out.append("II/B//П")
    if extremes:
        out.append("II/B//В")
    if abs(P1 - P2) <= TIE and abs(P3 - 1) <= TIE:
        out.append("III/C//П")
    if abs(P1 - 1) <= TIE and abs(P2 - P3) <= TIE:
        out.append("IV/D//П")
    return tuple(out)


def _plain_extremes_and_limits(P1: float, P2: float, P3: float) -> tuple[bool, bool]:
    """Whether the four-bar has output extremes and input limits that are not change
    points: the extremes where |O1 B| = P2 ± P1 is reachable by the output's circle
    about O2 without all four centres in line, the limits likewise with |A O2| = P2 ± P3.
    """

    def plain(a: float, b: float, c: float) -> bool:
        # a point on the circle of radius c about the far pivot (distance 1) at a
        # distance d = a + b or |a - b| from the near pivot: a triangle (1, c, d) that
        # closes and is not flat (flat: all four centres in line, a change point)
        for d in (a + b, abs(a - b)):
            if d <= TIE:
                continue  # the pair folds onto the pivot: a fold arc, not a point
            lo, hi = abs(1 - c), 1 + c
            if lo + TIE < d < hi - TIE:
                return True
        return False

    return plain(P1, P2, P3), plain(P3, P2, P1)


def theta_of_zones(psis: Sequence[float | None]) -> float | None:
    """The widest of a position's zone angles (None when none is known)."""
    known = [p for p in psis if p is not None and math.isfinite(p)]
    return max(known) if known else None


def theta_without_pair(
    eq: ClosureEquations, x: FloatArray, fixed: str, clearance: float
) -> float | None:
    """θ of a singular position with no two moving links in line (an Assur point, or
    an output extreme of a six-bar whose output dyad is not in line): the
    leading-order zone of the link that turns most with the coordinate ``fixed``
    (``"input"`` or ``"output"``) held, the clearance split evenly over the pins."""
    v, _ = singular_direction(eq, x, fixed)
    link = eq.moving[int(np.argmax(np.abs(v[2::3])))]
    per_pin = {j.id: clearance / len(eq.mechanism.joints) for j in eq.mechanism.joints}
    return leading_order_zone(eq, x, fixed, link, per_pin)
