"""The forces and reactions steps of a dynamic analysis, on the frames of a link motion.

Owns the two last steps before the result: the loads on every moving link at its
centre of mass (:func:`link_loads`: active loads and gravity, inertia loads), and the
joint loads they need (:func:`joint_loads`: the stacked link equations of
:mod:`mjstruct.dynamics.reactions` solved with their condition estimate, the warnings
for singular, unassembled and ill-conditioned frames, the excluded-equation check,
the loads per joint and link and the actuators' loads).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.dynamics.inputs import read_inputs
>>> from mjstruct.dynamics.matrices import link_motion
>>> model, data = read_inputs(read_mechanism(example_path("slider-crank-seed000-dynamics")),
...                           parameters={"p": 3.0})
>>> lm = link_motion(model, data.inertia, model.sweep(8), 2.0)
>>> loads = link_loads(data, lm, data.parameter_values(), lm.q[:, 0], 2.0)
>>> out = joint_loads(model, lm, loads, {"reactions", "check"})
>>> sorted(out.reactions["A"]), out.check < 1e-12
(['1', '2'], True)
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.data import DynamicsData
from mjstruct.dynamics.element_loads import element_loads
from mjstruct.dynamics.matrices import LinkMotion, active_forces
from mjstruct.dynamics.reactions import (
    SINGULAR_CONDITION,
    Unknown,
    generalised_drive,
    inertia_loads,
    is_moment,
    solve_stack,
    stack_loads,
    system_matrix,
    unknowns,
)
from mjstruct.kinematics.model import KinematicModel
from mjstruct.typing import BoolArray, ComplexArray, FloatArray

__all__ = ["EPS", "ILL_CONDITIONED", "JointLoads", "LinkLoads", "joint_loads", "link_loads"]


#: frames whose system is worse conditioned than this are named in a warning
ILL_CONDITIONED = 1e3

#: a lever (distance of a centre of mass or load point from its link's joints, in
#: mechanism sizes) from which it, not a position, may explain a large condition number
LONG_LEVER = 10.0

#: machine epsilon: the solve's relative error is up to condition × EPS
EPS = float(np.finfo(float).eps)


@dataclass(frozen=True)
class LinkLoads:
    """Loads on the moving links at their centres of mass (links × frames).

    Forces are complex ``Fx + i Fy``; moments about the centre of mass.
    """

    active_force: ComplexArray
    active_moment: FloatArray
    inertia_force: ComplexArray
    inertia_moment: FloatArray
    #: the largest distance of a centre of mass or a load's point from its link's
    #: joints in mechanism sizes, and its field (:attr:`DynamicsData.lever`)
    lever: float = 0.0
    lever_field: str = ""

    @property
    def force(self) -> ComplexArray:
        """Active plus inertia force."""
        out: ComplexArray = self.active_force + self.inertia_force
        return out

    @property
    def moment(self) -> FloatArray:
        """Active plus inertia moment."""
        out: FloatArray = self.active_moment + self.inertia_moment
        return out


def link_loads(
    data: DynamicsData,
    lm: LinkMotion,
    parameters: Mapping[str, float],
    q: npt.ArrayLike,
    qdot: npt.ArrayLike,
) -> LinkLoads:
    """The forces step: active loads (gravity and the force elements included) and inertia
    loads ``−m a``, ``−J ε``.

    ``q``, ``qdot``: what the load expressions see (the first driver's coordinate and
    speed).
    """
    mass = np.array([data.inertia[x].mass for x in lm.links])
    J = np.array([data.inertia[x].J for x in lm.links])
    fa, ma = active_forces(data, lm, parameters, q, qdot)
    if data.elements:
        el = element_loads(data, lm, parameters)
        fa, ma = fa + el.force, ma + el.moment
    fi, mi = inertia_loads(lm, mass, J)
    return LinkLoads(fa, ma, fi, mi, data.lever, data.lever_field)


@dataclass(frozen=True)
class JointLoads:
    """The reactions step's results over the frames of a link motion.

    Attributes
    ----------
    reactions : joint -> link -> components (None when not asked for).
    driving : driver -> actuator load (None when not asked for).
    residual : per-frame relative residual of the excluded equation (None when the
        check was not asked for); ``check`` its largest value.
    condition : per-frame condition estimate of the link equations (NaN where the
        mechanism does not assemble); ``accuracy`` condition × machine epsilon on
        the frames solved.
    warnings : singular, unassembled and ill-conditioned frames.
    """

    reactions: dict[str, dict[str, dict[str, FloatArray]]] | None
    driving: dict[str, FloatArray] | None
    residual: FloatArray | None
    check: float | None
    condition: FloatArray
    accuracy: FloatArray
    warnings: tuple[str, ...]


def joint_loads(
    model: KinematicModel,
    lm: LinkMotion,
    loads: LinkLoads,
    wanted: Collection[str],
    joints: Collection[str] | None = None,
    free: bool = False,
) -> JointLoads:
    """The reactions step: joint and actuator loads on the frames of ``lm``.

    Parameters
    ----------
    wanted : the outputs asked for (``reactions``, ``driving``, ``check``).
    joints : report the reactions of these joints only (checked ids; default all).
    free : free motion (the actuator of the free coordinate applies no load).
    """
    cols = unknowns(model)
    force, moment = loads.force, loads.moment
    # in units of the mechanism's size: the solve and its condition are scale-free
    A = system_matrix(model, lm, cols)
    ok = lm.valid.copy()
    S = np.where(ok[:, None], stack_loads(force, moment, model.scale), np.nan)
    x, solved, cond = solve_stack(A, S)
    moments = is_moment(model, cols)
    x[:, moments] *= model.scale  # moments back in the file's units
    warnings = _frame_warnings(lm, ok, solved, cond)
    solved &= ok
    solved_kappa = np.where(solved, cond, np.nan)
    worst = int(np.nanargmax(solved_kappa)) if np.isfinite(solved_kappa).any() else None
    if worst is not None and cond[worst] > ILL_CONDITIONED:
        c = cond[worst]
        lever = loads.lever
        # the condition grows with the square of a long lever (about 4 λ² on the
        # examples): then the lever, not the position, is the cause
        what = (
            f"ill-conditioned link equations ({loads.lever_field} lies {lever:.3g} × the "
            "mechanism's size from its link's joints)"
            if lever >= LONG_LEVER and c <= 100 * lever**2
            else "near-singular position"
        )
        warnings.append(
            f"{what}: the link equations' condition number reaches "
            f"{c:.3g} at q = {float(lm.q[worst, 0]):.9g}; accelerations and "
            f"reactions there lose {np.log10(c):.0f} to "
            f"{2 * np.log10(c):.0f} digits"
        )
    drive_cols = [c for c, u in enumerate(cols) if u.kind == "drive"]
    tau_sys = x[:, drive_cols].T  # drivers × frames
    tau_eom = np.zeros_like(tau_sys) if free else generalised_drive(lm, force, moment)
    residual = _excluded_equation(model, moments, loads, x, solved, tau_sys, tau_eom)
    check = float(np.nanmax(residual)) if np.isfinite(residual).any() else None
    driving: dict[str, FloatArray] | None = None
    if "driving" in wanted:
        shown = np.zeros_like(tau_sys) if free else np.where(solved[None], tau_sys, np.nan)
        driving = {d: shown[i] for i, d in enumerate(model.drivers)}
    return JointLoads(
        reactions=_per_joint(model, lm, cols, x, joints) if "reactions" in wanted else None,
        driving=driving,
        residual=residual if "check" in wanted else None,
        check=check if "check" in wanted else None,
        condition=np.where(ok, cond, np.nan),  # singular frames keep theirs: it says why
        accuracy=solved_kappa * EPS,
        warnings=tuple(warnings),
    )


def _frame_warnings(
    lm: LinkMotion, ok: BoolArray, solved: BoolArray, cond: FloatArray
) -> list[str]:
    """Warnings naming the singular frames and those that do not assemble."""
    out: list[str] = []
    if (ok & ~solved).any():
        bad = float(lm.q[np.argmax(ok & ~solved), 0])
        out.append(
            f"the joint loads are not determined at {int((ok & ~solved).sum())} frame(s) "
            f"(a singular position: condition number above {SINGULAR_CONDITION:.0e}; "
            f"first q = {bad:.9g}); their values are null"
        )
    if (~ok).any():
        out.append(
            f"the mechanism does not assemble at {int((~ok).sum())} frame(s) "
            f"(first q = {float(lm.q[np.argmax(~ok), 0]):.9g}); their values are null"
        )
    return out


def _excluded_equation(
    model: KinematicModel,
    moments: BoolArray,
    loads: LinkLoads,
    x: FloatArray,
    solved: BoolArray,
    tau_sys: FloatArray,
    tau_eom: FloatArray,
) -> FloatArray:
    """Per-frame residual of the excluded equation, relative to the frame's largest load.

    ``moments``: which unknowns (columns of ``x``) are moments.  Moments count as
    forces at the mechanism's size (which also multiplies the divisor of a torque);
    frames not solved are NaN.
    """
    m = model.mechanism
    ell = model.scale
    is_force = ~moments
    ax = np.abs(x)
    fa, ma = loads.active_force, loads.active_moment
    fi, mi = loads.inertia_force, loads.inertia_moment
    # np.fmax ignores NaN without the All-NaN warning of np.nanmax (frames not solved)
    with np.errstate(all="ignore"):
        big_f = np.fmax.reduce(np.concatenate([np.abs(fa), np.abs(fi), ax[:, is_force].T]), axis=0)
        big_m = np.fmax.reduce(
            np.concatenate([np.abs(ma), np.abs(mi), ax[:, ~is_force].T]), axis=0
        )
        big = np.fmax(big_f, big_m / ell)
        unit = np.array([ell if m.joint(d).kind == "R" else 1.0 for d in model.drivers])
        rel = np.abs(tau_sys - tau_eom) / (big[None] * unit[:, None])
        rel = np.where(big[None] > 0, rel, np.abs(tau_sys - tau_eom))
    out: FloatArray = np.where(solved, np.fmax.reduce(rel, axis=0), np.nan)
    return out


def _per_joint(
    model: KinematicModel,
    lm: LinkMotion,
    cols: list[Unknown],
    x: FloatArray,
    joints: Collection[str] | None,
) -> dict[str, dict[str, dict[str, FloatArray]]]:
    """The load of each joint on each of its links (an MJ's carrier takes minus the sum)."""
    reactions: dict[str, dict[str, dict[str, FloatArray]]] = {}
    index = {(u.joint, u.link, u.kind): c for c, u in enumerate(cols)}
    for j in model.mechanism.joints:
        if joints is not None and j.id not in joints:
            continue
        per: dict[str, dict[str, FloatArray]] = {}
        if j.kind == "R":
            sx = np.zeros(lm.q.shape[0])
            sy = np.zeros(lm.q.shape[0])
            for link in j.links[1:]:
                rx, ry = x[:, index[(j.id, link, "x")]], x[:, index[(j.id, link, "y")]]
                per[link] = {"x": rx, "y": ry}
                sx, sy = sx + rx, sy + ry
            per = {j.links[0]: {"x": -sx, "y": -sy}, **per}
        else:
            nvec = 1j * lm.axis[j.id] * x[:, index[(j.id, j.links[1], "n")]]
            mm = x[:, index[(j.id, j.links[1], "m")]]
            per[j.links[0]] = {"x": -nvec.real, "y": -nvec.imag, "m": -mm}
            per[j.links[1]] = {"x": nvec.real, "y": nvec.imag, "m": mm}
        reactions[j.id] = per
    return reactions
