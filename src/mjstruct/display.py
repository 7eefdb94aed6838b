"""Pictures in notebooks through one seam: the model asks, the drawing side answers.

Owns the hook between the objects that show themselves in a notebook (a
:class:`~mjstruct.mechanism.Mechanism`, a kinematics result) and the drawings that
make their pictures.  Their ``_repr_svg_`` calls :func:`svg`, which hands the object to
the renderer installed with :func:`set_svg_renderer`.  The package installs
:func:`mjstruct.plot.notebook.svg_of` (imported at the first picture), so the model
never imports the drawings and the drawings stay a layer above it.

Examples
--------
>>> previous = set_svg_renderer(lambda obj: f"<svg>{obj}</svg>")
>>> svg(3)
'<svg>3</svg>'
>>> _ = set_svg_renderer(previous)
"""

from __future__ import annotations

from collections.abc import Callable

#: turns an object into SVG text (None: no picture for it)
SvgRenderer = Callable[[object], "str | None"]

_renderer: SvgRenderer | None = None


def set_svg_renderer(render: SvgRenderer | None) -> SvgRenderer | None:
    """Install ``render`` as the notebook renderer; returns the one it replaces."""
    global _renderer
    previous, _renderer = _renderer, render
    return previous


def svg(obj: object) -> str | None:
    """The picture of ``obj`` as SVG text; None when no renderer is installed (a
    notebook then shows the text form)."""
    return None if _renderer is None else _renderer(obj)
