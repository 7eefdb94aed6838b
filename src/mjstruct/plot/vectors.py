"""Artists of the vector layers: velocity and acceleration arrows, force arrows, couples.

Owns the arrows drawn over the scheme at one frame: velocity v = σ W and acceleration
a = κ W² at each moving joint and point, and the force layers' arrows (on one force
scale) and couples (an arc turning their way).  Every arrow carries a thin white
outline so it stays visible on a link of any colour.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.plot.forces import FORCE_LAYERS
from mjstruct.plot.scene import Scene, vector_sites
from mjstruct.plot.style import FORCE_COLOURS, HALO
from mjstruct.typing import ComplexArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes


def draw_vectors(
    ax: Axes, scene: Scene, k: int, layer: str, order: int, colour: str
) -> Any | None:
    """The velocity or acceleration arrows at frame ``k`` (None when there are none)."""
    sites = vector_sites(scene.model, scene.motion, order, scene.speed)
    if not sites:
        return None
    z = np.array([p[k] for p, _ in sites])
    v = np.array([w[k] for _, w in sites])
    s = scene.arrow_scale.get(layer, 0.0)
    if s <= 0 or not np.isfinite(v).all():
        return None
    return quiver(ax, z, v, s, colour, layer, width=0.004)


def quiver(
    ax: Axes, z: ComplexArray, v: ComplexArray, s: float, colour: str, gid: str, width: float
) -> Any:
    return ax.quiver(
        z.real,
        z.imag,
        v.real,
        v.imag,
        angles="xy",
        scale_units="xy",
        scale=1.0 / s,
        color=colour,
        edgecolor=HALO,
        linewidth=0.7,
        width=width,
        zorder=7,
        gid=gid,
    )


def draw_forces(ax: Axes, scene: Scene, k: int) -> dict[str, Any]:
    """Arrows of the force layers on one scale, couples as arcs turning their way."""
    s = scene.arrow_scale.get("force", 0.0)
    out: dict[str, Any] = {}
    for layer in (x for x in FORCE_LAYERS if x in scene.forces):
        fl = scene.forces[layer]
        colour = FORCE_COLOURS[layer]
        pts = [(at[k], f[k]) for _, at, f in fl.arrows if np.isfinite(at[k]) and np.isfinite(f[k])]
        if pts and s > 0:
            z = np.array([p for p, _ in pts])
            f = np.array([v for _, v in pts])
            out[layer] = quiver(ax, z, f, s, colour, layer, width=0.005)
        for _, at, moment in fl.couples:
            if np.isfinite(at[k]) and np.isfinite(moment[k]) and moment[k] != 0:
                _turn(ax, scene, complex(at[k]), float(moment[k]), colour, f"torque:{layer}")
    return out


def _turn(ax: Axes, scene: Scene, c: complex, sense: float, colour: str, gid: str) -> None:
    """A three-quarter arc around ``c`` with its head the way ``sense`` turns."""
    from matplotlib.patches import FancyArrowPatch
    from matplotlib.path import Path

    r = 2.6 * scene.pin
    t = np.linspace(-0.75, 0.75, 24) * np.pi
    if sense < 0:
        t = t[::-1]
    arc = c + r * np.exp(1j * t)
    ax.add_artist(
        FancyArrowPatch(
            path=Path(np.column_stack([arc.real, arc.imag])),
            arrowstyle="-|>",
            mutation_scale=9,
            color=colour,
            lw=1.4,
            zorder=7,
            gid=gid,
        )
    )
