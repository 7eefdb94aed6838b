"""Scenes: a solved motion with everything its drawing needs, over the frames it shows.

Owns :class:`Scene` and how it is built: :func:`scene_at` follows the drivers from the
reference configuration to one configuration, :func:`scene_over_cycle` sweeps one
cycle (an animation).  A scene computes only what its layers show
(:mod:`mjstruct.plot.layers`) and fixes, over every frame it may show, the axes
limits, the arrow scales, the slide range of each prismatic guide and the paths, so
an animation's frames share one picture frame.  Also the positions the artists read
(:func:`anchor_positions`: joint centres, points, blocks, guide ends).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("slider-crank")))
>>> scene = scene_over_cycle(model, 12, ("velocity",))
>>> scene.motion.order, len(scene.shown)
(1, 12)
>>> guide_sides(model, "O4")     # the frame carries the piston's guide
('0', '3')
"""

from __future__ import annotations

import math
from collections.abc import Container, Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.plot.extent import drawing_limits
from mjstruct.plot.forces import ForceLayer, force_layers
from mjstruct.plot.layers import kinematic_order, parse_layers
from mjstruct.plot.style import ARROW, PIN
from mjstruct.plot.targets import SynthesisTargets, synthesis_targets
from mjstruct.typing import ComplexArray, IntArray

if TYPE_CHECKING:
    from mjstruct.structure.assur import Decomposition

#: frames of the cycle on which a still drawing computes its paths
PATH_FRAMES = 180


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
    targets : the synthesis task's targets (``targets`` layer, also shown with
        ``paths`` when the file has them).
    footer : height (length units) of the band below the mechanism that ``limits
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
    targets: SynthesisTargets | None = None

    @property
    def pin(self) -> float:
        """Pin radius in length units."""
        return PIN * self.model.scale


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
            mags = [np.abs(v[ok]) for _, v in vector_sites(model, motion, k, speed)]
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
    cloud += [a[ok] for a in anchor_arrays(scene).values()]
    for layer, order in (("velocity", 1), ("acceleration", 2)):
        if layer in layers:
            for z, v in vector_sites(model, motion, order, speed):
                cloud.append((z + v * arrow_scale[layer])[ok])
    for fl in forces.values():
        for _, at, f in fl.arrows:
            cloud.append((at + f * arrow_scale["force"])[ok])
    for z in paths.values():
        cloud.append(z[np.isfinite(z)])
    if m.extra.get("gears"):
        from mjstruct.plot.gear_artists import gear_cloud

        cloud += [z[ok] for z in gear_cloud(model, anchor_arrays(scene))]
    targets = synthesis_targets(m) if "targets" in layers or "paths" in layers else None
    if "targets" in layers and targets is None:
        raise MechanismError(
            "show: layer 'targets' needs a synthesised mechanism file (targets under its "
            "'synthesis' key)"
        )
    if targets is not None:
        cloud.append(targets.points)
    allz = np.concatenate(cloud)
    legend = 0 if decomposition is None else 1 + len(decomposition.initial)
    legend += 0 if decomposition is None else len(decomposition.groups)
    limits, footer = drawing_limits(
        allz[np.isfinite(allz)],
        model.scale,
        layers,
        forces,
        arrow_scale,
        legend,
        lines=int(targets is not None),
    )
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
        targets,
    )


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
    return [
        j.id for j in m.joints if not fixed_joint(model, j.id) and not duplicate_joint(model, j.id)
    ]


def _position(motion: Motion, ident: str) -> ComplexArray:
    geom = motion.model.geometry
    if ident in geom.points:
        link, z = geom.points[ident]
        return np.asarray(motion.point(link, z)[0], complex)
    return np.asarray(motion.centre(ident)[0], complex)


def fixed_joint(model: KinematicModel, joint: str) -> bool:
    """A revolute joint on the frame never moves."""
    j = model.mechanism.joint(joint)
    return j.kind == "R" and model.frame in j.links


def duplicate_joint(model: KinematicModel, joint: str) -> bool:
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


def vector_sites(
    model: KinematicModel, motion: Motion, order: int, speed: float
) -> list[tuple[ComplexArray, ComplexArray]]:
    """(position, vector) over frames at each moving joint and point: v = σW, a = κW²."""
    out: list[tuple[ComplexArray, ComplexArray]] = []
    factor = speed**order
    jets = [
        motion.centre(j.id)
        for j in model.mechanism.joints
        if not fixed_joint(model, j.id) and not duplicate_joint(model, j.id)
    ]
    jets += [motion.point(link, z) for link, z in model.geometry.points.values()]
    with np.errstate(invalid="ignore"):  # frames that do not assemble stay NaN
        for jet in jets:
            out.append((as_complex(jet[0]), as_complex(jet[order]) * factor))
    return out


def as_complex(a: Any) -> ComplexArray:
    return np.asarray(a, dtype=np.complex128)


def anchor_joint(key: str, joints: Container[str]) -> str:
    """The joint an anchor key (:func:`anchor_arrays`) belongs to: the key itself for a
    joint's centre, else the joint of a slider's block, origin or guide end
    (``"J/block"``).  Joint ids may hold ``/`` themselves (``"A/B"``): only a key that
    is not a joint's loses its last part.

    >>> anchor_joint("A/B", {"A/B"}), anchor_joint("A/B/block", {"A/B"})
    ('A/B', 'A/B')
    """
    return key if key in joints else key.rsplit("/", 1)[0]


def anchor_positions(scene: Scene, k: int) -> dict[str, complex]:
    """Where every joint centre, point, block and guide end is drawn at frame ``k``."""
    return {key: complex(a[k]) for key, a in anchor_arrays(scene).items()}


def anchor_arrays(scene: Scene) -> dict[str, ComplexArray]:
    """The drawn points over all frames: joint centres, points, blocks, guide ends."""
    motion, geom = scene.motion, scene.model.geometry
    out = {j: as_complex(motion.centre(j)[0]) for j in geom.centres}
    for pid, (link, z) in geom.points.items():
        out[pid] = as_complex(motion.point(link, z)[0])
    ext = 0.12 * scene.model.scale
    for jid in geom.axes:
        carrier, block = guide_sides(scene.model, jid)
        z = geom.centres[jid]
        out[f"{jid}/block"] = as_complex(motion.point(block, z)[0])
        u = geom.axes[jid] * as_complex(motion.evaluation.poses[carrier].r)
        origin = as_complex(motion.point(carrier, z)[0])
        lo, hi = scene.guides.get(jid, (0.0, 0.0))
        out[f"{jid}/origin"] = origin
        out[f"{jid}/guide0"] = origin + u * (lo - ext)
        out[f"{jid}/guide1"] = origin + u * (hi + ext)
    return out
