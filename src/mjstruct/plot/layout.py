"""Where things go on a drawing: the axes limits, the footer band and the figure shape.

Owns the page layout of a scheme: where the scale bar, the vector keys, the couples'
values (two to a row), the legend and the title go in the footer band below the
mechanism; the figure follows the limits' shape; lengths shown as keys are round
(1, 2 or 5 × 10^k).

The room a drawing needs (limits and footer height) is :mod:`mjstruct.plot.extent`'s,
which the scene reads; this module places things in that room.

Examples
--------
>>> round_length(0.37), round_length(180.0)
(0.2, 100.0)
"""

from __future__ import annotations

import math
import textwrap
from typing import TYPE_CHECKING, Any

from mjstruct.plot.extent import ROW

if TYPE_CHECKING:
    from mjstruct.plot.scene import Scene


def round_length(x: float) -> float:
    """The largest 1, 2 or 5 × 10^k not above ``x``."""
    if x <= 0 or not math.isfinite(x):
        return 1.0
    e = math.floor(math.log10(x))
    for f in (5, 2, 1):
        if f * 10**e <= x:
            return float(f * 10**e)
    return float(10**e)


def _footer_top(scene: Scene) -> tuple[float, float]:
    """(top of the footer's first row, the row height) in length units."""
    x0, x1, y0, _ = scene.limits
    w = x1 - x0
    return y0 + scene.footer - 0.3 * ROW * w, ROW * w


def _across(scene: Scene, xlim: tuple[float, float] | None) -> tuple[float, float]:
    """(left, width) the footer spreads over: the axes' x range when given (a drawing
    widened to its axes), else the scene's."""
    x0, x1 = xlim if xlim is not None else scene.limits[:2]
    return x0, x1 - x0


def footer_slot(
    scene: Scene, i: int, xlim: tuple[float, float] | None = None
) -> tuple[float, float]:
    """Where the ``i``-th key or couple value of the footer starts (two to a row)."""
    x0, w = _across(scene, xlim)
    top, row = _footer_top(scene)
    return x0 + (0.30 + 0.36 * (i % 2)) * w, top - (i // 2 + 0.5) * row


def scale_bar_place(
    scene: Scene, xlim: tuple[float, float] | None = None
) -> tuple[float, float, float]:
    """(left end x, y, length) of the scale bar: a round length at the footer's left,
    short enough to stay clear of the keys."""
    x0, w = _across(scene, xlim)
    length = round_length(min(0.25 * scene.model.scale, 0.2 * w))
    if scene.footer <= 0:  # a scene built by hand: the lower left
        sx0, sx1, y0, y1 = scene.limits
        return x0 + 0.04 * w, y0 + 0.05 * (y1 - y0) - 0.2 * ROW * (sx1 - sx0), length
    top, row = _footer_top(scene)
    return x0 + 0.04 * w, top - 1.2 * row, length


def legend_place(
    scene: Scene, slots: int, xlim: tuple[float, float] | None = None, lines: int = 0
) -> tuple[float, float]:
    """Top-left corner of the Assur legend: below the footer's ``slots`` keys and values
    and ``lines`` lines of text."""
    x0, w = _across(scene, xlim)
    top, row = _footer_top(scene)
    return x0 + 0.04 * w, top - (max(2, -(-slots // 2)) + lines) * row


def footer_line(
    scene: Scene, slots: int, xlim: tuple[float, float] | None = None
) -> tuple[float, float]:
    """Where a full-width line of the footer starts: below the ``slots`` keys."""
    x0, w = _across(scene, xlim)
    top, row = _footer_top(scene)
    return x0 + 0.04 * w, top - (max(2, -(-slots // 2)) + 0.5) * row


#: the drawing's height (inches, title left out) at the usual width of 7 inches, at most
TALLEST = 8.0
#: height (inches) of one line of a drawing's title (10 points and the line spacing)
TITLE_LINE = 0.19


def title_lines(name: str, width: float) -> list[str]:
    """A drawing's name broken into lines that fit ``width`` inches at 10 points."""
    chars = max(20, int(width * 72 / (10 * 0.58)))
    return textwrap.wrap(name, chars, break_long_words=True) or [name]


def _title_room(scene: Scene, width: float) -> float:
    """Height (inches) above the drawing for its title: the name's lines and q's."""
    return (len(title_lines(scene.model.mechanism.name or "mechanism", width)) + 1) * TITLE_LINE


def figure_for(scene: Scene, width: float = 7.0, pyplot: bool = True) -> Any:
    """A figure whose shape follows the scene's limits, with room for the title.

    ``pyplot=False``: a figure pyplot does not track (nothing to close, never shown).
    """
    x0, x1, y0, y1 = scene.limits
    ratio = min(2.0, max(0.5, (y1 - y0) / (x1 - x0)))
    # a tall mechanism is drawn narrower rather than taller than a page
    width = max(0.5 * width, min(width, TALLEST * width / 7.0 / ratio))
    size = (width, width * ratio + _title_room(scene, width) + 0.12)
    if not pyplot:
        from matplotlib.figure import Figure

        return Figure(figsize=size)
    import matplotlib.pyplot as plt

    return plt.figure(figsize=size)


def drawing_figure(
    scene: Scene, width: float = 7.0, pyplot: bool = True, title: bool = True
) -> tuple[Any, Any]:
    """(figure, axes) for a drawing of ``scene``: the figure of :func:`figure_for` and
    axes filling it below the title's room (the drawing's limits are widened to the
    axes' shape, :func:`fill_axes`, so no margin is left)."""
    fig = figure_for(scene, width=width, pyplot=pyplot)
    height = fig.get_figheight()
    room = _title_room(scene, fig.get_figwidth()) + 0.06 if title else 0.0
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0 - room / height))
    return fig, ax


def equal_scale(ax: Any) -> None:
    """One length unit as long on both axes of ``ax``, at the limits it has now.

    matplotlib's own equal aspect gives up on spans below about 1e-35 (a mechanism of
    size 1e-45 came out squashed, its pins ellipses); the box's shape computed here
    from the limits, a ratio of two spans, holds at any size a double can hold.
    """
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    ax.set_xlim(x0, x1)  # fixed: artists added later must not move them
    ax.set_ylim(y0, y1)
    ax.set_box_aspect(abs((y1 - y0) / (x1 - x0)))


def fill_axes(limits: tuple[float, float, float, float], ax: Any) -> tuple[float, ...]:
    """``limits`` widened (on both sides of the short direction) to the shape of
    ``ax``, so that an equal-aspect drawing fills its axes instead of leaving margins."""
    x0, x1, y0, y1 = limits
    box = ax.get_position()
    fig = ax.get_figure(root=True)
    shape = (box.height * fig.get_figheight()) / (box.width * fig.get_figwidth())
    dx, dy = x1 - x0, y1 - y0
    if dy < shape * dx:
        grow = 0.5 * (shape * dx - dy)
        return x0, x1, y0 - grow, y1 + grow
    grow = 0.5 * (dy / shape - dx)
    return x0 - grow, x1 + grow, y0, y1
