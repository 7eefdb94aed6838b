"""Drawing a mechanism at a configuration: the kinematic scheme and its layers.

Owns :func:`draw_scene`, which draws one frame of a :class:`Scene` (built by
:func:`scene_at` or :func:`scene_over_cycle`, :mod:`mjstruct.plot.scene`) on a
matplotlib axes, and :func:`write_drawing`: the scheme (:mod:`mjstruct.plot.scheme`:
the frame with ground hatching and guide lines, links as bars or plates, pins, blocks,
the driver, labels, points of interest), then the layers asked for
(:mod:`mjstruct.plot.layers`; vectors in :mod:`mjstruct.plot.vectors`), then what
explains the drawing (:mod:`mjstruct.plot.annotations`: keys, scale bar, legend,
title) in the places :mod:`mjstruct.plot.layout` gives.  The names a caller needs
(:class:`Scene`, :func:`scene_at`, :func:`scene_over_cycle`, the colours) are
importable from here.  Every size is a fraction of the mechanism's size, so a
1 mm and a 100 m mechanism look alike.  Artists carry a ``gid`` naming what they show
(``"joint:A"``, ``"link:2"``, ``"mj:A"``, ``"velocity"``, ...), which the tests read.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("kin-radial-engine-5")))
>>> scene = scene_at(model, q=1.0, layers=("velocity",))
>>> ax = draw_scene(scene)
>>> len(artists(ax, "mj:A")[0].get_offsets())      # the MJ A joins six links
6
>>> len(artists(ax, "velocity"))
1
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from mjstruct.plot.annotations import (
    draw_assur_legend,
    draw_branch_marks,
    draw_footer,
    draw_scale_bar,
)
from mjstruct.plot.layout import figure_for
from mjstruct.plot.scene import (
    PATH_FRAMES,
    Scene,
    anchor_positions,
    guide_sides,
    scene_at,
    scene_over_cycle,
)
from mjstruct.plot.scheme import (
    draw_block,
    draw_driver_marks,
    draw_ground,
    draw_guide,
    draw_labels,
    draw_link,
    draw_paths,
    draw_pin,
    draw_points,
    link_colours,
    q_text,
)
from mjstruct.plot.style import (
    ACCELERATION_COLOUR,
    ARROW,
    DRIVER_COLOUR,
    FORCE_COLOURS,
    FRAME_COLOUR,
    GROUP_COLOURS,
    LINK_COLOUR,
    PIN,
    VELOCITY_COLOUR,
)
from mjstruct.plot.vectors import draw_forces, draw_vectors

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = [
    "ACCELERATION_COLOUR",
    "ARROW",
    "DRIVER_COLOUR",
    "FORCE_COLOURS",
    "FRAME_COLOUR",
    "GROUP_COLOURS",
    "LINK_COLOUR",
    "PATH_FRAMES",
    "PIN",
    "VELOCITY_COLOUR",
    "Scene",
    "anchor_positions",
    "artists",
    "draw_scene",
    "figure_for",
    "guide_sides",
    "scene_at",
    "scene_over_cycle",
    "write_drawing",
]


def draw_scene(
    scene: Scene, frame: int | None = None, ax: Axes | None = None, title: bool = True
) -> Axes:
    """Draw frame ``frame`` of ``scene`` (default its last shown frame); returns the axes.

    A frame that does not assemble shows the frame link and a note; a frame at a
    branch point marks the joint where the branches meet.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 6))
    k = int(scene.shown[-1]) if frame is None else int(frame)
    model, motion = scene.model, scene.motion
    m = model.mechanism
    x0, x1, y0, y1 = scene.limits
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_axis_off()
    colours = link_colours(scene)
    ok = bool(motion.valid[k])
    at = anchor_positions(scene, k) if ok else {}
    for j in m.joints:
        if j.kind == "R" and model.frame in j.links:
            draw_ground(ax, scene, j.id)
    draw_paths(ax, scene)
    if ok:
        for jid in model.geometry.axes:
            draw_guide(ax, scene, jid, at, colours)
        for link in m.links:
            if link != model.frame:
                draw_link(ax, scene, link, at, colours[link])
        for j in m.joints:
            if j.kind == "R":
                draw_pin(ax, scene, j.id, at[j.id])
            else:
                draw_block(ax, scene, j.id, at, k, colours)
        draw_driver_marks(ax, scene, at, k)
        draw_labels(ax, scene, at)
        draw_points(ax, scene, at)
        quivers: dict[str, Any] = {}
        for layer, order, colour in (
            ("velocity", 1, VELOCITY_COLOUR),
            ("acceleration", 2, ACCELERATION_COLOUR),
        ):
            if layer in scene.layers:
                quivers[layer] = draw_vectors(ax, scene, k, layer, order, colour)
        quivers.update(draw_forces(ax, scene, k))
        draw_footer(ax, scene, k, quivers)
    else:
        ax.text(
            0.5,
            0.5,
            f"q = {q_text(scene, k)}: the mechanism does not assemble",
            transform=ax.transAxes,
            ha="center",
            va="center",
            fontsize=10,
            color=DRIVER_COLOUR,
            gid="note",
        )
    draw_branch_marks(ax, scene, k, at)
    if "assur" in scene.layers:
        draw_assur_legend(ax, scene, colours)
    draw_scale_bar(ax, scene)
    if title:
        name = m.name or "mechanism"
        # a text in axes coordinates: set_title costs a tight-bbox pass per frame
        ax.text(
            0.5,
            1.0,
            f"{name}\nq = {q_text(scene, k)}",
            transform=ax.transAxes,
            ha="center",
            va="bottom",
            fontsize=10,
            gid="title",
        )
    return ax


def artists(ax: Axes, gid: str) -> list[Any]:
    """The artists of ``ax`` whose ``gid`` is ``gid`` (or starts with ``gid`` + ':')."""
    found = []
    for a in ax.get_children():
        g = a.get_gid()
        if g is not None and (g == gid or g.startswith(gid + ":")):
            found.append(a)
    return found


def write_drawing(scene: Scene, path: str, dpi: int = 120, name: str = "path") -> None:
    """Draw the scene's frame and write it (.svg, .png, .pdf) atomically."""
    import matplotlib.pyplot as plt

    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output, write_atomically

    check_output(path, FIGURE_SUFFIXES, name=name)
    fig = figure_for(scene)
    try:
        draw_scene(scene, ax=fig.add_subplot())
        fig.tight_layout()
        write_atomically(path, lambda tmp: fig.savefig(tmp, dpi=dpi), name=name)
    finally:
        plt.close(fig)
