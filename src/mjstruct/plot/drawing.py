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

from mjstruct.plot.annotations import AnnotationArtists
from mjstruct.plot.layout import drawing_figure, equal_scale, figure_for, fill_axes
from mjstruct.plot.scene import (
    PATH_FRAMES,
    Scene,
    anchor_positions,
    guide_sides,
    scene_at,
    scene_over_cycle,
)
from mjstruct.plot.scheme import SchemeArtists, link_colours
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
from mjstruct.plot.targets import draw_targets
from mjstruct.plot.vectors import VectorArtists

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
    "SceneArtists",
    "anchor_positions",
    "artists",
    "draw_scene",
    "drawing_figure",
    "figure_for",
    "guide_sides",
    "scene_at",
    "scene_over_cycle",
    "write_drawing",
]


class SceneArtists:
    """Every artist of ``scene`` on ``ax``, built once; :meth:`show` sets them to a frame.

    The axes get the scene's fixed limits; the scheme, the vector layers and the
    annotations are built in the order they are drawn.  An animation builds one
    and shows each frame in turn, so only the artists' data change between frames.
    """

    def __init__(self, ax: Axes, scene: Scene, title: bool = True, radians: bool = False) -> None:
        self.ax, self.scene = ax, scene
        x0, x1, y0, y1 = fill_axes(scene.limits, ax)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        equal_scale(ax)
        ax.set_axis_off()
        colours = link_colours(scene)
        self.scheme = SchemeArtists(ax, scene, colours)
        if scene.targets is not None:  # fixed: the same at every frame
            draw_targets(ax, scene.targets, scene.model.scale)
        self.vectors = VectorArtists(ax, scene)
        quivers = {layer: q for layer, (q, _, _) in self.vectors.layers.items()}
        self.annotations = AnnotationArtists(
            ax, scene, colours, quivers, title=title, radians=radians
        )

    @property
    def changing(self) -> list[Any]:
        """The artists that change from frame to frame, in the order they are drawn
        (z-order, then the order they were added), leaving out :attr:`labels` and
        :attr:`keys`; every other artist looks the same at every frame."""
        order = {id(a): i for i, a in enumerate(self.ax.get_children())}
        found = self.scheme.changing + self.vectors.changing + self.annotations.changing
        return sorted(found, key=lambda a: (a.get_zorder(), order[id(a)]))

    @property
    def labels(self) -> list[Any]:
        """The ids beside joints, links and points: text that moves but never changes."""
        return self.scheme.labels

    @property
    def keys(self) -> list[Any]:
        """The vector layers' keys: fixed in place, shown while their layer is."""
        return list(self.annotations.keys.values())

    def fits(self, scene: Scene) -> bool:
        """Whether ``scene``'s limits lie within the axes' (:meth:`rebind` keeps them)."""
        x0, x1, y0, y1 = scene.limits
        (a0, a1), (b0, b1) = self.ax.get_xlim(), self.ax.get_ylim()
        return bool(a0 <= x0 and x1 <= a1 and b0 <= y0 and y1 <= b1)

    def rebind(self, scene: Scene) -> None:
        """Draw ``scene`` from now on, with the artists already built: the same
        mechanism with other joint centres (same joints, links, drivers and paths;
        layers without vectors, whose scales and keys would change), within the axes'
        limits, which stay as they are (:meth:`fits`), as do the footer and the title's
        name.  The explorer's joint sliders take this way."""
        vectors = {"velocity", "acceleration", *FORCE_COLOURS}
        if vectors & set(scene.layers) or vectors & set(self.scene.layers):
            raise ValueError("rebind: a scene with vector layers is drawn anew")
        if not self.fits(scene):
            raise ValueError("rebind: the scene's limits leave the axes")
        self.scene = scene
        self.scheme.rebind(scene)
        self.vectors.scene = scene
        self.annotations.scene = scene

    def show(self, frame: int) -> None:
        """Set every artist to frame ``frame`` of the scene.

        A frame that does not assemble shows the frame link and a note; a frame at a
        branch point marks the joint where the branches meet.
        """
        k = int(frame)
        ok = bool(self.scene.motion.valid[k])
        at = self.scheme.positions(k) if ok else None
        self.scheme.show(k, at)
        shown = self.vectors.show(k, ok)
        self.annotations.show(k, shown, at)


def draw_scene(
    scene: Scene,
    frame: int | None = None,
    ax: Axes | None = None,
    title: bool = True,
    radians: bool = False,
) -> Axes:
    """Draw frame ``frame`` of ``scene`` (default its last shown frame); returns the axes.

    Without ``ax``, a figure shaped to the scene is made (pyplot's).  A frame that does
    not assemble shows the frame link and a note; a frame at a branch point marks the
    joint where the branches meet.  The title gives the drivers' values, angles in
    degrees from 0 to 360 (``radians=True``: in radians).
    """
    if ax is None:
        _, ax = drawing_figure(scene, title=title)
    k = int(scene.shown[-1]) if frame is None else int(frame)
    SceneArtists(ax, scene, title=title, radians=radians).show(k)
    return ax


def artists(ax: Axes, gid: str) -> list[Any]:
    """The visible artists of ``ax`` whose ``gid`` is ``gid`` (or starts with ``gid`` + ':').

    Artists hidden at the frame shown (a layer with nothing to draw there, the pins of
    a frame that does not assemble) are left out.
    """
    found = []
    for a in ax.get_children():
        if not a.get_visible():
            continue
        g = a.get_gid()
        if g is not None and (g == gid or g.startswith(gid + ":")):
            found.append(a)
    return found


def write_drawing(
    scene: Scene, path: str, dpi: int = 120, name: str = "path", radians: bool = False
) -> None:
    """Draw the scene's frame and write it (.svg, .png, .pdf) atomically, cropped to
    what is drawn."""
    import matplotlib.pyplot as plt

    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output, write_atomically

    check_output(path, FIGURE_SUFFIXES, name=name)
    fig, ax = drawing_figure(scene)
    try:
        draw_scene(scene, ax=ax, radians=radians)
        write_atomically(
            path,
            lambda tmp: fig.savefig(tmp, dpi=dpi, bbox_inches="tight", pad_inches=0.08),
            name=name,
        )
    finally:
        plt.close(fig)
