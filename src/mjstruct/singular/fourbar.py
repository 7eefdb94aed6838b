"""Closed-form theory of the hinged four-bar: singularity matrix, Grashof class, motion.

Owns the four-bar results that need no tracing: the singularity matrix
``MS = [P1 P2 P3]`` (input, coupler and output lengths over the frame length), the
Grashof test, the motion (which of input and output turn fully), the change-point
conditions (4.1)-(4.3) of system (4), the input's range, the output's swing and the
time ratio of a crank-rocker, and the closed-form singular angles used to check the
general Jacobian analysis of :mod:`mjstruct.singular.analysis`.

Angles here are measured from the frame line O1 -> O2: ``phi`` is the direction of
O1 -> A (input), ``theta`` that of O2 -> B (output).

References
----------
.. [1] Singular positions and synthesis of hinged multi-joint mechanisms with
   clearances in their revolute pairs (in Russian; eLibrary document code EDN PBGDPR;
   authors, exact title, journal and year not given in the available copy).
   [Four-bar clearances] in docs/references.md.

Examples
--------
MS4 = [0.5 1 1.5] swings its output through the change point by 2 arccos(1/3):

>>> import math
>>> fb = fourbar_theory(0.5, 1.0, 1.5)
>>> fb.motion, fb.system4, round(math.degrees(fb.swing), 2)
('crank-rocker', (2,), 141.06)
>>> fourbar_theory(0.5, 1.5, 1.0).time_ratio
2.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mjstruct.errors import MechanismError, expect_number

#: two length sums closer than this (relative to the frame) are taken as equal
TIE = 1e-9

MOTIONS = ("crank-rocker", "double-crank", "double-rocker", "triple-rocker", "rocker-crank")

#: reference matrices of the P2-P3 diagram (l0 = 1)
REFERENCE_MATRICES: dict[str, tuple[float, float, float]] = {
    "MS1": (0.5, 1.0, 0.5),
    "MS2": (0.5, 0.5, 1.0),
    "MS3": (0.5, 1.5, 1.0),
    "MS4": (0.5, 1.0, 1.5),
    "MS5": (1.0, 1.0, 1.0),
}


@dataclass(frozen=True)
class FourBar:
    """What the lengths of a four-bar decide (frame length 1).

    Attributes
    ----------
    MS : (P1, P2, P3), input, coupler and output over the frame.
    grashof : ``s + l <= p + q`` (true for every change-point four-bar).
    motion : ``crank-rocker``, ``double-crank``, ``double-rocker``,
        ``triple-rocker`` (non-Grashof) or ``rocker-crank``.
    system4 : the conditions 1-3 of system (4) that hold (a change point each).
    input_full_turn : the input turns fully (on some branch).
    input_intervals : where the input can be (``phi`` from the frame line, rad),
        as increasing [from, to] pairs; ``((0, 2 pi),)`` for a full turn.
    swing : output swing (rad): through the change point for a change-point
        four-bar whose output rocks, per circuit otherwise; ``2 pi`` for a turning
        output; ``None`` for a double-crank.
    time_ratio : crank angle of the slower stroke over the faster one
        (crank-rocker only, per circuit), else ``None``.
    notes : why a number is missing where a reader would expect one (a crank-rocker
        whose folded dead point is a whole fold arc has no time ratio).
    """

    MS: tuple[float, float, float]
    grashof: bool
    motion: str
    system4: tuple[int, ...]
    input_full_turn: bool
    input_intervals: tuple[tuple[float, float], ...]
    swing: float | None
    time_ratio: float | None
    notes: tuple[str, ...] = ()


def _acos(c: float) -> float:
    """``acos`` with a cosine within TIE of +-1 taken as +-1 exactly.

    Near +-1 acos turns a rounding error e of the lengths into sqrt(e) (1e-16 into
    1e-8 rad); within TIE the four-bar is classified as a change-point four-bar
    (system (4)), so its angles are those of the exact change point.
    """
    if abs(c - 1.0) <= TIE:
        return 0.0
    if abs(c + 1.0) <= TIE:
        return math.pi
    return math.acos(max(-1.0, min(1.0, c)))


def _cos_window(lo: float, hi: float) -> tuple[tuple[float, float], ...]:
    """Angles x in [-pi, pi) (as increasing arcs) with lo <= cos x <= hi."""
    lo = -1.0 if abs(lo + 1.0) <= TIE else lo  # a change point: the arcs touch
    hi = 1.0 if abs(hi - 1.0) <= TIE else hi
    if lo > hi or lo > 1.0 or hi < -1.0:
        return ()
    a = math.acos(min(1.0, hi)) if hi < 1.0 else 0.0  # |x| >= a
    b = math.acos(max(-1.0, lo)) if lo > -1.0 else math.pi  # |x| <= b
    if a <= 0.0 and b >= math.pi:
        return ((0.0, 2 * math.pi),)
    if a <= 0.0:
        return ((-b, b),)
    if b >= math.pi:
        return ((a, 2 * math.pi - a),)
    return ((-b, -a), (a, b))


def fourbar_theory(P1: float, P2: float, P3: float) -> FourBar:
    """Classify the four-bar with relative lengths ``MS = [P1 P2 P3]`` (frame = 1).

    Parameters
    ----------
    P1, P2, P3 : input (crank), coupler and output lengths over the frame length.

    Raises
    ------
    MechanismError
        a length that is not positive, or one longer than the other three together
        (the loop does not close), or equal to their sum (it cannot move).

    Examples
    --------
    >>> fourbar_theory(0.5, 1.0, 0.5).motion      # MS1: parallelogram / antiparallelogram
    'double-crank'
    >>> fourbar_theory(0.5, 0.5, 1.0).system4     # MS2 lies on (4.1) and (4.2)
    (1, 2)
    """
    for name, value in (("P1", P1), ("P2", P2), ("P3", P3)):
        expect_number(value, name)
    lengths = [1.0, float(P1), float(P2), float(P3)]
    for name, v in zip(("P1", "P2", "P3"), lengths[1:], strict=True):
        if not (math.isfinite(v) and v > 0.0):
            raise MechanismError(f"{name}: a link length must be positive, got {v}")
    total = sum(lengths)
    longest = max(lengths)
    if longest >= total - longest - TIE:
        raise MechanismError(
            f"MS: [{P1:g} {P2:g} {P3:g}] cannot move (the longest link is not shorter "
            "than the other three together)"
        )
    s = min(lengths)
    grashof = s + longest <= total - s - longest + TIE
    p1, p2, p3 = lengths[1:]
    system4 = tuple(
        k
        for k, (a, b) in enumerate(((1 + p1, p2 + p3), (1 + p2, p1 + p3), (1 + p3, p1 + p2)), 1)
        if abs(a - b) <= TIE
    )
    # a Grashof link turns fully relative to the frame iff it or the frame is shortest
    input_turns = grashof and min(p1, 1.0) <= s + TIE
    output_turns = grashof and min(p3, 1.0) <= s + TIE
    if input_turns and output_turns:
        motion = "double-crank"
    elif input_turns:
        motion = "crank-rocker"
    elif output_turns:
        motion = "rocker-crank"
    else:
        motion = "double-rocker" if grashof else "triple-rocker"

    # input: |A O2| must lie within [|P2 - P3|, P2 + P3]
    c_lo = (1 + p1 * p1 - (p2 + p3) ** 2) / (2 * p1)
    c_hi = (1 + p1 * p1 - (p2 - p3) ** 2) / (2 * p1)
    phi_arcs = _cos_window(c_lo, c_hi)
    full_in = phi_arcs == ((0.0, 2 * math.pi),) or input_turns
    intervals = ((0.0, 2 * math.pi),) if full_in else phi_arcs
    # output: |O1 B| must lie within [|P1 - P2|, P1 + P2]
    d_lo = ((p1 - p2) ** 2 - 1 - p3 * p3) / (2 * p3)
    d_hi = ((p1 + p2) ** 2 - 1 - p3 * p3) / (2 * p3)
    theta_arcs = _cos_window(d_lo, d_hi)
    swing: float | None
    if motion == "double-crank":
        swing = None
    elif output_turns or theta_arcs == ((0.0, 2 * math.pi),):
        swing = 2 * math.pi
    elif len(theta_arcs) == 1:  # one arc across 0 or pi: through the change point
        swing = theta_arcs[0][1] - theta_arcs[0][0]
    else:
        swing = theta_arcs[1][1] - theta_arcs[1][0]

    time_ratio = None
    notes: tuple[str, ...] = ()
    if motion == "crank-rocker":
        th_s, th_f = _acos(d_hi), _acos(d_lo)
        b_s = 1 + p3 * complex(math.cos(th_s), math.sin(th_s))  # input along the coupler
        b_f = 1 + p3 * complex(math.cos(th_f), math.sin(th_f))  # input folded on it
        phi_s = math.atan2(b_s.imag, b_s.real)
        phi_f = math.atan2(b_f.imag, b_f.real) + math.pi if abs(b_f) > TIE else math.nan
        if math.isfinite(phi_f):
            d = (phi_f - phi_s) % (2 * math.pi)
            slow, fast = max(d, 2 * math.pi - d), min(d, 2 * math.pi - d)
            time_ratio = round(slow / fast, 12) if fast > 0 else None
        else:
            # |O1 B| = |P2 - P1| = 0 folded: B sits on O1 for every input angle (MS2)
            notes = (
                "fourbar: time_ratio is null: the folded dead point is not a point (P1 = P2 "
                "and P3 = 1, so B sits on O1 for every input angle: the output dwells along "
                "a fold arc), and the return stroke has no end",
            )
    return FourBar(
        (p1, p2, p3), grashof, motion, system4, full_in, intervals, swing, time_ratio, notes
    )


@dataclass(frozen=True)
class FourBarSingularAngles:
    """Closed-form singular angles of a four-bar (union over its circuits).

    Attributes
    ----------
    input_limits : ``phi`` where coupler and output are in line (the input stops).
    output_extremes : ``theta`` where input and coupler are in line (the output
        reverses).
    change_points : ``phi`` where all four centres are in line (0 or pi).
    """

    input_limits: tuple[float, ...]
    output_extremes: tuple[float, ...]
    change_points: tuple[float, ...]


def fourbar_singular_angles(P1: float, P2: float, P3: float) -> FourBarSingularAngles:
    """Input limits, output extremes and change points of ``[P1 P2 P3]`` in closed form.

    Angles are in [0, 2 pi); a change point is not repeated as a limit or extreme.

    >>> sa = fourbar_singular_angles(0.5, 1.0, 1.5)
    >>> sa.change_points, [round(math.degrees(t), 2) for t in sa.output_extremes]
    ((0.0,), [109.47, 250.53])
    """
    fb = fourbar_theory(P1, P2, P3)
    p1, p2, p3 = fb.MS
    change = []
    if 1 in fb.system4:
        change.append(math.pi)  # O2 O1 A in line, A beyond O1
    if 2 in fb.system4 or 3 in fb.system4:
        change.append(0.0)
    limits: list[float] = []
    for c in (
        (1 + p1 * p1 - (p2 + p3) ** 2) / (2 * p1),
        (1 + p1 * p1 - (p2 - p3) ** 2) / (2 * p1),
    ):
        if -1.0 - TIE <= c <= 1.0 + TIE:
            a = _acos(c)
            limits += [a, (2 * math.pi - a) % (2 * math.pi)]
    extremes: list[float] = []
    for d in (
        ((p1 + p2) ** 2 - 1 - p3 * p3) / (2 * p3),
        ((p1 - p2) ** 2 - 1 - p3 * p3) / (2 * p3),
    ):
        if -1.0 - TIE <= d <= 1.0 + TIE:
            t = _acos(d)
            extremes += [t, (2 * math.pi - t) % (2 * math.pi)]

    def clean(xs: list[float], drop: list[float]) -> tuple[float, ...]:
        out: list[float] = []
        for x in sorted(xs):
            if all(abs(x - y) > 1e-9 for y in out):
                out.append(x)
        return tuple(x for x in out if all(abs(x - y) > 1e-9 for y in drop))

    # at a change point the limit/extreme angles coincide with the collinear state
    limits_clean = clean(limits, change)
    theta_change = [0.0, math.pi] if change else []
    return FourBarSingularAngles(
        limits_clean, clean(extremes, theta_change), tuple(sorted(change))
    )
