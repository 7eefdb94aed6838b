"""Lagrange's equations of a mechanism with any number of drivers: ``M(q) q̈ + h(q, q̇) = Q(q, q̇)``.

Owns :func:`motion_terms`: on states ``(q, q̇)`` (frames × drivers) the mass matrix, the
velocity terms, the generalised forces and the energies, from the characteristic
matrices of :mod:`mjstruct.dynamics.matrices` (one driver's V, W and Q in D
dimensions).  With σ_i the analogs of the links' centres of mass and angles along
driver i (the kinematics' derivatives along e_i) and ``a₀ = Σ_jk κ_jk q̇_j q̇_k`` their
accelerations at q̈ = 0 (the kinematics' second derivative along q̇):

* ``M_ij = Σ (m σc_i · σc_j + J σθ_i σθ_j)`` (the kinetic energy is ``q̇ᵀ M q̇ / 2``);
* ``h_i = Σ (m σc_i · a₀c + J σθ_i a₀θ)`` (for one driver ``W q̇²``);
* ``Q_i = Σ (F · σc_i + M σθ_i)`` with F, M the active force matrix (gravity and the
  file's loads) plus the force elements' loads
  (:mod:`mjstruct.dynamics.element_loads`), each reduced to the centre of mass.

So ``q̈ = M⁻¹ (Q − h)``.  For one driver, M = V and h = W q̇² (tests).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.dynamics.inputs import read_inputs
>>> model, data = read_inputs(read_mechanism(example_path("five-bar-springs-dynamics")))
>>> t = motion_terms(model, data, data.parameter_values(), model.q_ref[None], [[1.0, -0.5]])
>>> t.M.shape, bool(np.allclose(t.M[0], t.M[0].T)), bool(np.linalg.eigvalsh(t.M[0]).min() > 0)
((1, 2, 2), True, True)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.data import DynamicsData, LinkInertia
from mjstruct.dynamics.element_loads import element_loads, gravity_potential
from mjstruct.dynamics.matrices import LinkMotion, active_forces, link_motion
from mjstruct.dynamics.reactions import generalised_drive
from mjstruct.kinematics.model import KinematicModel
from mjstruct.typing import BoolArray, FloatArray

__all__ = ["MotionTerms", "motion_terms"]


@dataclass(frozen=True)
class MotionTerms:
    """The terms of ``M q̈ + h = Q`` on states (frames × drivers).

    Attributes
    ----------
    M : mass matrices, frames × D × D.
    h : velocity terms, frames × D.
    Q : generalised forces of every load (gravity, loads, elements), frames × D.
    Q_work : the part of the loads, dampers and motors (frames × D): the forces
        without a potential, whose power ``Q_work · q̇`` is integrated for the energy
        balance.
    kinetic, potential : ``q̇ᵀ M q̇ / 2`` and the energy of gravity and the springs.
    valid : frames that assemble.
    motion : the link motion of the states.
    """

    M: FloatArray
    h: FloatArray
    Q: FloatArray
    Q_work: FloatArray
    kinetic: FloatArray
    potential: FloatArray
    valid: BoolArray
    motion: LinkMotion

    def acceleration(self) -> FloatArray:
        """``q̈ = M⁻¹ (Q − h)`` per frame (frames × D); NaN on a frame that does not
        assemble or whose mass matrix is singular (a dead position of the drivers)."""
        D = self.M.shape[-1]
        out = np.full(self.h.shape, np.nan)
        rhs = self.Q - self.h
        ok = self.valid & np.isfinite(self.M).all(axis=(1, 2)) & np.isfinite(rhs).all(axis=1)
        if ok.any():
            M = self.M[ok]
            # singular to the precision of M itself: no acceleration is determined
            cond = np.linalg.cond(M) if D > 1 else np.ones(M.shape[0])
            good = (cond < 1e14) & (np.abs(M).reshape(M.shape[0], -1).max(axis=1) > 0)
            idx = np.flatnonzero(ok)[good]
            if idx.size:
                out[idx] = np.linalg.solve(self.M[idx], rhs[idx][..., None])[..., 0]
        return out


def _generalised(
    lm: LinkMotion, force: npt.NDArray[np.complex128], moment: FloatArray
) -> FloatArray:
    """``Σ (F · σc_i + M σθ_i)`` per frame, frames × drivers."""
    out: FloatArray = -generalised_drive(lm, force, moment).T
    return out


def motion_terms(
    model: KinematicModel,
    data: DynamicsData,
    parameters: Mapping[str, float],
    q: npt.ArrayLike,
    qdot: npt.ArrayLike,
) -> MotionTerms:
    """``M``, ``h``, ``Q`` and the energies on states ``(q, q̇)`` (frames × drivers).

    The file's load expressions see the first driver's ``q`` and ``qdot``; a motor's
    law sees its own joint's (:mod:`mjstruct.dynamics.elements`).
    """
    qa = model.driver_values(q)
    if qa.shape[0] == 1:
        lm = state_motion(model, data.inertia, qa[0], lm_speed_row(qdot, qa.shape[1]))
    else:
        lm = link_motion(model, data.inertia, qa, qdot)  # accelerations at q̈ = 0: a₀
    mass = np.array([data.inertia[x].mass for x in lm.links])
    J = np.array([data.inertia[x].J for x in lm.links])
    sc, st = lm.sigma_com, lm.sigma_angle  # D × links × frames
    M = np.einsum("l,ilf,jlf->fij", mass, sc.real, sc.real)
    M += np.einsum("l,ilf,jlf->fij", mass, sc.imag, sc.imag)
    M += np.einsum("l,ilf,jlf->fij", J, st, st)
    h = _generalised(lm, mass[:, None] * lm.com[2], J[:, None] * lm.angle[2])
    qd = lm_speed(lm, qdot)
    fa, ma = active_forces(data, lm, parameters, lm.q[:, 0], qd[:, 0])
    weight = mass[:, None] * data.gravity
    el = element_loads(data, lm, parameters)
    Q = _generalised(lm, fa + el.force, ma + el.moment)
    Q_work = _generalised(lm, fa - weight + el.working_force, ma + el.working_moment)
    kinetic = 0.5 * np.einsum("fi,fij,fj->f", qd, M, qd)
    potential = gravity_potential(data, lm) + el.potential
    return MotionTerms(M, h, Q, Q_work, kinetic, potential, lm.valid, lm)


def lm_speed(lm: LinkMotion, qdot: npt.ArrayLike) -> FloatArray:
    """``qdot`` shaped as frames × drivers like ``lm.q``."""
    F, D = lm.q.shape
    out: FloatArray = np.broadcast_to(np.asarray(qdot, float).reshape(-1, D), (F, D))
    return out


def lm_speed_row(qdot: npt.ArrayLike, D: int) -> FloatArray:
    """One state's speeds as a vector of D."""
    out: FloatArray = np.asarray(qdot, float).reshape(D)
    return out


def state_motion(
    model: KinematicModel,
    inertia: Mapping[str, LinkInertia],
    q: FloatArray,
    qdot: FloatArray,
) -> LinkMotion:
    """:func:`~mjstruct.dynamics.matrices.link_motion` of one state at q̈ = 0, lean.

    One kinematic solve per driver (the analogs σ_i, derivatives along e_i) and one
    along q̇ (velocities and a₀); the angles are the poses' (not continued: one frame
    has nothing to continue from), which is what a time integrator calls thousands of
    times.
    """
    D = q.shape[0]
    qa = q[None]
    links = tuple(x for x in model.mechanism.links if x != model.frame)
    char = model.geometry.char_angle
    sig_c = np.empty((D, len(links), 1), complex)
    sig_t = np.empty((D, len(links), 1))
    full = model.motion(qa, order=2, rates=qdot if D > 1 else np.ones(1))
    valid = full.valid.copy()
    if D == 1:
        firsts = [full]
    else:
        firsts = [model.motion(qa, order=1, rates=e) for e in np.eye(D)]
        for f in firsts:
            valid &= f.valid
    for i, f in enumerate(firsts):
        poses = f.evaluation.poses
        for j, link in enumerate(links):
            sig_c[i, j] = poses[link].point(inertia[link].com)[1]
            sig_t[i, j] = poses[link].w[0]
    com = [np.empty((len(links), 1), complex) for _ in range(3)]
    ang = [np.empty((len(links), 1)) for _ in range(3)]
    poses = full.evaluation.poses
    w = 1.0 if D > 1 else float(qdot[0])
    for j, link in enumerate(links):
        pose = poses[link]
        jet = pose.point(inertia[link].com)
        com[0][j], com[1][j], com[2][j] = jet[0], jet[1] * w, jet[2] * w * w
        ang[0][j] = np.angle(pose.r) + char[link]
        ang[1][j], ang[2][j] = pose.w[0] * w, pose.w[1] * w * w
    none = np.zeros((0, 1), complex)
    return LinkMotion(
        links,
        (),
        qa,
        (com[0], com[1], com[2]),
        (ang[0], ang[1], ang[2]),
        sig_c,
        sig_t,
        none,
        {},
        valid,
        full,
    )
