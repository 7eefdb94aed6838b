"""Evaluation of a plan over all frames at once: positions and their exact derivatives.

Owns the one code path that runs the plan of a
:class:`~mjstruct.kinematics.model.KinematicModel`: every step is computed, by its
kind in :mod:`mjstruct.kinematics.steps`, for all frames in one go (numpy arrays over
frames, no Python loop per frame), carrying jets ``[value, d/dτ, d²/dτ²]`` along a
path parameter τ whose derivatives of the driver coordinates and closure unknowns are
given as seeds. The same routine gives positions, analogs, and the Jacobian of the
closure equations (seeds on the unknowns), so Newton and the analogs use the same
formulas.

Examples
--------
>>> import numpy as np
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("four-bar")))
>>> ev = evaluate(model, model.q_ref[None, :], order=0)
>>> bool(abs(ev.centre("B")[0][0] - model.geometry.centres["B"]) < 1e-12)   # the file
True
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.geometry import Geometry
from mjstruct.kinematics.steps import STEP_KINDS, Run
from mjstruct.kinematics.steps.base import Modes
from mjstruct.kinematics.triangles import Jet, Pose
from mjstruct.mechanism import Mechanism

if TYPE_CHECKING:
    from mjstruct.kinematics.model_view import ModelView
    from mjstruct.kinematics.planner import Plan

FloatArray = npt.NDArray[np.float64]
ComplexArray = npt.NDArray[np.complex128]


@dataclass
class Evaluation:
    """Poses of all links over the frames, residual jets and per-step diagnostics.

    ``diag[k] = (disc, det)`` for each dyad step k: the discriminant (h²/r², negative
    where the dyad does not assemble) and the signed sine at the solved joint (the
    step's Jacobian; zero at a dead or change point).
    """

    m: Mechanism
    geom: Geometry
    order: int
    poses: dict[str, Pose]
    residuals: list[Jet] = field(default_factory=list)
    diag: dict[int, tuple[FloatArray, FloatArray]] = field(default_factory=dict)
    first: dict[str, str] = field(default_factory=dict)
    solved: dict[str, Jet] = field(default_factory=dict)
    #: joint -> its centre's jet as the steps read it (kept when asked: an evaluation
    #: of higher order at the same configuration starts from it)
    carried: dict[str, Jet] = field(default_factory=dict)
    #: whether it can be the ``lower`` of another evaluation (its centres kept, its
    #: poses in the reference link's coordinates)
    reusable: bool = False

    def centre(self, joint: str) -> Jet:
        """Jet of a joint centre (prismatic: the point carried by its second link)."""
        if joint in self.solved:
            return self.solved[joint]
        j = self.m.joint(joint)
        link = j.links[1] if j.kind == "P" else self.first[joint]
        return self.poses[link].point(self.geom.centres[joint])

    def carrier(self, joint: str) -> str | None:
        """The link whose pose carries a joint centre (None: a centre solved directly)."""
        if joint in self.solved:
            return None
        j = self.m.joint(joint)
        return j.links[1] if j.kind == "P" else self.first[joint]

    def stacked(self, items: Sequence[tuple[str | None, complex, str]]) -> list[ComplexArray]:
        """Jets of many points at once, each derivative stacked items × frames.

        ``items``: (link, reference position, joint) — the point of ``link`` whose
        reference position is given (as :meth:`Pose.point`), or, with link None, the
        centre ``joint`` solved directly.  The points of one link are carried in one
        broadcast (the same arithmetic per element as :meth:`Pose.point`).
        """
        n = len(items)
        poses = self.poses
        F = next(iter(poses.values())).r.shape[-1] if poses else 0
        out = [np.empty((n, F), complex) for _ in range(self.order + 1)]
        by_link: dict[str, list[int]] = {}
        for i, (link, z, joint) in enumerate(items):
            if link is None:
                for k, x in enumerate(self.solved[joint][: self.order + 1]):
                    out[k][i] = x
            elif isinstance(z, np.ndarray) or isinstance(poses[link].zA, np.ndarray):
                # per-frame geometry (one reference per frame): the point as it is
                for k, x in enumerate(poses[link].point(z)[: self.order + 1]):
                    out[k][i] = x
            elif z == poses[link].zA:  # the anchor itself: its jet as it is
                for k, x in enumerate(poses[link].A[: self.order + 1]):
                    out[k][i] = x
            else:
                by_link.setdefault(link, []).append(i)
        with np.errstate(invalid="ignore", over="ignore"):
            for link, rows in by_link.items():
                p = poses[link]
                d = np.array([items[i][1] - p.zA for i in rows])
                rd = p.r[None, :] * d[:, None]
                idx = rows[0] if len(rows) == 1 else np.array(rows)
                out[0][idx] = p.A[0] + rd
                if self.order >= 1:
                    out[1][idx] = p.A[1] + (1j * p.w[0]) * rd
                if self.order >= 2:
                    out[2][idx] = p.A[2] + (1j * p.w[1] - p.w[0] ** 2) * rd
        return out

    def truncate(self, order: int) -> None:
        """Drop the derivatives above ``order`` (what an evaluation kept as another's
        ``lower`` needs no more: they are most of its memory)."""
        if order >= self.order:
            return
        n = order + 1
        self.order = order
        for p in self.poses.values():
            p.A, p.w = p.A[:n], p.w[:order]
        for table in (self.solved, self.carried):
            for joint, jet in table.items():
                table[joint] = jet[:n]
        self.residuals = [jet[:n] for jet in self.residuals]

    def residual_matrix(self, k: int = 0) -> FloatArray:
        """Derivative ``k`` of the closure equations, shape (frames, equations).

        With seeds (see :func:`evaluate`), derivatives are (seeds, frames, equations).
        """
        if len(self.residuals) == 1:  # one equation: a column, without np.stack's checks
            out: FloatArray = self.residuals[0][k][..., None].copy()
            return out
        parts = [r[k] for r in self.residuals]
        if len({p.shape for p in parts}) > 1:  # a derivative that depends on no seed
            parts = list(np.broadcast_arrays(*parts))
        return np.stack(parts, axis=-1)


def evaluate(
    model: ModelView,
    q: FloatArray,
    order: int = 2,
    rates: npt.ArrayLike | None = None,
    t: FloatArray | None = None,
    t1: FloatArray | None = None,
    t2: FloatArray | None = None,
    K: Modes | None = None,
    upto: int | None = None,
    only: Sequence[int] | None = None,
    lower: Evaluation | None = None,
    known: int = -1,
    keep_carried: bool = False,
) -> Evaluation:
    """Run the model's plan on driver coordinates ``q`` (frames × drivers).

    Parameters
    ----------
    model : the mechanism, its geometry and its plan.
    order : 0 positions, 1 with first derivatives, 2 with second derivatives.
    rates : dq_i/dτ for each driver (default 1: analogs with respect to q); or one
        row per seed (seeds × drivers), with ``t1`` (and ``t2``) seeds × frames (or
        1) × unknowns: then every derivative jet has a leading seed axis (seeds ×
        frames) and the positions, computed once, serve all seeds.
    t, t1, t2 : closure unknowns (frames × unknowns) and their derivatives.
    K : assembly mode per dyad step (±1, scalar or per frame); missing: chosen to
        reproduce the reference configuration (see :func:`reference_mode`).
    upto : stop after this many steps (for refining branch points).
    only : evaluate only these steps (indices in plan order, closed under what they
        read: :attr:`~mjstruct.kinematics.model.KinematicModel.step_dependencies`).
    lower, known : an evaluation of (some of) the same steps at the same ``q``, ``t``
        and ``K``, kept with ``keep_carried`` and not carried to the frame link, whose
        derivatives up to order ``known`` hold here (1: also the same ``rates`` and
        ``t1``, without a seed axis): the steps take those orders from it and compute
        the orders above (the same numbers as computed afresh).
    keep_carried : keep the joint centres' jets the steps read (for ``lower``).
    """
    plan, geom, m = model.plan, model.geometry, model.mechanism
    F = int(q.shape[0])
    zeros = np.zeros((F, plan.unknowns))
    rate = np.ones(q.shape[1]) if rates is None else np.asarray(rates, float)
    if rate.ndim == 2:  # one row per seed: broadcast against the frames
        rate = rate[:, None, :]
    run = Run(
        mechanism=m,
        geometry=geom,
        q=q,
        order=order,
        rates=rate,
        t=zeros if t is None else t,
        t1=zeros if t1 is None else t1,
        t2=zeros if t2 is None else t2,
        modes=K if K is not None else {},
        first_memo=model.first_links(None if only is None else tuple(only), upto),
        lower=lower if known >= 0 and lower is not None and lower.reusable else None,
        known=known if lower is not None and lower.reusable else -1,
    )
    # frames that do not assemble or sit at a singular position get NaN or inf, which
    # their validity reports: numpy's warnings are silenced once for all steps
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if only is not None:
            for k in only:
                s = plan.steps[k]
                STEP_KINDS[s.kind].evaluate(s, k, run)
        else:
            for k, s in enumerate(plan.steps if upto is None else plan.steps[:upto]):
                STEP_KINDS[s.kind].evaluate(s, k, run)
    ev = Evaluation(m, geom, order, run.poses, run.residuals, run.diag, run.first, run.solved)
    if plan.reference != plan.frame and plan.frame in ev.poses and upto is None and only is None:
        _to_frame(ev, plan.frame)
    elif keep_carried:
        ev.carried, ev.reusable = run.carried, True
    return ev


def reference_mode(plan: Plan, geom: Geometry, k: int) -> int:
    """Assembly mode (±1) of dyad step k that reproduces the reference configuration."""
    s = plan.steps[k]
    rule = STEP_KINDS[s.kind].reference_mode
    if rule is None:
        raise ValueError(f"step {k + 1} ({s.kind}) has no assembly modes")
    return rule(s, geom)


def _to_frame(ev: Evaluation, frame: str) -> None:
    """Carry every pose from the reference link's coordinates to the frame's."""
    ev.solved.clear()  # solved centres were in the reference link's coordinates
    f = ev.poses[frame]
    c = f.r.conjugate()
    cw: list[npt.NDArray[Any]] = [c]
    if ev.order >= 1:
        cw.append(-1j * f.w[0] * c)
    if ev.order >= 2:
        cw.append((-1j * f.w[1] - f.w[0] ** 2) * c)
    for link, p in list(ev.poses.items()):
        Y = [p.A[i] - f.A[i] for i in range(ev.order + 1)]
        A: Jet = [f.zA + c * Y[0]]
        if ev.order >= 1:
            A.append(cw[1] * Y[0] + c * Y[1])
        if ev.order >= 2:
            A.append(cw[2] * Y[0] + 2 * cw[1] * Y[1] + c * Y[2])
        w: Jet = [p.w[i] - f.w[i] for i in range(ev.order)]
        ev.poses[link] = Pose(p.zA, A, p.r * c, w)
