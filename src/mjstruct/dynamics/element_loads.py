"""The loads of the force elements on a link motion: at the centres of mass, with their energy.

Owns :func:`element_loads`: every element of :mod:`mjstruct.dynamics.elements`
evaluated on the frames of a :class:`~mjstruct.dynamics.matrices.LinkMotion` (the
positions and velocities of the links' centres of mass and angles), reduced to a force
at each moving link's centre of mass and a moment about it (the active force matrix's
form, so the equations of motion and the link equations take them like any load), the
part of it that does work (dampers and motors) kept apart, and the energy the springs
store.

A point of link l whose reference position is r is at ``P + e^{i(θ − θ_ref)} (r − c_ref)``
(P, θ the link's centre of mass and angle, c_ref, θ_ref their reference values) and
moves at ``V + i ω (z − P)``.  A joint element's coordinate is link b's against link a's:
the relative angle ``θ_b − θ_a`` at a revolute joint (as the kinematics prints a
revolute driver's q), the slide along the guide from the reference position at a
prismatic joint (a prismatic driver's q).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.dynamics.inputs import read_inputs
>>> from mjstruct.dynamics.matrices import link_motion
>>> model, data = read_inputs(read_mechanism(example_path("five-bar-springs-dynamics")))
>>> lm = link_motion(model, data.inertia, model.q_ref[None], [[0.0, 0.0]])
>>> out = element_loads(data, lm)
>>> out.force.shape, float(out.potential[0]) > 0
((4, 1), True)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from mjstruct.dynamics.data import DynamicsData
from mjstruct.dynamics.elements import Element
from mjstruct.dynamics.matrices import LinkMotion
from mjstruct.errors import MechanismError
from mjstruct.typing import ComplexArray, FloatArray

__all__ = ["ElementLoads", "element_loads", "gravity_potential"]


@dataclass(frozen=True)
class ElementLoads:
    """The elements' loads at the moving links' centres of mass (links × frames).

    ``force``, ``moment``: all elements; ``working_force``, ``working_moment``: the
    part of dampers and motors (its work is carried along in time, the springs' is
    ``potential``, their stored energy per frame).
    """

    force: ComplexArray
    moment: FloatArray
    working_force: ComplexArray
    working_moment: FloatArray
    potential: FloatArray


class _Poses:
    """Positions and velocities of points and angles of every link, frame included."""

    def __init__(self, data: DynamicsData, lm: LinkMotion) -> None:
        self.lm = lm
        self.geometry = lm.motion.model.geometry
        self.frame = lm.motion.model.frame
        self.index = {link: j for j, link in enumerate(lm.links)}
        self.inertia = data.inertia
        self.n = lm.com[0].shape[1]

    def angle(self, link: str) -> tuple[FloatArray, FloatArray, float]:
        """θ, ω over the frames and θ_ref."""
        if link == self.frame:
            return np.zeros(self.n), np.zeros(self.n), 0.0
        j = self.index[link]
        return self.lm.angle[0][j], self.lm.angle[1][j], self.geometry.char_angle[link]

    def point(self, link: str, at: complex) -> tuple[ComplexArray, ComplexArray]:
        """Position and velocity of the point of ``link`` at ``at`` in the reference."""
        if link == self.frame:
            return np.full(self.n, at, complex), np.zeros(self.n, complex)
        j = self.index[link]
        theta, omega, ref = self.angle(link)
        P, V = self.lm.com[0][j], self.lm.com[1][j]
        z = P + np.exp(1j * (theta - ref)) * (at - self.inertia[link].com)
        return z, V + 1j * omega * (z - P)


class _Sum:
    """Loads reduced to the centres of mass of the moving links."""

    def __init__(self, poses: _Poses) -> None:
        L = len(poses.lm.links)
        self.poses = poses
        self.force = np.zeros((L, poses.n), complex)
        self.moment = np.zeros((L, poses.n))

    def add_force(self, link: str, f: ComplexArray, z: ComplexArray) -> None:
        if link == self.poses.frame:
            return
        j = self.poses.index[link]
        arm = z - self.poses.lm.com[0][j]
        self.force[j] += f
        self.moment[j] += arm.real * f.imag - arm.imag * f.real

    def add_moment(self, link: str, m: FloatArray) -> None:
        if link != self.poses.frame:
            self.moment[self.poses.index[link]] += m


def element_loads(
    data: DynamicsData, lm: LinkMotion, parameters: Mapping[str, float] | None = None
) -> ElementLoads:
    """The loads and the stored energy of ``data.elements`` on the frames of ``lm``.

    ``parameters``: the values a motor law may use (default the file's).

    Raises
    ------
    MechanismError
        naming the element: a motor law that is not finite, a line element whose two
        points meet (its direction is lost).
    """
    poses = _Poses(data, lm)
    springs, working = _Sum(poses), _Sum(poses)
    potential = np.zeros(poses.n)
    values = data.parameter_values() if parameters is None else parameters
    for el in data.elements:
        total = springs if el.conservative else working
        if el.points:
            potential += _line(el, poses, total)
        else:
            potential += _joint(el, poses, total, values)
    return ElementLoads(
        springs.force + working.force,
        springs.moment + working.moment,
        working.force,
        working.moment,
        potential,
    )


def _line(el: Element, poses: _Poses, out: _Sum) -> FloatArray:
    p1, p2 = el.points
    z1, v1 = poses.point(p1.link, p1.at)
    z2, v2 = poses.point(p2.link, p2.at)
    d = z2 - z1
    length = np.abs(d)
    if not (length > 0).all():
        raise MechanismError(f"{el.where}.between: the two points meet; the force has no line")
    e = d / length
    if el.kind == "spring":
        tension = el.stiffness * (length - el.free)
        energy = 0.5 * el.stiffness * (length - el.free) ** 2
    else:
        tension = el.rate * ((v2 - v1) * e.conjugate()).real
        energy = np.zeros(poses.n)
    out.add_force(p2.link, -tension * e, z2)
    out.add_force(p1.link, tension * e, z1)
    out_energy: FloatArray = np.asarray(energy, float)
    return out_energy


def joint_coordinate(
    el: Element, poses: _Poses
) -> tuple[FloatArray, FloatArray, ComplexArray, ComplexArray]:
    """A joint element's coordinate and rate, and (slides) the guide and the centre."""
    a, b = el.links
    ta, wa, ra = poses.angle(a)
    tb, wb, rb = poses.angle(b)
    if not el.slide:
        none = np.zeros(0, complex)
        model = poses.lm.motion.model
        if (
            el.joint in model.drivers
            and tuple(model.mechanism.joint(el.joint).links[:2]) == el.links
        ):
            # a driver's own coordinate: continued whatever the link angles' wrapping
            i = model.drivers.index(el.joint)
            return poses.lm.q[:, i], wb - wa, none, none
        ref = rb - ra  # within a half-turn of the reference relative angle
        turn = np.mod(tb - ta - ref + np.pi, 2 * np.pi) - np.pi
        return ref + turn, wb - wa, none, none
    g = poses.geometry
    c = g.centres[el.joint]
    u = g.axes[el.joint] * np.exp(1j * (ta - ra))
    za, va = poses.point(a, c)
    zb, vb = poses.point(b, c)
    s = ((zb - za) * u.conjugate()).real
    rate = ((vb - va) * u.conjugate()).real + ((zb - za) * (1j * wa * u).conjugate()).real
    return s, rate, u, zb


def _joint(el: Element, poses: _Poses, out: _Sum, parameters: Mapping[str, float]) -> FloatArray:
    x, rate, u, centre = joint_coordinate(el, poses)
    energy = np.zeros(poses.n)
    if el.kind == "motor":
        assert el.law is not None
        with np.errstate(all="ignore"):
            try:
                raw = np.asarray(el.law(x, rate, *[parameters[a] for a in el.arguments]))
                load = np.broadcast_to(raw, x.shape).astype(float)
            except (ArithmeticError, ValueError, TypeError):
                load = np.full(x.shape, np.nan)
        if not np.isfinite(load).all():
            bad = int(np.argmax(~np.isfinite(load)))
            raise MechanismError(f"{el.where}.law: not finite at q = {float(x[bad]):.9g}")
    elif el.kind in ("torsion_damper", "slide_damper"):
        load = -el.rate * rate
    else:
        free = el.free
        if free is None:  # a torsion spring free in the reference configuration
            g = poses.geometry
            a, b = el.links
            ref = {link: 0.0 if link == poses.frame else g.char_angle[link] for link in el.links}
            free = ref[b] - ref[a]
        load = -el.stiffness * (x - free)
        energy = 0.5 * el.stiffness * (x - free) ** 2
    a, b = el.links
    if el.slide:
        f = load * u
        out.add_force(b, f, centre)
        out.add_force(a, -f, centre)
    else:
        out.add_moment(b, load)
        out.add_moment(a, -load)
    result: FloatArray = np.asarray(energy, float)
    return result


def gravity_potential(data: DynamicsData, lm: LinkMotion) -> FloatArray:
    """``−Σ m g · P`` over the frames: the potential energy of the weights."""
    g = data.gravity
    out = np.zeros(lm.com[0].shape[1])
    for j, link in enumerate(lm.links):
        m = data.inertia[link].mass
        if m:
            out -= m * (g.real * lm.com[0][j].real + g.imag * lm.com[0][j].imag)
    return out
