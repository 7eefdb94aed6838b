"""Charts against the driver coordinate q: angles, ω, ε, paths, Jacobian, transmission,
and with the dynamics plug-in V(q), Q(q), q̇(q), q̈(q) and joint reactions.

Owns the registry :data:`CHARTS` that ``mjstruct plot --what`` dispatches on: each
chart names the derivative order it needs (a chart computes only what it shows) and
a function that draws it from a solved :class:`~mjstruct.kinematics.model.Motion`.
Frames that do not assemble are gaps in the curves, shaded grey; the Jacobian and
transmission charts shade the near-singular frames (|det| below 10⁻³ of its largest
value over the cycle) red.  A dynamics chart asks :func:`mjstruct.dynamics.dynamic_analysis`
for its one output: V and Q at constant speed (the ``--speed``), q̇ and q̈ of the free
motion from q̇0 = speed, reactions at constant speed.  Adding a chart is one entry in
:data:`CHARTS`.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("four-bar")))
>>> fig = draw_chart(model, "transmission", frames=90)
>>> [line.get_gid() for line in fig.axes[0].get_lines()][:1]
['transmission']
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.plot.layers import dynamics_available
from mjstruct.typing import FloatArray, IntArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: |det| below this fraction of its largest value over the cycle is shaded near-singular
NEAR_SINGULAR = 1e-3
#: the usual limits of a good transmission angle (degrees)
TRANSMISSION_LIMITS = (40.0, 140.0)


@dataclass(frozen=True)
class ChartData:
    """What a chart draws from: the motion over the cycle, the user's choices and, for a
    dynamics chart, the :class:`~mjstruct.dynamics.DynamicsResult`.

    The abscissa is the first driver's coordinate: for a revolute driver its angle in
    degrees from 0 to 360 (the cycle's frames in that order, the curve closed across
    360°), with ``radians`` the coordinate in radians as the cycle runs from the
    reference; for a prismatic driver its slide.
    """

    model: KinematicModel
    motion: Motion
    speed: float
    ids: tuple[str, ...] | None
    dynamics: Any = None
    radians: bool = False

    @property
    def q(self) -> FloatArray:
        """The first driver's coordinate over the frames, in the cycle's order."""
        return np.asarray(self.motion.q[:, 0], float)

    @property
    def degrees(self) -> bool:
        """Whether the abscissa is the driver's angle from 0 to 360°."""
        d = self.model.drivers[0]
        return not self.radians and self.model.mechanism.joint(d).kind == "R"

    def masked(self, values: Any) -> FloatArray:
        """Real values with the frames that do not assemble set to NaN (gaps)."""
        a = np.array(values, dtype=float)
        a[~self.motion.valid] = np.nan
        return a

    def _order(self) -> tuple[FloatArray, IntArray]:
        """(abscissa, the frames in its order)."""
        q = self.q
        if not self.degrees:
            return q, np.arange(q.size)
        phi = np.degrees(q) % 360.0
        order = np.argsort(phi, kind="stable")
        return phi[order], order

    def curve(self, values: Any, angle: bool = False) -> tuple[FloatArray, FloatArray]:
        """(x, y) of a quantity over the frames as the chart plots it.

        ``angle``: the values are angles (radians), shown in degrees on a 360° window
        that cuts their range where it is emptiest.  In degrees the frames are put in
        the order of the driver's angle and the curve is continued across 0/360°; where
        the cycle's end does not come back to its start (a mechanism that changes
        branch, an angle that turns a full turn) the curve is broken, not joined.
        """
        y = self.masked(values)
        if not self.degrees:
            return self.q, y
        if angle:
            y = _window(np.degrees(y))
        x, order = self._order()
        ys = y[order]
        n = ys.size
        first = int(np.flatnonzero(order == 0)[0])
        # the sweep's end meets its start between sorted positions first - 1 and first
        joined = _comes_back(y)
        xa, ya = x, ys
        if not joined and 0 < first < n:
            xa, ya = np.insert(xa, first, np.nan), np.insert(ya, first, np.nan)
        if joined or first != 0:
            # continue across 360°: the last frame before it and the first after it
            before, after = ya[-1], ya[0]
            if angle:  # the same angles, by whole turns the nearest to their neighbours
                before -= 360.0 * np.round((before - ya[0]) / 360.0)
                after -= 360.0 * np.round((after - ya[-1]) / 360.0)
            xa = np.concatenate([[xa[-1] - 360.0], xa, [xa[0] + 360.0]])
            ya = np.concatenate([[before], ya, [after]])
        if angle:
            xa, ya = _break_jumps(xa, ya, 180.0)
        return xa, ya

    def mask(self, flags: Any) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
        """(x, flags) in the abscissa's order, for shading runs of frames."""
        x, order = self._order()
        return x, np.asarray(flags, bool)[order]


def _comes_back(y: FloatArray) -> bool:
    """Whether a cycle's last value leads back to its first: the step between them is
    no longer than twice the longest other step (NaN steps left out)."""
    steps = np.abs(np.diff(y))
    steps = steps[np.isfinite(steps)]
    closing = abs(y[0] - y[-1])
    if not np.isfinite(closing):
        return True  # a gap there: nothing is joined anyway
    return bool(steps.size and closing <= 2.0 * steps.max() + 1e-12 * (1 + abs(y[0])))


def _window(deg: FloatArray) -> FloatArray:
    """Angles (degrees) moved by whole turns into one 360° window whose cut lies in the
    middle of the widest empty arc of their values (a rocker's swing stays in one
    piece); the window is [cut, cut + 360°), or a turn lower when the cut is past 180°;
    angles with no empty arc of 90° (a link that turns round) go from 0 to 360°."""
    finite = np.sort(np.mod(deg[np.isfinite(deg)], 360.0))
    if finite.size == 0:
        return deg
    gaps = np.diff(np.concatenate([finite, [finite[0] + 360.0]]))
    i = int(np.argmax(gaps))
    if gaps[i] < 90.0:
        cut = 0.0  # a link that turns round: 0 to 360°, as the crank angle
    else:
        cut = float(np.mod(finite[i] + 0.5 * gaps[i], 360.0))
        if cut >= 180.0:
            cut -= 360.0
    return np.asarray(cut + np.mod(deg - cut, 360.0), float)


def _break_jumps(x: FloatArray, y: FloatArray, jump: float) -> tuple[FloatArray, FloatArray]:
    """A NaN between neighbours whose values differ by more than ``jump`` (a wrap)."""
    d = np.abs(np.diff(y))
    cut = np.flatnonzero(np.isfinite(d) & (d > jump)) + 1
    return np.insert(x, cut, np.nan), np.insert(y, cut, np.nan)


@dataclass(frozen=True)
class Chart:
    """One kind of chart: its derivative order, whether it needs dynamics, its drawer."""

    name: str
    order: int
    dynamics: bool
    help: str
    draw: Callable[[ChartData, Figure], None]


def _links(data: ChartData) -> list[str]:
    m = data.model.mechanism
    if data.ids is None:
        return [x for x in m.links if x != data.model.frame]
    for x in data.ids:
        if x not in m.links:
            raise MechanismError(f"ids: {x!r} is not a link")
    return list(data.ids)


def _link_chart(order: int, label: str, unit: str) -> Callable[[ChartData, Figure], None]:
    def draw(data: ChartData, fig: Figure) -> None:
        ax = fig.add_subplot()
        angle = order == 0 and data.degrees
        for link in _links(data):
            y = data.motion.angle(link)[order] * data.speed**order
            x, yy = data.curve(y, angle=angle)
            ax.plot(x, yy, lw=1.4, label=f"link {link}", gid=f"link:{link}")
        _finish(ax, data, f"{label} ({'°' if angle else unit})")
        _legend(ax)

    return draw


def _point_ids(data: ChartData) -> list[str]:
    geom = data.model.geometry
    if data.ids is not None:
        for x in data.ids:
            if x not in geom.points and x not in geom.centres:
                raise MechanismError(f"ids: {x!r} is neither a joint nor a point")
        return list(data.ids)
    if geom.points:
        return list(geom.points)
    m = data.model.mechanism
    return [j.id for j in m.joints if not (j.kind == "R" and data.model.frame in j.links)]


def _paths(data: ChartData, fig: Figure) -> None:
    geom = data.model.geometry
    ax_x = fig.add_subplot(2, 1, 1)
    ax_y = fig.add_subplot(2, 1, 2, sharex=ax_x)
    for pid in _point_ids(data):
        if pid in geom.points:
            link, z = geom.points[pid]
            pos = data.motion.point(link, z)[0]
        else:
            pos = data.motion.centre(pid)[0]
        ax_x.plot(*data.curve(pos.real), lw=1.4, label=pid, gid=f"x:{pid}")
        ax_y.plot(*data.curve(pos.imag), lw=1.4, label=pid, gid=f"y:{pid}")
    _finish(ax_x, data, "x", xlabel=False)
    _finish(ax_y, data, "y")
    _legend(ax_x)


def jacobian_determinant(motion: Motion) -> FloatArray:
    """Determinant of the driver-fixed constraint Jacobian at every frame (NaN: no assembly)."""
    from mjstruct.kinematics.jacobian import constraint_jacobian

    model = motion.model
    J, D = constraint_jacobian(
        model.mechanism, model.geometry, motion.evaluation.poses, model.drivers
    )
    A = np.concatenate([J, D], axis=1)
    det = np.full(A.shape[0], np.nan)
    ok = motion.valid & np.isfinite(A).all(axis=(1, 2))
    if A.shape[1] != A.shape[2]:
        raise MechanismError("drivers: the constraint Jacobian is not square with these drivers")
    if ok.any():
        det[ok] = np.linalg.det(A[ok])
    return det


def near_singular(det: FloatArray) -> npt.NDArray[np.bool_]:
    """Frames whose |det| is below :data:`NEAR_SINGULAR` of its largest value."""
    a = np.abs(det)
    if not np.isfinite(a).any():
        return np.zeros(a.shape, bool)
    return np.asarray(a < NEAR_SINGULAR * np.nanmax(a), bool)


def _jacobian(data: ChartData, fig: Figure) -> None:
    ax = fig.add_subplot()
    det = jacobian_determinant(data.motion)
    ax.plot(*data.curve(det), lw=1.4, color="tab:blue", gid="jacobian")
    ax.axhline(0.0, color="0.5", lw=0.8)
    _shade(ax, *data.mask(near_singular(det)), "tab:red", "near-singular", "singular")
    _finish(ax, data, "det J (drivers fixed)")
    _legend(ax)


def fourbar_joints(model: KinematicModel) -> tuple[str, str, str]:
    """(crank–coupler joint A, coupler–rocker joint P, rocker–frame joint Q) of a four-bar."""
    m = model.mechanism
    if m.n != 4 or len(m.joints) != 4 or any(j.kind != "R" or j.is_multiple for j in m.joints):
        raise MechanismError("what: the transmission angle needs a four-bar (4 links, 4 pins)")
    (d,) = model.drivers if len(model.drivers) == 1 else (None,)
    if d is None or model.frame not in m.joint(d).links:
        raise MechanismError("drivers: the transmission angle needs one driver on the frame")
    crank = next(x for x in m.joint(d).links if x != model.frame)
    a = next(j.id for j in m.joints if crank in j.links and j.id != d)
    coupler = next(x for x in m.joint(a).links if x != crank)
    p = next(j.id for j in m.joints if coupler in j.links and j.id != a)
    q = next(j.id for j in m.joints if j.id not in (d, a, p))
    return a, p, q


def transmission_angle(motion: Motion) -> FloatArray:
    """Angle (radians, 0..π) between coupler and rocker at their joint, over the frames."""
    a, p, q = fourbar_joints(motion.model)
    za, zp, zq = (np.asarray(motion.centre(j)[0]) for j in (a, p, q))
    return np.asarray(np.abs(np.angle((za - zp) / (zq - zp))), dtype=np.float64)


def _transmission(data: ChartData, fig: Figure) -> None:
    ax = fig.add_subplot()
    mu = np.degrees(transmission_angle(data.motion))
    ax.plot(*data.curve(mu), lw=1.4, color="tab:blue", gid="transmission")
    for n, limit in enumerate(TRANSMISSION_LIMITS):
        ax.axhline(limit, color="0.4", lw=0.8, ls=":", gid=f"limit:{n}")
        ax.annotate(
            f"usual limit {limit:g}°", (1.0, limit), xycoords=("axes fraction", "data"),
            xytext=(-4, 3 if n else -3), textcoords="offset points", ha="right",
            va="bottom" if n else "top", fontsize=7, color="0.35", gid=f"limit:{n}:label",
        )  # fmt: skip
    det = jacobian_determinant(data.motion)
    _shade(ax, *data.mask(near_singular(det)), "tab:red", "near-singular", "singular")
    ax.set_ylim(0, 180)
    ax.set_yticks(np.arange(0, 181, 30))
    _finish(ax, data, "transmission angle (°)")
    _legend(ax)


def _shade(
    ax: Axes, q: FloatArray, mask: npt.NDArray[np.bool_], colour: str, label: str, gid: str
) -> None:
    """Shade the runs of frames where ``mask`` holds (half a step either side)."""
    if q.size < 2:
        return
    half = 0.5 * float(np.nanmin(np.abs(np.diff(q)))) if q.size > 1 else 0.0
    half = max(half, 0.5 * abs(q[1] - q[0]))
    k, first = 0, True
    while k < q.size:
        if not mask[k]:
            k += 1
            continue
        e = k
        while e + 1 < q.size and mask[e + 1]:
            e += 1
        lo, hi = sorted((q[k], q[e]))
        ax.axvspan(
            lo - half,
            hi + half,
            color=colour,
            alpha=0.25,
            lw=0,
            label=label if first else None,
            gid=gid,
        )
        first = False
        k = e + 1


def _finish(ax: Axes, data: ChartData, ylabel: str, xlabel: bool = True) -> None:
    _shade(ax, *data.mask(~data.motion.valid), "0.5", "does not assemble", "gap")
    ax.set_ylabel(ylabel)
    if data.degrees:
        ax.set_xlim(0.0, 360.0)
        ax.set_xticks(np.arange(0, 361, 45))
    if xlabel:
        d = data.model.drivers[0]
        if data.degrees:
            ax.set_xlabel(f"q: angle of driver {d} (°)")
        elif data.model.mechanism.joint(d).kind == "R":
            ax.set_xlabel(f"q: angle of driver {d} (rad)")
        else:
            ax.set_xlabel(f"q: slide of driver {d} (length)")
    ax.grid(True, lw=0.4, alpha=0.5)


def _legend(ax: Axes) -> None:
    """The legend beside the plot, right of the axes: never on the curves."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(
            fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
            frameon=False,
        )  # fmt: skip


def _ms_diagram(data: ChartData, fig: Figure) -> None:
    from mjstruct.plot.ms_diagram import ms_point, plot_ms_diagram

    p1, p2, p3 = ms_point(data.model.mechanism)
    name = data.model.mechanism.name or "mechanism"
    plot_ms_diagram(p1, point=(p2, p3), label=name, ax=fig.add_subplot())


def _dynamic(what: str) -> Callable[[ChartData, Figure], None]:
    labels = {
        "V": "reduced moment of inertia V",
        "Q": "generalised force Q",
        "qdot": "q̇ (free motion)",
        "qddot": "q̈ (free motion)",
    }

    def draw(data: ChartData, fig: Figure) -> None:
        dyn = data.dynamics
        assert dyn is not None
        ax = fig.add_subplot()
        if what == "reactions":
            m = data.model.mechanism
            for jid, per in (dyn.reactions or {}).items():
                # a simple joint: the load on its second link (the first gets the opposite)
                links = list(per) if m.joint(jid).is_multiple else [m.joint(jid).links[1]]
                for link in links:
                    f = per[link]
                    mag = np.hypot(f["x"], f["y"])
                    ax.plot(
                        *data.curve(mag),
                        lw=1.3,
                        label=f"{jid} on {link}",
                        gid=f"reaction:{jid}:{link}",
                    )
            _finish(ax, data, "|R| (force units)")
            _legend(ax)
            return
        y = getattr(dyn, what)
        y = y[:, 0] if y.ndim == 2 else y
        ax.plot(*data.curve(y), lw=1.4, color="tab:blue", gid=what)
        _finish(ax, data, labels[what])

    return draw


CHARTS: dict[str, Chart] = {
    c.name: c
    for c in (
        Chart("angles", 0, False, "link angles against q", _link_chart(0, "angle", "rad")),
        Chart("omega", 1, False, "angular velocities ω against q", _link_chart(1, "ω", "rad/s")),
        Chart("eps", 2, False, "angular accelerations ε against q", _link_chart(2, "ε", "rad/s²")),
        Chart("paths", 0, False, "x and y of points against q", _paths),
        Chart("jacobian", 0, False, "driver-fixed Jacobian determinant against q", _jacobian),
        Chart(
            "transmission", 0, False, "transmission angle of a four-bar against q", _transmission
        ),
        Chart("ms-diagram", 0, False, "four-bar P2-P3 diagram of singular motions", _ms_diagram),
        Chart("V", 0, True, "reduced moment of inertia V(q)", _dynamic("V")),
        Chart("Q", 0, True, "generalised force Q(q)", _dynamic("Q")),
        Chart(
            "qdot",
            0,
            True,
            "driver speed q̇(q) under the loads (from q̇0 = speed)",
            _dynamic("qdot"),
        ),
        Chart("qddot", 0, True, "driver acceleration q̈(q) under the loads", _dynamic("qddot")),
        Chart(
            "reactions", 0, True, "joint reactions |R| at constant speed", _dynamic("reactions")
        ),
    )
}


def chart(what: str, name: str = "what") -> Chart:
    """The chart called ``what``; ``name`` is what error messages call the choice."""
    if what not in CHARTS:
        raise MechanismError(f"{name}: unknown chart {what!r} (known: {', '.join(CHARTS)})")
    c = CHARTS[what]
    if c.dynamics and not dynamics_available():
        raise MechanismError(
            f"{name}: chart {what!r} needs the dynamics plug-in (mjstruct.dynamics), "
            "which is not installed"
        )
    return c


def draw_chart(
    model: KinematicModel,
    what: str,
    frames: int = 360,
    speed: float = 1.0,
    stroke: float = 1.0,
    ids: Sequence[str] | None = None,
    fig: Figure | None = None,
    radians: bool = False,
) -> Figure:
    """Solve one cycle to the order chart ``what`` needs and draw it; returns the figure.

    Against a revolute driver the abscissa is its angle from 0 to 360°, and link angles
    are in degrees; ``radians=True`` plots both in radians, the cycle from the reference.
    The title is broken into lines that fit the figure.
    """
    import matplotlib.pyplot as plt

    c = chart(what)
    if not math.isfinite(speed) or speed == 0:
        raise MechanismError(f"speed: must be a finite nonzero number, got {speed}")
    dyn = _dynamics_for(model, what, frames, speed) if c.dynamics else None
    q = model.sweep(frames, speed, stroke) if dyn is None else dyn.q
    motion = model.motion(q, order=c.order)
    data = ChartData(model, motion, speed, None if ids is None else tuple(ids), dyn, radians)
    if fig is None:
        size = {"paths": (7.0, 5.5), "ms-diagram": (8.4, 6.0)}.get(what, (7.0, 4.2))
        fig = plt.figure(figsize=size)
    c.draw(data, fig)
    about = c.help if not data.degrees else c.help.replace("against q", "against the crank angle")
    title = f"{model.mechanism.name or 'mechanism'}: {about}"
    chars = int(fig.get_figwidth() * 72 / (10 * 0.58))
    fig.suptitle("\n".join(textwrap.wrap(title, chars)), fontsize=10)
    return fig


def _dynamics_for(model: KinematicModel, what: str, frames: int, speed: float) -> Any:
    """The dynamic analysis a dynamics chart needs, and only that output."""
    from mjstruct.dynamics import dynamic_analysis
    from mjstruct.dynamics.data import read_dynamics

    m = model.mechanism
    data = read_dynamics(m)
    if not data.loads and all(i.mass == 0 and i.J == 0 for i in data.inertia.values()):
        raise MechanismError(
            "inertia: the file has no dynamics data (no masses, no loads) to chart"
        )
    if what in ("qdot", "qddot"):
        return dynamic_analysis(
            m, qdot0=speed, frames=frames, model=model, outputs=("coefficients",)
        )
    outputs = ("reactions",) if what == "reactions" else ("coefficients",)
    if what != "reactions" and len(model.drivers) != 1:
        raise MechanismError(f"what: {what} needs a mechanism with one driver")
    return dynamic_analysis(m, speed=speed, frames=frames, model=model, outputs=outputs)
