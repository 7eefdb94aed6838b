"""Drawing a mechanism at a configuration: the kinematic scheme and its layers.

Owns :class:`Scene` (a solved motion with everything its drawing needs, computed once
for every frame it may show) and :func:`draw_scene`, which draws one frame on a
matplotlib axes: the frame with ground hatching and guide lines, binary links as bars,
ternary and higher links as filled polygons, every revolute joint as one pin (a
multiple joint carries one dot per link on a ring around it, so its multiplicity is
seen), prismatic joints as blocks on their guides, the driver marked by an arrow,
joint and link labels, points of interest, a scale bar; then the layers asked for
(:mod:`mjstruct.plot.layers`).  Every size is a fraction of the mechanism's size, so a
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

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.plot.forces import FORCE_LAYERS, ForceLayer, force_layers
from mjstruct.plot.layers import kinematic_order, parse_layers
from mjstruct.typing import ComplexArray, IntArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from mjstruct.structure.assur import Decomposition

#: pin radius as a fraction of the mechanism's size
PIN = 0.018
#: the longest velocity / acceleration arrow as a fraction of the mechanism's size
ARROW = 0.28
#: frames of the cycle on which a still drawing computes its paths
PATH_FRAMES = 180

LINK_COLOUR = "#34495e"
FRAME_COLOUR = "0.35"
DRIVER_COLOUR = "crimson"
#: Assur groups: tab10 without its pink and grey (kept apart from the vectors, the frame)
GROUP_COLOURS = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#bcbd22",
    "#17becf",
)
#: vectors in colours outside the group palette, with a white halo, so that an arrow
#: stays visible on a link of any colour
VELOCITY_COLOUR = "black"
ACCELERATION_COLOUR = "#e6008a"
FORCE_COLOURS = {"loads": "#0a3dff", "inertia": "indigo", "reactions": "darkred"}
HALO = "white"
#: the vector layers in the order their keys are listed below the drawing
KEYED = ("velocity", "acceleration", "loads", "inertia", "reactions")
#: height of a row of the footer (scale bar, keys, couples) over the drawing's width
ROW = 0.036


@dataclass(frozen=True)
class Scene:
    """A solved motion and what its drawing needs, fixed over the frames it shows.

    Attributes
    ----------
    model : the kinematic model drawn.
    motion : positions (and derivatives up to the layers' order) over the frames.
    layers : the optional layers shown.
    speed : constant driver speed W (velocity = σ W, acceleration = κ W²).
    shown : the frames this scene may draw (limits and arrow scales cover them).
    paths : id -> positions over a cycle (``paths`` layer; NaN where not assembled).
    guides : prismatic joint -> (min, max) slide of its block along the guide,
        measured from the guide's reference point.
    limits : fixed axes limits (x0, x1, y0, y1) over the shown frames.
    arrow_scale : layer -> drawing length per unit of the vector shown (``force``: one
        scale for every force layer).
    decomposition : the Assur decomposition (``assur`` layer).
    forces : force layer -> its arrows and couples (dynamics plug-in).
    footer : height (length units) of the band below the mechanism that ``limits``
        keep free for the scale bar, the vector keys and the couples' values.
    """

    model: KinematicModel
    motion: Motion
    layers: tuple[str, ...]
    speed: float
    shown: IntArray
    paths: dict[str, ComplexArray]
    guides: dict[str, tuple[float, float]]
    limits: tuple[float, float, float, float]
    arrow_scale: dict[str, float]
    decomposition: Decomposition | None = None
    forces: dict[str, ForceLayer] = field(default_factory=dict)
    footer: float = 0.0

    @property
    def pin(self) -> float:
        """Pin radius in length units."""
        return PIN * self.model.scale


# -- building scenes ---------------------------------------------------------------


def scene_at(
    model: KinematicModel,
    q: float | Sequence[float] | None = None,
    layers: Iterable[str] = (),
    speed: float = 1.0,
    paths: Iterable[str] | None = None,
    stroke: float = 1.0,
) -> Scene:
    """A scene of one configuration: the drivers at ``q`` (default the reference).

    The motion is followed from the reference configuration to ``q`` in small steps, so
    the assembly branch is the one reached by moving the drivers there; ``paths`` (ids
    of joints or points; default the file's points, else the moving joints) are
    computed over one cycle only when the ``paths`` layer is shown.
    """
    layers = parse_layers(layers, name="layers")
    _check_speed(speed)
    q_ref = model.q_ref
    if q is None:
        qa = q_ref[None, :]
    else:
        target = np.atleast_1d(np.asarray(q, float))
        if target.shape != q_ref.shape or not np.isfinite(target).all():
            raise MechanismError(f"q: expected {len(q_ref)} finite driver value(s)")
        step = np.array(
            [
                math.pi / 90 if model.mechanism.joint(d).kind == "R" else model.scale / 90
                for d in model.drivers
            ]
        )
        n = int(min(4000, max(1, np.ceil(np.max(np.abs(target - q_ref) / step)))))
        qa = q_ref + np.linspace(0.0, 1.0, n + 1)[:, None] * (target - q_ref)
    motion = model.motion(qa, order=kinematic_order(layers))
    shown = np.array([qa.shape[0] - 1])
    cycle = None
    if "paths" in layers:
        cycle = model.motion(model.sweep(PATH_FRAMES, speed, stroke), order=0)
    return _scene(model, motion, layers, speed, shown, cycle, paths, over_cycle=False)


def scene_over_cycle(
    model: KinematicModel,
    frames: int,
    layers: Iterable[str] = (),
    speed: float = 1.0,
    paths: Iterable[str] | None = None,
    stroke: float = 1.0,
) -> Scene:
    """A scene of ``frames`` frames over one cycle (an animation); paths use the same frames."""
    layers = parse_layers(layers, name="layers")
    _check_speed(speed)
    motion = model.motion(model.sweep(frames, speed, stroke), order=kinematic_order(layers))
    shown = np.arange(motion.q.shape[0])
    return _scene(
        model, motion, layers, speed, shown, motion if "paths" in layers else None, paths, True
    )


def _check_speed(speed: float) -> None:
    if not math.isfinite(speed) or speed == 0:
        raise MechanismError(f"speed: must be a finite nonzero number, got {speed}")


def _scene(
    model: KinematicModel,
    motion: Motion,
    layers: tuple[str, ...],
    speed: float,
    shown: IntArray,
    cycle: Motion | None,
    path_ids: Iterable[str] | None,
    over_cycle: bool,
) -> Scene:
    m, geom = model.mechanism, model.geometry
    paths: dict[str, ComplexArray] = {}
    full_turn = cycle is not None and _full_turn(model, cycle)
    if cycle is not None:
        for pid in _path_ids(model, path_ids):
            z = _position(cycle, pid)
            z = np.where(cycle.valid, z, np.nan + 0j)
            # the sweep leaves out its end point (the start again): close the trace
            paths[pid] = np.append(z, z[0]) if full_turn and _returns(model, z) else z
    guides: dict[str, tuple[float, float]] = {}
    ok = shown[motion.valid[shown]]
    for j in m.joints:
        if j.kind != "P":
            continue
        carrier, block = guide_sides(model, j.id)
        s = _slide(motion, model, j.id, carrier, block)[ok]
        if cycle is not None:
            s = np.concatenate([s, _slide(cycle, model, j.id, carrier, block)[cycle.valid]])
        s = s[np.isfinite(s)]
        lo, hi = (float(s.min()), float(s.max())) if s.size else (0.0, 0.0)
        guides[j.id] = (lo, hi)
    arrow_scale: dict[str, float] = {}
    for layer, k in (("velocity", 1), ("acceleration", 2)):
        if layer in layers:
            mags = [np.abs(v[ok]) for _, v in _vector_sites(model, motion, k, speed)]
            top = max((float(np.nanmax(a)) for a in mags if a.size), default=0.0)
            arrow_scale[layer] = ARROW * model.scale / top if top > 0 else 0.0
    forces = force_layers(model, motion, layers, speed, over_cycle)
    top_force = 0.0
    for fl in forces.values():
        for _, _, f in fl.arrows:
            a = np.abs(f[ok])
            a = a[np.isfinite(a)]
            top_force = max(top_force, float(a.max()) if a.size else 0.0)
    if forces:
        arrow_scale["force"] = ARROW * model.scale / top_force if top_force > 0 else 0.0
    decomposition = None
    if "assur" in layers:
        from mjstruct.structure.assur import assur_groups

        decomposition = assur_groups(m, model.drivers)
    pts = [geom.centres[j.id] for j in m.joints]
    scene = Scene(
        model,
        motion,
        layers,
        speed,
        shown,
        paths,
        guides,
        (0, 0, 0, 0),
        arrow_scale,
        decomposition,
    )
    cloud = [np.asarray(pts, complex)]
    cloud += [a[ok] for a in _anchor_arrays(scene).values()]
    for layer, order in (("velocity", 1), ("acceleration", 2)):
        if layer in layers:
            for z, v in _vector_sites(model, motion, order, speed):
                cloud.append((z + v * arrow_scale[layer])[ok])
    for fl in forces.values():
        for _, at, f in fl.arrows:
            cloud.append((at + f * arrow_scale["force"])[ok])
    for z in paths.values():
        cloud.append(z[np.isfinite(z)])
    allz = np.concatenate(cloud)
    allz = allz[np.isfinite(allz)]
    pad = 0.12 * model.scale
    x0, x1 = float(allz.real.min() - pad), float(allz.real.max() + pad)
    rows = _footer_rows(layers, forces, arrow_scale)
    footer = (rows + 0.6) * ROW * (x1 - x0)
    limits = (x0, x1, float(allz.imag.min() - pad - footer), float(allz.imag.max() + pad))
    return Scene(
        model,
        motion,
        layers,
        speed,
        shown,
        paths,
        guides,
        limits,
        arrow_scale,
        decomposition,
        forces,
        footer,
    )


def _footer_rows(
    layers: tuple[str, ...], forces: dict[str, ForceLayer], arrow_scale: dict[str, float]
) -> int:
    """Rows of the footer: keys and couples two to a row beside the scale bar (>= 2)."""
    slots = len(_keyed(layers, arrow_scale)) + sum(len(f.couples) for f in forces.values())
    return max(2, -(-slots // 2))


def _keyed(layers: tuple[str, ...], arrow_scale: dict[str, float]) -> list[str]:
    """The vector layers that get a key (those with something to scale)."""
    scale = {x: arrow_scale.get("force" if x in FORCE_LAYERS else x, 0.0) for x in KEYED}
    return [x for x in KEYED if x in layers and scale[x] > 0]


def _full_turn(model: KinematicModel, cycle: Motion) -> bool:
    """Whether the cycle's next frame is its first turn again: every driver turns a
    full turn (revolute drivers, equal steps) and every frame assembles."""
    if cycle.q.shape[0] < 3 or not cycle.valid.all():
        return False
    if any(model.mechanism.joint(d).kind != "R" for d in model.drivers):
        return False
    span = np.abs(cycle.q[-1] - cycle.q[0]) + np.abs(cycle.q[1] - cycle.q[0])
    return bool(np.allclose(span, 2 * np.pi, rtol=1e-9))


def _returns(model: KinematicModel, z: ComplexArray) -> bool:
    """Whether a point's trace comes back to its start after a full turn: the last step
    is no longer than twice the longest other one (a mechanism that changes branch on
    the way, period 4π, leaves the trace open rather than drawing a false chord)."""
    hop = float(np.abs(np.diff(z)).max())
    return bool(abs(z[0] - z[-1]) <= 2.0 * hop + 1e-9 * model.scale)


def _path_ids(model: KinematicModel, ids: Iterable[str] | None) -> list[str]:
    m, geom = model.mechanism, model.geometry
    if ids is not None:
        out = [str(x).strip() for x in ids if str(x).strip()]
        for pid in out:
            if pid not in geom.points and pid not in geom.centres:
                raise MechanismError(f"paths: {pid!r} is neither a joint nor a point")
        return out
    if geom.points:
        return list(geom.points)
    return [j.id for j in m.joints if not _fixed(model, j.id) and not _duplicate(model, j.id)]


def _position(motion: Motion, ident: str) -> ComplexArray:
    geom = motion.model.geometry
    if ident in geom.points:
        link, z = geom.points[ident]
        return np.asarray(motion.point(link, z)[0], complex)
    return np.asarray(motion.centre(ident)[0], complex)


def _fixed(model: KinematicModel, joint: str) -> bool:
    """A revolute joint on the frame never moves."""
    j = model.mechanism.joint(joint)
    return j.kind == "R" and model.frame in j.links


def _duplicate(model: KinematicModel, joint: str) -> bool:
    """A joint whose centre is an earlier joint's centre on a shared link (a slider's pin)."""
    m, geom = model.mechanism, model.geometry
    tol = 1e-9 * model.scale
    me = m.joint(joint)
    for j in m.joints:
        if j.id == joint:
            return False
        if set(j.links) & set(me.links) and abs(geom.centres[j.id] - geom.centres[joint]) <= tol:
            return True
    return False


def guide_sides(model: KinematicModel, joint: str) -> tuple[str, str]:
    """(link carrying the guide, link carrying the block) of a prismatic joint.

    The frame always carries the guide; otherwise the block is the link whose joints
    all sit at this joint's centre (a slider block), else the second listed link.
    """
    m, geom = model.mechanism, model.geometry
    a, b = m.joint(joint).links
    if a == model.frame:
        return a, b
    if b == model.frame:
        return b, a
    tol = 1e-9 * model.scale
    z = geom.centres[joint]

    def point_like(link: str) -> bool:
        return all(abs(geom.centres[k] - z) <= tol for k in m.link_joints[link])

    if point_like(a) and not point_like(b):
        return b, a
    return a, b


def _slide(
    motion: Motion, model: KinematicModel, joint: str, carrier: str, block: str
) -> npt.NDArray[np.float64]:
    z = model.geometry.centres[joint]
    u = model.geometry.axes[joint] * motion.evaluation.poses[carrier].r
    d = np.asarray(motion.point(block, z)[0]) - np.asarray(motion.point(carrier, z)[0])
    return np.asarray((np.conj(u) * d).real, float)


def _vector_sites(
    model: KinematicModel, motion: Motion, order: int, speed: float
) -> list[tuple[ComplexArray, ComplexArray]]:
    """(position, vector) over frames at each moving joint and point: v = σW, a = κW²."""
    out: list[tuple[ComplexArray, ComplexArray]] = []
    factor = speed**order
    jets = [
        motion.centre(j.id)
        for j in model.mechanism.joints
        if not _fixed(model, j.id) and not _duplicate(model, j.id)
    ]
    jets += [motion.point(link, z) for link, z in model.geometry.points.values()]
    with np.errstate(invalid="ignore"):  # frames that do not assemble stay NaN
        for jet in jets:
            out.append((_complex(jet[0]), _complex(jet[order]) * factor))
    return out


def _complex(a: Any) -> ComplexArray:
    return np.asarray(a, dtype=np.complex128)


def anchor_positions(scene: Scene, k: int) -> dict[str, complex]:
    """Where every joint centre, point, block and guide end is drawn at frame ``k``."""
    return {key: complex(a[k]) for key, a in _anchor_arrays(scene).items()}


def _anchor_arrays(scene: Scene) -> dict[str, ComplexArray]:
    """The drawn points over all frames: joint centres, points, blocks, guide ends."""
    motion, geom = scene.motion, scene.model.geometry
    out = {j: _complex(motion.centre(j)[0]) for j in geom.centres}
    for pid, (link, z) in geom.points.items():
        out[pid] = _complex(motion.point(link, z)[0])
    ext = 0.12 * scene.model.scale
    for jid in geom.axes:
        carrier, block = guide_sides(scene.model, jid)
        z = geom.centres[jid]
        out[f"{jid}/block"] = _complex(motion.point(block, z)[0])
        u = geom.axes[jid] * _complex(motion.evaluation.poses[carrier].r)
        origin = _complex(motion.point(carrier, z)[0])
        lo, hi = scene.guides.get(jid, (0.0, 0.0))
        out[f"{jid}/origin"] = origin
        out[f"{jid}/guide0"] = origin + u * (lo - ext)
        out[f"{jid}/guide1"] = origin + u * (hi + ext)
    return out


# -- drawing ---------------------------------------------------------------------


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
    colours = _link_colours(scene)
    ok = bool(motion.valid[k])
    at = anchor_positions(scene, k) if ok else {}
    for j in m.joints:
        if j.kind == "R" and model.frame in j.links:
            _ground(ax, scene, j.id)
    for pid, z in scene.paths.items():
        ax.plot(z.real, z.imag, ls="--", lw=1.0, color="0.45", zorder=1.2, gid=f"path:{pid}")
    if ok:
        for jid in model.geometry.axes:
            _guide(ax, scene, jid, at, colours)
        for link in m.links:
            if link != model.frame:
                _link(ax, scene, link, at, colours[link])
        for j in m.joints:
            if j.kind == "R":
                _pin(ax, scene, j.id, at[j.id])
            else:
                _block(ax, scene, j.id, at, k, colours)
        _driver_marks(ax, scene, at, k)
        _labels(ax, scene, at)
        for pid in model.geometry.points:
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
        quivers: dict[str, Any] = {}
        for layer, order, colour in (
            ("velocity", 1, VELOCITY_COLOUR),
            ("acceleration", 2, ACCELERATION_COLOUR),
        ):
            if layer in scene.layers:
                quivers[layer] = _vectors(ax, scene, k, layer, order, colour)
        quivers.update(_forces(ax, scene, k))
        _footer(ax, scene, k, quivers)
    else:
        ax.text(
            0.5,
            0.5,
            f"q = {_q_text(scene, k)}: the mechanism does not assemble",
            transform=ax.transAxes,
            ha="center",
            va="center",
            fontsize=10,
            color=DRIVER_COLOUR,
            gid="note",
        )
    _branch_marks(ax, scene, k, at)
    if "assur" in scene.layers:
        _assur_legend(ax, scene, colours)
    _scale_bar(ax, scene)
    if title:
        name = m.name or "mechanism"
        # a text in axes coordinates: set_title costs a tight-bbox pass per frame
        ax.text(
            0.5,
            1.0,
            f"{name}\nq = {_q_text(scene, k)}",
            transform=ax.transAxes,
            ha="center",
            va="bottom",
            fontsize=10,
            gid="title",
        )
    return ax


def _q_text(scene: Scene, k: int) -> str:
    return ", ".join(f"{v:.4g}" for v in scene.motion.q[k])


def _link_colours(scene: Scene) -> dict[str, Any]:
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


def _anchors(scene: Scene, link: str) -> list[str]:
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


def _link(ax: Axes, scene: Scene, link: str, at: dict[str, complex], colour: Any) -> None:
    from matplotlib.patches import Polygon

    keys = _anchors(scene, link)
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


def _pin(ax: Axes, scene: Scene, joint: str, z: complex) -> None:
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


def _ground(ax: Axes, scene: Scene, joint: str) -> None:
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


def _guide(
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


def _block(
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


def _driver_marks(ax: Axes, scene: Scene, at: dict[str, complex], k: int) -> None:
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


def _labels(ax: Axes, scene: Scene, at: dict[str, complex]) -> None:
    model = scene.model
    m = model.mechanism
    for j in m.joints:
        if j.kind == "P" and _duplicate(model, j.id):
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
        pts = [at[key] for key in _anchors(scene, link)]
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


def _vectors(ax: Axes, scene: Scene, k: int, layer: str, order: int, colour: str) -> Any | None:
    """The velocity or acceleration arrows at frame ``k`` (None when there are none)."""
    sites = _vector_sites(scene.model, scene.motion, order, scene.speed)
    if not sites:
        return None
    z = np.array([p[k] for p, _ in sites])
    v = np.array([w[k] for _, w in sites])
    s = scene.arrow_scale.get(layer, 0.0)
    if s <= 0 or not np.isfinite(v).all():
        return None
    return _quiver(ax, z, v, s, colour, layer, width=0.004)


def _quiver(
    ax: Axes, z: ComplexArray, v: ComplexArray, s: float, colour: str, gid: str, width: float
) -> Any:
    return ax.quiver(
        z.real,
        z.imag,
        v.real,
        v.imag,
        angles="xy",
        scale_units="xy",
        scale=1.0 / s,
        color=colour,
        edgecolor=HALO,
        linewidth=0.7,
        width=width,
        zorder=7,
        gid=gid,
    )


def _forces(ax: Axes, scene: Scene, k: int) -> dict[str, Any]:
    """Arrows of the force layers on one scale, couples as arcs turning their way."""
    s = scene.arrow_scale.get("force", 0.0)
    out: dict[str, Any] = {}
    for layer in (x for x in FORCE_LAYERS if x in scene.forces):
        fl = scene.forces[layer]
        colour = FORCE_COLOURS[layer]
        pts = [(at[k], f[k]) for _, at, f in fl.arrows if np.isfinite(at[k]) and np.isfinite(f[k])]
        if pts and s > 0:
            z = np.array([p for p, _ in pts])
            f = np.array([v for _, v in pts])
            out[layer] = _quiver(ax, z, f, s, colour, layer, width=0.005)
        for _, at, moment in fl.couples:
            if np.isfinite(at[k]) and np.isfinite(moment[k]) and moment[k] != 0:
                _turn(ax, scene, complex(at[k]), float(moment[k]), colour, f"torque:{layer}")
    return out


def _turn(ax: Axes, scene: Scene, c: complex, sense: float, colour: str, gid: str) -> None:
    """A three-quarter arc around ``c`` with its head the way ``sense`` turns."""
    from matplotlib.patches import FancyArrowPatch
    from matplotlib.path import Path

    r = 2.6 * scene.pin
    t = np.linspace(-0.75, 0.75, 24) * np.pi
    if sense < 0:
        t = t[::-1]
    arc = c + r * np.exp(1j * t)
    ax.add_artist(
        FancyArrowPatch(
            path=Path(np.column_stack([arc.real, arc.imag])),
            arrowstyle="-|>",
            mutation_scale=9,
            color=colour,
            lw=1.4,
            zorder=7,
            gid=gid,
        )
    )


def _footer(ax: Axes, scene: Scene, k: int, quivers: dict[str, Any]) -> None:
    """Keys of the vector layers and the couples' values, two to a row below the drawing.

    The slots are fixed by the scene (not the frame), so an animation's keys keep
    their places; a layer with nothing drawn at this frame leaves its slot empty.
    """
    x0, x1, y0, _ = scene.limits
    w = x1 - x0
    top = y0 + scene.footer - 0.3 * ROW * w

    def slot(i: int) -> tuple[float, float]:
        return x0 + (0.30 + 0.36 * (i % 2)) * w, top - (i // 2 + 0.5) * ROW * w

    keyed = _keyed(scene.layers, scene.arrow_scale)
    for i, layer in enumerate(keyed):
        quiver = quivers.get(layer)
        if quiver is None:
            continue
        force = layer in FORCE_LAYERS
        s = scene.arrow_scale["force" if force else layer]
        key = _nice(ARROW * scene.model.scale / s / 2)
        unit = "units" if force else ("units/s" if layer == "velocity" else "units/s²")
        x, y = slot(i)
        qk = ax.quiverkey(
            quiver,
            x,
            y,
            key,
            f"{layer} {key:g} {unit}",
            labelpos="E",
            coordinates="data",
            labelcolor=quiver.get_facecolor()[0],
            fontproperties={"size": 8},
        )
        qk.set_gid(f"key:{layer}")
    i = len(keyed)
    for layer in (x for x in FORCE_LAYERS if x in scene.forces):
        for label, at, moment in scene.forces[layer].couples:
            x, y = slot(i)
            i += 1
            if not (np.isfinite(at[k]) and np.isfinite(moment[k])):
                continue
            ax.text(
                x,
                y,
                f"{label} = {moment[k] + 0.0:.3g}",
                ha="left",
                va="center",
                fontsize=8,
                color=FORCE_COLOURS[layer],
                zorder=9,
                gid=f"couple:{layer}",
            )


def _nice(x: float) -> float:
    """The largest 1, 2 or 5 × 10^k not above ``x``."""
    if x <= 0 or not math.isfinite(x):
        return 1.0
    e = math.floor(math.log10(x))
    for f in (5, 2, 1):
        if f * 10**e <= x:
            return float(f * 10**e)
    return float(10**e)


def _scale_bar(ax: Axes, scene: Scene) -> None:
    """A bar of a round length at the left of the footer, clear of the mechanism."""
    x0, x1, y0, y1 = scene.limits
    length = _nice(0.25 * scene.model.scale)
    w = x1 - x0
    xa = x0 + 0.04 * w
    # the footer's middle; without a footer (a scene built by hand) the lower left
    ya = y0 + (scene.footer / 2 if scene.footer > 0 else 0.05 * (y1 - y0)) - 0.2 * ROW * w
    tick = 0.15 * ROW * w
    ax.plot(
        [xa, xa + length, xa + length, xa + length, xa, xa],
        [ya, ya, ya + tick, ya - tick, ya - tick, ya + tick],
        color="black",
        lw=1.2,
        gid="scalebar",
    )
    ax.text(
        xa + length / 2,
        ya + 1.5 * tick,
        f"{length:g}",
        ha="center",
        va="bottom",
        fontsize=8,
        gid="scalebar",
    )


def _branch_marks(ax: Axes, scene: Scene, k: int, at: dict[str, complex]) -> None:
    for e in scene.motion.events:
        if e.frame != k:
            continue
        ax.text(
            0.5,
            0.02,
            f"{e.kind} at joint {e.joint} (q = {e.q:.4g})",
            transform=ax.transAxes,
            ha="center",
            va="bottom",
            fontsize=9,
            color=DRIVER_COLOUR,
            gid="branch",
        )
        z = at.get(e.joint)
        if z is not None:
            ax.plot(
                [z.real],
                [z.imag],
                marker="*",
                ms=16,
                color=DRIVER_COLOUR,
                alpha=0.7,
                zorder=8,
                gid="branch",
            )


def _assur_legend(ax: Axes, scene: Scene, colours: dict[str, Any]) -> None:
    from matplotlib.lines import Line2D

    from mjstruct.structure.assur import roman

    d = scene.decomposition
    assert d is not None
    handles = [Line2D([], [], lw=5, color=FRAME_COLOUR, label=f"frame {d.frame}")]
    for dr, _, driven in d.initial:
        handles.append(
            Line2D([], [], lw=5, color=colours[driven], label=f"driven link {driven} ({dr})")
        )
    for g, group in enumerate(d.groups):
        text = f"group {g + 1}: class {roman(group.klass)}, links {', '.join(group.links)}"
        handles.append(Line2D([], [], lw=5, color=colours[group.links[0]], label=text))
    ax.legend(handles=handles, loc="upper left", fontsize=7, framealpha=0.85)


def artists(ax: Axes, gid: str) -> list[Any]:
    """The artists of ``ax`` whose ``gid`` is ``gid`` (or starts with ``gid`` + ':')."""
    found = []
    for a in ax.get_children():
        g = a.get_gid()
        if g is not None and (g == gid or g.startswith(gid + ":")):
            found.append(a)
    return found


def figure_for(scene: Scene, width: float = 7.0) -> Any:
    """A figure whose shape follows the scene's limits (title room included)."""
    import matplotlib.pyplot as plt

    x0, x1, y0, y1 = scene.limits
    ratio = min(2.0, max(0.5, (y1 - y0) / (x1 - x0)))
    return plt.figure(figsize=(width, width * ratio + 0.6))


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
