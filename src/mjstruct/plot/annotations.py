"""Artists around the scheme: the footer's keys and values, the scale bar, the Assur
legend, branch-point marks, the note of a frame that does not assemble, the title.

Owns what explains a drawing rather than shows the mechanism; the places come from
:mod:`mjstruct.plot.layout`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.plot.forces import FORCE_LAYERS
from mjstruct.plot.layout import ROW, footer_slot, keyed_layers, round_length
from mjstruct.plot.scene import Scene
from mjstruct.plot.style import ARROW, DRIVER_COLOUR, FORCE_COLOURS, FRAME_COLOUR

if TYPE_CHECKING:
    from matplotlib.axes import Axes


def draw_footer(ax: Axes, scene: Scene, k: int, quivers: dict[str, Any]) -> None:
    """Keys of the vector layers and the couples' values, two to a row below the drawing.

    The slots are fixed by the scene (not the frame), so an animation's keys keep
    their places; a layer with nothing drawn at this frame leaves its slot empty.
    """
    keyed = keyed_layers(scene.layers, scene.arrow_scale)
    for i, layer in enumerate(keyed):
        quiver = quivers.get(layer)
        if quiver is None:
            continue
        force = layer in FORCE_LAYERS
        s = scene.arrow_scale["force" if force else layer]
        key = round_length(ARROW * scene.model.scale / s / 2)
        unit = "units" if force else ("units/s" if layer == "velocity" else "units/s²")
        x, y = footer_slot(scene, i)
        qk = ax.quiverkey(
            quiver,
            x,
            y,
            key,
            f"{layer} {key:g} {unit}",
            labelpos="E",
            coordinates="data",
            labelcolor=quiver.get_facecolor()[0],
            fontproperties={"size": 8},
        )
        qk.set_gid(f"key:{layer}")
    i = len(keyed)
    for layer in (x for x in FORCE_LAYERS if x in scene.forces):
        for label, at, moment in scene.forces[layer].couples:
            x, y = footer_slot(scene, i)
            i += 1
            if not (np.isfinite(at[k]) and np.isfinite(moment[k])):
                continue
            ax.text(
                x,
                y,
                f"{label} = {moment[k] + 0.0:.3g}",
                ha="left",
                va="center",
                fontsize=8,
                color=FORCE_COLOURS[layer],
                zorder=9,
                gid=f"couple:{layer}",
            )


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


def draw_branch_marks(ax: Axes, scene: Scene, k: int, at: dict[str, complex]) -> None:
    for e in scene.motion.events:
        if e.frame != k:
            continue
        ax.text(
            0.5,
            0.02,
            f"{e.kind} at joint {e.joint} (q = {e.q:.4g})",
            transform=ax.transAxes,
            ha="center",
            va="bottom",
            fontsize=9,
            color=DRIVER_COLOUR,
            gid="branch",
        )
        z = at.get(e.joint)
        if z is not None:
            ax.plot(
                [z.real],
                [z.imag],
                marker="*",
                ms=16,
                color=DRIVER_COLOUR,
                alpha=0.7,
                zorder=8,
                gid="branch",
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
