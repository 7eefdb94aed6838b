"""Artists of the vector layers: velocity and acceleration arrows, force arrows, couples.

Owns the arrows drawn over the scheme (:class:`VectorArtists`, built once and set to
a frame): velocity v = σ W and acceleration a = κ W² at each moving joint and point,
and the force layers' arrows (on one force scale) and couples (an arc turning their
way).  Every arrow carries a thin white outline so it stays visible on a link of any
colour.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.plot.forces import FORCE_LAYERS
from mjstruct.plot.scene import Scene, vector_sites
from mjstruct.plot.style import ACCELERATION_COLOUR, FORCE_COLOURS, HALO, VELOCITY_COLOUR
from mjstruct.typing import ComplexArray, FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes


class VectorArtists:
    """The vector layers of ``scene`` on ``ax``: arrows built once, set by :meth:`show`.

    One quiver per layer (velocity, acceleration, each force layer) and one arc per
    couple; a layer with nothing to draw at a frame is hidden there.
    """

    def __init__(self, ax: Axes, scene: Scene) -> None:
        self.ax, self.scene = ax, scene
        #: layer -> (quiver, positions, vectors): positions and vectors (sites, frames)
        self.layers: dict[str, tuple[Any, ComplexArray, ComplexArray]] = {}
        #: (arc, transform, position over frames, moment over frames) per couple
        self.couples: list[tuple[Any, Any, ComplexArray, FloatArray]] = []
        for layer, order, colour in (
            ("velocity", 1, VELOCITY_COLOUR),
            ("acceleration", 2, ACCELERATION_COLOUR),
        ):
            if layer in scene.layers:
                sites = vector_sites(scene.model, scene.motion, order, scene.speed)
                if sites:
                    z = np.array([p for p, _ in sites])
                    v = np.array([w for _, w in sites])
                    self._quiver(layer, z, v, scene.arrow_scale.get(layer, 0.0), colour, 0.004)
        s = scene.arrow_scale.get("force", 0.0)
        for layer in (x for x in FORCE_LAYERS if x in scene.forces):
            fl = scene.forces[layer]
            colour = FORCE_COLOURS[layer]
            if fl.arrows:
                z = np.array([at for _, at, _ in fl.arrows])
                f = np.array([f for _, _, f in fl.arrows])
                self._quiver(layer, z, f, s, colour, 0.005)
            for n, (_, at, moment) in enumerate(fl.couples, 1):
                self._couple(at, moment, colour, f"torque:{layer}:{n}")

    def _quiver(
        self, layer: str, z: ComplexArray, v: ComplexArray, s: float, colour: str, width: float
    ) -> None:
        if s <= 0:
            return
        n = z.shape[0]
        arrows = self.ax.quiver(
            np.zeros(n),
            np.zeros(n),
            np.zeros(n),
            np.zeros(n),
            angles="xy",
            scale_units="xy",
            scale=1.0 / s,
            color=colour,
            edgecolor=HALO,
            linewidth=0.7,
            width=width,
            zorder=7,
        )
        # set after: a gid given to quiver() is passed on to its keys' arrows (one id twice)
        arrows.set_gid(layer)
        self.layers[layer] = (arrows, z, v)

    def _couple(self, at: ComplexArray, moment: FloatArray, colour: str, gid: str) -> None:
        """A three-quarter arc around the origin with its head turning positive; a
        transform puts it at the couple's point and mirrors it for a negative one."""
        from matplotlib.patches import FancyArrowPatch
        from matplotlib.path import Path
        from matplotlib.transforms import Affine2D

        r = 2.6 * self.scene.pin
        t = np.linspace(-0.75, 0.75, 24) * np.pi
        arc = r * np.exp(1j * t)
        place = Affine2D()
        patch = FancyArrowPatch(
            path=Path(np.column_stack([arc.real, arc.imag])),
            arrowstyle="-|>",
            mutation_scale=9,
            color=colour,
            lw=1.4,
            zorder=7,
            gid=gid,
            transform=place + self.ax.transData,
        )
        self.ax.add_artist(patch)
        self.couples.append((patch, place, at, moment))

    @property
    def changing(self) -> list[Any]:
        """Every artist :meth:`show` changes."""
        return [q for q, _, _ in self.layers.values()] + [p for p, _, _, _ in self.couples]

    def show(self, k: int, ok: bool) -> dict[str, Any]:
        """Set the arrows to frame ``k`` (``ok``: it assembles); the layers shown there."""
        shown: dict[str, Any] = {}
        for layer, (arrows, z, v) in self.layers.items():
            zk, vk = z[:, k], v[:, k]
            if layer in FORCE_LAYERS:
                # an arrow whose point or force is not finite at this frame is left out
                drawn = np.isfinite(zk) & np.isfinite(vk)
            else:
                # velocity and acceleration: all arrows or none
                drawn = np.full(zk.shape, bool(np.isfinite(vk).all()))
            visible = ok and bool(drawn.any())
            arrows.set_visible(visible)
            if visible:
                zk = np.where(drawn, zk, 0.0)
                u = np.ma.masked_array(vk.real, ~drawn)
                w = np.ma.masked_array(vk.imag, ~drawn)
                arrows.set_offsets(np.column_stack([zk.real, zk.imag]))
                arrows.set_UVC(u, w)
                shown[layer] = arrows
        for patch, place, at, moment in self.couples:
            c, mk = complex(at[k]), float(moment[k])
            visible = ok and np.isfinite(c) and np.isfinite(mk) and mk != 0
            patch.set_visible(visible)
            if visible:
                place.clear().scale(1.0, 1.0 if mk > 0 else -1.0).translate(c.real, c.imag)
        return shown
