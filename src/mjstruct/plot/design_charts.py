"""Charts of a synthesis run: the objective's history, and the design against its targets.

Owns :func:`draw_history` and :func:`write_history_chart`: the error-against-run-time
report of a :class:`~mjstruct.design.result.DesignResult` (its ``history``: the best
feasible objective after each generation of the global stage, then the verdict of the
local stage), on two panels sharing a logarithmic objective axis: candidate
evaluations, and wall time in seconds (``mjstruct synthesize --history CHART``); and
:func:`draw_targets` and :func:`write_targets_chart`: a synthesised mechanism (read
from its ``synthesis`` key) at its reference configuration, the path its point traces
over one turn and the targets, numbered (path and motion; a motion target's angle as a
short stroke), or its output angle against the driver with the targets (function)
(``mjstruct synthesize --targets-chart CHART``).

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> from mjstruct.design.result import DesignResult
>>> from mjstruct.mechanism import Mechanism
>>> m = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]), ("O2", [3, 0])],
...                     frame=0, drivers=["O1"])
>>> r = DesignResult(m, "path", 1e-3, True, (1e-3,), 900, 0.6, 1,
...                  history=((100, 0.1, 0.5), (500, 0.3, 0.02), (900, 0.6, 1e-3)))
>>> fig = draw_history(r)
>>> [ax.get_xlabel() for ax in fig.axes]
['candidate evaluations', 'time (s)']
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from mjstruct.design.result import DesignResult
from mjstruct.errors import MechanismError
from mjstruct.mechanism import Mechanism

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from mjstruct.kinematics.model import KinematicModel, Motion


def draw_history(result: DesignResult, fig: Figure | None = None) -> Figure:
    """The objective (best feasible so far) against evaluations and against time."""
    import matplotlib.pyplot as plt

    if fig is None:
        fig = plt.figure(figsize=(9.0, 3.6))
    points = [(k, t, f) for k, t, f in result.history if math.isfinite(f) and f > 0]
    ax1 = fig.add_subplot(1, 2, 1)
    ax2 = fig.add_subplot(1, 2, 2, sharey=ax1)
    if points:
        ks, ts, fs = zip(*points, strict=True)
        ax1.step(ks, fs, where="post", color="tab:blue")
        ax2.step(ts, fs, where="post", color="tab:blue")
        ax1.set_yscale("log")
    else:
        for ax in (ax1, ax2):
            ax.text(
                0.5, 0.5, "no feasible candidate recorded", ha="center", transform=ax.transAxes
            )
    ax1.set_xlabel("candidate evaluations")
    ax2.set_xlabel("time (s)")
    ax1.set_ylabel("objective (RMS target error)")
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(
        f"{result.task} synthesis: objective {result.objective:.3g} after "
        f"{result.evaluations} evaluations, {result.seconds:.2g} s (seed {result.seed})"
    )
    fig.tight_layout()
    return fig


def draw_targets(
    m: Mechanism, fig: Figure | None = None, frames: int = 360, ax: Axes | None = None
) -> Figure:
    """The design ``m`` (a file written by synthesis) against its targets (into ``ax``,
    a panel of a larger figure, when given)."""
    import matplotlib.pyplot as plt
    import numpy as np

    from mjstruct.design.result import SYNTHESIS_KEY
    from mjstruct.kinematics.model import KinematicModel

    entry = m.extra.get(SYNTHESIS_KEY)
    if not isinstance(entry, dict) or "targets" not in entry:
        raise MechanismError(f"mechanism: no '{SYNTHESIS_KEY}' targets to draw")
    model = KinematicModel.build(m)
    motion = model.motion(model.sweep(frames), order=0)
    targets = np.array(entry["targets"], float)
    if ax is not None:
        fig = ax.figure  # type: ignore[assignment]
    else:
        if fig is None:
            fig = plt.figure(figsize=(6.4, 5.2))
        ax = fig.add_subplot(1, 1, 1)
    assert fig is not None
    if entry.get("task") == "function":
        _function_chart(ax, model, motion, entry)
    else:
        from mjstruct.plot.scheme import plate_outline

        g = model.geometry
        for link in m.links:
            pts = [g.centres[j] for j in m.link_joints[link]]
            if link == m.frame:
                ax.plot([z.real for z in pts], [z.imag for z in pts], "k^", ms=8)
                continue
            # the link as the part: the hull of its joints and the points it carries
            pts += [z for on, z in g.points.values() if on == link]
            hull = list(plate_outline(np.array(pts, complex)))
            loop = hull + hull[:1] if len(hull) > 2 else hull
            ax.plot([z.real for z in loop], [z.imag for z in loop], "-", color="0.35", lw=2)
        point = entry["point"]
        if point in g.points:
            link, z0 = g.points[point]
            path = motion.point(link, z0)[0]
        else:
            path = motion.centre(point)[0]
            z0 = g.centres[point]
        ok = np.isfinite(path)
        ax.plot(path[ok].real, path[ok].imag, "-", color="tab:blue", lw=1.2,
                label=f"path of {point}")  # fmt: skip
        ax.plot([z0.real], [z0.imag], "o", color="tab:blue", ms=4)
        ax.plot(targets[:, 0], targets[:, 1], "x", color="tab:red", ms=7, mew=1.6,
                label="targets")  # fmt: skip
        if targets.shape[1] == 3:
            size = 0.12 * float(np.ptp(targets[:, :2], axis=0).max() or 1.0)
            for x, y, a in targets:
                ax.plot([x, x + size * np.cos(a)], [y, y + size * np.sin(a)], color="tab:red")
        for k, (x, y) in enumerate(targets[:, :2], 1):
            ax.annotate(str(k), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title(f"{m.name or 'design'}: {entry.get('task', '')} synthesis, targets and motion")
    if len(fig.axes) == 1:
        fig.tight_layout()
    return fig


def _function_chart(ax: Axes, model: KinematicModel, motion: Motion, entry: Any) -> None:
    """The output angle against the driver, in degrees as every chart against q, with
    the targets where the design meets them: at the driver values as met, their angles
    moved by the common offset the search found (``angle_offset`` tasks)."""
    import numpy as np

    from mjstruct.plot.charts import ChartData
    from mjstruct.plot.targets import read_targets

    targets = read_targets(entry)
    link = str(entry["link"])
    data = ChartData(model, motion, 1.0, None)
    x, y = data.curve(motion.angle(link)[0], angle=data.degrees)
    ax.plot(x, y, color="tab:blue", label=f"angle of link {link}", gid="output")
    q = np.array(targets.timing if targets.timing is not None else targets.values, float)
    goal = targets.angles + targets.angle_offset
    if data.degrees:
        q, goal = np.degrees(q) % 360.0, np.degrees(goal)
        # each target's angle by whole turns the nearest to the curve there
        ok = np.isfinite(y)
        near = np.interp(q, x[ok], y[ok]) if ok.any() else goal
        goal = goal - 360.0 * np.round((goal - near) / 360.0)
    offset = ""
    if targets.angle_offset:
        value = math.degrees(targets.angle_offset) if data.degrees else targets.angle_offset
        offset = f" + offset {value:.4g}{'°' if data.degrees else ' rad'}"
    ax.plot(q, goal, "o", color="tab:red", mfc="none", label=f"targets{offset}", gid="targets")
    for k, (a, b) in enumerate(zip(q, goal, strict=True), 1):
        ax.annotate(str(k), (a, b), textcoords="offset points", xytext=(5, -9), fontsize=7)
    d = model.drivers[0]
    unit = "°" if data.degrees else ("rad" if model.mechanism.joint(d).kind == "R" else "length")
    ax.set_xlabel(f"q: {'angle' if unit != 'length' else 'slide'} of driver {d} ({unit})")
    ax.set_ylabel(f"output angle of link {link} ({'°' if data.degrees else 'rad'})")
    if data.degrees:
        ax.set_xlim(0.0, 360.0)
        ax.set_xticks(np.arange(0, 361, 45))


def write_targets_chart(m: Mechanism, path: str, name: str = "path") -> None:
    """Draw :func:`draw_targets` into ``path`` (``.svg``, ``.png``, ``.pdf``), atomically."""
    import matplotlib.pyplot as plt

    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output, write_atomically

    check_output(path, FIGURE_SUFFIXES, name=name)
    fig = draw_targets(m)
    try:
        write_atomically(path, fig.savefig, name=name)
    finally:
        plt.close(fig)


def write_history_chart(result: DesignResult, path: str, name: str = "path") -> None:
    """Draw :func:`draw_history` into ``path`` (``.svg``, ``.png``, ``.pdf``), atomically."""
    import matplotlib.pyplot as plt

    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output, write_atomically

    check_output(path, FIGURE_SUFFIXES, name=name)
    fig = draw_history(result)
    try:
        write_atomically(path, fig.savefig, name=name)
    except ValueError as exc:  # matplotlib refusing the figure
        raise MechanismError(f"{name}: cannot draw the chart ({exc})") from None
    finally:
        plt.close(fig)
