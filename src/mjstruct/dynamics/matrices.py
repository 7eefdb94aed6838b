"""Characteristic matrices of a mechanism (Panasenko's method), as arrays over frames.

Owns the five input matrices of the force analysis and their motion derivatives:

* the incidence matrix (links × simple joints, ±1) with the joint kinds, a multiple
  joint expanded into simple joints between its first listed link (the *carrier*) and
  each of its other links;
* the position functions of the links ``s`` (centre of mass x, y and the
  characteristic angle) and of the joints ``r`` (centre x, y and, for a slider, the
  guide angle), with the arms ``ρ = r − s``;
* their first and second derivatives (per-driver analogs σ, or time derivatives);
* the inertia matrix ``I`` (mass, mass, central moment) and the active force matrix
  ``F`` (Fx, Fy and the moment about the centre of mass; gravity included).

Positions are complex numbers ``x + iy`` inside; the public arrays are real.

References
----------
.. [1] A. N. Panasenko, "Practical implementation…" (in Russian; the available copy
   gives only this beginning of the title), Systems. Methods. Technologies,
   no. 2 (66), pp. 32–42, 2025. [Panasenko 2025] in docs/references.md.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> K, columns, kinds = incidence(read_mechanism(example_path("kin-radial-engine-5")))
>>> K.shape, int(abs(K.sum(axis=0)).max())         # 12 links × 16 simple joints; columns sum to 0
((12, 16), 0)
>>> columns[1], kinds[1]                           # the MJ A: carrier 1, expanded towards 2
(('A', '2'), 'R')
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.data import DynamicsData, LinkInertia
from mjstruct.errors import MechanismError
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.mechanism import Mechanism

FloatArray = npt.NDArray[np.float64]
ComplexArray = npt.NDArray[np.complex128]
BoolArray = npt.NDArray[np.bool_]


def incidence(m: Mechanism) -> tuple[npt.NDArray[np.int8], list[tuple[str, str]], list[str]]:
    """Incidence matrix links × simple joints, the columns' (joint, link) and kinds.

    A joint of m links is m − 1 simple joints: column (J, l) joins the carrier (the
    joint's first listed link, entry −1) to link l (entry +1), so every column sums to 0.
    ``kinds`` holds ``"R"`` or ``"P"`` per column.
    """
    cols: list[tuple[str, str]] = []
    kinds: list[str] = []
    for j in m.joints:
        for link in j.links[1:]:
            cols.append((j.id, link))
            kinds.append(j.kind)
    row = {link: i for i, link in enumerate(m.links)}
    K = np.zeros((len(m.links), len(cols)), np.int8)
    for c, (jid, link) in enumerate(cols):
        K[row[m.joint(jid).links[0]], c] = -1
        K[row[link], c] = 1
    return K, cols, kinds


def inertia_matrix(links: Sequence[str], inertia: Mapping[str, LinkInertia]) -> FloatArray:
    """``I`` (3 × moving links): rows mass, mass, central moment of inertia."""
    out = np.zeros((3, len(links)))
    for j, link in enumerate(links):
        out[0, j] = out[1, j] = inertia[link].mass
        out[2, j] = inertia[link].J
    return out


@dataclass(frozen=True)
class LinkMotion:
    """Motion of the moving links' centres of mass and of the joint centres over frames.

    Attributes
    ----------
    links : the moving links (rows of every per-link array).
    joints : the joints (rows of ``centre``).
    q : driver values, frames × drivers.
    com : centre of mass jets ``[position, velocity, acceleration]`` (complex, links × frames).
    angle : angle jets ``[θ, ω, ε]`` (links × frames).
    sigma_com, sigma_angle : per-driver analogs ``∂s/∂q_i`` (drivers × links × frames).
    centre : joint centres (joints × frames, complex; a slider: the point its second
        link carries).
    axis : prismatic joint -> current unit guide direction (frames,).
    valid : frames that assemble.
    motion : the kinematic solution (for points of links).
    """

    links: tuple[str, ...]
    joints: tuple[str, ...]
    q: FloatArray
    com: tuple[ComplexArray, ComplexArray, ComplexArray]
    angle: tuple[FloatArray, FloatArray, FloatArray]
    sigma_com: ComplexArray
    sigma_angle: FloatArray
    centre: ComplexArray
    axis: dict[str, ComplexArray]
    valid: BoolArray
    motion: Motion

    def s(self) -> FloatArray:
        """Position functions of the links ``s[i, j, frame]`` (x, y, angle)."""
        return np.stack([self.com[0].real, self.com[0].imag, self.angle[0]])

    def r(self) -> FloatArray:
        """Position functions of the joints ``r[i, k, frame]`` (x, y, guide angle or NaN)."""
        guide = np.full(self.centre.shape, np.nan)
        for k, jid in enumerate(self.joints):
            if jid in self.axis:
                guide[k] = np.angle(self.axis[jid])
        return np.stack([self.centre.real, self.centre.imag, guide])

    def rho(self) -> FloatArray:
        """Arms ``ρ[i, j, k, frame] = r[i, k] − s[i, j]`` (i = x, y)."""
        d = self.centre[None, :, :] - self.com[0][:, None, :]
        return np.stack([d.real, d.imag])


def _jets(
    mo: Motion, links: Sequence[str], inertia: Mapping[str, LinkInertia], order: int
) -> tuple[list[ComplexArray], list[FloatArray]]:
    c = [
        np.stack([mo.point(link, inertia[link].com)[k] for link in links])
        for k in range(order + 1)
    ]
    th = [np.stack([mo.angle(link)[k] for link in links]) for k in range(order + 1)]
    return c, th


# frames without a configuration carry NaN analogs (0 * NaN is intended there): they are
# marked in `valid` and reported, so numpy's warning would only repeat it
@np.errstate(invalid="ignore")
def link_motion(
    model: KinematicModel,
    inertia: Mapping[str, LinkInertia],
    q: npt.ArrayLike,
    qdot: npt.ArrayLike,
    qddot: npt.ArrayLike | None = None,
    motion: Motion | None = None,
) -> LinkMotion:
    """Positions, velocities, accelerations and analogs of every moving link.

    Parameters
    ----------
    q, qdot, qddot : driver values, speeds and accelerations (frames × drivers, or one
        value per frame for one driver; ``qdot`` may be one row for all frames).
    motion : a kinematic solution of ``model`` on ``q`` with order 2 and unit rates
        (one driver), reused when given.

    Notes
    -----
    The derivatives are exact analogs from the kinematics, never finite differences:
    ``a = Σ σ_i q̈_i + Σ κ_ij q̇_i q̇_j``, with κ_ij of several drivers from second
    derivatives along the directions e_i and e_i + e_j.
    """
    m = model.mechanism
    qa = model.driver_values(q)
    F, D = qa.shape
    qd = np.broadcast_to(
        np.asarray(qdot, float).reshape(-1, D),
        (F, D),
    )
    qdd = (
        np.zeros((F, D))
        if qddot is None
        else np.broadcast_to(np.asarray(qddot, float).reshape(-1, D), (F, D))
    )
    links = tuple(x for x in m.links if x != model.frame)
    if D == 1:
        mo = motion if motion is not None else model.motion(qa, order=2)
        c, th = _jets(mo, links, inertia, 2)
        sig_c, sig_t = c[1][None], th[1][None]
        w, wd = qd[:, 0], qdd[:, 0]
        com = (c[0], c[1] * w, c[2] * w**2 + c[1] * wd)
        ang = (th[0], th[1] * w, th[2] * w**2 + th[1] * wd)
        valid = mo.valid
    else:
        eye = np.eye(D)
        firsts = [model.motion(qa, order=1, rates=eye[i]) for i in range(D)]
        parts = [_jets(f, links, inertia, 1) for f in firsts]
        sig_c = np.stack([p[0][1] for p in parts])
        sig_t = np.stack([p[1][1] for p in parts])
        steady = qddot is None or not np.any(qdd)
        if steady and np.all(qd == qd[0]):
            mo = model.motion(qa, order=2, rates=qd[0])
            c, th = _jets(mo, links, inertia, 2)
            com = (c[0], c[1], c[2])
            ang = (th[0], th[1], th[2])
        else:
            mo = firsts[0]
            c0, t0 = parts[0][0][0], parts[0][1][0]
            vc = np.einsum("dlf,fd->lf", sig_c, qd)
            vt = np.einsum("dlf,fd->lf", sig_t, qd)
            ac = np.einsum("dlf,fd->lf", sig_c, qdd)
            at = np.einsum("dlf,fd->lf", sig_t, qdd)
            hess: dict[tuple[int, int], tuple[ComplexArray, FloatArray]] = {}
            for i in range(D):
                for k in range(i, D):
                    direction = eye[i] if i == k else eye[i] + eye[k]
                    cc, tt = _jets(model.motion(qa, order=2, rates=direction), links, inertia, 2)
                    hess[(i, k)] = (cc[2], tt[2])
            for i in range(D):
                ac = ac + hess[(i, i)][0] * qd[:, i] ** 2
                at = at + hess[(i, i)][1] * qd[:, i] ** 2
                for k in range(i + 1, D):
                    # κ_ik from the second derivative along e_i + e_k (polarisation)
                    kc = (hess[(i, k)][0] - hess[(i, i)][0] - hess[(k, k)][0]) / 2
                    kt = (hess[(i, k)][1] - hess[(i, i)][1] - hess[(k, k)][1]) / 2
                    ac = ac + 2 * kc * qd[:, i] * qd[:, k]
                    at = at + 2 * kt * qd[:, i] * qd[:, k]
            com = (c0, vc, ac)
            ang = (t0, vt, at)
        valid = np.logical_and.reduce([f.valid for f in firsts] + [mo.valid])
    joints = tuple(j.id for j in m.joints)
    centre = np.stack([mo.centre(jid)[0] for jid in joints])
    axis: dict[str, ComplexArray] = {}
    geom = model.geometry
    for j in m.joints:
        if j.kind == "P":
            base = j.links[0]
            turn = (
                mo.angle(base)[0] - geom.char_angle[base] if base != model.frame else np.zeros(F)
            )
            axis[j.id] = geom.axes[j.id] * np.exp(1j * turn)
    return LinkMotion(links, joints, qa, com, ang, sig_c, sig_t, centre, axis, valid, mo)


def active_forces(
    data: DynamicsData,
    lm: LinkMotion,
    parameters: Mapping[str, float],
    q: npt.ArrayLike,
    qdot: npt.ArrayLike,
) -> tuple[ComplexArray, FloatArray]:
    """The active force matrix at the centres of mass: force (complex) and moment, links × frames.

    Gravity ``m g`` acts at the centre of mass; a force applied at another point adds
    its moment about the centre of mass.  ``q`` and ``qdot`` are the values the load
    expressions see (the first driver's coordinate and speed).
    """
    index = {link: j for j, link in enumerate(lm.links)}
    F = lm.com[0].shape[1]
    force = np.zeros((len(lm.links), F), complex)
    moment = np.zeros((len(lm.links), F))
    for link, j in index.items():
        force[j] += data.inertia[link].mass * data.gravity
    for load in data.loads:
        j = index[load.link]
        comp = load.evaluate(q, qdot, parameters)
        if load.kind == "force":
            f = comp[0] + 1j * comp[1]
            arm = lm.motion.point(load.link, load.at)[0] - lm.com[0][j]
            force[j] += f
            moment[j] += arm.real * f.imag - arm.imag * f.real
        else:
            moment[j] += comp[2]
    return force, moment


def check_dimensions(model: KinematicModel) -> None:
    """Raise when the link equations cannot determine the joint loads (redundant joints)."""
    m = model.mechanism
    moving = sum(1 for x in m.links if x != model.frame)
    unknowns = sum(2 * j.multiplicity for j in m.joints) + len(model.drivers)
    if unknowns != 3 * moving:
        raise MechanismError(
            f"joints: the force analysis needs 3 equations per moving link for {unknowns} "
            f"unknown joint loads, got {3 * moving} (a mechanism with redundant constraints "
            "or the wrong number of drivers)"
        )
