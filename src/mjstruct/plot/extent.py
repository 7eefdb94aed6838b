"""The room a drawing needs: the axes limits and the footer band below the mechanism.

Owns the extent of a scheme: the limits cover the mechanism over every frame a scene
shows (with its vectors and paths, given as one cloud of points) and keep a band below
it free for the scale bar, the vector keys and the couples' values (two to a row), the
Assur legend and lines of text.  The scene computes its limits here; where each thing
goes inside that band is :mod:`mjstruct.plot.layout`'s.

Examples
--------
>>> footer_rows(("velocity", "acceleration", "paths"), {}, {"velocity": 1.0, "acceleration": 2.0})
2
"""

from __future__ import annotations

from mjstruct.plot.forces import FORCE_LAYERS, ForceLayer
from mjstruct.typing import ComplexArray

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
    legend: int = 0,
    lines: int = 0,
) -> tuple[tuple[float, float, float, float], float]:
    """(limits (x0, x1, y0, y1), footer height) of a drawing whose points are ``cloud``.

    ``cloud`` holds every drawn position over the frames shown (finite values only);
    ``legend`` is the number of entries of the Assur legend, set below the keys, after
    ``lines`` full-width lines of text (what a synthesised mechanism's targets are).
    """
    pad = PAD * scale
    x0, x1 = float(cloud.real.min() - pad), float(cloud.real.max() + pad)
    rows = footer_rows(layers, forces, arrow_scale) + lines + legend_rows(legend)
    footer = (rows + 0.6) * ROW * (x1 - x0)
    limits = (x0, x1, float(cloud.imag.min() - pad - footer), float(cloud.imag.max() + pad))
    return limits, footer


def footer_rows(
    layers: tuple[str, ...], forces: dict[str, ForceLayer], arrow_scale: dict[str, float]
) -> int:
    """Rows of the footer's slots: keys and couples two to a row beside the scale bar
    (at least two: the scale bar's)."""
    slots = len(keyed_layers(layers, arrow_scale)) + sum(len(f.couples) for f in forces.values())
    return max(2, -(-slots // 2))


def legend_rows(entries: int) -> int:
    """Rows of the footer the Assur legend takes (two entries to a row)."""
    return -(-entries // 2)


def keyed_layers(layers: tuple[str, ...], arrow_scale: dict[str, float]) -> list[str]:
    """The vector layers that get a key (those with something to scale)."""
    scale = {x: arrow_scale.get("force" if x in FORCE_LAYERS else x, 0.0) for x in KEYED}
    return [x for x in KEYED if x in layers and scale[x] > 0]
