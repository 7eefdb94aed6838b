"""The explorer's picture: a mechanism's scheme and paths over a strip of the driver's range.

Owns :class:`ExplorerView`, the part of the notebook explorer
(:func:`mjstruct.plot.explorer.explore`) that needs no widgets: the mechanism at its
current joint centres, its scene over one cycle, its singular positions, the frame
shown, and the picture as PNG.  It answers the two changes a slider makes:

* the driver moves (:meth:`ExplorerView.set_driver`): only the frame shown changes;
  the artists built once are set to it and drawn over the background
  (:class:`~mjstruct.plot.animation.FrameRenderer`, as an animation draws a frame);
* a joint moves (:meth:`ExplorerView.move_joint`): the mechanism is rebuilt with the
  joint at its new centre (and the joints drawn at its centre on a shared link, such
  as a slider's block, with it); its kinematic model keeps the plan (the same
  topology and drivers, so only the geometry is read again); the cycle is solved
  again, the singular positions found again
  (:func:`~mjstruct.singular.analysis.singular_analysis`), and the artists are set
  to the new scene in place (a new figure only when the mechanism leaves the axes).

The strip below the drawing spans the driver's range (a revolute driver: 0 to 360°):
green where the mechanism assembles (the singular analysis's input range, else the
frames of the cycle that assemble), the singular positions marked in red (``|`` input
limit, ``v`` output extreme, ``X`` change point), a line at the driver's value.  A
geometry that cannot be drawn leaves the last one that could on the picture and says
why in :attr:`ExplorerView.problem`.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> view = ExplorerView(read_mechanism(example_path("six-bar-mj-slider")), ["B"])
>>> view.set_driver(90.0)
>>> round(float(np.degrees(view.q[0])), 6)
90.0
>>> view.move_joint("B", 2.7, 2.5)
True
>>> view.png()[:4] == b"\\x89PNG"
True
>>> view.move_joint("B", 0.0, 1.0)       # onto A: link 2 would have no length
False
>>> view.problem.startswith("this geometry cannot be drawn")
True
"""

from __future__ import annotations

import dataclasses
import io
import math
import warnings
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.errors import MechanismError, NumericalError
from mjstruct.io import mechanism_from_dict, mechanism_to_dict
from mjstruct.kinematics.geometry import geometry_of
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.plot.animation import FrameRenderer
from mjstruct.plot.drawing import Scene, scene_over_cycle
from mjstruct.plot.layout import drawing_figure
from mjstruct.plot.style import DRIVER_COLOUR

if TYPE_CHECKING:
    from mjstruct.singular.analysis import SingularAnalysis, SingularPosition
    from mjstruct.singular.classification import SingularClass

#: height (inches) of the strip of the driver's range below the drawing
STRIP = 0.62
#: room for the joints to move around the first drawing, and around the drawing made
#: when they leave it (fractions of the mechanism's size on every side)
SLACK, REGROW = 0.1, 0.25
#: colour of the stretches where the mechanism assembles
ASSEMBLES = "#8fd18f"
#: the singular positions' markers on the strip, by kind
MARKERS = {"input_limit": ("|", 13), "output_extreme": ("v", 7), "change_point": ("X", 8)}
#: the singular positions' kinds in words
KIND_WORDS = {
    "input_limit": "input limit",
    "output_extreme": "output extreme",
    "change_point": "change point",
}
#: what a geometry change may raise when the geometry cannot be drawn
GEOMETRY_TROUBLE = (MechanismError, NumericalError, ArithmeticError, np.linalg.LinAlgError)


class ExplorerView:
    """A mechanism whose driver and joint centres change, drawn as PNG after each change.

    Parameters
    ----------
    mechanism : a mechanism with geometry, frame and drivers (as for ``draw``).
    joints : ids of the joints whose centres :meth:`move_joint` may move.
    frames : frames of the cycle (the driver's steps: 360 is one degree).
    paths : ids of joints or points whose paths are drawn (default: the file's
        points, else the moving joints).
    dpi, width : the picture's resolution and width (inches).
    radians : driver angles in radians (default: degrees, 0 to 360).
    stroke : a prismatic driver's slide over the cycle (length units).

    Raises
    ------
    MechanismError
        the mechanism cannot be drawn (no geometry, drivers that do not determine
        it), an unknown joint, ``frames`` below 4 or more than fit the memory limit
        (:func:`~mjstruct.kinematics.memory.check_sweep_memory`).
    """

    def __init__(
        self,
        mechanism: Mechanism,
        joints: Iterable[str] = (),
        frames: int = 360,
        paths: Iterable[str] | None = None,
        dpi: int = 80,
        width: float = 6.0,
        radians: bool = False,
        stroke: float = 1.0,
    ) -> None:
        expect_mechanism(mechanism, "mechanism")
        if isinstance(joints, str):
            joints = [joints]
        self.joints = tuple(str(j) for j in joints)
        known = {j.id for j in mechanism.joints}
        for j in self.joints:
            if j not in known:
                raise MechanismError(f"joints: {j!r} is not a joint of the mechanism")
        if not isinstance(frames, int) or isinstance(frames, bool) or frames < 4:
            raise MechanismError(f"frames: must be an integer >= 4, got {frames!r}")
        if not (math.isfinite(stroke) and stroke > 0):
            raise MechanismError(f"stroke: must be a finite number > 0, got {stroke}")
        self.original = mechanism
        self.frames, self.stroke, self.radians = frames, stroke, radians
        self.paths = None if paths is None else tuple(paths)
        self.dpi, self.width = dpi, width
        #: joint -> its centre as asked by :meth:`move_joint` (kept while it fails)
        self.requested: dict[str, complex] = {}
        #: why the joint centres asked for are not drawn (None: they are)
        self.problem: str | None = None
        #: what the last change warned about
        self.notes: tuple[str, ...] = ()
        self.mechanism = mechanism
        self.model = KinematicModel.build(mechanism)
        from mjstruct.kinematics.memory import check_sweep_memory

        check_sweep_memory(self.model, frames, checks=False)  # before the sweep is made
        #: joint -> the joints that move with it (itself, a slider's block at its centre)
        self.moves_with = {j: _drawn_with(mechanism, j, self.model.scale) for j in self.joints}
        self.scene = self._scene(self.model)
        self.singular, self.singular_note = _singular(mechanism)
        self.value = self.display(float(self.model.q_ref[0]))
        self.k = 0
        self._build_figure(self.scene, SLACK)

    # -- the driver -------------------------------------------------------------------

    @property
    def revolute(self) -> bool:
        """Whether the (first) driver turns: its values are angles."""
        return self.original.joint(self.model.drivers[0]).kind == "R"

    @property
    def unit(self) -> str:
        """The unit of the driver's values as shown."""
        return ("rad" if self.radians else "°") if self.revolute else "length"

    def driver_range(self) -> tuple[float, float, float]:
        """(lowest, highest, step) of the driver's values as a slider shows them."""
        if self.revolute:
            top = 2 * math.pi if self.radians else 360.0
            return 0.0, top, top / self.frames
        q0 = float(self.model.q_ref[0])
        return q0, q0 + self.stroke, self.stroke / self.frames

    def display(self, q: float) -> float:
        """A driver value (radians or length) as shown: degrees in [0, 360) by default."""
        if not self.revolute:
            return q
        if self.radians:
            return q % (2 * math.pi)
        return math.degrees(q) % 360.0

    def frame_of(self, value: float) -> int:
        """The cycle's frame nearest to the driver value ``value`` (as shown)."""
        q0 = float(self.model.q_ref[0])
        if self.revolute:
            q = value if self.radians else math.radians(value)
            step = 2 * math.pi / self.frames
            return round(((q - q0) % (2 * math.pi)) / step) % self.frames
        step = self.stroke / self.frames
        return int(min(self.frames - 1, max(0, round((value - q0) / step))))

    def set_driver(self, value: float) -> None:
        """Show the frame nearest to the driver value ``value`` (as shown: degrees).

        Raises
        ------
        MechanismError
            ``value`` is not a finite number.
        """
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise MechanismError(f"value: expected a number, got {value!r}") from None
        if not math.isfinite(number):
            raise MechanismError(f"value: the driver value must be finite, got {number}")
        self.value = number
        self.k = self.frame_of(self.value)

    @property
    def q(self) -> np.ndarray[Any, np.dtype[np.float64]]:
        """The driver values (radians, lengths) of the frame shown."""
        return np.asarray(self.scene.motion.q[self.k], float)

    @property
    def assembles(self) -> bool:
        """Whether the mechanism assembles at the frame shown."""
        return bool(self.scene.motion.valid[self.k])

    # -- the joints -------------------------------------------------------------------

    def centre(self, joint: str) -> complex:
        """The joint's centre in the reference configuration now drawn."""
        return self.model.geometry.centres[joint]

    def move_joint(self, joint: str, x: float, y: float) -> bool:
        """Move ``joint``'s reference centre to (x, y) and solve the mechanism again.

        Joints drawn at its centre on a link it shares (a slider's block) move with it.
        Returns whether the new geometry is drawn; when it cannot be (no assembly, no
        size, a degenerate link), :attr:`problem` says why and the picture keeps the
        last geometry that could be drawn.
        """
        if joint not in self.joints:
            raise MechanismError(f"joint: {joint!r} is not one of the explorer's joints")
        self.requested[joint] = complex(float(x), float(y))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                mechanism = self._moved()
                model = self._model_of(mechanism)
                scene = self._scene(model)
                if not scene.motion.valid.any():
                    raise MechanismError("the mechanism assembles at no driver value")
            except GEOMETRY_TROUBLE as exc:
                self.problem = (
                    f"this geometry cannot be drawn: {exc}; the drawing shows the last one "
                    "that can"
                )
                self.notes = tuple(str(w.message) for w in caught)
                return False
            singular, note = _singular(mechanism)
        self.problem = None
        self.notes = tuple(dict.fromkeys(str(w.message) for w in caught))
        self.mechanism, self.model, self.singular, self.singular_note = (
            mechanism,
            model,
            singular,
            note,
        )
        self.k = self.frame_of(self.value)
        if self.renderer.drawing.fits(scene):
            self.scene = scene
            self._set_range()
            self.renderer.rebind(scene)
        else:  # the mechanism leaves the axes: a figure covering both, with room to move
            x0, x1, y0, y1 = self.scene.limits
            a0, a1, b0, b1 = scene.limits
            both = (min(x0, a0), max(x1, a1), min(y0, b0), max(y1, b1))
            self.scene = scene
            self._build_figure(dataclasses.replace(scene, limits=both), REGROW)
        return True

    def _moved(self) -> Mechanism:
        """The original mechanism with the requested joint centres."""
        at: dict[str, complex] = {}
        for joint, z in self.requested.items():
            for j in self.moves_with[joint]:
                at[j] = z
        data = mechanism_to_dict(self.original)
        for j in data["joints"]:
            if j["id"] in at:
                z = at[j["id"]]
                j["at"] = [z.real, z.imag]
        return mechanism_from_dict(data)

    def _model_of(self, mechanism: Mechanism) -> KinematicModel:
        """The model of a moved mechanism: the plan kept (same topology and drivers),
        the geometry read and checked anew; planned anew if the kept plan does not
        place the reference configuration."""
        geometry = geometry_of(mechanism, self.model.drivers)
        model = KinematicModel(mechanism, geometry, self.model.plan)
        if model.motion(model.q_ref[None, :], order=0).valid[0]:
            return model
        return KinematicModel.from_geometry(mechanism, geometry)

    def _scene(self, model: KinematicModel) -> Scene:
        return scene_over_cycle(
            model, self.frames, ("paths",), paths=self.paths, stroke=self.stroke
        )

    # -- the picture ------------------------------------------------------------------

    def _build_figure(self, scene: Scene, slack: float) -> None:
        """The figure: the drawing (as ``draw`` makes it, its limits grown by ``slack``
        times the mechanism's size on every side, room for joints to move) over the
        strip."""
        grow = slack * scene.model.scale
        x0, x1, y0, y1 = scene.limits
        scene = dataclasses.replace(scene, limits=(x0 - grow, x1 + grow, y0 - grow, y1 + grow))
        fig, ax = drawing_figure(scene, width=self.width, pyplot=False)
        height = fig.get_figheight()
        box = ax.get_position()
        total = height + STRIP
        fig.set_figheight(total)
        ax.set_position(
            (box.x0, (STRIP + box.y0 * height) / total, box.width, box.height * height / total)
        )
        strip = fig.add_axes((0.06, 0.42 * STRIP / total, 0.88, 0.28 * STRIP / total))
        self.ax, self.strip = ax, strip
        lo, hi, _ = self.driver_range()
        strip.set_xlim(lo, hi)
        strip.set_ylim(0.0, 1.0)
        strip.set_yticks([])
        for side in ("left", "right", "top"):
            strip.spines[side].set_visible(False)
        if self.revolute and not self.radians:
            strip.set_xticks(np.arange(0, 361, 45))
            strip.set_xticklabels([f"{t}°" for t in range(0, 361, 45)])
        strip.tick_params(labelsize=7, length=2, pad=1)
        strip.set_gid("range:axes")
        strip.text(
            -0.01, 0.5, self.model.drivers[0], transform=strip.transAxes, ha="right",
            va="center", fontsize=8, color=DRIVER_COLOUR, gid="range:driver",
        )  # fmt: skip
        strip.broken_barh([(lo, hi - lo)], (0.3, 0.4), color="0.9", gid="range:cycle")
        self.assembled = strip.broken_barh([], (0.3, 0.4), color=ASSEMBLES, gid="range:assembles")
        self.singular_marks = {
            kind: strip.plot(
                [], [], ls="none", marker=marker, ms=size, mew=2.0, color=DRIVER_COLOUR,
                zorder=4, gid=f"singular:{kind}",
            )[0]
            for kind, (marker, size) in MARKERS.items()
        }  # fmt: skip
        (self.marker,) = strip.plot(
            [self.value, self.value], [-0.25, 1.25], color="black", lw=1.6,
            clip_on=False, zorder=5, gid="range:q",
        )  # fmt: skip
        self._set_range()
        self.renderer = FrameRenderer(
            scene,
            self.dpi,
            ax=ax,
            moving=[self.marker],
            varying=[self.assembled, *self.singular_marks.values()],
            rebindable=True,
        )

    def assembly_intervals(self) -> list[tuple[float, float]]:
        """Where the mechanism assembles, as (from, to) driver values as shown: the
        singular analysis's input range, else the cycle's frames that assemble."""
        lo, hi, _ = self.driver_range()
        r = self.singular
        if r is not None:
            if r.input_range.full_turn:
                return [(lo, hi)]
            out: list[tuple[float, float]] = []
            for a, b in r.input_range.intervals:
                out += self._spans(float(a), float(b))
            return out
        valid = self.scene.motion.valid
        out = []
        for k in np.flatnonzero(valid):
            q = float(self.scene.motion.q[k, 0])
            out += self._spans(q - 0.5 * self._q_step(), q + 0.5 * self._q_step())
        return _merged(out)

    def _q_step(self) -> float:
        return (2 * math.pi if self.revolute else self.stroke) / self.frames

    def _spans(self, a: float, b: float) -> list[tuple[float, float]]:
        """The driver values a..b (radians, lengths; a <= b) as shown, cut at 360°."""
        if not self.revolute:
            return [(a, b)]
        lo, hi, _ = self.driver_range()
        if b - a >= 2 * math.pi:
            return [(lo, hi)]
        x, y = self.display(a), self.display(b)
        return [(x, y)] if x <= y else [(x, hi), (lo, y)]

    def _set_range(self) -> None:
        """The strip's stretches where the mechanism assembles and its singular marks."""
        rectangles = [
            [(a, 0.3), (b, 0.3), (b, 0.7), (a, 0.7)] for a, b in self.assembly_intervals()
        ]
        self.assembled.set_verts(rectangles)
        for kind, mark in self.singular_marks.items():
            xs = [self.display(p.q) for p in self.singular_positions() if p.kind == kind]
            mark.set_data(xs, [0.5] * len(xs))

    def singular_positions(self) -> tuple[SingularPosition, ...]:
        """The singular positions of the geometry drawn (none when not found)."""
        return () if self.singular is None else self.singular.singular

    def image(self) -> np.ndarray[Any, np.dtype[np.uint8]]:
        """The RGB picture of the frame shown (the artists are set to it here)."""
        self.marker.set_xdata([self.display(float(self.q[0]))] * 2)
        return self.renderer.frame(self.k)

    def png(self) -> bytes:
        """The picture of the frame shown as PNG."""
        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(self.image()).save(buf, format="PNG", compress_level=1)
        return buf.getvalue()

    # -- words ------------------------------------------------------------------------

    def text(self, q: float) -> str:
        """A driver value as shown, with its unit."""
        v = self.display(q)
        if not self.revolute:
            return f"{v:.4g}"
        return f"{v:.4g} rad" if self.radians else f"{v:.1f}°"

    def singular_words(self, positions: Sequence[SingularPosition]) -> str:
        """The singular positions in the driver's order; positions of one kind at one
        driver value as shown are on different assembly branches, and said so, with
        the output's angle on each where those differ ("output extreme at 38.6° on 2
        assembly branches (output at 12.5°, 190.1°)")."""
        groups: dict[tuple[str, str], list[SingularPosition]] = {}
        for p in sorted(positions, key=lambda p: (self.display(p.q), p.output_angle)):
            groups.setdefault((p.kind, self.text(p.q)), []).append(p)
        words = []
        for (kind, at), group in groups.items():
            classes = "".join(dict.fromkeys(_notation(p.classification) for p in group))
            if len(group) == 1:
                words.append(f"{KIND_WORDS[kind]} at {at}{classes}")
                continue
            outputs = list(dict.fromkeys(self.angle_text(p.output_angle) for p in group))
            where = f" (output at {', '.join(outputs)})" if len(outputs) == len(group) else ""
            words.append(
                f"{KIND_WORDS[kind]} at {at} on {len(group)} assembly branches{where}{classes}"
            )
        return ", ".join(words)

    def angle_text(self, angle: float) -> str:
        """A link's angle (radians) as shown: degrees in [0, 360) (``radians``: rad)."""
        if self.radians:
            return f"{angle % (2 * math.pi):.4g} rad"
        return f"{math.degrees(angle) % 360.0:.1f}°"

    def summary(self) -> list[str]:
        """What the picture shows, in words: the assembly range, the singular
        positions, the frame shown, and what went wrong."""
        lines = []
        if self.problem is not None:
            lines.append(self.problem)
        d = self.model.drivers[0]
        r = self.singular
        if r is not None and r.input_range.full_turn:
            lines.append(f"assembles over the whole turn of {d}")
        elif r is not None:
            spans = ", ".join(
                f"{self.text(a)} to {self.text(b)}" for a, b in r.input_range.intervals
            )
            lines.append(f"assembles for {d} from {spans}")
        else:
            n = int(self.scene.motion.valid.sum())
            if n == self.frames:
                lines.append("assembles on every frame of the cycle")
            else:
                lines.append(f"assembles on {n} of the cycle's {self.frames} frames")
        if r is not None and r.singular:
            lines.append(f"singular positions: {self.singular_words(r.singular)}")
        elif r is not None:
            lines.append("no singular positions")
        else:
            lines.append(self.singular_note)
        if r is not None:
            for a in r.fold_arcs:
                what = "input locked" if a.kind == "input_limit" else "output dwells"
                span = (
                    f"at {self.text(a.q_from)}"
                    if a.q_to == a.q_from
                    else f"from {self.text(a.q_from)} to {self.text(a.q_to)}"
                )
                lines.append(f"fold arc: {what} {span}{_notation(a.classification)}")
            lines += [f"singular analysis: {w}" for w in r.warnings]
        if not self.assembles:
            lines.append(f"at {d} = {self.text(float(self.q[0]))} the mechanism does not assemble")
        lines += [f"warning: {w}" for w in self.notes]
        return lines


def _notation(c: SingularClass | None) -> str:
    """`` (II/B//П)``: the class of [Four-bar clearances] in brackets, or nothing."""
    return "" if c is None else f" ({c.notation})"


def _singular(mechanism: Mechanism) -> tuple[SingularAnalysis | None, str]:
    """The singular analysis of ``mechanism``, or None and why it has none."""
    from mjstruct.singular.analysis import singular_analysis

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return singular_analysis(mechanism), ""
    except (MechanismError, NumericalError) as exc:
        return None, f"singular positions not found: {exc}"


def _drawn_with(m: Mechanism, joint: str, scale: float) -> list[str]:
    """``joint`` and the joints at its centre on a link it shares (a slider's block)."""
    me = m.joint(joint)
    out = [joint]
    if me.at is None:
        return out
    z = complex(*me.at)
    for j in m.joints:
        if j.id == joint or j.at is None or not set(j.links) & set(me.links):
            continue
        if abs(complex(*j.at) - z) <= 1e-9 * scale:
            out.append(j.id)
    return out


def _merged(spans: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """Overlapping or touching (from, to) spans joined."""
    out: list[tuple[float, float]] = []
    for a, b in sorted(spans):
        if out and a <= out[-1][1] + 1e-9 * max(1.0, abs(b)):
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out
