"""Notebook pictures: small SVGs of mechanisms and kinematics results.

Owns what :class:`~mjstruct.mechanism.Mechanism` and the kinematics result show in a
notebook: :func:`svg_of` is the renderer the package installs in
:mod:`mjstruct.display`.  Kept small and quick: a mechanism with geometry is drawn at
its reference configuration (a chain without it as an atlas panel), a kinematics
result as that drawing with the paths of its moving joints.  Figures are built without
pyplot (nothing is shown twice by an inline backend) and fonts stay text in the SVG.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> svg = mechanism_svg(read_mechanism(example_path("four-bar")))
>>> svg.startswith("<?xml") and len(svg) < 60_000
True
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

from mjstruct.errors import MechanismError
from mjstruct.mechanism import Mechanism

if TYPE_CHECKING:
    from mjstruct.kinematics.result import KinematicsResult

#: figure width (inches) of a notebook picture
WIDTH = 4.2


def _svg(fig: Any) -> str:
    import matplotlib

    buf = io.StringIO()
    with matplotlib.rc_context({"svg.fonttype": "none"}):
        fig.savefig(buf, format="svg", bbox_inches="tight")
    return buf.getvalue()


def _figure(height: float = WIDTH) -> Any:
    from matplotlib.figure import Figure

    return Figure(figsize=(WIDTH, height))


def mechanism_svg(m: Mechanism) -> str:
    """SVG of ``m``: the kinematic scheme at the reference configuration when the file
    has geometry, frame and drivers, else the chain as an atlas panel."""
    if m.frame is not None and m.drivers and all(j.at is not None for j in m.joints):
        from mjstruct.kinematics.model import KinematicModel
        from mjstruct.plot.drawing import draw_scene, drawing_figure, scene_at

        try:
            scene = scene_at(KinematicModel.build(m))
        except MechanismError:
            scene = None
        if scene is not None:
            fig, ax = drawing_figure(scene, width=WIDTH, pyplot=False)
            draw_scene(scene, ax=ax)
            return _svg(fig)
    from mjstruct.plot.atlas_sheet import draw_chain

    fig = _figure(WIDTH * 0.8)
    draw_chain(fig.add_subplot(), m, caption=m.name or None)
    return _svg(fig)


def kinematics_svg(result: KinematicsResult) -> str:
    """SVG of a kinematics result: the mechanism at its first frame with the paths of the
    moving joints and points over the result's frames."""
    import numpy as np

    from mjstruct.plot.drawing import Scene, draw_scene, drawing_figure, scene_at

    base = scene_at(result.model, result.q[0])
    paths = {}
    for kind in (result.joints, result.points):
        for pid, v in kind.items():
            z = np.where(result.valid, v["x"] + 1j * v["y"], np.nan + 0j)
            if np.nanmax(np.abs(z - z[0]), initial=0.0) > 1e-9 * result.model.scale:
                paths[pid] = z
    cloud = np.concatenate([z[np.isfinite(z)] for z in paths.values()] or [np.zeros(0, complex)])
    x0, x1, y0, y1 = base.limits
    if cloud.size:
        pad = 0.08 * result.model.scale
        x0, x1 = min(x0, cloud.real.min() - pad), max(x1, cloud.real.max() + pad)
        y0, y1 = min(y0, cloud.imag.min() - pad), max(y1, cloud.imag.max() + pad)
    scene = Scene(
        base.model,
        base.motion,
        base.layers,
        base.speed,
        base.shown,
        paths,
        base.guides,
        (float(x0), float(x1), float(y0), float(y1)),
        base.arrow_scale,
        footer=base.footer,
    )
    fig, ax = drawing_figure(scene, width=WIDTH, pyplot=False)
    draw_scene(scene, ax=ax)
    return _svg(fig)


def svg_of(obj: object) -> str | None:
    """The notebook picture of a mechanism or a kinematics result (the renderer the
    package installs in :mod:`mjstruct.display`); None for anything else."""
    from mjstruct.kinematics.result import KinematicsResult

    if isinstance(obj, Mechanism):
        return mechanism_svg(obj)
    if isinstance(obj, KinematicsResult):
        return kinematics_svg(obj)
    return None
