"""Artists around the scheme: the footer's keys and values, the scale bar, the Assur
legend, branch-point marks, the note of a frame that does not assemble, the title.

Owns what explains a drawing rather than shows the mechanism; the places come from
:mod:`mjstruct.plot.layout`.
"""

from __future__ import annotations

from functools import cache
from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.plot.extent import ROW, keyed_layers
from mjstruct.plot.forces import FORCE_LAYERS
from mjstruct.plot.layout import (
    footer_line,
    footer_slot,
    legend_place,
    round_length,
    scale_bar_place,
    title_lines,
)
from mjstruct.plot.scene import Scene
from mjstruct.plot.scheme import angle_text, q_text
from mjstruct.plot.style import ARROW, DRIVER_COLOUR, FORCE_COLOURS, FRAME_COLOUR
from mjstruct.typing import ComplexArray, FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes


class AnnotationArtists:
    """What explains the drawing of ``scene`` on ``ax``, built once, set by :meth:`show`.

    The footer's keys (one per vector layer, each in its fixed slot, shown while its
    layer is) and couples' values, the scale bar and the Assur legend (fixed), the
    branch-point note and star, the note of a frame that does not assemble, the title.
    """

    def __init__(
        self,
        ax: Axes,
        scene: Scene,
        colours: dict[str, Any],
        quivers: dict[str, Any],
        title: bool = True,
        radians: bool = False,
    ) -> None:
        self.ax, self.scene, self.radians = ax, scene, radians
        #: the footer spreads over the axes' width (a tall drawing is widened to them)
        self.xlim: tuple[float, float] = tuple(ax.get_xlim())  # type: ignore[assignment]
        self.keys: dict[str, Any] = {}
        for i, layer in enumerate(keyed_layers(scene.layers, scene.arrow_scale)):
            if layer in quivers:
                self.keys[layer] = self._key(layer, quivers[layer], i)
        self.couples: list[tuple[Any, Any, str, FloatArray, ComplexArray]] = []
        i = len(keyed_layers(scene.layers, scene.arrow_scale))
        s = scene.arrow_scale.get("force", 0.0)
        # a couple's entry lines up with the force keys: its sense where their arrows
        # are, its value where their labels start
        arrow = round_length(ARROW * scene.model.scale / s / 2) * s if s > 0 else 0.0
        for layer in (x for x in FORCE_LAYERS if x in scene.forces):
            for n, (label, at, moment) in enumerate(scene.forces[layer].couples, 1):
                x, y = footer_slot(scene, i, self.xlim)
                i += 1
                colour = FORCE_COLOURS[layer]
                sense = ax.text(
                    x + 0.5 * arrow, y, "", ha="center", va="center", fontsize=11,
                    color=colour, zorder=9, gid=f"couple:{layer}:{n}:sense",
                )  # fmt: skip
                text = ax.annotate(
                    "", (x + arrow, y), xytext=(7.2, 0.0), textcoords="offset points",
                    ha="left", va="center", fontsize=8, color=colour, zorder=9,
                    gid=f"couple:{layer}:{n}",
                )  # fmt: skip
                self.couples.append((text, sense, label, moment, at))
        self.note = ax.text(
            0.5,
            0.5,
            "",
            transform=ax.transAxes,
            ha="center",
            va="center",
            fontsize=10,
            color=DRIVER_COLOUR,
            gid="note",
        )
        self.branch = ax.text(
            0.5,
            0.02,
            "",
            transform=ax.transAxes,
            ha="center",
            va="bottom",
            fontsize=9,
            color=DRIVER_COLOUR,
            gid="branch",
        )
        (self.star,) = ax.plot(
            [], [], ls="none", marker="*", ms=16, color=DRIVER_COLOUR, alpha=0.7, zorder=8,
            gid="branch:star",
        )  # fmt: skip
        slots = len(keyed_layers(scene.layers, scene.arrow_scale)) + len(self.couples)
        lines = 0
        if scene.targets is not None:
            from mjstruct.plot.targets import TARGET_COLOUR

            x, y = footer_line(scene, slots, self.xlim)
            ax.text(x, y, scene.targets.describe(), ha="left", va="center", fontsize=8,
                    color=TARGET_COLOUR, gid="targets:about")  # fmt: skip
            lines = 1
        if "assur" in scene.layers:
            corner = legend_place(scene, slots, self.xlim, lines)
            draw_assur_legend(ax, scene, colours, corner)
        draw_scale_bar(ax, scene, self.xlim)
        self.title = self.subtitle = None
        if title:
            # texts in axes coordinates: set_title costs a tight-bbox pass per frame;
            # the name never changes, the driver values below it do
            name = scene.model.mechanism.name or "mechanism"
            fig: Any = ax.get_figure(root=True)
            width = fig.get_figwidth() * ax.get_position().width
            self.title = ax.annotate(
                "\n".join(title_lines(name, width)), (0.5, 1.0), xycoords="axes fraction",
                xytext=(0, 12), textcoords="offset points", ha="center", va="bottom",
                fontsize=10, gid="title",
            )  # fmt: skip
            self.subtitle = ax.text(
                0.5, 1.0, "", transform=ax.transAxes, ha="center", va="bottom", fontsize=10,
                gid="title:q",
            )  # fmt: skip

    @property
    def changing(self) -> list[Any]:
        """The artists :meth:`show` changes other than the keys (which only toggle)."""
        texts = [a for text, sense, _, _, _ in self.couples for a in (text, sense)]
        return [*texts, self.note, self.branch, self.star, self.subtitle]

    def _key(self, layer: str, quiver: Any, slot: int) -> Any:
        scene = self.scene
        force = layer in FORCE_LAYERS
        s = scene.arrow_scale["force" if force else layer]
        length = round_length(ARROW * scene.model.scale / s / 2)
        unit = "units" if force else ("units/s" if layer == "velocity" else "units/s²")
        x, y = footer_slot(scene, slot, self.xlim)
        key = _key_class()(
            quiver,
            x + length * s,  # the key's arrow ends there (its label follows): from the slot
            y,
            length,
            f"{layer} {length:g} {unit}",
            labelpos="E",
            coordinates="data",
            labelcolor=quiver.get_facecolor()[0],
            fontproperties={"size": 8},
        )
        key.set_gid(f"key:{layer}")
        self.ax.add_artist(key)
        return key

    def show(self, k: int, shown: dict[str, Any], at: dict[str, complex] | None) -> None:
        """Set the annotations to frame ``k``: ``shown`` the vector layers drawn there,
        ``at`` the positions (None: the frame does not assemble)."""
        scene = self.scene
        for layer, key in self.keys.items():
            key.set_visible(layer in shown)
        for text, sense, label, moment, where in self.couples:
            visible = at is not None and np.isfinite(where[k]) and np.isfinite(moment[k])
            text.set_visible(bool(visible))
            sense.set_visible(bool(visible) and moment[k] != 0)
            if visible:
                text.set_text(f"{label} = {moment[k] + 0.0:.3g}")
                sense.set_text("↺" if moment[k] > 0 else "↻")
        self.note.set_visible(at is None)
        q = q_text(scene, k, self.radians)
        if at is None:
            self.note.set_text(f"q = {q}: the mechanism does not assemble")
        events = [e for e in scene.motion.events if e.frame == k]
        self.branch.set_visible(bool(events))
        self.branch.set_text(
            "\n".join(
                f"{e.kind} at joint {e.joint} "
                f"(q = {angle_text(e.q, self.radians) if self._revolute else f'{e.q:.4g}'})"
                for e in events
            )
        )
        stars = [at[e.joint] for e in events if at is not None and e.joint in at]
        self.star.set_data([z.real for z in stars], [z.imag for z in stars])
        self.star.set_visible(bool(stars))
        if self.subtitle is not None:
            self.subtitle.set_text(f"q = {q}")

    @property
    def _revolute(self) -> bool:
        """Whether the first driver turns (its q is an angle)."""
        model = self.scene.model
        return model.mechanism.joint(model.drivers[0]).kind == "R"


@cache
def _key_class() -> Any:
    """A quiver key that stays hidden while its layer is (matplotlib's draws regardless);
    made on first use, since matplotlib is imported only when something is drawn."""
    from matplotlib.quiver import QuiverKey

    class Key(QuiverKey):
        def draw(self, renderer: Any) -> None:
            if self.get_visible():
                super().draw(renderer)

    return Key


def draw_scale_bar(ax: Axes, scene: Scene, xlim: tuple[float, float] | None = None) -> None:
    """A bar of a round length at the left of the footer, clear of the mechanism."""
    x0, x1, _, _ = scene.limits
    xa, ya, length = scale_bar_place(scene, xlim)
    tick = 0.15 * ROW * (x1 - x0)
    ax.plot(
        [xa, xa + length, xa + length, xa + length, xa, xa],
        [ya, ya, ya + tick, ya - tick, ya - tick, ya + tick],
        color="black",
        lw=1.2,
        gid="scalebar",
    )
    ax.text(
        xa + length / 2,
        ya + 1.5 * tick,
        f"{length:g}",
        ha="center",
        va="bottom",
        fontsize=8,
        gid="scalebar:length",
    )


def draw_assur_legend(
    ax: Axes, scene: Scene, colours: dict[str, Any], corner: tuple[float, float]
) -> None:
    """The Assur groups' colours as a legend in the footer, two entries to a row, its
    top-left corner at ``corner`` (length units): below the drawing, never on it."""
    from matplotlib.lines import Line2D

    from mjstruct.structure.assur import roman

    d = scene.decomposition
    assert d is not None
    handles = [Line2D([], [], lw=5, color=FRAME_COLOUR, label=f"frame {d.frame}")]
    for dr, _, driven in d.initial:
        handles.append(
            Line2D([], [], lw=5, color=colours[driven], label=f"driven link {driven} ({dr})")
        )
    for g, group in enumerate(d.groups):
        text = f"group {g + 1}: class {roman(group.klass)}, links {', '.join(group.links)}"
        handles.append(Line2D([], [], lw=5, color=colours[group.links[0]], label=text))
    legend = ax.legend(
        handles=handles,
        loc="upper left",
        bbox_to_anchor=corner,
        bbox_transform=ax.transData,
        ncols=2,
        fontsize=7,
        frameon=False,
        borderaxespad=0.0,
        borderpad=0.0,
        labelspacing=0.45,
        handlelength=1.8,
        columnspacing=1.5,
    )
    legend.set_gid("legend:assur")
