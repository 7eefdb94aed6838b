"""The four-bar matrix synthesis (task ``fourbar-ms``): relative lengths from the P2-P3 diagram.

Owns the three steps of the matrix synthesis of hinged four-bars with useful singular
positions [Four-bar clearances]:

1. **the diagram**: at a fixed input length ``P1`` the lines of system (4)
   (``1 + P1 = P2 + P3``, ``1 + P2 = P1 + P3``, ``1 + P3 = P1 + P2``) cut the plane of
   ``(P2, P3)`` into regions of motion (crank-rocker, double-crank, double-rocker), as
   :func:`~mjstruct.singular.fourbar.fourbar_theory` classifies every point;
2. **structural-parametric synthesis**: the singularity matrix ``MS = [P1 P2 P3]`` —
   a reference matrix by name (MS1 ... MS5), given, or solved from a requirement on one
   line of (4) (the motion, the output swing, an exact dwell, the time ratio) — and the
   assembly mode;
3. **the working mechanism**: scaled to the frame length, built at a reference
   configuration in that assembly mode, with its singular positions and, given a
   clearance, their zones, from the singular plug-in
   (:func:`~mjstruct.singular.analysis.singular_analysis` run on the built mechanism).

**The requirement solve.** On line (4.k) ``P3`` is an affine function of ``(P1, P2)``,
so two conditions fix the point.  ``P1`` given, ``P2`` given and ``dwell`` (``P2 = P1``,
hence ``P3 = 1`` on (4.1) and (4.2): B can sit on O1) restrict ``(P1, P2)`` to a line
segment; ``swing_deg`` and ``time_ratio`` are equations ``fourbar_theory(...) = target``.
With one condition only, ``P1`` is the diagram's 0.5.  Two restrictions give the point;
a restriction and an equation give a 1-D root find along the segment (sampled between
the points where two of the four lengths tie — between them the motion is constant and
the swing and time ratio are monotone — then Brent's method); ``swing_deg`` and
``time_ratio`` together give a nested 2-D root find (the swing solved for ``P2`` at each
``P1``, the time ratio for ``P1``).  Closed forms check it in the tests: a crank-rocker
on (4.2) swings ``s`` when ``P2 = (1 - P1)(1 - c) / (2 P1 - 1 + c)``, ``c = cos(s/2)``
(MS4 at ``s = 2 arccos(1/3)``), a dwell crank-rocker when ``P1 = sin(s/4)`` (MS2 at 120°).

References
----------
.. [1] Singular positions and synthesis of hinged multi-joint mechanisms with
   clearances in their revolute pairs (in Russian; eLibrary document code EDN PBGDPR;
   authors, exact title, journal and year not given in the available copy).
   [Four-bar clearances] in docs/references.md.

Examples
--------
>>> r = synthesize_fourbar_ms({"task": "fourbar-ms", "change_point": "4.2",
...                            "swing_deg": 141.0576})
>>> [round(p, 3) for p in r.details["MS"]], r.details["motion"], r.details["system4"]
([0.5, 1.0, 1.5], 'crank-rocker', [2])
>>> r = synthesize_fourbar_ms({"ms": "MS3", "frame_length": 0.2})
>>> round(r.details["swing_deg"], 6), r.details["time_ratio"]
(240.0, 2.0)
"""

from __future__ import annotations

import cmath
import dataclasses
import itertools
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mjstruct.design.result import SYNTHESIS_KEY, DesignResult
from mjstruct.errors import MechanismError, NumericalError, expect_number
from mjstruct.mechanism import Joint, Mechanism, Point
from mjstruct.output_numbers import json_number
from mjstruct.singular.analysis import singular_analysis
from mjstruct.singular.classification import fourbar_classes
from mjstruct.singular.fourbar import REFERENCE_MATRICES, TIE, fourbar_theory

TASK = "fourbar-ms"
#: the lines of system (4) by the name a task gives them
LINES = {"4.1": 1, "4.2": 2, "4.3": 3}
#: motions a task may require (a change-point four-bar is Grashof)
REQUIRED_MOTIONS = ("crank-rocker", "double-crank", "double-rocker")
#: the input length of the seed's diagram (the reference points M1-M4), used when a
#: requirement leaves P1 free and gives one condition only
DIAGRAM_P1 = 0.5
#: relative lengths are sought up to this (beyond, the swing's cosines lose digits)
MAX_RELATIVE = 1e4
#: the reference input angle of the built mechanism unless the task gives one (deg)
DEFAULT_REFERENCE_DEG = 60.0
#: samples of a target along one segment of constant motion before Brent's method
SEGMENT_SAMPLES = 24
#: samples closing in on each end of a segment (fractions of its length)
END_OFFSETS = (1e-8, 1e-6, 1e-4, 1e-2)
#: samples of P1 in the nested (swing and time ratio) solve
OUTER_SAMPLES = 40
#: a solved requirement must hold to this (swing in rad, time ratio) or it is trouble
SOLVED = 1e-9
#: a reference configuration whose coupler and output are closer than this to a line
#: (sine of the transmission angle) is a singular position: refused
REFERENCE_MARGIN = 1e-6

KEYS = (
    "task",
    "name",
    "description",
    "ms",
    "frame_length",
    "motion",
    "change_point",
    "swing_deg",
    "dwell",
    "time_ratio",
    "P1",
    "P2",
    "assembly",
    "reference_deg",
    "coupler_point",
    "clearance",
)
REQUIREMENT_KEYS = ("change_point", "swing_deg", "dwell", "time_ratio", "P1", "P2")


def line_P3(line: int, P1: float, P2: float) -> float:
    """``P3`` on line (4.``line``) of system (4) at ``(P1, P2)``.

    >>> line_P3(2, 0.5, 1.0)      # MS4 lies on (4.2): 1 + P2 = P1 + P3
    1.5
    """
    if line == 1:
        return 1.0 + P1 - P2
    if line == 2:
        return 1.0 + P2 - P1
    return P1 + P2 - 1.0


@dataclass(frozen=True)
class Requirement:
    """What a ``fourbar-ms`` task asks of the four-bar when it gives no ``ms``.

    Attributes
    ----------
    line : the line of system (4) (1, 2 or 3) the result lies on (a change point).
    motion : ``crank-rocker``, ``double-crank`` or ``double-rocker``.
    swing : output swing (rad; through the change point where the output rocks).
    time_ratio : crank angle of the slower stroke over the faster (crank-rocker).
    dwell : an exact dwell of the output for half a turn (B on O1: P2 = P1, P3 = 1).
    P1, P2 : relative lengths fixed by the task.
    """

    line: int
    motion: str = "crank-rocker"
    swing: float | None = None
    time_ratio: float | None = None
    dwell: bool = False
    P1: float | None = None
    P2: float | None = None


@dataclass(frozen=True)
class MSSolution:
    """The relative lengths a requirement gives, and how they were found.

    Attributes
    ----------
    MS : (P1, P2, P3).
    method : ``"point"`` (two restrictions fix it), ``"root find"`` (1-D, Brent's
        method along a segment of the diagram) or ``"nested root find"`` (2-D).
    free : the lengths solved for.
    evaluations : calls of :func:`~mjstruct.singular.fourbar.fourbar_theory`.
    others : further solutions of the same requirement (the chosen one has the
        smallest ratio of the longest to the shortest link).
    defaults : conditions the task did not give and the solve assumed
        (``"P1 = 0.5"``).
    """

    MS: tuple[float, float, float]
    method: str
    free: tuple[str, ...]
    evaluations: int
    others: tuple[tuple[float, float, float], ...] = ()
    defaults: tuple[str, ...] = ()


# ------------------------------------------------------------------ the requirement solve


class _Counter:
    """fourbar_theory with a call count and the requirement's motion and line."""

    def __init__(self, line: int, motion: str) -> None:
        self.line, self.motion, self.calls = line, motion, 0

    def theory(self, P1: float, P2: float) -> Any:
        """The four-bar at (P1, P2) on the line, or None where it is not of the motion."""
        self.calls += 1
        P3 = line_P3(self.line, P1, P2)
        if min(P1, P2, P3) <= 0.0:
            return None
        try:
            fb = fourbar_theory(P1, P2, P3)
        except MechanismError:
            return None
        if fb.motion != self.motion or self.line not in fb.system4:
            return None
        return fb


@dataclass(frozen=True)
class _Path:
    """A segment of the diagram: (P1, P2) = point(v) for v in (lo, hi)."""

    what: str  # the free length, for messages ("P2", "P1")
    point: Callable[[float], tuple[float, float]]
    lo: float
    hi: float
    breaks: tuple[float, ...]


def _path(line: int, fixed: str, value: float) -> _Path:
    """The segment with P1 fixed, P2 fixed or P2 = P1 (``fixed`` = "P1", "P2", "dwell")."""

    def point(v: float) -> tuple[float, float]:
        if fixed == "P1":
            return value, v
        if fixed == "P2":
            return v, value
        return v, v

    def lengths(v: float) -> tuple[float, float, float, float]:
        p1, p2 = point(v)
        return 1.0, p1, p2, line_P3(line, p1, p2)

    # every length is affine in v: where it is positive and where two of them tie
    lo, hi = 0.0, MAX_RELATIVE
    breaks: list[float] = []
    L0, L1 = lengths(0.0), lengths(1.0)
    slopes = [b - a for a, b in zip(L0, L1, strict=True)]
    for a, s in zip(L0, slopes, strict=True):
        if s > 0:
            lo = max(lo, -a / s)
        elif s < 0:
            hi = min(hi, -a / s)
    for (a, s), (b, t) in itertools.combinations(zip(L0, slopes, strict=True), 2):
        if s != t:
            breaks.append((b - a) / (s - t))
    return _Path(
        "P2" if fixed == "P1" else "P1",
        point,
        lo,
        hi,
        tuple(sorted(v for v in breaks if lo < v < hi)),
    )


def _grid(a: float, b: float) -> list[float]:
    """Samples of [a, b]: its ends, points closing in on them (a reachable range is
    seen to about the square root of the closest offset), and an interior grid
    (geometric where the segment spans more than a factor of 4)."""
    if a > 0 and b / a > 4:
        inner = [float(a * (b / a) ** s) for s in np.linspace(0.0, 1.0, SEGMENT_SAMPLES)[1:-1]]
    else:
        inner = [float(a + (b - a) * s) for s in np.linspace(0.0, 1.0, SEGMENT_SAMPLES)[1:-1]]
    near = [(b - a) * e for e in END_OFFSETS]
    return sorted({a, b, *inner, *(a + e for e in near), *(b - e for e in near)})


def _samples(path: _Path) -> list[float]:
    """Samples of a path, segment by segment (between the points where lengths tie)."""
    vs: list[float] = []
    for a, b in itertools.pairwise([path.lo, *path.breaks, path.hi]):
        if b > a:
            vs += _grid(a, b)
    return vs


def _roots(fun: Callable[[float], float], vs: Sequence[float]) -> tuple[list[float], list[float]]:
    """Roots of ``fun`` (Brent's method between sign changes of its samples at ``vs``)
    and the finite values sampled (the reachable range)."""
    from scipy.optimize import brentq

    fs = [fun(v) for v in vs]
    roots: list[float] = []
    for (v1, f1), (v2, f2) in itertools.pairwise(zip(vs, fs, strict=True)):
        if not (math.isfinite(f1) and math.isfinite(f2)):
            continue
        if f1 == 0.0:
            roots.append(v1)
        elif f1 * f2 < 0:
            r = float(brentq(fun, v1, v2, xtol=1e-15, rtol=1e-15, maxiter=200))
            if math.isfinite(fun(r)):
                roots.append(r)
    if fs and math.isfinite(fs[-1]) and fs[-1] == 0.0:
        roots.append(vs[-1])
    unique: list[float] = []
    for r in sorted(roots):
        if not unique or r - unique[-1] > 1e-9 * max(1.0, abs(r)):
            unique.append(r)
    return unique, [f for f in fs if math.isfinite(f)]


def _target(
    c: _Counter, what: str, value: float, seen: list[float] | None = None
) -> Callable[[float, float], float]:
    """``theory(P1, P2).what - value`` (NaN where the four-bar is not of the motion);
    the values themselves are added to ``seen`` (the reachable range, which the
    residuals lose beside a large ``value``)."""

    def f(P1: float, P2: float) -> float:
        fb = c.theory(P1, P2)
        got = None if fb is None else getattr(fb, what)
        if got is None:
            return math.nan
        if seen is not None and math.isfinite(got):
            seen.append(float(got))
        return float(got) - value

    return f


def _beyond(what: str, value: float, seen: Sequence[float]) -> str:
    """The reachable range in words: about lo to hi, saying so where ``value`` is one of
    its ends, which the four-bars only approach (a degenerate four-bar reaches it)."""
    lo, hi = min(seen), max(seen)
    words = f"those there give about {_show(what, lo)} to {_show(what, hi)}"
    close = 1e-3 * max(1.0, abs(value))  # the samples come within sqrt(1e-8) of an end
    if lo - close <= value <= hi + close:  # within the range shown, yet never met
        words += f"; {_show(what, value)} is an end of that range, approached but not reached"
    return words


def _spread(lengths: tuple[float, float, float]) -> float:
    """Longest over shortest of the four links (the frame is 1)."""
    all4 = (1.0, *lengths)
    return max(all4) / min(all4)


def _field(what: str) -> str:
    return "swing_deg" if what == "swing" else what


def _show(what: str, v: float, digits: int = 4) -> str:
    return f"{math.degrees(v):.{digits}g} deg" if what == "swing" else f"{v:.{digits}g}"


def _where(req: Requirement, fixed: Mapping[str, float]) -> str:
    parts = [f"{k} = {v:g}" for k, v in fixed.items()]
    if req.dwell:
        parts.append("an exact dwell")
    return f"on (4.{req.line})" + (" with " + " and ".join(parts) if parts else "")


def _solve_1d(
    req: Requirement,
    c: _Counter,
    path: _Path,
    what: str,
    value: float,
    fixed: Mapping[str, float],
) -> list[tuple[float, float, float]]:
    """The points of the path where ``what`` (swing or time_ratio) equals ``value``."""
    reached: list[float] = []
    f = _target(c, what, value, reached)
    roots, seen = _roots(lambda v: f(*path.point(v)), _samples(path))
    if not roots:
        where = _where(req, fixed)
        if not seen:
            raise MechanismError(
                f"motion: no {req.motion} {where} has a {what.replace('_', ' ')} "
                "(change the motion or the fixed lengths)"
            )
        raise MechanismError(
            f"{_field(what)}: no {req.motion} {where} has {what.replace('_', ' ')} "
            f"{_show(what, value, 6)} ({_beyond(what, value, reached)})"
        )
    out = []
    for r in roots:
        p1, p2 = path.point(r)
        out.append((p1, p2, line_P3(req.line, p1, p2)))
    return out


def solve_requirement(req: Requirement) -> MSSolution:
    """The singularity matrix ``[P1 P2 P3]`` meeting a requirement on a line of (4).

    Two conditions from ``P1``, ``P2``, ``dwell``, ``swing`` and ``time_ratio`` fix the
    point (``P1`` is the diagram's 0.5 when only one is given).

    Raises
    ------
    MechanismError
        too few or too many conditions, or a requirement no four-bar of the motion on
        that line meets (the message names the field and the reachable range).

    Examples
    --------
    >>> s = solve_requirement(Requirement(line=3, swing=math.radians(240), time_ratio=2.0))
    >>> [round(p, 9) for p in s.MS], s.method
    ([0.5, 1.5, 1.0], 'nested root find')
    >>> solve_requirement(Requirement(line=2, dwell=True)).MS    # MS2: exact dwell
    (0.5, 0.5, 1.0)
    """
    if req.motion not in REQUIRED_MOTIONS:
        raise MechanismError(
            f"motion: expected one of {', '.join(REQUIRED_MOTIONS)}, got {req.motion!r}"
        )
    if req.dwell and req.line == 3:
        raise MechanismError(
            "dwell: an exact dwell needs B on O1 (P2 = P1, P3 = 1), which lies on (4.1) "
            'and (4.2); on (4.3) only the hinged square [1 1 1] has it (ms: "MS5")'
        )
    if req.dwell and req.time_ratio is not None:
        raise MechanismError(
            "time_ratio: a dwell four-bar has none (its folded dead point is the whole "
            "dwell, so the return stroke has no end)"
        )
    given = [k for k in ("P1", "P2", "dwell") if getattr(req, k) not in (None, False)]
    targets = [k for k in ("swing", "time_ratio") if getattr(req, k) is not None]
    defaults: tuple[str, ...] = ()
    p1 = req.P1
    if len(given) + len(targets) < 2 and p1 is None:
        p1, defaults = DIAGRAM_P1, (f"P1 = {DIAGRAM_P1:g}",)
        given = ["P1", *given]
    conditions = given + targets
    if len(conditions) < 2:
        raise MechanismError(
            "swing_deg: missing (a requirement needs, besides change_point, one of "
            "swing_deg, time_ratio, dwell or P2 when P1 is given)"
        )
    if len(conditions) > 2:
        extra = _field(conditions[2])
        raise MechanismError(
            f"{extra}: one condition too many ({_field(conditions[0])} and "
            f"{_field(conditions[1])} already fix the point on (4.{req.line}))"
        )
    c = _Counter(req.line, req.motion)
    values = {"P1": p1, "P2": req.P2}
    if len(given) == 2:  # the point itself
        a = values["P1"] if "P1" in given else values["P2"]
        b = values["P2"] if "P2" in given else a
        assert a is not None and b is not None
        return _checked(req, c, [(a, b, line_P3(req.line, a, b))], "point", (), defaults)
    if len(given) == 1:
        key = given[0]
        val = values.get(key) or 0.0
        path = _path(req.line, key, val)
        what = targets[0]
        value = req.swing if what == "swing" else req.time_ratio
        assert value is not None
        fixed = {} if key == "dwell" else {key: val}
        sols = _solve_1d(req, c, path, what, value, fixed)
        return _checked(req, c, sols, "root find", (path.what,), defaults)
    # swing and time ratio: the swing solved for P2 at each P1, the time ratio for P1
    assert req.swing is not None and req.time_ratio is not None
    swing, ratio = req.swing, req.time_ratio
    p1_hi = 1.0 if req.motion == "crank-rocker" else MAX_RELATIVE
    inner_cache: dict[float, tuple[float, float, float] | None] = {}

    def inner(P1: float) -> tuple[float, float, float] | None:
        if P1 not in inner_cache:
            try:
                sols = _solve_1d(req, c, _path(req.line, "P1", P1), "swing", swing, {})
            except MechanismError:
                inner_cache[P1] = None
            else:
                inner_cache[P1] = min(sols, key=_spread)
        return inner_cache[P1]

    ratios: list[float] = []

    def outer(P1: float) -> float:
        s = inner(P1)
        if s is None:
            return math.nan
        return _target(c, "time_ratio", ratio, ratios)(s[0], s[1])

    p1_samples = [float(v) for v in np.linspace(0.0, p1_hi, OUTER_SAMPLES + 1)[1:-1]]
    roots, seen = _roots(outer, p1_samples)
    if not roots:
        if not seen:
            raise MechanismError(
                f"swing_deg: no {req.motion} on (4.{req.line}) swings "
                f"{math.degrees(swing):.6g} deg with a time ratio"
            )
        raise MechanismError(
            f"time_ratio: no {req.motion} on (4.{req.line}) swinging "
            f"{math.degrees(swing):.6g} deg has time ratio {ratio:.6g} "
            f"({_beyond('time_ratio', ratio, ratios)})"
        )
    sols = [s for r in roots if (s := inner(r)) is not None]
    return _checked(req, c, sols, "nested root find", ("P1", "P2"), defaults)


def _checked(
    req: Requirement,
    c: _Counter,
    sols: Sequence[tuple[float, float, float]],
    method: str,
    free: tuple[str, ...],
    defaults: tuple[str, ...],
) -> MSSolution:
    """The best-proportioned solution, checked against every condition."""
    ordered = sorted(sols, key=_spread)
    best = ordered[0]
    fb = c.theory(best[0], best[1])
    if fb is None:
        p = " ".join(f"{x:g}" for x in best)
        raise MechanismError(
            f"motion: [{p}] on (4.{req.line}) is not a {req.motion} (it is a {_motion_of(best)})"
        )
    for what, want in (("swing", req.swing), ("time_ratio", req.time_ratio)):
        got = getattr(fb, what)
        if want is not None and (got is None or abs(got - want) > SOLVED * max(1.0, want)):
            raise NumericalError(
                f"fourbar-ms: the solve missed {_field(what)} ({got} instead of {want})"
            )
    return MSSolution(best, method, free, c.calls, tuple(ordered[1:]), defaults)


def _motion_of(ms: tuple[float, float, float]) -> str:
    try:
        return fourbar_theory(*ms).motion
    except MechanismError:
        return "four-bar that cannot move"


# ------------------------------------------------------------------ the mechanism


def fourbar_mechanism(
    ms: Sequence[float],
    frame_length: float = 1.0,
    reference_deg: float | None = None,
    assembly: int = 1,
    coupler_point: Sequence[float] | None = None,
    name: str = TASK,
) -> Mechanism:
    """The four-bar ``[P1 P2 P3]`` with frame ``frame_length`` at a reference configuration.

    Joints O1 (frame 0, input 1) at the origin, A (1, 2), B (2, 3), O2 (3, 0) at
    ``(frame_length, 0)``; driver O1.  The input stands at ``reference_deg`` from the
    frame line (default 60°, or the middle of the input's range where 60° does not
    assemble); ``assembly`` +1 puts B on the left of the line A -> O2, -1 on its right.
    ``coupler_point`` ``[u, v]`` adds point P on the coupler, ``u`` along A -> B and
    ``v`` to its left of A, both lengths in the unit of ``frame_length`` (not
    fractions of the coupler or the frame).

    >>> m = fourbar_mechanism((0.5, 1.0, 1.5))          # the shipped MS4 example
    >>> [round(c, 6) for c in m.joint("B").at]
    [0.478714, 1.406506]
    """
    P1, P2, P3 = (float(p) for p in ms)
    fb = fourbar_theory(P1, P2, P3)
    if reference_deg is None:
        phi = math.radians(DEFAULT_REFERENCE_DEG)
        if _reference_sine(P1, P2, P3, phi) <= REFERENCE_MARGIN:
            a, b = max(fb.input_intervals, key=lambda ab: ab[1] - ab[0])
            phi = 0.5 * (a + b)
    else:
        phi = math.radians(reference_deg)
        if _reference_sine(P1, P2, P3, phi) <= REFERENCE_MARGIN:
            raise MechanismError(
                f"reference_deg: the four-bar [{P1:g} {P2:g} {P3:g}] does not assemble at "
                f"{reference_deg:g} deg, or its coupler and output are in line there"
            )
    l0 = float(frame_length)
    A = l0 * P1 * cmath.exp(1j * phi)
    O2 = complex(l0, 0.0)
    d = abs(O2 - A)
    r2, r3 = l0 * P2, l0 * P3
    along = (r2 * r2 - r3 * r3 + d * d) / (2 * d)
    h = math.sqrt(max(r2 * r2 - along * along, 0.0))
    B = A + (along + 1j * assembly * h) * (O2 - A) / d
    joints = (
        Joint("O1", ("0", "1"), "R", (0.0, 0.0)),
        Joint("A", ("1", "2"), "R", (A.real, A.imag)),
        Joint("B", ("2", "3"), "R", (B.real, B.imag)),
        Joint("O2", ("3", "0"), "R", (l0, 0.0)),
    )
    points: tuple[Point, ...] = ()
    if coupler_point is not None:
        u, v = (float(x) for x in coupler_point)
        P = A + complex(u, v) * (B - A) / abs(B - A)
        points = (Point("P", "2", (P.real, P.imag)),)
    extra = {
        "description": (
            f"MS = [{P1:.9g} {P2:.9g} {P3:.9g}]: {fb.motion}, system (4): "
            + (", ".join(f"(4.{k})" for k in fb.system4) or "none")
        ),
        SYNTHESIS_KEY: {"task": TASK, "MS": [P1, P2, P3], "assembly": assembly},
    }
    return Mechanism(
        links=("0", "1", "2", "3"),
        joints=joints,
        frame="0",
        drivers=("O1",),
        name=name,
        points=points,
        extra=extra,
    )


def _input_angle_deg(m: Mechanism) -> float:
    """The input's angle at the reference configuration (deg, from the frame line)."""
    at = m.joint("A").at
    assert at is not None
    return math.degrees(math.atan2(at[1], at[0]))


def _reference_sine(P1: float, P2: float, P3: float, phi: float) -> float:
    """|sin| of the transmission angle at input ``phi`` (<= 0 where it does not close)."""
    d2 = 1 + P1 * P1 - 2 * P1 * math.cos(phi)
    cos_mu = (P2 * P2 + P3 * P3 - d2) / (2 * P2 * P3)
    if abs(cos_mu) >= 1.0:
        return 0.0
    return math.sqrt(1.0 - cos_mu * cos_mu)


# ------------------------------------------------------------------ the task


def _number(task: Mapping[str, Any], key: str, *, positive: bool = False) -> float | None:
    if key not in task:
        return None
    v = expect_number(task[key], key)
    if positive and not v > 0:
        raise MechanismError(f"{key}: must be > 0, got {v:g}")
    return v


def _parse_ms(value: Any) -> tuple[tuple[float, float, float], str | None]:
    if isinstance(value, str):
        name = value.strip().upper()
        if name not in REFERENCE_MATRICES:
            raise MechanismError(
                f"ms: unknown matrix {value!r} (expected one of "
                f"{', '.join(REFERENCE_MATRICES)} or [P1, P2, P3])"
            )
        return REFERENCE_MATRICES[name], name
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or len(value) != 3:
        raise MechanismError(f"ms: expected a name (MS1 ... MS5) or [P1, P2, P3], got {value!r}")
    ms = tuple(expect_number(v, f"ms[{k}]") for k, v in enumerate(value))
    for k, v in enumerate(ms):
        if not v > 0:
            raise MechanismError(f"ms[{k}]: a relative length must be > 0, got {v:g}")
    return (ms[0], ms[1], ms[2]), None


def _parse_requirement(task: Mapping[str, Any], motion: str | None) -> Requirement:
    if "change_point" not in task:
        raise MechanismError(
            "change_point: missing (give ms, or a requirement: change_point with "
            "swing_deg, time_ratio, dwell, P1 or P2)"
        )
    raw = task["change_point"]
    key = raw if isinstance(raw, str) else (f"{raw:g}" if isinstance(raw, float) else None)
    key = None if key is None else key.strip().strip("()")
    if key not in LINES:
        raise MechanismError(
            f"change_point: expected one of {', '.join(LINES)} (a line of system (4)), got {raw!r}"
        )
    swing = _number(task, "swing_deg", positive=True)
    if swing is not None and swing > 360.0:
        raise MechanismError(f"swing_deg: an output swings at most 360 deg, got {swing:g}")
    ratio = _number(task, "time_ratio", positive=True)
    if ratio is not None and ratio < 1.0:
        raise MechanismError(
            f"time_ratio: the slower stroke over the faster is >= 1, got {ratio:g}"
        )
    dwell = task.get("dwell", False)
    if not isinstance(dwell, bool):
        raise MechanismError(f"dwell: expected true or false, got {dwell!r}")
    return Requirement(
        line=LINES[key],
        motion=motion or "crank-rocker",
        swing=None if swing is None else math.radians(swing),
        time_ratio=ratio,
        dwell=dwell,
        P1=_number(task, "P1", positive=True),
        P2=_number(task, "P2", positive=True),
    )


#: the kinematics' mechanism sizes (docs/contract.md section 4) and how far from its
#: joints a point may lie, in sizes
SIZE_RANGE = (1e-50, 1e50)
POINT_REACH = 1e8


def _check_size(
    frame_length: float, ms: tuple[float, float, float], coupler: tuple[float, float] | None
) -> None:
    """The built four-bar within the sizes the kinematics analyses (frame_length 1e300
    gave NaN joint centres), its coupler point within reach."""
    size = frame_length * max(1.0, *ms)
    lo, hi = SIZE_RANGE
    if not lo <= size <= hi:
        raise MechanismError(
            f"frame_length: {frame_length:g} gives a four-bar of size {size:.3g}, outside "
            f"the sizes analysed ({lo:g} to {hi:g} in the file's unit)"
        )
    if coupler is not None and math.hypot(*coupler) > POINT_REACH * size:
        raise MechanismError(
            f"coupler_point: {list(coupler)} lies more than {POINT_REACH:g} sizes of the "
            "four-bar from its coupler"
        )


def _reference_name(ms: tuple[float, float, float]) -> str | None:
    for name, ref in REFERENCE_MATRICES.items():
        if all(abs(a - b) <= TIE for a, b in zip(ms, ref, strict=True)):
            return name
    return None


def _any_line(task: Mapping[str, Any], seed: int | None) -> DesignResult:
    """``change_point: true``: every line of system (4) tried; the one that meets the
    other requirements best (least objective, then the lower line) is the design."""
    found: list[DesignResult] = []
    why: list[str] = []
    for line in LINES:
        try:
            found.append(synthesize_fourbar_ms({**task, "change_point": line}, seed=seed))
        except MechanismError as exc:
            why.append(f"{line}: {str(exc).split(': ', 1)[-1]}")
    if not found:
        raise MechanismError(
            "change_point: no line of system (4) meets the other requirements ("
            + "; ".join(why)
            + ")"
        )
    best = min(found, key=lambda r: r.objective)  # LINES in order: the lower line on ties
    details = dict(best.details)
    details["lines_tried"] = {
        str(r.details["requirement"]["change_point"]): json_number(r.objective) for r in found
    }
    return dataclasses.replace(best, details=details)


def synthesize_fourbar_ms(task: Mapping[str, Any], *, seed: int | None = None) -> DesignResult:
    """The matrix synthesis of a hinged four-bar: the ``fourbar-ms`` task.

    Parameters
    ----------
    task : the task's keys (``docs/contract.md``, "Synthesis"): ``ms`` (``"MS1"`` ...
        ``"MS5"`` or ``[P1, P2, P3]``), or a requirement — ``change_point`` (``"4.1"``,
        ``"4.2"``, ``"4.3"``, or ``true``: any line that can meet the others) with two
        of ``swing_deg``, ``time_ratio``, ``dwell``, ``P1``, ``P2`` (``P1`` = 0.5 when
        only one is given) and ``motion``
        (``crank-rocker`` by default) —; ``frame_length`` (1), ``assembly`` (+1 or -1),
        ``reference_deg``, ``coupler_point`` ``[u, v]``, ``clearance``, ``name``.
    seed : recorded in the result; the synthesis is deterministic and draws no
        random numbers.

    Returns
    -------
    DesignResult
        the mechanism (driver O1, frame 0, output link 3) and in ``details`` the
        matrix, motion, Grashof, lines of (4), swing, time ratio, how the matrix was
        found, and the singular analysis of the built mechanism (its positions, and
        their zones with a clearance).  ``errors`` are the requirement's residuals
        (swing in degrees, then time ratio) of the solved matrix.

    Raises
    ------
    MechanismError
        a bad key or value, or a requirement no four-bar meets; the message names the
        field.
    """
    t0 = time.perf_counter()
    if not isinstance(task, Mapping):
        raise MechanismError(f"task: expected an object of task keys, got {type(task).__name__}")
    for key in task:
        if key not in KEYS:
            raise MechanismError(f"{key}: not a key of a {TASK} task (known: {', '.join(KEYS)})")
    if "task" in task and task["task"] != TASK:
        raise MechanismError(f"task: expected {TASK!r}, got {task['task']!r}")
    if task.get("change_point") is True and "ms" not in task:
        return _any_line(task, seed)
    motion = task.get("motion")
    if motion is not None and motion not in REQUIRED_MOTIONS:
        raise MechanismError(
            f"motion: expected one of {', '.join(REQUIRED_MOTIONS)}, got {motion!r}"
        )
    frame_length = _number(task, "frame_length", positive=True) or 1.0
    reference_deg = _number(task, "reference_deg")
    clearance = _number(task, "clearance")
    if clearance is not None and clearance < 0:
        raise MechanismError(f"clearance: must be >= 0, got {clearance:g}")
    assembly = task.get("assembly", 1)
    if isinstance(assembly, bool) or assembly not in (1, -1):
        raise MechanismError(f"assembly: expected 1 or -1, got {assembly!r}")
    cp = task.get("coupler_point")
    coupler: tuple[float, float] | None = None
    if cp is not None:
        if isinstance(cp, (str, bytes)) or not isinstance(cp, Sequence) or len(cp) != 2:
            raise MechanismError(f"coupler_point: expected [u, v], got {cp!r}")
        coupler = (
            expect_number(cp[0], "coupler_point[0]"),
            expect_number(cp[1], "coupler_point[1]"),
        )
    name = task.get("name")
    if name is not None and not isinstance(name, str):
        raise MechanismError(f"name: expected a string, got {name!r}")
    description = task.get("description")
    if description is not None and not isinstance(description, str):
        raise MechanismError(f"description: expected a string, got {description!r}")

    requirement: Requirement | None = None
    if "ms" in task:
        for key in REQUIREMENT_KEYS:
            if key in task:
                raise MechanismError(f"{key}: not used with ms (give either ms or a requirement)")
        ms, ref_name = _parse_ms(task["ms"])
        try:
            fourbar_theory(*ms)
        except MechanismError as e:
            raise MechanismError(f"ms: {str(e).split(': ', 1)[-1]}") from None
        solution = MSSolution(ms, "given", (), 1)
    else:
        requirement = _parse_requirement(task, motion)
        solution = solve_requirement(requirement)
        ms, ref_name = solution.MS, None
    ref_name = ref_name or _reference_name(ms)
    fb = fourbar_theory(*ms)
    if motion is not None and fb.motion != motion:
        raise MechanismError(f"motion: [{' '.join(f'{p:g}' for p in ms)}] is a {fb.motion}")

    _check_size(frame_length, ms, coupler)
    label = name or (f"fourbar-{ref_name.lower()}" if ref_name else TASK)
    mech = fourbar_mechanism(ms, frame_length, reference_deg, assembly, coupler, label)
    if description is not None:  # the task's own words replace the generated line
        mech = dataclasses.replace(mech, extra={**mech.extra, "description": description})
    from mjstruct.design.verify import fourbar_ms_verdict

    broken = fourbar_ms_verdict(
        mech,
        fb.motion,
        fb.system4,
        None if requirement is None else requirement.line,
        None if requirement is None else requirement.swing,
        None if requirement is None else requirement.time_ratio,
    )
    if broken:
        raise NumericalError(f"fourbar-ms: the final verdict refused the four-bar ({broken[0]})")
    if clearance is not None:  # kept in the file: `mjstruct singular FILE` reuses it
        entry = {**mech.extra[SYNTHESIS_KEY], "clearance": clearance}
        mech = dataclasses.replace(mech, extra={**mech.extra, SYNTHESIS_KEY: entry})
    analysis = singular_analysis(mech, clearance=clearance)
    built = fb  # the matrix's own numbers (the file's coordinates round them)

    errors: list[float] = []
    error_of: list[str] = []
    if requirement is not None and requirement.swing is not None:
        errors.append(abs(math.degrees((built.swing or 0.0) - requirement.swing)))
        error_of.append("swing_deg")
    if requirement is not None and requirement.time_ratio is not None:
        errors.append(abs((built.time_ratio or 0.0) - requirement.time_ratio))
        error_of.append("time_ratio")
    objective = math.sqrt(sum(e * e for e in errors) / len(errors)) if errors else 0.0
    seconds = time.perf_counter() - t0
    details: dict[str, Any] = {
        "MS": [json_number(p) for p in built.MS],
        "reference_matrix": ref_name,
        "lengths": {
            "frame": frame_length,
            "input": frame_length * ms[0],
            "coupler": frame_length * ms[1],
            "output": frame_length * ms[2],
        },
        "motion": built.motion,
        "grashof": built.grashof,
        "system4": list(built.system4),
        "swing": json_number(built.swing),
        "swing_deg": None if built.swing is None else json_number(math.degrees(built.swing)),
        "time_ratio": json_number(built.time_ratio),
        "assembly": assembly,
        "reference_deg": json_number(_input_angle_deg(mech)),
        "solve": {
            "method": solution.method,
            "free": list(solution.free),
            "evaluations": solution.evaluations,
            "defaults": list(solution.defaults),
            "other_solutions": [[json_number(p) for p in s] for s in solution.others],
        },
        "errors_of": error_of,
        "singular": analysis.to_dict(),
        # the closed form's classes of [Four-bar clearances]; the traced ones are in
        # "singular" (each position's and fold arc's "classification")
        "classes": list(fourbar_classes(*ms)),
    }
    if requirement is not None:
        details["requirement"] = {
            "change_point": f"4.{requirement.line}",
            "motion": requirement.motion,
            "swing_deg": None
            if requirement.swing is None
            else json_number(math.degrees(requirement.swing)),
            "time_ratio": json_number(requirement.time_ratio),
            "dwell": requirement.dwell,
            "P1": json_number(requirement.P1),
            "P2": json_number(requirement.P2),
        }
    return DesignResult(
        mechanism=mech,
        task=TASK,
        objective=objective,
        feasible=True,
        errors=tuple(errors),
        evaluations=solution.evaluations,
        seconds=seconds,
        seed=seed,
        history=((solution.evaluations, seconds, objective),),
        details=details,
    )
