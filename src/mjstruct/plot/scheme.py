"""Artists of the kinematic scheme: frame, guides, links, pins, blocks, drivers, labels.

Owns how the mechanism itself is drawn: a hatched pivot under each frame revolute
joint, guide lines (hatched on the frame), binary links as bars, ternary and higher
links as plates, the convex hull of their joint centres and points (a straight one as a
bar; a binary link that carries a point off its line is a plate too), revolute
joints as pins (a multiple joint with one dot per link on a ring), prismatic joints
as blocks, the driver's arc or arrow, joint and link labels, points of interest, the
traced paths and the links' colours (by Assur group on that layer); gears through
:mod:`mjstruct.plot.gear_artists`.

:class:`SchemeArtists` builds these artists once on an axes and moves them to a
frame (:meth:`SchemeArtists.show`), so an animation updates their data instead of
drawing the scheme again for every frame.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.plot.gear_artists import gear_artists
from mjstruct.plot.placement import clearance, free_direction
from mjstruct.plot.scene import (
    Scene,
    anchor_arrays,
    anchor_joint,
    duplicate_joint,
    guide_sides,
    vector_sites,
)
from mjstruct.plot.style import DRIVER_COLOUR, FRAME_COLOUR, GROUP_COLOURS, LINK_COLOUR
from mjstruct.typing import ComplexArray

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes

#: where a frame's anchors are drawn: key (joint id, point id, "J/block", ...) -> z
At = dict[str, complex]
#: font size (points) of the joint, link and point labels
LABEL_SIZE = 8


def angle_text(q: float, radians: bool = False) -> str:
    """An angle as people read it: degrees from 0 to 360 (or radians on request).

    >>> angle_text(1.2), angle_text(-0.5), angle_text(2 * math.pi), angle_text(1.2, True)
    ('68.8°', '331.4°', '0.0°', '1.2 rad')
    """
    if radians:
        return f"{q:.4g} rad"
    deg = round(math.degrees(q) % 360.0, 1) % 360.0
    return f"{deg:.1f}°"


def q_text(scene: Scene, k: int, radians: bool = False) -> str:
    """The driver values of frame ``k`` as a title shows them: angles of revolute
    drivers in degrees (or radians), slides in length units."""
    m = scene.model.mechanism
    return ", ".join(
        angle_text(float(v), radians) if m.joint(d).kind == "R" else f"{v:.4g}"
        for d, v in zip(scene.model.drivers, scene.motion.q[k], strict=True)
    )


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
    """Keys of the distinct points outlining ``link``: its joint centres (guide origins,
    blocks) and the points it carries (coupler points, centres of mass), so that a
    link's bar or plate holds every point of it: a part that could be made."""
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
    if len(keys) < 2:
        return keys  # a slider block: drawn as a block, its points beside it
    for pid, (on, z) in geom.points.items():
        if on == link and not any(abs(z - s) <= tol for s in seen):
            seen.append(z)
            keys.append(pid)
    return keys


def outline_reference(scene: Scene, keys: list[str]) -> ComplexArray:
    """Where the outline's points are in the file's geometry (the reference)."""
    geom = scene.model.geometry
    return np.array(
        [
            geom.points[k][1] if k in geom.points else geom.centres[anchor_joint(k, geom.centres)]
            for k in keys
        ],
        np.complex128,
    )


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
    """The plate through the points ``z``: their convex hull, counter-clockwise (a
    point inside it is on the plate, not a corner of it; monotone chain).

    >>> plate_outline(np.array([0, 2, 2 + 2j, 1 + 0.5j, 2j]))
    array([0.+0.j, 2.+0.j, 2.+2.j, 0.+2.j])
    """
    p = sorted({(float(w.real), float(w.imag)) for w in z})

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def chain(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for q in points:
            while len(out) >= 2 and cross(out[-2], out[-1], q) <= 0:
                out.pop()
            out.append(q)
        return out

    hull = chain(p)[:-1] + chain(p[::-1])[:-1]
    return np.array([complex(x, y) for x, y in hull], np.complex128)


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
        self._arrows: list[tuple[ComplexArray, ComplexArray]] = []
        #: where the couples' arcs are drawn, over the frames
        self._turns: list[ComplexArray] = []
        #: the target crosses of a synthesised mechanism's task (labels keep off them)
        self._targets = [complex(t) for t in scene.targets.points] if scene.targets else []
        #: label directions chosen at a point in the frame being shown (key -> directions)
        self._taken: dict[str, list[complex]] = {}
        #: the symbols' sizes (pin radius): the first scene's, kept by :meth:`rebind`
        self.pin = scene.pin
        #: frame joint -> its pivot (triangle, hatching); path id -> its line
        self.grounds: dict[str, tuple[Any, Any]] = {}
        self.path_lines: dict[str, Any] = {}
        model = scene.model
        m = model.mechanism
        for j in m.joints:
            if j.kind == "R" and model.frame in j.links:
                self._ground(j.id)
        for pid, z in scene.paths.items():
            (line,) = ax.plot(
                z.real, z.imag, ls="--", lw=1.0, color="0.45", zorder=1.2, gid=f"path:{pid}"
            )
            self.path_lines[pid] = line
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
        if m.extra.get("gears"):
            for artists, update in gear_artists(ax, model, scene.motion.evaluation.poses):
                self._add(artists, update)
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

    def rebind(self, scene: Scene) -> None:
        """Draw ``scene`` from now on: the same mechanism with other joint centres (the
        same joints, links, drivers, layers and paths), as the explorer moves a joint.

        The frame's pivots and the paths move to the new scene; the moving artists
        follow at the next :meth:`show`; symbol sizes stay those of the first scene.
        """
        self.scene = scene
        self.anchors = anchor_arrays(scene)
        self._arrows = _arrow_tails(scene)
        self._targets = [complex(t) for t in scene.targets.points] if scene.targets else []
        self._turns = [at for fl in scene.forces.values() for _, at, _ in fl.couples]
        for joint, (pivot, hatching) in self.grounds.items():
            tri, segs = self._ground_shape(scene.model.geometry.centres[joint])
            pivot.set_xy(tri)
            hatching.set_segments(segs)
        for pid, line in self.path_lines.items():
            z = scene.paths[pid]
            line.set_data(z.real, z.imag)

    def show(self, k: int, at: At | None) -> None:
        """Place the moving artists at frame ``k`` (``at``: its positions; None: hidden)."""
        self._taken.clear()
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

    def _ground_shape(
        self, c: complex
    ) -> tuple[list[tuple[float, float]], list[list[tuple[float, float]]]]:
        """(triangle, hatching segments) of a frame pivot at ``c``."""
        r = self.pin
        base = c - 3.2j * r
        tri = _xy([c, base - 2.2 * r, base + 2.2 * r])
        segs = [[(base.real - 3.2 * r, base.imag), (base.real + 3.2 * r, base.imag)]]
        for t in np.linspace(-3.0, 2.2, 6):
            a = base + t * r
            segs.append([(a.real, a.imag), (a.real - r, a.imag - 1.2 * r)])
        return tri, segs

    def _ground(self, joint: str) -> None:
        from matplotlib.collections import LineCollection
        from matplotlib.patches import Polygon

        tri, segs = self._ground_shape(self.scene.model.geometry.centres[joint])
        pivot = Polygon(
            tri,
            closed=True,
            facecolor="0.85",
            edgecolor=FRAME_COLOUR,
            lw=1.2,
            zorder=1.5,
            gid=f"ground:{joint}",
        )
        self.ax.add_artist(pivot)
        hatching = LineCollection(
            segs, colors=FRAME_COLOUR, lw=1.0, zorder=1.5, gid=f"ground:{joint}:hatching"
        )
        self.ax.add_artist(hatching)
        self.grounds[joint] = (pivot, hatching)

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
        if is_bar(outline_reference(self.scene, keys)):
            (bar,) = self.ax.plot(
                [], [], lw=5, color=colour, solid_capstyle="round", zorder=3, gid=f"link:{link}"
            )

            def update_bar(at: At, k: int) -> None:
                a, b = bar_ends(np.array([at[key] for key in keys]))
                bar.set_data([a.real, b.real], [a.imag, b.imag])

            self._add([bar], update_bar)
            return
        plate = Polygon(
            np.zeros((3, 2)),
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
            gid=f"driver:{d}:arrow" if revolute else f"driver:{d}",
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
        self._arrows = _arrow_tails(scene)
        self._targets = [complex(t) for t in scene.targets.points] if scene.targets else []
        self._turns = [at for fl in scene.forces.values() for _, at, _ in fl.couples]
        for j in m.joints:
            if j.kind == "P" and duplicate_joint(model, j.id):
                continue
            label = self.ax.annotate(
                j.id,
                (0.0, 0.0),
                xytext=(0.0, 0.0),
                textcoords="offset points",
                ha="center",
                va="center",
                fontsize=LABEL_SIZE,
                zorder=9,
                gid=f"label:joint:{j.id}",
            )
            self._add([label], self._joint_label(label, j.id))
            self.labels.append(label)
        for link in m.links:
            if link == model.frame:
                continue
            keys = link_outline(scene, link)
            text = self.ax.annotate(
                link,
                (0.0, 0.0),
                xytext=(0.0, 0.0),
                textcoords="offset points",
                ha="center",
                va="center",
                fontsize=LABEL_SIZE,
                zorder=9,
                bbox={"boxstyle": "circle,pad=0.15", "fc": "white", "ec": "0.6", "lw": 0.6},
                gid=f"label:link:{link}",
            )
            self._add([text], self._link_label(text, link, keys))
            self.labels.append(text)

    def _occupied(self, at: At, k: int, where: str, z: complex) -> list[complex]:
        """Directions taken at ``z`` (joint or point ``where``) at frame ``k``: the bars and
        plates of its links, the frame's pivot and guides, the arrows leaving it."""
        scene = self.scene
        model = scene.model
        m = model.mechanism
        tol = 0.5 * scene.pin
        out: list[complex] = []
        geom = model.geometry
        if where in geom.points:
            links = [geom.points[where][0]]
        else:
            j = m.joint(where)
            links = [x for x in j.links if x != model.frame]
            if j.kind == "R" and model.frame in j.links:
                out += [-1j, np.exp(-1j * np.pi / 3), np.exp(-2j * np.pi / 3)]  # the pivot
            for p in self._blocks_at(where):
                u = self._direction(p, k)
                out += [u, -u]  # the guide through a block at this point
        for link in links:
            pts = [at[key] for key in link_outline(scene, link)]
            others = [p - z for p in pts if abs(p - z) > tol]
            out += others
            if len(pts) > 2:
                out.append(sum(pts) / len(pts) - z)  # into the plate
        for tails, vectors in self._arrows:
            near = np.abs(tails[:, k] - z) <= tol
            out += list(vectors[near, k])
        out += self._taken.get(where, [])
        # other pins close by (a label set towards one would touch it), and the target
        # crosses of a synthesised mechanism's task
        pins = [at[j.id] for j in m.joints if j.id != where and j.kind == "R"]
        for w in [*pins, *self._targets]:
            d = w - z
            if tol < abs(d) <= 8.0 * scene.pin:
                out.append(d)
        return out

    def _blocks_at(self, where: str) -> list[str]:
        """The prismatic joints whose block sits at joint ``where`` (itself included)."""
        model = self.scene.model
        m, geom = model.mechanism, model.geometry
        if where not in geom.centres:
            return []
        z = geom.centres[where]
        tol = 1e-9 * model.scale
        links = set(m.joint(where).links)
        return [
            p
            for p in geom.axes
            if p == where
            or (abs(geom.centres[p] - z) <= tol and guide_sides(model, p)[1] in links)
        ]

    def _joint_label(self, label: Any, joint: str) -> Callable[[At, int], None]:
        scene = self.scene
        j = scene.model.mechanism.joint(joint)
        r = scene.pin
        key = f"{joint}/block" if j.kind == "P" else joint
        side: dict[int, complex] = {}  # the direction of the frame shown last
        if self._blocks_at(joint) or joint in scene.model.drivers:
            clear = 3.3 * r  # beyond a block's corners, or the driver's arc
        else:
            clear = (2.2 if j.is_multiple else 1.35) * r

        def update(at: At, k: int) -> None:
            z = at[key]
            u = free_direction(np.array(self._occupied(at, k, joint, z), complex), side.get(0))
            side[0] = u
            w = z + clear * u
            label.xy = (w.real, w.imag)
            label.xyann = clearance(u, joint, LABEL_SIZE)
            self._taken[key] = [u]

        return update

    def _link_label(self, label: Any, link: str, keys: list[str]) -> Callable[[At, int], None]:
        pin = self.scene.pin
        geom = self.scene.model.geometry
        points = [p for p, (on, _) in geom.points.items() if on == link]
        # beside a bar: half its width, the label's circle and a gap (points)
        side = 2.5 + 0.35 * LABEL_SIZE * len(link) + 4.0
        reach = 0.35 * LABEL_SIZE * len(link) + 3.0  # the label's circle (points)

        def update(at: At, k: int) -> None:
            pts = np.array([at[key] for key in keys])
            offset = (0.0, 0.0)
            if len(pts) == 1:
                # a slider block: beside it, clear of its guide and its joint's label
                z = complex(pts[0])
                key = keys[0]
                joint = anchor_joint(key, self.scene.model.geometry.centres)
                taken = self._taken.get(key, []) + self._taken.get(joint, [])
                blocks = self._blocks_at(joint)
                guides = [self._direction(p, k) for p in blocks]
                u = free_direction(np.array(taken + guides + [-g for g in guides], complex))
                c = z + 3.3 * pin * u
                offset = clearance(u, link, LABEL_SIZE)
            elif is_bar(pts):
                # beside the bar: the middle above it (or right of an upright one) first,
                # then a third, two thirds, ... either side, clear of pins and points
                a, b = bar_ends(pts)
                n = 1j * (b - a) / abs(b - a)
                if n.imag < -1e-9 or (abs(n.imag) <= 1e-9 and n.real < 0):
                    n = -n
                spots = [(a + t * (b - a), sign * n * side) for t in (0.5, 0.33, 0.67, 0.25, 0.75)
                         for sign in (1.0, -1.0)]  # fmt: skip
                c, o = spots[self._clearest(spots, reach, at, k, points)]
                offset = (o.real, o.imag)
            else:
                # inside the plate: its centre, else towards a corner or an edge
                mid = complex(pts.mean())
                edges = (pts + np.roll(pts, -1)) / 2
                inner = [mid, *(mid + 0.4 * (v - mid) for v in [*pts, *edges])]
                c = inner[self._clearest([(z, 0j) for z in inner], reach, at, k, points)]
            label.xy = (c.real, c.imag)
            label.xyann = offset

        return update

    def _point_size(self) -> float:
        """Length units per point of the axes (equal aspect: the same both ways)."""
        fig: Any = self.ax.get_figure(root=True)
        width = self.ax.get_position().width * fig.get_figwidth() * 72.0
        x0, x1 = self.ax.get_xlim()
        return float(x1 - x0) / width if width > 0 else 0.0

    def _clearest(
        self,
        spots: list[tuple[complex, complex]],
        reach: float,
        at: At,
        k: int,
        points: list[str],
    ) -> int:
        """Index of the first of ``spots`` ((point, offset in points) of a label of radius
        ``reach`` points) whose circle clears every pin, point and couple's arc; else of
        the clearest."""
        scene = self.scene
        pt = self._point_size()
        pin = scene.pin
        m = scene.model.mechanism
        obstacles = [(at[j.id], pin * (2.2 if j.is_multiple else 1.4)) for j in m.joints
                     if j.kind == "R"]  # fmt: skip
        obstacles += [(at[p], 0.6 * pin) for p in points]
        obstacles += [(t, 1.2 * pin) for t in self._targets]  # the task's crosses
        obstacles += [(complex(z[k]), 2.8 * pin) for z in self._turns if np.isfinite(z[k])]
        best, best_gap = 0, -np.inf
        for i, (c, offset) in enumerate(spots):
            centre = c + offset * pt
            gap = min((abs(centre - o) - r for o, r in obstacles), default=np.inf)
            gap -= reach * pt
            if gap >= 0:
                return i
            if gap > best_gap:
                best, best_gap = i, gap
        return best

    def _point(self, pid: str) -> None:
        (dot,) = self.ax.plot(
            [], [], marker="o", ms=4, color="black", zorder=7, gid=f"point:{pid}"
        )
        label = self.ax.annotate(
            pid,
            (0.0, 0.0),
            xytext=(0.0, 0.0),
            textcoords="offset points",
            ha="center",
            va="center",
            fontsize=LABEL_SIZE,
            style="italic",
            zorder=9,
            gid=f"label:point:{pid}",
        )
        clear = 0.6 * self.scene.pin
        side: dict[int, complex] = {}  # the direction of the frame shown last

        def update(at: At, k: int) -> None:
            z = at[pid]
            dot.set_data([z.real], [z.imag])
            u = free_direction(np.array(self._occupied(at, k, pid, z), complex), side.get(0))
            side[0] = u
            w = z + clear * u
            label.xy = (w.real, w.imag)
            label.xyann = clearance(u, pid, LABEL_SIZE)

        self._add([dot, label], update)
        self.labels.append(label)


def _arrow_tails(scene: Scene) -> list[tuple[ComplexArray, ComplexArray]]:
    """(tails, vectors) over (arrows, frames) of every vector layer the scene shows."""
    out: list[tuple[ComplexArray, ComplexArray]] = []
    for layer, order in (("velocity", 1), ("acceleration", 2)):
        if layer in scene.layers:
            sites = vector_sites(scene.model, scene.motion, order, scene.speed)
            if sites:
                out.append((np.array([p for p, _ in sites]), np.array([v for _, v in sites])))
    for fl in scene.forces.values():
        if fl.arrows:
            out.append(
                (np.array([at for _, at, _ in fl.arrows]), np.array([f for _, _, f in fl.arrows]))
            )
    return out
