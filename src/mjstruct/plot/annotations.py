"""Artists around the scheme: the footer's keys and values, the scale bar, the Assur
legend, branch-point marks, the note of a frame that does not assemble, the title.

Owns what explains a drawing rather than shows the mechanism; the places come from
:mod:`mjstruct.plot.layout`.
"""

from __future__ import annotations

from functools import cache
from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.plot.forces import FORCE_LAYERS
from mjstruct.plot.layout import ROW, footer_slot, keyed_layers, round_length
from mjstruct.plot.scene import Scene
from mjstruct.plot.scheme import q_text
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
    ) -> None:
        self.ax, self.scene = ax, scene
        self.keys: dict[str, Any] = {}
        for i, layer in enumerate(keyed_layers(scene.layers, scene.arrow_scale)):
            if layer in quivers:
                self.keys[layer] = self._key(layer, quivers[layer], i)
        self.couples: list[tuple[Any, str, FloatArray, ComplexArray]] = []
        i = len(keyed_layers(scene.layers, scene.arrow_scale))
        for layer in (x for x in FORCE_LAYERS if x in scene.forces):
            for label, at, moment in scene.forces[layer].couples:
                x, y = footer_slot(scene, i)
                i += 1
                text = ax.text(
                    x,
                    y,
                    "",
                    ha="left",
                    va="center",
                    fontsize=8,
                    color=FORCE_COLOURS[layer],
                    zorder=9,
                    gid=f"couple:{layer}",
                )
                self.couples.append((text, label, moment, at))
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
            gid="branch",
        )  # fmt: skip
        if "assur" in scene.layers:
            draw_assur_legend(ax, scene, colours)
        draw_scale_bar(ax, scene)
        self.title = self.subtitle = None
        if title:
            # texts in axes coordinates: set_title costs a tight-bbox pass per frame;
            # the name never changes, the driver values below it do
            name = scene.model.mechanism.name or "mechanism"
            self.title = ax.annotate(
                name, (0.5, 1.0), xycoords="axes fraction", xytext=(0, 12),
                textcoords="offset points", ha="center", va="bottom", fontsize=10, gid="title",
            )  # fmt: skip
            self.subtitle = ax.text(
                0.5, 1.0, "", transform=ax.transAxes, ha="center", va="bottom", fontsize=10,
                gid="title",
            )  # fmt: skip

    @property
    def changing(self) -> list[Any]:
        """The artists :meth:`show` changes other than the keys (which only toggle)."""
        texts = [text for text, _, _, _ in self.couples]
        return [*texts, self.note, self.branch, self.star, self.subtitle]

    def _key(self, layer: str, quiver: Any, slot: int) -> Any:
        scene = self.scene
        force = layer in FORCE_LAYERS
        s = scene.arrow_scale["force" if force else layer]
        length = round_length(ARROW * scene.model.scale / s / 2)
        unit = "units" if force else ("units/s" if layer == "velocity" else "units/s²")
        x, y = footer_slot(scene, slot)
        key = _key_class()(
            quiver,
            x,
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
        for text, label, moment, where in self.couples:
            visible = at is not None and np.isfinite(where[k]) and np.isfinite(moment[k])
            text.set_visible(bool(visible))
            if visible:
                text.set_text(f"{label} = {moment[k] + 0.0:.3g}")
        self.note.set_visible(at is None)
        if at is None:
            self.note.set_text(f"q = {q_text(scene, k)}: the mechanism does not assemble")
        events = [e for e in scene.motion.events if e.frame == k]
        self.branch.set_visible(bool(events))
        self.branch.set_text(
            "\n".join(f"{e.kind} at joint {e.joint} (q = {e.q:.4g})" for e in events)
        )
        stars = [at[e.joint] for e in events if at is not None and e.joint in at]
        self.star.set_data([z.real for z in stars], [z.imag for z in stars])
        self.star.set_visible(bool(stars))
        if self.subtitle is not None:
            self.subtitle.set_text(f"q = {q_text(scene, k)}")


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


def draw_scale_bar(ax: Axes, scene: Scene) -> None:
    """A bar of a round length at the left of the footer, clear of the mechanism."""
    x0, x1, y0, y1 = scene.limits
    length = round_length(0.25 * scene.model.scale)
    w = x1 - x0
    xa = x0 + 0.04 * w
    # the footer's middle; without a footer (a scene built by hand) the lower left
    ya = y0 + (scene.footer / 2 if scene.footer > 0 else 0.05 * (y1 - y0)) - 0.2 * ROW * w
    tick = 0.15 * ROW * w
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
        gid="scalebar",
    )


def draw_assur_legend(ax: Axes, scene: Scene, colours: dict[str, Any]) -> None:
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
    ax.legend(handles=handles, loc="upper left", fontsize=7, framealpha=0.85)
