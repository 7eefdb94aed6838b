"""The ``targets`` layer: a synthesised mechanism drawn with the task it was made for.

Owns reading the task a synthesised mechanism file keeps under its ``synthesis`` key
(:data:`mjstruct.design.result.SYNTHESIS_KEY`: ``task``, ``point``, ``targets``,
``timing``) and drawing it over the scheme: for a ``path`` task the target points as
crosses numbered in their order (the point's traced path comes from the ``paths``
layer), for a ``motion`` task each target pose as a dot with a short arrow along its
angle, for a ``function`` task nothing on the scheme (its targets are driver values
and output angles: a chart's business), only the line in the footer that says what
the targets are.  The layer is shown with ``paths`` whenever the file has targets.

Examples
--------
>>> read_targets({"task": "path", "point": "P", "targets": [[0, 1], [1, 2]]}).points
array([0.+1.j, 1.+2.j])
>>> read_targets({"task": "path", "targets": [[0, "x"]]})
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: synthesis.targets: target 1 is not a pair of finite numbers
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.design.result import SYNTHESIS_KEY
from mjstruct.errors import MechanismError
from mjstruct.typing import ComplexArray, FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from mjstruct.mechanism import Mechanism

#: targets' colour: outside the Assur groups' palette and the vectors' colours
TARGET_COLOUR = "#8b6508"
#: how many values a target of each task kind has
SIZES = {"path": 2, "function": 2, "motion": 3}


@dataclass(frozen=True)
class SynthesisTargets:
    """The task of a synthesised mechanism, as its drawing needs it.

    Attributes
    ----------
    task : ``"path"``, ``"function"`` or ``"motion"``.
    point : the point of interest of a path task (None otherwise).
    points : target positions (path, motion), else empty.
    angles : target angles in radians (motion: the pose's; function: the output's).
    values : the driver values of a function task's targets, else empty.
    timing : the driver values at which the design meets the targets, when the file
        gives them.
    timed : whether the task prescribed those driver values (``False``: untimed
        targets, met in their order over a cycle; None: a file that does not say).
    angle_offset : a function task's common offset of the target angles (radians),
        found by the search (``angle_offset`` tasks), else 0.
    """

    task: str
    point: str | None
    points: ComplexArray
    angles: FloatArray
    values: FloatArray
    timing: tuple[float, ...] | None
    timed: bool | None = None
    angle_offset: float = 0.0

    def describe(self) -> str:
        """One line for the footer: what the targets are."""
        n = max(len(self.points), len(self.values))
        how = {True: " (timed)", False: " (untimed: in their order over a cycle)", None: ""}
        if self.task == "path":
            return f"× {n} path targets of point {self.point}{how[self.timed]}"
        if self.task == "motion":
            return f"→ {n} target poses of the moving link{how[self.timed]}"
        return f"{n} function targets (driver value → output angle), shown on a chart"


def read_targets(data: Any) -> SynthesisTargets:
    """The task under a file's ``synthesis`` key, checked; errors name the field."""
    if not isinstance(data, Mapping):
        raise MechanismError("synthesis: expected an object with task and targets")
    task = data.get("task")
    if task not in SIZES:
        raise MechanismError(
            f"synthesis.task: {task!r} has no targets to draw (known: path, function, motion)"
        )
    raw = data.get("targets")
    if not isinstance(raw, list) or not raw:
        raise MechanismError("synthesis.targets: expected a non-empty list")
    size = SIZES[task]
    rows: list[list[float]] = []
    for i, t in enumerate(raw, 1):
        ok = isinstance(t, list | tuple) and len(t) == size
        values = [_number(v) for v in t] if ok else []
        if not ok or any(v is None for v in values):
            what = "pair" if size == 2 else "triple"
            raise MechanismError(
                f"synthesis.targets: target {i} is not a {what} of finite numbers"
            )
        rows.append([float(v) for v in values if v is not None])
    a = np.array(rows, float)
    timing = data.get("timing")
    times: tuple[float, ...] | None = None
    if timing is not None:
        values_t = [_number(v) for v in timing] if isinstance(timing, list) else [None]
        if len(values_t) != len(rows) or any(v is None for v in values_t):
            raise MechanismError(
                f"synthesis.timing: expected {len(rows)} finite numbers, one per target"
            )
        times = tuple(float(v) for v in values_t if v is not None)
    timed = data.get("timed")
    if timed is not None and not isinstance(timed, bool):
        raise MechanismError("synthesis.timed: expected true or false")
    offset = _number(data.get("angle_offset", 0.0))
    if offset is None:
        raise MechanismError("synthesis.angle_offset: expected a finite number (radians)")
    point = data.get("point")
    if task == "path" and point is not None and not isinstance(point, str):
        raise MechanismError("synthesis.point: expected a point id")
    empty_c = np.zeros(0, complex)
    empty_f = np.zeros(0, float)
    if task == "function":
        return SynthesisTargets(task, None, empty_c, a[:, 1].copy(), a[:, 0].copy(), times,
                                timed, offset)  # fmt: skip
    points = (a[:, 0] + 1j * a[:, 1]).astype(np.complex128)
    angles = a[:, 2].copy() if task == "motion" else empty_f
    return SynthesisTargets(task, point if task == "path" else None, points, angles, empty_f,
                            times, timed)  # fmt: skip


def _number(v: Any) -> float | None:
    if isinstance(v, bool) or not isinstance(v, int | float):
        return None
    return float(v) if math.isfinite(v) else None


def synthesis_targets(mechanism: Mechanism) -> SynthesisTargets | None:
    """The targets a synthesised mechanism keeps (None: the file has none to draw, such
    as an analysed mechanism or a four-bar matrix synthesis)."""
    data = mechanism.extra.get(SYNTHESIS_KEY)
    if data is None or (isinstance(data, Mapping) and "targets" not in data):
        return None
    targets = read_targets(data)
    _check_reach(targets, mechanism)
    return targets


def _check_reach(targets: SynthesisTargets, mechanism: Mechanism) -> None:
    """Refuse targets a task could not have (:func:`mjstruct.design.task` limits: within
    1e8 sizes of the origin, spread at most 1e50): a drawing would show the mechanism
    as a dot with the target pressed into a corner (a target at 1e300)."""
    from mjstruct.design.task import ORIGIN_LIMIT, SIZE_LIMIT

    pts = targets.points
    if not len(pts):
        return
    at = [complex(*j.at) for j in mechanism.joints if j.at is not None]
    size = max((abs(a - b) for a in at for b in at[:8]), default=0.0)
    with np.errstate(over="ignore", invalid="ignore"):
        spread = float(np.hypot(np.ptp(pts.real), np.ptp(pts.imag)))
    far = np.maximum(np.abs(pts.real), np.abs(pts.imag))
    k = int(np.argmax(far))
    if not spread <= SIZE_LIMIT or far[k] > ORIGIN_LIMIT * max(size, spread, 1e-300):
        raise MechanismError(
            f"synthesis.targets: target {k + 1} at [{pts[k].real:.6g}, {pts[k].imag:.6g}] "
            f"lies too far out to draw with the mechanism (a task keeps its targets within "
            f"{ORIGIN_LIMIT:g} sizes of the origin and {SIZE_LIMIT:g} of each other)"
        )


def draw_targets(ax: Axes, targets: SynthesisTargets, size: float) -> None:
    """The targets over the scheme (static: the same in every frame); ``size`` is the
    mechanism's size (a pose's arrow is a tenth of it)."""
    pts = targets.points
    if targets.task == "path" and pts.size:
        ax.plot(pts.real, pts.imag, ls="none", marker="x", ms=7, mew=1.8, color=TARGET_COLOUR,
                zorder=8, gid="targets")  # fmt: skip
        if len(pts) <= 12:  # numbered in their order; beyond a dozen numbers only clutter
            for i, z in enumerate(pts, 1):
                ax.annotate(str(i), (z.real, z.imag), xytext=(4, 4), textcoords="offset points",
                            fontsize=6, color=TARGET_COLOUR, zorder=8,
                            gid=f"targets:{i}")  # fmt: skip
    elif targets.task == "motion" and pts.size:
        u = 0.1 * size * np.exp(1j * targets.angles)
        ax.plot(pts.real, pts.imag, ls="none", marker="o", ms=4, color=TARGET_COLOUR, zorder=8,
                gid="targets")  # fmt: skip
        arrows = ax.quiver(pts.real, pts.imag, u.real, u.imag, angles="xy", scale_units="xy",
                           scale=1.0, color=TARGET_COLOUR, width=0.003, zorder=8)  # fmt: skip
        arrows.set_gid("targets:poses")
