"""Artists of the kinematic scheme: frame, guides, links, pins, blocks, drivers, labels.

Owns how the mechanism itself is drawn: a hatched pivot under each frame revolute
joint, guide lines (hatched on the frame), binary links as bars, ternary and higher
links as filled polygons of their joint centres (a straight one as a bar), revolute
joints as pins (a multiple joint with one dot per link on a ring), prismatic joints
as blocks, the driver's arc or arrow, joint and link labels, points of interest, the
traced paths and the links' colours (by Assur group on that layer).

:class:`SchemeArtists` builds these artists once on an axes and moves them to a
frame (:meth:`SchemeArtists.show`), so an animation updates their data instead of
drawing the scheme again for every frame.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.plot.scene import Scene, anchor_arrays, duplicate_joint, guide_sides
from mjstruct.plot.style import DRIVER_COLOUR, FRAME_COLOUR, GROUP_COLOURS, LINK_COLOUR
from mjstruct.typing import ComplexArray

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes

#: where a frame's anchors are drawn: key (joint id, point id, "J/block", ...) -> z
At = dict[str, complex]


def q_text(scene: Scene, k: int) -> str:
    """The driver values of frame ``k`` as a title shows them."""
    return ", ".join(f"{v:.4g}" for v in scene.motion.q[k])


def link_colours(scene: Scene) -> dict[str, Any]:
    """Colour of each link: the frame grey, the others dark, by Assur group on that layer."""
    m = scene.model.mechanism
    colours: dict[str, Any] = dict.fromkeys(m.links, LINK_COLOUR)
    colours[scene.model.frame] = FRAME_COLOUR
    d = scene.decomposition
    if d is not None:
        for _, _, driven in d.initial:
            colours[driven] = "0.25"
        for g, group in enumerate(d.groups):
            for link in group.links:
                colours[link] = GROUP_COLOURS[g % len(GROUP_COLOURS)]
    return colours


def link_outline(scene: Scene, link: str) -> list[str]:
    """Keys of the distinct points outlining ``link`` (joint centres, guide origins)."""
    model = scene.model
    geom = model.geometry
    tol = 1e-9 * model.scale
    keys: list[str] = []
    seen: list[complex] = []
    for jid in model.mechanism.link_joints[link]:
        z = geom.centres[jid]
        key = jid
        if jid in geom.axes and guide_sides(model, jid)[1] == link:
            key = f"{jid}/block"
        elif jid in geom.axes:
            key = f"{jid}/origin"
        if any(abs(z - s) <= tol for s in seen):
            continue
        seen.append(z)
        keys.append(key)
    return keys


def is_bar(z: ComplexArray) -> bool:
    """Whether the outline points ``z`` of a link lie on one line (two points: always)."""
    if len(z) == 2:
        return True
    d = z - z.mean()
    spread = np.abs(d).max()
    area2 = abs(float(np.imag(np.conj(d[:, None]) * d[None, :]).max()))
    return bool(area2 <= 1e-6 * spread**2)


def bar_ends(z: ComplexArray) -> tuple[complex, complex]:
    """The two extreme points of collinear points ``z`` (a straight link's bar)."""
    d = z - z.mean()
    u = d[np.argmax(np.abs(d))]
    t = (np.conj(u) * d).real
    return complex(z[np.argmin(t)]), complex(z[np.argmax(t)])


def plate_outline(z: ComplexArray) -> ComplexArray:
    """The points ``z`` of a plate in the order they go round its centre."""
    return np.asarray(z[np.argsort(np.angle(z - z.mean()))], np.complex128)


def _xy(z: Any) -> list[tuple[float, float]]:
    return [(p.real, p.imag) for p in z]


class SchemeArtists:
    """The scheme of ``scene`` on ``ax``: artists built once, moved by :meth:`show`.

    The frame's pivots and the paths do not move; everything else is placed at the
    frame shown and hidden at a frame where the mechanism does not assemble.
    """

    def __init__(self, ax: Axes, scene: Scene, colours: dict[str, Any]) -> None:
        self.ax, self.scene, self.colours = ax, scene, colours
        self.anchors = anchor_arrays(scene)
        #: (artists, their update at a frame) in the order they are drawn
        self.parts: list[tuple[list[Artist], Callable[[At, int], None]]] = []
        #: the ids drawn beside joints, links and points: text that only moves
        self.labels: list[Any] = []
        model = scene.model
        m = model.mechanism
        for j in m.joints:
            if j.kind == "R" and model.frame in j.links:
                self._ground(j.id)
        for pid, z in scene.paths.items():
            ax.plot(z.real, z.imag, ls="--", lw=1.0, color="0.45", zorder=1.2, gid=f"path:{pid}")
        for jid in model.geometry.axes:
            self._guide(jid)
        for link in m.links:
            if link != model.frame:
                self._link(link)
        for j in m.joints:
            if j.kind == "R":
                self._pin(j.id)
            else:
                self._block(j.id)
        for d in model.drivers:
            self._driver(d)
        self._labels()
        for pid in model.geometry.points:
            self._point(pid)

    @property
    def changing(self) -> list[Artist]:
        """The artists :meth:`show` moves, labels left out (:attr:`labels`)."""
        labels = set(map(id, self.labels))
        return [a for artists, _ in self.parts for a in artists if id(a) not in labels]

    def positions(self, k: int) -> At:
        """Where every joint centre, point, block and guide end is drawn at frame ``k``."""
        return {key: complex(a[k]) for key, a in self.anchors.items()}

    def show(self, k: int, at: At | None) -> None:
        """Place the moving artists at frame ``k`` (``at``: its positions; None: hidden)."""
        for artists, update in self.parts:
            for a in artists:
                a.set_visible(at is not None)
            if at is not None:
                update(at, k)

    def _add(self, artists: list[Artist], update: Callable[[At, int], None]) -> None:
        self.parts.append((artists, update))

    def _direction(self, joint: str, k: int) -> complex:
        """Unit vector of a prismatic joint's guide at frame ``k``."""
        model = self.scene.model
        carrier, _ = guide_sides(model, joint)
        return complex(
            model.geometry.axes[joint] * self.scene.motion.evaluation.poses[carrier].r[k]
        )

    def _ground(self, joint: str) -> None:
        from matplotlib.collections import LineCollection
        from matplotlib.patches import Polygon

        r = self.scene.pin
        c = self.scene.model.geometry.centres[joint]
        base = c - 3.2j * r
        tri = [c, base - 2.2 * r, base + 2.2 * r]
        self.ax.add_artist(
            Polygon(
                _xy(tri),
                closed=True,
                facecolor="0.85",
                edgecolor=FRAME_COLOUR,
                lw=1.2,
                zorder=1.5,
                gid=f"ground:{joint}",
            )
        )
        segs = [[(base.real - 3.2 * r, base.imag), (base.real + 3.2 * r, base.imag)]]
        for t in np.linspace(-3.0, 2.2, 6):
            a = base + t * r
            segs.append([(a.real, a.imag), (a.real - r, a.imag - 1.2 * r)])
        self.ax.add_artist(
            LineCollection(segs, colors=FRAME_COLOUR, lw=1.0, zorder=1.5, gid=f"ground:{joint}")
        )

    def _guide(self, joint: str) -> None:
        from matplotlib.collections import LineCollection

        scene = self.scene
        carrier, _ = guide_sides(scene.model, joint)
        on_frame = carrier == scene.model.frame
        pin = scene.pin
        lines = LineCollection(
            [], colors=[self.colours[carrier]], lw=1.2, zorder=1.6, gid=f"guide:{joint}"
        )
        self.ax.add_artist(lines)

        def update(at: At, k: int) -> None:
            a, b = at[f"{joint}/guide0"], at[f"{joint}/guide1"]
            segs = [[(a.real, a.imag), (b.real, b.imag)]]
            if on_frame:
                # hatching on one side of a frame guide
                u = (b - a) / abs(b - a)
                n = -1j * u
                off = 1.6 * pin * n
                for t in np.linspace(0.0, 1.0, max(4, int(abs(b - a) / (2.5 * pin)))):
                    p = a + t * (b - a) + off
                    e = p + pin * (n - u)
                    segs.append([(p.real, p.imag), (e.real, e.imag)])
                segs.append([((a + off).real, (a + off).imag), ((b + off).real, (b + off).imag)])
            lines.set_segments(segs)

        self._add([lines], update)

    def _link(self, link: str) -> None:
        from matplotlib.patches import Polygon

        keys = link_outline(self.scene, link)
        if len(keys) < 2:
            return
        colour = self.colours[link]
        # a rigid link keeps its shape: whether it is a bar is seen in the file's geometry
        # (every outline key is a joint's own centre there)
        centres = self.scene.model.geometry.centres
        if is_bar(np.array([centres[key.split("/")[0]] for key in keys])):
            (bar,) = self.ax.plot(
                [], [], lw=5, color=colour, solid_capstyle="round", zorder=3, gid=f"link:{link}"
            )

            def update_bar(at: At, k: int) -> None:
                a, b = bar_ends(np.array([at[key] for key in keys]))
                bar.set_data([a.real, b.real], [a.imag, b.imag])

            self._add([bar], update_bar)
            return
        plate = Polygon(
            np.zeros((len(keys), 2)),
            closed=True,
            facecolor=colour,
            alpha=0.45,
            edgecolor=colour,
            lw=2.5,
            zorder=2,
            gid=f"link:{link}",
        )
        self.ax.add_artist(plate)

        def update_plate(at: At, k: int) -> None:
            z = plate_outline(np.array([at[key] for key in keys]))
            plate.set_xy(np.column_stack([z.real, z.imag]))

        self._add([plate], update_plate)

    def _pin(self, joint: str) -> None:
        from matplotlib.patches import Circle

        scene = self.scene
        j = scene.model.mechanism.joint(joint)
        r = scene.pin * (1.35 if j.is_multiple else 1.0)
        edge = DRIVER_COLOUR if joint in scene.model.drivers else "black"
        circle = Circle(
            (0.0, 0.0),
            r,
            facecolor="white",
            edgecolor=edge,
            lw=1.6,
            zorder=5,
            gid=f"joint:{joint}",
        )
        self.ax.add_artist(circle)
        artists: list[Artist] = [circle]
        ring_offsets = np.zeros(0, complex)
        ring: Any = None
        if j.is_multiple:
            n = len(j.links)
            phi = np.pi / 2 + 2 * np.pi * np.arange(n) / n
            ring_offsets = 1.9 * scene.pin * np.exp(1j * phi)
            ring = self.ax.scatter(
                ring_offsets.real, ring_offsets.imag, s=10, c="black", zorder=6, gid=f"mj:{joint}"
            )
            artists.append(ring)

        def update(at: At, k: int) -> None:
            z = at[joint]
            circle.set_center((z.real, z.imag))
            if ring is not None:
                dots = z + ring_offsets
                ring.set_offsets(np.column_stack([dots.real, dots.imag]))

        self._add(artists, update)

    def _block(self, joint: str) -> None:
        from matplotlib.patches import Polygon

        scene = self.scene
        _, block = guide_sides(scene.model, joint)
        half_l, half_w = 2.8 * scene.pin, 1.7 * scene.pin
        edge = DRIVER_COLOUR if joint in scene.model.drivers else "black"
        box = Polygon(
            np.zeros((4, 2)),
            closed=True,
            facecolor=self.colours[block],
            alpha=0.8,
            edgecolor=edge,
            lw=1.4,
            zorder=4,
            gid=f"joint:{joint}",
        )
        self.ax.add_artist(box)
        corners = np.array([(-1, -1), (1, -1), (1, 1), (-1, 1)], float)

        def update(at: At, k: int) -> None:
            u = self._direction(joint, k)
            z = at[f"{joint}/block"] + (corners[:, 0] * half_l + 1j * corners[:, 1] * half_w) * u
            box.set_xy(np.column_stack([z.real, z.imag]))

        self._add([box], update)

    def _driver(self, d: str) -> None:
        from matplotlib.patches import Arc, FancyArrowPatch

        r = self.scene.pin
        revolute = self.scene.model.mechanism.joint(d).kind == "R"
        artists: list[Artist] = []
        arc = None
        if revolute:
            arc = Arc(
                (0.0, 0.0),
                6 * r,
                6 * r,
                theta1=20,
                theta2=300,
                color=DRIVER_COLOUR,
                lw=1.5,
                zorder=6,
                gid=f"driver:{d}",
            )
            self.ax.add_artist(arc)
            artists.append(arc)
        arrow = FancyArrowPatch(
            (0.0, 0.0),
            (1.0, 0.0),
            arrowstyle="-|>",
            mutation_scale=12,
            color=DRIVER_COLOUR,
            lw=1.5,
            zorder=6,
            gid=f"driver:{d}",
        )
        self.ax.add_artist(arrow)
        artists.append(arrow)

        def update(at: At, k: int) -> None:
            if arc is not None:
                c = at[d]
                arc.set_center((c.real, c.imag))
                tip = c + 3 * r * np.exp(1j * np.radians(300))
                tail = c + 3 * r * np.exp(1j * np.radians(280))
            else:
                u = self._direction(d, k)
                c = at[f"{d}/block"] + 3.2 * r * 1j * u
                tail, tip = c - 3 * r * u, c + 3 * r * u
            arrow.set_positions((tail.real, tail.imag), (tip.real, tip.imag))

        self._add(artists, update)

    def _labels(self) -> None:
        scene = self.scene
        model = scene.model
        m = model.mechanism
        for j in m.joints:
            if j.kind == "P" and duplicate_joint(model, j.id):
                continue
            key = j.id if j.kind == "R" else f"{j.id}/block"
            label = self.ax.annotate(
                j.id,
                (0.0, 0.0),
                xytext=(7, 7),
                textcoords="offset points",
                fontsize=8,
                zorder=9,
                gid=f"label:joint:{j.id}",
            )
            self._add([label], self._follow(label, key))
            self.labels.append(label)
        for link in m.links:
            if link == model.frame:
                continue
            keys = link_outline(scene, link)
            text = self.ax.text(
                0.0,
                0.0,
                link,
                ha="center",
                va="center",
                fontsize=8,
                zorder=9,
                bbox={"boxstyle": "circle,pad=0.15", "fc": "white", "ec": "0.6", "lw": 0.6},
                gid=f"label:link:{link}",
            )
            self._add([text], self._link_label(text, keys))
            self.labels.append(text)

    @staticmethod
    def _follow(label: Any, key: str) -> Callable[[At, int], None]:
        def update(at: At, k: int) -> None:
            z = at[key]
            label.xy = (z.real, z.imag)

        return update

    def _link_label(self, text: Any, keys: list[str]) -> Callable[[At, int], None]:
        pin = self.scene.pin

        def update(at: At, k: int) -> None:
            pts = [at[key] for key in keys]
            if len(pts) >= 2:
                c = sum(pts) / len(pts)
                if len(pts) == 2:
                    u = (pts[1] - pts[0]) / abs(pts[1] - pts[0])
                    c += 2.2 * pin * 1j * u
            else:
                c = pts[0] - 3.5j * pin
            text.set_position((c.real, c.imag))

        return update

    def _point(self, pid: str) -> None:
        (dot,) = self.ax.plot(
            [], [], marker="o", ms=4, color="black", zorder=7, gid=f"point:{pid}"
        )
        label = self.ax.annotate(
            pid,
            (0.0, 0.0),
            xytext=(5, -10),
            textcoords="offset points",
            fontsize=8,
            style="italic",
            zorder=9,
        )
        follow = self._follow(label, pid)

        def update(at: At, k: int) -> None:
            z = at[pid]
            dot.set_data([z.real], [z.imag])
            follow(at, k)

        self._add([dot, label], update)
        self.labels.append(label)
