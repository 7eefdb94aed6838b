"""Gears on a drawing: pitch circles, a mark turning with each gear, tooth counts, and
a cross at each mesh's pitch point.

Owns how the file's gear pairs are drawn (:func:`gear_artists`, moved by the
scheme) and the room they take (:func:`gear_cloud`, for the axes limits). A gear is
drawn once however many meshes it takes part in; a rack's pitch line is not drawn.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from mjstruct.gear_pairs import gear_pairs
from mjstruct.typing import ComplexArray

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

    from matplotlib.artist import Artist
    from matplotlib.axes import Axes

    from mjstruct.kinematics.model import KinematicModel

#: where a frame's anchors are drawn (the scheme's positions: joint id -> z)
At = dict[str, complex]

GEAR_COLOUR = "#2a7f62"


@dataclass(frozen=True)
class DrawnGear:
    """One gear: its link, the joint on its axis, pitch radius and tooth number."""

    link: str
    joint: str
    radius: float
    teeth: int | None


def drawn_gears(model: KinematicModel) -> list[DrawnGear]:
    """Each gear of the file's meshes that has a radius and an axis joint, once."""
    out: dict[tuple[str, str, float], DrawnGear] = {}
    for g in gear_pairs(model.mechanism):
        if g.kind == "rack" or g.radii is None or g.centres is None:
            continue
        for k in range(2):
            teeth = None if g.teeth is None else g.teeth[k]
            key = (g.links[k], g.centres[k], g.radii[k])
            out.setdefault(key, DrawnGear(*key, teeth))
    return list(out.values())


def gear_cloud(model: KinematicModel, anchors: dict[str, ComplexArray]) -> list[ComplexArray]:
    """The extreme points of every pitch circle, each over the frames (for the limits)."""
    return [anchors[g.joint] + g.radius * d for g in drawn_gears(model) for d in (1, -1, 1j, -1j)]


def gear_artists(
    ax: Axes, model: KinematicModel, poses: Mapping[str, Any]
) -> list[tuple[list[Artist], Callable[[At, int], None]]]:
    """Pitch circles (dash-dot), a radius turning with each gear, its tooth count, and
    a cross at each mesh's pitch point: (artists, their update at a frame) for the
    scheme to move (``poses``: the links' poses over the frames)."""
    from matplotlib.patches import Circle

    parts: list[tuple[list[Artist], Callable[[At, int], None]]] = []
    gears = drawn_gears(model)
    for g in gears:
        circle = Circle(
            (0, 0), g.radius, fill=False, ls="-.", lw=1.0, color=GEAR_COLOUR, zorder=1.4,
            gid=f"gear:{g.link}:{g.joint}",
        )  # fmt: skip
        ax.add_patch(circle)
        (mark,) = ax.plot([], [], color=GEAR_COLOUR, lw=1.0, zorder=1.4)
        label = ax.text(
            0, 0, "" if g.teeth is None else f"z = {g.teeth}", fontsize=7, color=GEAR_COLOUR,
            ha="center", va="bottom", zorder=3,
        )  # fmt: skip

        def update(at: At, k: int, g: DrawnGear = g, c: Any = circle, mk: Any = mark,
                   lb: Any = label) -> None:  # fmt: skip
            z = at[g.joint]
            c.center = (z.real, z.imag)
            tip = z + g.radius * complex(poses[g.link].r[k])
            mk.set_data([z.real, tip.real], [z.imag, tip.imag])
            lb.set_position((z.real, z.imag + 0.55 * g.radius))

        parts.append(([circle, mark, label], update))
    for pair in gear_pairs(model.mechanism):
        if pair.kind == "rack" or pair.radii is None or pair.centres is None:
            continue
        (cross,) = ax.plot([], [], marker="x", ms=7, mew=1.5, color=GEAR_COLOUR, ls="")

        def mesh(at: At, k: int, g: Any = pair, cross: Any = cross) -> None:
            a, b = (at[c] for c in g.centres)
            d = b - a
            if abs(d) == 0:
                return
            r1, r2 = g.radii
            s1 = r1 if g.kind == "external" or r1 > r2 else -r1
            p = a + s1 * d / abs(d)
            cross.set_data([p.real], [p.imag])

        parts.append(([cross], mesh))
    return parts
