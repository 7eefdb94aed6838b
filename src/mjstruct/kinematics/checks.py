"""Checks of a kinematic analysis against independent computations.

Owns what the analysis verifies about its own numbers: link lengths between every
pair of centres (and points) on one link over the valid frames, the analogs σ against
five-point differences of the positions, the closure equations' residuals, the
near-singular frames (below :data:`~mjstruct.kinematics.tolerances.NEAR_SINGULAR` of
the largest driver-fixed determinant) from the plan's group determinants — the
default checks, O(frames) — and, when asked (``checks="full"``), the constraint
Jacobian's rank (mobility refinement, redundant constraints) and determinant with the
drivers fixed.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.solver import kinematic_analysis
>>> m = read_mechanism(example_path("four-bar"))
>>> r = kinematic_analysis(m, frames=36)
>>> r.checks["jacobian"]["full"], r.checks["link_lengths"]["max_error"] < 1e-12
(False, True)
>>> kinematic_analysis(m, frames=36, checks="full").checks["jacobian"]["rank"]
[8]
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError
from mjstruct.kinematics.closure import closure_jacobian
from mjstruct.kinematics.jacobian import check_jacobian, one_blas_thread
from mjstruct.kinematics.model import Motion
from mjstruct.kinematics.result import KinematicsResult
from mjstruct.kinematics.tolerances import NEAR_SINGULAR
from mjstruct.singular_seam import singular_namer

FloatArray = npt.NDArray[np.float64]


def batched_det(A: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Sign and log |det| of stacked small square matrices (frames × k × k).

    Gaussian elimination with partial pivoting, vectorised over the frames (a Python
    loop over the k columns only): no LAPACK call per tiny matrix, no threads.

    >>> A = np.array([[[2.0, 1.0], [1.0, 3.0]], [[0.0, 1.0], [1.0, 0.0]]])
    >>> s, l = batched_det(A)
    >>> (s * np.exp(l)).round(12).tolist()
    [5.0, -1.0]
    """
    if A.shape[1] == 1 and A.shape[2] == 1:
        # one unknown: the entry itself (what the elimination below gives, bit for bit)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.sign(A[:, 0, 0]), np.log(np.abs(A[:, 0, 0]))
    M = np.array(A, dtype=float)
    F, k, _ = M.shape
    sign = np.ones(F)
    logabs = np.zeros(F)
    singular = np.zeros(F, bool)
    rows = np.arange(F)
    for c in range(k):
        p = c + np.argmax(np.abs(M[:, c:, c]), axis=1)
        swap = p != c
        sign[swap] *= -1.0
        top = M[rows, p].copy()
        M[rows, p] = M[:, c]
        M[:, c] = top
        piv = M[:, c, c]
        singular |= ~(piv != 0)
        piv = np.where(singular, 1.0, piv)  # a singular matrix stays one (below)
        sign *= np.sign(piv)
        with np.errstate(divide="ignore", invalid="ignore"):
            logabs += np.log(np.abs(piv))
            f = M[:, c + 1 :, c] / piv[:, None]
        M[:, c + 1 :, c:] -= f[:, :, None] * M[:, None, c, c:]
    sign[singular] = 0.0
    logabs[singular] = -np.inf
    return sign, logabs


def plan_determinant(motion: Motion) -> tuple[FloatArray, FloatArray]:
    """Sign and log | . | per frame of the product of the plan's group determinants.

    Each dyad's determinant (the signed sine at its solved joint, the Jacobian of its
    two equations) and, for a plan with closure unknowns, the determinant of the
    closure equations' Jacobian with respect to the unknowns.  Eliminating the groups
    in the plan's order makes the driver-fixed constraint Jacobian block triangular,
    so its determinant is this product times a constant of the geometry.
    """
    ev, q = motion.evaluation, motion.q
    F = q.shape[0]
    sign = np.ones(F)
    logabs = np.zeros(F)
    with np.errstate(divide="ignore", invalid="ignore"):
        for _, det in ev.diag.values():
            sign *= np.sign(det)
            logabs += np.log(np.abs(det))
        if motion.closure is not None:
            Rt = _closure_jacobian(motion)
            if Rt.shape[1] != Rt.shape[2]:
                return np.full(F, np.nan), np.full(F, np.nan)
            s, lg = batched_det(Rt)
            sign *= s
            logabs += lg
    return sign, logabs


def _closure_jacobian(motion: Motion) -> FloatArray:
    """dR/dt of the closure equations on every frame, in the closure's modes.

    The closure's own (from Newton's last round, at the final unknowns) where it has
    it; evaluated afresh only on the other frames (closed at the reference or by
    reseeding, or not closed: there at the unknowns it ended with, else 0).
    """
    sol, q = motion.closure, motion.q
    assert sol is not None
    have = sol.jacobian
    if have is not None and have.shape[0] == q.shape[0]:
        miss = np.flatnonzero(~np.isfinite(have).all(axis=(1, 2)))
        if miss.size == 0:
            return have
        Rt = have.copy()
    else:
        miss = np.arange(q.shape[0])
        Rt = np.empty((q.shape[0], motion.model.plan.equations, motion.model.plan.unknowns))
    t = sol.t[miss]
    t = np.where(np.isfinite(t), t, 0.0)
    # the closure's inner dyads in their modes of each frame
    modes = {k: v[miss] for k, v in sol.modes.items()} or None
    _, Rt[miss] = closure_jacobian(motion.model, q[miss], t, modes)
    return Rt


#: what ``checks`` may ask for: True (the default: O(frames) checks), "full" (the
#: constraint Jacobian's rank and determinant too) or False (none)
Checks = bool | Literal["full"]


def checks_level(checks: object) -> Checks:
    """``checks`` checked: True, False or "full" (bad input otherwise)."""
    if checks is True or checks is False or checks == "full":
        return checks
    raise MechanismError(f"checks: expected True, False or 'full', got {checks!r}")


def run_checks(r: KinematicsResult, motion: Motion, full: bool = False) -> None:
    """Add the checks to ``r.checks`` (and their warnings to ``r.warnings``).

    Now, since they word warnings: the near-singular frames from the product of the
    plan's group determinants (:func:`plan_checks`, O(frames)), or with ``full`` the
    constraint Jacobian's rank and its determinant with the drivers fixed (the dense
    Jacobian on a few frames, :func:`check_jacobian`); the closure equations'
    residuals.  Link lengths and analogs against differences (:func:`value_checks`)
    when ``r.checks`` is first read.
    """
    if full:
        _jacobian_checks(r, motion)
    else:
        plan_checks(r, motion)
    residual = closure_residual(r, motion)
    if residual is not None:
        r.checks["closure_residual"] = residual
    r.check_on_demand(value_checks)


def closure_residual(r: KinematicsResult, motion: Motion) -> dict[str, Any] | None:
    """The largest residual of the plan's closure equations over the valid frames.

    Evaluated at the configuration the tables give (independent of the Newton
    iteration's own error estimate), relative to the mechanism's size; None for a
    plan without closure equations.
    """
    ev = motion.evaluation
    if not ev.residuals:
        return None
    v = r.valid
    worst = 0.0
    for jet in ev.residuals:
        x = np.abs(jet[0][v]) if not v.all() else np.abs(jet[0])
        if x.size:
            worst = max(worst, float(x.max()))
    return {
        "equations": len(ev.residuals),
        "max_error": worst,
        "relative": worst / r.geometry.scale,
    }


def plan_checks(r: KinematicsResult, motion: Motion) -> None:
    """The Jacobian's near-singular frames from the plan's group determinants alone.

    The driver-fixed constraint Jacobian's determinant is the product of the plan's
    group determinants times one constant of the geometry (see
    :func:`plan_determinant`), so the frames where it falls below
    :data:`NEAR_SINGULAR` of its largest value are found from the product without
    the constant, in O(frames) and without a dense matrix.  The constant, the rank
    (an SVD at the dips) and the agreement of the product with the dense
    determinant are the full check's (``checks="full"``); here their keys are null.
    A system that is not square (redundant constraints) has no determinant: only
    its singular frames (positions without analogs) are flagged.
    """
    m, v = r.mechanism, r.valid
    nu = sum(2 * (len(j.links) - 1) if j.kind == "R" else 2 for j in m.joints)
    nc = 3 * (len(m.links) - 1)
    flagged = np.zeros(0, dtype=np.intp)
    if nu + len(r.plan.drivers) == nc:
        with np.errstate(all="ignore"):
            sign, logf = plan_determinant(motion)
        usable = v & np.isfinite(logf) & (sign != 0)
        if usable.any():
            top = float(logf[usable].max())
            flagged = np.flatnonzero(usable & (logf < top + np.log(NEAR_SINGULAR)))
    dead = r.placed & ~v
    if dead.any():
        flagged = np.union1d(flagged, np.flatnonzero(dead))
    flagged = flagged.astype(int)
    kinds = _kinds(r, flagged) if len(flagged) else []
    r.checks["jacobian"] = {
        "equations": nu,
        "coordinates": nc,
        "rank": [],
        "rank_frames": 0,
        "redundant_constraints": None,
        "dof": None,
        "min_abs_det": None,
        "max_abs_det": None,
        "det_from_plan_error": None,
        "near_singular_frames": [int(i) for i in flagged],
        "near_singular_kinds": kinds,
        "full": False,
    }
    _near_singular_warning(r, flagged, kinds)


def _near_singular_warning(
    r: KinematicsResult, flagged: npt.NDArray[np.intp], kinds: list[str | None]
) -> None:
    if len(flagged):
        r.warnings.append(
            f"near-singular Jacobian (|det| < {NEAR_SINGULAR:g} of its maximum) at "
            f"{len(flagged)} frame(s), first q = {r.q[flagged[0], 0]:.9g}"
            + _kinds_text(r, flagged, kinds)
        )


def value_checks(r: KinematicsResult) -> dict[str, Any]:
    """Link lengths and analogs against differences, by name.

    Link lengths between every pair of centres and points on a link over the valid
    frames; analogs against five-point differences of the positions (uniform
    one-driver sweeps).
    """
    with np.errstate(all="ignore"):
        out = {"link_lengths": _link_lengths(r)}
        analogs = _analogs_vs_differences(r)
    if analogs is not None:
        out["analogs_vs_differences"] = analogs
    return out


def _link_lengths(r: KinematicsResult) -> dict[str, Any]:
    """The largest change of a distance between two centres (or points) of one link."""
    m, g, v = r.mechanism, r.geometry, r.valid
    # every pair on a link with few of them, else every one against three anchors
    # (two far apart and the one farthest from their line: distances to three
    # non-collinear points fix a point of a rigid link), linear in its joints
    worst = 0.0
    worst_link = ""
    every = bool(v.all())
    on_link: dict[str, list[str]] = {x: [] for x in m.links}
    for pid, (lk, _) in g.points.items():
        on_link[lk].append(pid)
    for link in m.links:
        ids = [j for j in m.link_joints[link] if m.joint(j).kind == "R"] + on_link[link]
        ref = {i: g.centres[i] if i in g.centres else g.points[i][1] for i in ids}
        for a, b in _length_pairs(ids, ref):
            ta, tb = _table(r, a), _table(r, b)
            # the distance in place (np.hypot is twice as slow; sizes are far from
            # overflowing a square)
            d, dy = ta["x"] - tb["x"], ta["y"] - tb["y"]
            d *= d
            dy *= dy
            d += dy
            np.sqrt(d, out=d)
            d -= abs(ref[a] - ref[b])
            e = float(np.abs(d if every else d[v]).max()) if v.any() else 0.0
            if e > worst:
                worst, worst_link = e, link
    return {"max_error": worst, "link": worst_link or None}


def _analogs_vs_differences(r: KinematicsResult) -> dict[str, Any] | None:
    """The analogs against central differences of the positions (uniform one-driver
    sweeps of at least 7 frames; None otherwise)."""
    # the five-point stencil (error ~ h^4 x^(5)/30) so that a disagreement means a
    # wrong analog or a branch jump, not the coarseness of the frames
    v = r.valid
    q = r.q[:, 0]
    F = q.size
    if F < 7 or r.q.shape[1] != 1:
        return None
    dq = np.diff(q)
    if not np.abs(dq - dq[0]).max() <= 1e-9 * abs(dq[0]):
        return None
    h = q[1] - q[0]
    err, big, at = 0.0, 0.0, None
    ok = v[4:] & v[3:-1] & v[2:-2] & v[1:-3] & v[:-4]
    if ok.any():
        # row by row (a coordinate of a joint or point): temporaries of one row stay
        # small, where a stack of every row costs more to allocate than to compute
        dev = np.zeros(F - 4)
        top = np.zeros(F - 4)
        fd = np.empty(F - 4)
        for table in (r.joints, r.points):
            for d in table.values():
                for c, sc in (("x", "sx"), ("y", "sy")):
                    x, sx = d[c], d[sc][2:-2]
                    # (8 (x3 - x1) - (x4 - x0)) / 12h: the five-point derivative
                    np.subtract(x[3:-1], x[1:-3], out=fd)
                    fd *= 8
                    fd -= x[4:]
                    fd += x[:-4]
                    fd /= 12 * h
                    fd -= sx
                    np.maximum(dev, np.abs(fd, out=fd), out=dev)
                    np.maximum(top, np.abs(sx), out=top)
        # frames not checked count zero (ok is per frame)
        dev[~ok] = 0.0
        k = int(dev.argmax())
        err, at = float(dev[k]), float(q[k + 2])
        big = float(top[ok].max())
        if err == 0.0:
            at = None
    return {"max_error": err, "max_analog": big, "step": float(h), "q_of_max_error": at}


def _jacobian_checks(r: KinematicsResult, motion: Motion) -> None:
    """The constraint Jacobian's rank (mobility refinement) and driver-fixed determinant,
    the near-singular frames and the redundant constraints (with their warnings)."""
    m, g, v = r.mechanism, r.geometry, r.valid
    ev = motion.evaluation
    with np.errstate(all="ignore"), one_blas_thread():
        jc = check_jacobian(m, g, ev.poses, r.plan.drivers, factor=plan_determinant(motion))
    r.jacobian = jc
    seen = jc.rank[v]
    seen = seen[seen >= 0]
    if seen.size and seen.min() == seen.max():
        ranks = [int(seen[0])]
    else:
        ranks = [int(x) for x in np.unique(seen)]
    # near singular frames compared in log |det| (the determinant of a large
    # mechanism may not be representable as a float)
    logd = jc.log_det
    usable = v & np.isfinite(logd)
    top_log = float(logd[usable].max()) if usable.any() else float("nan")
    flagged = (
        np.flatnonzero(usable & (logd < top_log + np.log(NEAR_SINGULAR)))
        if usable.any()
        else np.zeros(0, int)
    )
    # frames whose positions exist but whose analogs do not: the driver-fixed Jacobian
    # is singular there (|det| = 0), the deepest of near-singular frames
    dead = r.placed & ~v
    if dead.any():
        flagged = np.union1d(flagged, np.flatnonzero(dead))
    flagged = flagged.astype(int)
    kinds = _kinds(r, flagged) if len(flagged) else []
    with np.errstate(over="ignore", under="ignore"):
        lo = float(np.exp(logd[usable].min())) if usable.any() else float("nan")
        top = float(np.exp(top_log))
    dof = jc.coordinates - (max(ranks) if ranks else 0)
    r.checks["jacobian"] = {
        "equations": jc.equations,
        "coordinates": jc.coordinates,
        "rank": ranks,
        "rank_frames": int((jc.rank[v] >= 0).sum()),
        "redundant_constraints": jc.equations - max(ranks) if ranks else None,
        "dof": dof,
        "min_abs_det": lo if np.isfinite(lo) and usable.any() else None,
        "max_abs_det": top if np.isfinite(top) and usable.any() else None,
        "det_from_plan_error": jc.factor_error,
        "near_singular_frames": [int(i) for i in flagged],
        "near_singular_kinds": kinds,
        "full": True,
    }
    _near_singular_warning(r, flagged, kinds)
    if ranks and max(ranks) < jc.equations:
        r.warnings.append(
            f"constraint Jacobian rank {max(ranks)} < {jc.equations} equations: "
            f"{jc.equations - max(ranks)} redundant constraint(s)"
        )


#: the words for the kinds of singular position in the warnings
KIND_WORDS = {
    "input_limit": "input limit",
    "output_extreme": "output extreme",
    "change_point": "change point",
}


def _kinds(r: KinematicsResult, frames: npt.NDArray[np.intp]) -> list[str | None]:
    """Kind of the singular position at each flagged frame (None: not identified)."""
    namer = singular_namer()
    return [None] * len(frames) if namer is None else namer(r, frames)


def _kinds_text(r: KinematicsResult, frames: npt.NDArray[np.intp], kinds: list[str | None]) -> str:
    """The kinds of the flagged frames in words (the first few), or nothing."""
    named = [(int(i), k) for i, k in zip(frames, kinds, strict=True) if k is not None]
    if not named:
        return ""
    words = [f"{KIND_WORDS[k]} at q = {r.q[i, 0]:.9g} (frame {i})" for i, k in named[:4]]
    more = f", and {len(named) - 4} more" if len(named) > 4 else ""
    return ": " + "; ".join(words) + more


#: a link with at most this many centres and points has every pair checked
ALL_PAIRS = 6


def _length_pairs(ids: list[str], ref: dict[str, complex]) -> list[tuple[str, str]]:
    """Pairs whose distances fix the link's shape: all, or each against three anchors."""
    if len(ids) <= ALL_PAIRS:
        return [(a, b) for k, a in enumerate(ids) for b in ids[k + 1 :]]
    a = ids[0]
    b = max(ids, key=lambda i: abs(ref[i] - ref[a]))
    u = (ref[b] - ref[a]) / abs(ref[b] - ref[a])
    c = max(ids, key=lambda i: abs(((ref[i] - ref[a]) * u.conjugate()).imag))
    anchors = list(dict.fromkeys((a, b, c)))
    return [(x, i) for x in anchors for i in ids if i != x]


def _table(r: KinematicsResult, ident: str) -> Mapping[str, FloatArray]:
    return r.joints.get(ident) or r.points[ident]
