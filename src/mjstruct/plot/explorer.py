"""An interactive explorer of a mechanism in Jupyter: sliders for its driver and joints.

Owns :func:`explore` and :class:`Explorer`, the widgets (ipywidgets, the optional
``notebook`` extra) around an :class:`~mjstruct.plot.explorer_view.ExplorerView`: a
slider for the driver (its angle in degrees from 0 to 360, or its slide), an x and a
y slider for each joint asked for, the picture (the drawing with the traced paths,
and below it the driver's range: where the mechanism assembles and its singular
positions, with a line at the driver's value) and a few lines of text saying the
same in words.  Moving the driver only sets the drawing's artists to another frame of
the cycle; moving a joint rebuilds the mechanism with the joint there and solves it
again (see :mod:`mjstruct.plot.explorer_view`).  A geometry that cannot be drawn is
said in the text, in red, and the picture keeps the last one that could.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> ex = explore(read_mechanism(example_path("six-bar-mj-slider")), joints=["B", "O2"])
>>> ex.driver.value = 90.0                      # what dragging the slider does
>>> round(float(np.degrees(ex.view.q[0])), 6)
90.0
>>> ex.sliders["B"][0].value += 0.1             # B's x slider
>>> round(ex.view.centre("B").real, 3)
2.715
>>> "assembles over the whole turn of O1" in ex.message.value
True
"""

from __future__ import annotations

import html
import importlib.util
from collections.abc import Iterable
from typing import Any

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.mechanism import Mechanism
from mjstruct.plot.explorer_view import ExplorerView
from mjstruct.plot.style import DRIVER_COLOUR

__all__ = ["NOTEBOOK_EXTRA", "Explorer", "explore"]

#: the extra that installs ipywidgets
NOTEBOOK_EXTRA = "mjstruct[notebook]"


def explore(
    mechanism: Mechanism,
    joints: Iterable[str] = (),
    *,
    frames: int = 360,
    paths: Iterable[str] | None = None,
    reach: float = 0.5,
    stroke: float = 1.0,
    radians: bool = False,
    dpi: int = 80,
    width: float = 6.0,
) -> Explorer:
    """An explorer of ``mechanism`` in a notebook: the driver and joints on sliders.

    Show it as a cell's last value (or with ``display``).  Dragging the driver's
    slider moves the mechanism over its cycle (the first driver's value; several
    drivers move together, as in an animation); dragging a joint's x or y slider moves
    that joint's centre in the reference configuration (and a slider's block drawn at
    it) and solves the mechanism again: the drawing, the traced paths, where it
    assembles and its singular positions follow.

    Parameters
    ----------
    mechanism : a mechanism with geometry, frame and drivers.
    joints : ids of the joints to put on sliders.
    frames : frames of the cycle (a revolute driver's slider steps by 360 / frames°).
    paths : ids of joints or points whose paths are drawn (default: the file's
        points, else the moving joints).
    reach : how far a joint's sliders go each way, as a fraction of the mechanism's
        size (the largest distance between two joint centres).
    stroke : a prismatic driver's slide over the cycle, from its reference (length
        units; as ``animate --stroke``).
    radians : driver angles in radians (default: degrees, 0 to 360).
    dpi, width : the picture's resolution and width (inches).

    Raises
    ------
    MechanismError
        ipywidgets is not installed (naming the ``notebook`` extra), the mechanism
        cannot be drawn, an unknown joint, a ``reach`` that is not positive.
    """
    if importlib.util.find_spec("ipywidgets") is None:
        raise MechanismError(
            f"explore: needs ipywidgets, which is not installed (pip install '{NOTEBOOK_EXTRA}')"
        )
    if not (isinstance(reach, int | float) and np.isfinite(reach) and reach > 0):
        raise MechanismError(f"reach: must be a finite number > 0, got {reach!r}")
    view = ExplorerView(mechanism, joints, frames=frames, paths=paths, dpi=dpi, width=width,
                        radians=radians, stroke=stroke)  # fmt: skip
    return Explorer(view, float(reach))


class Explorer:
    """The explorer's widgets; :attr:`widget` is what a notebook shows.

    Attributes
    ----------
    view : the mechanism, its scene and its picture (no widgets).
    driver : the driver's slider.
    sliders : joint id -> (x slider, y slider).
    image : the picture (PNG).
    message : what the picture shows in words (HTML).
    widget : all of them in a column.
    """

    def __init__(self, view: ExplorerView, reach: float = 0.5) -> None:
        import ipywidgets as w

        self.view = view
        lo, hi, step = view.driver_range()
        self.driver = w.FloatSlider(
            value=view.value,
            min=lo,
            max=hi,
            step=step,
            description=f"{view.model.drivers[0]} ({view.unit})",
            readout_format=".1f" if view.revolute and not view.radians else ".4g",
            layout=w.Layout(width="95%"),
        )
        self.driver.observe(self._on_driver, names="value")
        size = view.model.scale
        self.sliders: dict[str, tuple[Any, Any]] = {}
        rows = []
        for joint in view.joints:
            z = view.centre(joint)
            pair = tuple(
                w.FloatSlider(
                    value=v,
                    min=v - reach * size,
                    max=v + reach * size,
                    step=size / 500,
                    description=f"{joint} {axis}",
                    readout_format=".4g",
                )
                for axis, v in (("x", z.real), ("y", z.imag))
            )
            for s in pair:
                s.observe(self._on_joint(joint), names="value")
            self.sliders[joint] = (pair[0], pair[1])
            rows.append(w.HBox(list(pair)))
        self.image = w.Image(value=view.png(), format="png")
        self.message = w.HTML(value=self._words())
        self.widget = w.VBox([self.image, self.driver, *rows, self.message])

    def _repr_mimebundle_(self, **kwargs: Any) -> Any:
        return self.widget._repr_mimebundle_(**kwargs)

    def _on_driver(self, change: dict[str, Any]) -> None:
        self.view.set_driver(float(change["new"]))
        self.refresh()

    def _on_joint(self, joint: str) -> Any:
        def moved(change: dict[str, Any]) -> None:
            x, y = self.sliders[joint]
            self.view.move_joint(joint, float(x.value), float(y.value))
            self.refresh()

        return moved

    def refresh(self) -> None:
        """Draw the picture and the words again (the sliders call it)."""
        self.image.value = self.view.png()
        self.message.value = self._words()

    def _words(self) -> str:
        lines = [html.escape(line) for line in self.view.summary()]
        if self.view.problem is not None:
            lines[0] = f'<b style="color:{DRIVER_COLOUR}">{lines[0]}</b>'
        return "<br>".join(lines)
