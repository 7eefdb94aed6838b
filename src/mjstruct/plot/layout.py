"""Where things go on a drawing: the axes limits, the footer band and the figure shape.

Owns the page layout of a scheme: the limits cover the mechanism over every frame a
scene shows (with its vectors and paths) and keep a band below it free for the scale
bar, the vector keys and the couples' values (two to a row); the figure follows the
limits' shape; lengths shown as keys are round (1, 2 or 5 × 10^k).

Examples
--------
>>> round_length(0.37), round_length(180.0)
(0.2, 100.0)
>>> footer_rows(("velocity", "acceleration", "paths"), {}, {"velocity": 1.0, "acceleration": 2.0})
2
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from mjstruct.plot.forces import FORCE_LAYERS, ForceLayer
from mjstruct.typing import ComplexArray

if TYPE_CHECKING:
    from mjstruct.plot.scene import Scene

#: the vector layers in the order their keys are listed below the drawing
KEYED = ("velocity", "acceleration", "loads", "inertia", "reactions")
#: height of a row of the footer (scale bar, keys, couples) over the drawing's width
ROW = 0.036
#: margin around the mechanism as a fraction of its size
PAD = 0.12


def drawing_limits(
    cloud: ComplexArray,
    scale: float,
    layers: tuple[str, ...],
    forces: dict[str, ForceLayer],
    arrow_scale: dict[str, float],
) -> tuple[tuple[float, float, float, float], float]:
    """(limits (x0, x1, y0, y1), footer height) of a drawing whose points are ``cloud``.

    ``cloud`` holds every drawn position over the frames shown (finite values only).
    """
    pad = PAD * scale
    x0, x1 = float(cloud.real.min() - pad), float(cloud.real.max() + pad)
    rows = footer_rows(layers, forces, arrow_scale)
    footer = (rows + 0.6) * ROW * (x1 - x0)
    limits = (x0, x1, float(cloud.imag.min() - pad - footer), float(cloud.imag.max() + pad))
    return limits, footer


def footer_rows(
    layers: tuple[str, ...], forces: dict[str, ForceLayer], arrow_scale: dict[str, float]
) -> int:
    """Rows of the footer: keys and couples two to a row beside the scale bar (>= 2)."""
    slots = len(keyed_layers(layers, arrow_scale)) + sum(len(f.couples) for f in forces.values())
    return max(2, -(-slots // 2))


def keyed_layers(layers: tuple[str, ...], arrow_scale: dict[str, float]) -> list[str]:
    """The vector layers that get a key (those with something to scale)."""
    scale = {x: arrow_scale.get("force" if x in FORCE_LAYERS else x, 0.0) for x in KEYED}
    return [x for x in KEYED if x in layers and scale[x] > 0]


def round_length(x: float) -> float:
    """The largest 1, 2 or 5 × 10^k not above ``x``."""
    if x <= 0 or not math.isfinite(x):
        return 1.0
    e = math.floor(math.log10(x))
    for f in (5, 2, 1):
        if f * 10**e <= x:
            return float(f * 10**e)
    return float(10**e)


def footer_slot(scene: Scene, i: int) -> tuple[float, float]:
    """Where the ``i``-th key or couple value of the footer starts (two to a row)."""
    x0, x1, y0, _ = scene.limits
    w = x1 - x0
    top = y0 + scene.footer - 0.3 * ROW * w
    return x0 + (0.30 + 0.36 * (i % 2)) * w, top - (i // 2 + 0.5) * ROW * w


def figure_for(scene: Scene, width: float = 7.0, pyplot: bool = True) -> Any:
    """A figure whose shape follows the scene's limits (title room included).

    ``pyplot=False``: a figure pyplot does not track (nothing to close, never shown).
    """
    x0, x1, y0, y1 = scene.limits
    ratio = min(2.0, max(0.5, (y1 - y0) / (x1 - x0)))
    size = (width, width * ratio + 0.6)
    if not pyplot:
        from matplotlib.figure import Figure

        return Figure(figsize=size)
    import matplotlib.pyplot as plt

    return plt.figure(figsize=size)
