"""Force layers of a drawing (dynamics plug-in): applied loads, inertia forces, reactions.

Owns what the ``loads``, ``inertia`` and ``reactions`` layers draw, as arrows over the
frames of a scene: each layer gives ``(label, position, force)`` arrays over the frames
(positions and forces as complex numbers) and couples as ``(label, position, moment)``.

* ``loads``: each force of the file's ``loads`` at its point, gravity ``m g`` at each
  centre of mass, and the file's couples; a steady-motion unknown parameter is first
  solved (one call of :func:`mjstruct.dynamics.dynamic_analysis` with no outputs).
* ``inertia``: ``-m a`` at each centre of mass and the couple ``-J ε``, from the scene's
  own second-order motion (a = κ W² at constant driver speed W).
* ``reactions``: the load each joint applies to a link: one arrow per simple joint (on
  its second listed link; the first gets the opposite) and one per link at a multiple
  joint, from :func:`~mjstruct.dynamics.dynamic_analysis` asked for reactions only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.typing import ComplexArray, FloatArray

FORCE_LAYERS = ("loads", "inertia", "reactions")


@dataclass(frozen=True)
class ForceLayer:
    """Arrows and couples of one force layer over the frames of a scene."""

    arrows: tuple[tuple[str, ComplexArray, ComplexArray], ...]
    couples: tuple[tuple[str, ComplexArray, FloatArray], ...]


def _data(model: KinematicModel) -> Any:
    from mjstruct.dynamics.data import read_dynamics

    data = read_dynamics(model.mechanism)
    if not data.loads and all(i.mass == 0 and i.J == 0 for i in data.inertia.values()):
        raise MechanismError("inertia: the file has no dynamics data (no masses, no loads)")
    return data


def _parameters(model: KinematicModel, data: Any, speed: float, frames: int) -> dict[str, float]:
    if data.unknown is None:
        return dict(data.parameter_values())
    from mjstruct.dynamics import dynamic_analysis

    r = dynamic_analysis(model.mechanism, speed=speed, frames=frames, model=model, outputs=())
    return dict(r.parameters)


def force_layers(
    model: KinematicModel,
    motion: Motion,
    layers: tuple[str, ...],
    speed: float,
    over_cycle: bool,
) -> dict[str, ForceLayer]:
    """The force layers among ``layers`` over the frames of ``motion``.

    ``over_cycle``: the motion is the constant-speed sweep of one cycle (an animation),
    else a path to one configuration (the reactions are then solved on that path).
    """
    wanted = [x for x in layers if x in FORCE_LAYERS]
    if not wanted:
        return {}
    data = _data(model)
    q = motion.q
    frames = q.shape[0]
    params = _parameters(model, data, speed, frames if over_cycle else 72)
    out: dict[str, ForceLayer] = {}
    if "loads" in wanted:
        arrows: list[tuple[str, ComplexArray, ComplexArray]] = []
        couples: list[tuple[str, ComplexArray, FloatArray]] = []
        qdot = np.full(frames, float(speed))
        for link, inertia in data.inertia.items():
            if inertia.mass and data.gravity:
                at = _point(motion, link, inertia.com)
                arrows.append((f"m g ({link})", at, np.full(frames, inertia.mass * data.gravity)))
        for load in data.loads:
            comp = load.evaluate(q[:, 0], qdot, params)
            if load.kind == "force":
                at = _point(motion, load.link, load.at)
                arrows.append((load.where, at, (comp[0] + 1j * comp[1]).astype(np.complex128)))
            else:
                at = _point(motion, load.link, data.inertia[load.link].com)
                couples.append((f"M ({load.link})", at, comp[2].astype(np.float64)))
        out["loads"] = ForceLayer(tuple(arrows), tuple(couples))
    if "inertia" in wanted:
        if motion.order < 2:
            raise MechanismError("layers: the inertia layer needs a motion of order 2")
        arrows, couples = [], []
        for link, inertia in data.inertia.items():
            jet = motion.point(link, inertia.com)
            at = np.asarray(jet[0], np.complex128)
            if inertia.mass:
                acc = np.asarray(jet[2], np.complex128) * speed**2
                arrows.append((f"-m a ({link})", at, -inertia.mass * acc))
            eps = np.asarray(motion.angle(link)[2], np.float64) * speed**2
            if inertia.J and np.nanmax(np.abs(eps), initial=0.0) > 1e-12 * speed**2:
                couples.append((f"-J ε ({link})", at, -inertia.J * eps))
        out["inertia"] = ForceLayer(tuple(arrows), tuple(couples))
    if "reactions" in wanted:
        out["reactions"] = ForceLayer(_reactions(model, motion, speed, params, over_cycle), ())
    return out


def _point(motion: Motion, link: str, z: complex) -> ComplexArray:
    return np.asarray(motion.point(link, z)[0], np.complex128)


def _reactions(
    model: KinematicModel, motion: Motion, speed: float, params: dict[str, float], cycle: bool
) -> tuple[tuple[str, ComplexArray, ComplexArray], ...]:
    from mjstruct.dynamics import dynamic_analysis

    m = model.mechanism
    frames = motion.q.shape[0]
    if cycle:
        r = dynamic_analysis(
            m, speed=speed, frames=frames, model=model, outputs=("reactions",), parameters=params
        )
    else:
        d = len(model.drivers)
        r = dynamic_analysis(
            m,
            q=motion.q,
            qdot=np.full((frames, d), float(speed)),
            qddot=np.zeros((frames, d)),
            model=model,
            outputs=("reactions",),
            parameters=params,
        )
    arrows = []
    for jid, per in (r.reactions or {}).items():
        j = m.joint(jid)
        links = list(per) if j.is_multiple else [j.links[1]]
        at = np.asarray(motion.centre(jid)[0], np.complex128)
        for link in links:
            f = per[link]
            force = (np.asarray(f["x"], float) + 1j * np.asarray(f["y"], float)).astype(
                np.complex128
            )
            arrows.append((f"{jid}→{link}", at, force))
    return tuple(arrows)
