"""Artists of the kinematic scheme: frame, guides, links, pins, blocks, drivers, labels.

Owns how the mechanism itself is drawn at one frame: a hatched pivot under each frame
revolute joint, guide lines (hatched on the frame), binary links as bars, ternary and
higher links as filled polygons of their joint centres (a straight one as a bar),
revolute joints as pins (a multiple joint with one dot per link on a ring), prismatic
joints as blocks, the driver's arc or arrow, joint and link labels, points of
interest, the traced paths and the links' colours (by Assur group on that layer).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.plot.scene import Scene, duplicate_joint, guide_sides
from mjstruct.plot.style import DRIVER_COLOUR, FRAME_COLOUR, GROUP_COLOURS, LINK_COLOUR

if TYPE_CHECKING:
    from matplotlib.axes import Axes


def q_text(scene: Scene, k: int) -> str:
    """The driver values of frame ``k`` as a title shows them."""
    return ", ".join(f"{v:.4g}" for v in scene.motion.q[k])


def link_colours(scene: Scene) -> dict[str, Any]:
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


def draw_link(ax: Axes, scene: Scene, link: str, at: dict[str, complex], colour: Any) -> None:
    from matplotlib.patches import Polygon

    keys = link_outline(scene, link)
    pts = [at[key] for key in keys]
    if len(pts) < 2:
        return
    z = np.array(pts)
    centre = z.mean()
    spread = np.abs(z - centre).max()
    d = z - centre
    # collinear joints (a straight ternary link): a bar between the extremes
    area2 = abs(float(np.imag(np.conj(d[:, None]) * d[None, :]).max())) if len(z) > 2 else 0.0
    if len(z) == 2 or area2 <= 1e-6 * spread**2:
        u = d[np.argmax(np.abs(d))]
        t = (np.conj(u) * d).real
        a, b = z[np.argmin(t)], z[np.argmax(t)]
        ax.plot(
            [a.real, b.real],
            [a.imag, b.imag],
            lw=5,
            color=colour,
            solid_capstyle="round",
            zorder=3,
            gid=f"link:{link}",
        )
        return
    order = np.argsort(np.angle(d))
    poly = Polygon(
        np.column_stack([z[order].real, z[order].imag]),
        closed=True,
        facecolor=colour,
        alpha=0.45,
        edgecolor=colour,
        lw=2.5,
        zorder=2,
        gid=f"link:{link}",
    )
    ax.add_artist(poly)


def draw_pin(ax: Axes, scene: Scene, joint: str, z: complex) -> None:
    from matplotlib.patches import Circle

    j = scene.model.mechanism.joint(joint)
    r = scene.pin * (1.35 if j.is_multiple else 1.0)
    edge = DRIVER_COLOUR if joint in scene.model.drivers else "black"
    ax.add_artist(
        Circle(
            (z.real, z.imag),
            r,
            facecolor="white",
            edgecolor=edge,
            lw=1.6,
            zorder=5,
            gid=f"joint:{joint}",
        )
    )
    if j.is_multiple:
        n = len(j.links)
        phi = np.pi / 2 + 2 * np.pi * np.arange(n) / n
        ring = z + 1.9 * scene.pin * np.exp(1j * phi)
        ax.scatter(ring.real, ring.imag, s=10, c="black", zorder=6, gid=f"mj:{joint}")


def draw_ground(ax: Axes, scene: Scene, joint: str) -> None:
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Polygon

    r = scene.pin
    c = scene.model.geometry.centres[joint]
    base = c - 3.2j * r
    tri = [c, base - 2.2 * r, base + 2.2 * r]
    ax.add_artist(
        Polygon(
            [(p.real, p.imag) for p in tri],
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
    ax.add_artist(
        LineCollection(segs, colors=FRAME_COLOUR, lw=1.0, zorder=1.5, gid=f"ground:{joint}")
    )


def draw_guide(
    ax: Axes, scene: Scene, joint: str, at: dict[str, complex], colours: dict[str, Any]
) -> None:
    from matplotlib.collections import LineCollection

    carrier, _ = guide_sides(scene.model, joint)
    a, b = at[f"{joint}/guide0"], at[f"{joint}/guide1"]
    segs = [[(a.real, a.imag), (b.real, b.imag)]]
    if carrier == scene.model.frame:
        # hatching on one side of a frame guide
        u = (b - a) / abs(b - a)
        n = -1j * u
        off = 1.6 * scene.pin * n
        for t in np.linspace(0.0, 1.0, max(4, int(abs(b - a) / (2.5 * scene.pin)))):
            p = a + t * (b - a) + off
            e = p + scene.pin * (n - u)
            segs.append([(p.real, p.imag), (e.real, e.imag)])
        segs.append([((a + off).real, (a + off).imag), ((b + off).real, (b + off).imag)])
    ax.add_artist(
        LineCollection(segs, colors=[colours[carrier]], lw=1.2, zorder=1.6, gid=f"guide:{joint}")
    )


def draw_block(
    ax: Axes, scene: Scene, joint: str, at: dict[str, complex], k: int, colours: dict[str, Any]
) -> None:
    from matplotlib.patches import Polygon

    carrier, block = guide_sides(scene.model, joint)
    u = complex(scene.model.geometry.axes[joint] * scene.motion.evaluation.poses[carrier].r[k])
    c = at[f"{joint}/block"]
    half_l, half_w = 2.8 * scene.pin, 1.7 * scene.pin
    n = 1j * u
    corners = [
        c + s * half_l * u + t * half_w * n for s, t in ((-1, -1), (1, -1), (1, 1), (-1, 1))
    ]
    edge = DRIVER_COLOUR if joint in scene.model.drivers else "black"
    ax.add_artist(
        Polygon(
            [(p.real, p.imag) for p in corners],
            closed=True,
            facecolor=colours[block],
            alpha=0.8,
            edgecolor=edge,
            lw=1.4,
            zorder=4,
            gid=f"joint:{joint}",
        )
    )


def draw_driver_marks(ax: Axes, scene: Scene, at: dict[str, complex], k: int) -> None:
    from matplotlib.patches import Arc, FancyArrowPatch

    r = scene.pin
    for d in scene.model.drivers:
        j = scene.model.mechanism.joint(d)
        if j.kind == "R":
            c = at[d]
            ax.add_artist(
                Arc(
                    (c.real, c.imag),
                    6 * r,
                    6 * r,
                    theta1=20,
                    theta2=300,
                    color=DRIVER_COLOUR,
                    lw=1.5,
                    zorder=6,
                    gid=f"driver:{d}",
                )
            )
            tip = c + 3 * r * np.exp(1j * np.radians(300))
            tail = c + 3 * r * np.exp(1j * np.radians(280))
        else:
            carrier, _ = guide_sides(scene.model, d)
            u = complex(scene.model.geometry.axes[d] * scene.motion.evaluation.poses[carrier].r[k])
            c = at[f"{d}/block"] + 3.2 * r * 1j * u
            tail, tip = c - 3 * r * u, c + 3 * r * u
        ax.add_artist(
            FancyArrowPatch(
                (tail.real, tail.imag),
                (tip.real, tip.imag),
                arrowstyle="-|>",
                mutation_scale=12,
                color=DRIVER_COLOUR,
                lw=1.5,
                zorder=6,
                gid=f"driver:{d}",
            )
        )


def draw_labels(ax: Axes, scene: Scene, at: dict[str, complex]) -> None:
    model = scene.model
    m = model.mechanism
    for j in m.joints:
        if j.kind == "P" and duplicate_joint(model, j.id):
            continue
        z = at[j.id] if j.kind == "R" else at[f"{j.id}/block"]
        ax.annotate(
            j.id,
            (z.real, z.imag),
            xytext=(7, 7),
            textcoords="offset points",
            fontsize=8,
            zorder=9,
            gid=f"label:joint:{j.id}",
        )
    for link in m.links:
        if link == model.frame:
            continue
        pts = [at[key] for key in link_outline(scene, link)]
        if len(pts) >= 2:
            c = sum(pts) / len(pts)
            if len(pts) == 2:
                u = (pts[1] - pts[0]) / abs(pts[1] - pts[0])
                c += 2.2 * scene.pin * 1j * u
        else:
            c = pts[0] - 3.5j * scene.pin
        ax.text(
            c.real,
            c.imag,
            link,
            ha="center",
            va="center",
            fontsize=8,
            zorder=9,
            bbox={"boxstyle": "circle,pad=0.15", "fc": "white", "ec": "0.6", "lw": 0.6},
            gid=f"label:link:{link}",
        )


def draw_points(ax: Axes, scene: Scene, at: dict[str, complex]) -> None:
    """The points of interest: black dots with their ids in italics."""
    for pid in scene.model.geometry.points:
        zp = at[pid]
        ax.plot(
            [zp.real], [zp.imag], marker="o", ms=4, color="black", zorder=7, gid=f"point:{pid}"
        )
        ax.annotate(
            pid,
            (zp.real, zp.imag),
            xytext=(5, -10),
            textcoords="offset points",
            fontsize=8,
            style="italic",
            zorder=9,
        )


def draw_paths(ax: Axes, scene: Scene) -> None:
    """The traces of the ``paths`` layer, dashed grey under the scheme."""
    for pid, z in scene.paths.items():
        ax.plot(z.real, z.imag, ls="--", lw=1.0, color="0.45", zorder=1.2, gid=f"path:{pid}")
