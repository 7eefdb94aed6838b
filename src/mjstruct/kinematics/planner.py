"""Planner: turn a mechanism and its drivers into a sequence of triangle steps.

Owns the *plan*: the ordered steps that place every link (the rule of adjacent
triangles), the unknown angles a closure must iterate on when no triangle sequence
exists, and the plan's complexity in triangles.  What each step kind does, and the
rule that finds it, is in :mod:`mjstruct.kinematics.steps`; this module runs the rules
(group by group of the Assur decomposition, then over what is left) and, when they
stall, searches for the fewest assumed angles.

Every step has three known parameters and solves three (a dyad: two known centres
and two side lengths give the inner joint).  All steps are computed in the frame of
one *reference* link; when a driver is an inner joint (an inner driver)
the reference is that joint's first link, the frame itself becomes one more link to
place, and the whole cluster is carried to the frame at the end.

The sequence is found by propagation of known points (a link with two known points is
placed; two links each with one known centre meeting at an unknown joint form a dyad).
Each rule keeps a queue of the candidates whose neighbourhood changed, so a plan costs
O(n log n) queue operations plus the breadth-first searches that count a dyad's base
triangles across the placed cluster. When the Assur decomposition is given the
propagation runs group by group in its order, and the decomposition's ``reference``
link is used; the same step kinds result either way.

References
----------
.. [1] A. N. Panasenko, "Practical implementation…" (in Russian; the available copy
   gives only this beginning of the title), Systems. Methods. Technologies,
   no. 2 (66), pp. 32–42, 2025. [Panasenko 2025] in docs/references.md.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> p = plan_kinematics(read_mechanism(example_path("slider-crank")))
>>> [s.kind for s in p.steps]
['reference', 'driver-R', 'RRP']
>>> p.complexity()
{'general': 0, 'right': 2, 'checks': 0, 'unknowns': 0}
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import cached_property
from heapq import heappop

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.kinematics.geometry import Geometry, geometry_of
from mjstruct.kinematics.steps import PLAN_RULES, STEP_KINDS, PlanState, Step, Topology
from mjstruct.kinematics.steps.drivers import assume_angle, assume_slide
from mjstruct.kinematics.steps.gears import geared_dof
from mjstruct.kinematics.tolerances import PLAN_RANK_TOL
from mjstruct.mechanism import Mechanism
from mjstruct.structure.assur import Decomposition
from mjstruct.structure.assur.decomposition import decompose
from mjstruct.structure.drivers import (
    DriverBalance,
    check_balance,
    driver_balance,
    validate_drivers,
)
from mjstruct.typing import FloatArray

__all__ = ["STEP_KINDS", "Plan", "Step", "plan_checked", "plan_kinematics"]


@dataclass(frozen=True)
class Plan:
    """The ordered steps, the reference link and the closure unknowns of a mechanism."""

    frame: str
    reference: str
    drivers: tuple[str, ...]
    steps: tuple[Step, ...]
    unknowns: int
    source: str = "propagation"
    notes: tuple[str, ...] = field(default=())

    @cached_property
    def equations(self) -> int:
        """Closure equations of the plan (counted once: every evaluation asks)."""
        return sum(s.equations for s in self.steps)

    def complexity(self) -> dict[str, int]:
        """Triangles of the triangle rule: ``general`` and ``right`` ones, and closure unknowns.

        A dyad RRR is one general triangle, a dyad RRP, RPR, PRP or RPP one right triangle
        (the last two intersect two guides: linear, no assembly mode); finding the
        dyad's base side across already placed links costs one triangle per
        intermediate joint (the crank's right triangle of the slider-crank).
        ``checks``: triangles that find a base again along another shortest path (the
        Zhivago mechanism's count, 7, is ``general + checks``).
        """
        count = {"general": 0, "right": 0}
        for s in self.steps:
            tri = s.step_kind.triangle
            if tri is not None:
                count[tri] += 1 + s.diagonal
        checks = sum(s.checks for s in self.steps)
        return {**count, "checks": checks, "unknowns": self.unknowns}

    def describe(self) -> list[str]:
        """The plan in words, one line per step."""
        lines = [f"{k + 1}. {s.describe()}" for k, s in enumerate(self.steps)]
        if self.reference != self.frame:
            lines.append(
                f"{len(self.steps) + 1}. carry the cluster solved in link {self.reference}'s "
                f"frame to the frame {self.frame} (rigid motion)"
            )
        return lines


def _propagate(st: PlanState, allowed: set[str] | None = None) -> None:
    """Apply the planning rules until nothing more can be placed.

    Rules in priority order; each pops its candidates (smallest file index first)
    until one applies, and then the search restarts from the first rule.
    """
    st.open(allowed)
    links, joints = st.m.links, st.topo.joint_ids
    rules = [
        (
            rule.apply,
            None if rule.subject == "drivers" else links if rule.subject == "link" else joints,
            st.queues[k],
            st.queued[k],
        )
        for k, rule in enumerate(PLAN_RULES)
    ]
    while True:
        for apply, names, heap, waiting in rules:
            if names is None:  # the drivers: no candidates
                if apply(st, ""):
                    break
                continue
            while heap:
                i = heappop(heap)
                waiting.discard(i)
                if apply(st, names[i]):
                    break
            else:
                continue
            break
        else:
            return


def _complete(st: PlanState) -> bool:
    return len(st.placed) == len(st.m.links)


#: link-propagations the first pass's searches may run in all (they stop with the best
#: plan found so far; the group-by-group pass follows when none is complete)
SEARCH_WORK = 100_000
#: propagations the first pass may always run
SEARCH_MIN = 200
#: propagations one search may run when no budget is shared
SEARCH_BUDGET = 2000
#: assumed angles one search may stack (per group in the group-by-group pass)
MAX_SEARCH_DEPTH = 3


def _search(
    st: PlanState, depth: int, allowed: set[str] | None, budget: list[int] | None = None
) -> PlanState:
    """Propagate; when stalled assume one link angle (fewest unknowns first).

    Tries every link with one known centre, up to ``depth`` assumptions deep, within
    :data:`SEARCH_BUDGET` propagations (shared through ``budget``).
    """
    budget = [SEARCH_BUDGET] if budget is None else budget
    budget[0] -= 1
    _propagate(st, allowed)
    if _complete(st) or (allowed is not None and allowed <= st.placed) or depth == 0:
        return st
    best: PlanState | None = None
    # angles about a known centre first, then slides of links with no known centre
    # on a placed guide (a later trial replaces an earlier one only when cheaper)
    for link, slide in [(x, False) for x in st.m.links] + [(x, True) for x in st.m.links]:
        if budget[0] <= 0:
            break
        if link in st.placed or (allowed is not None and link not in allowed):
            continue
        known = st.known_on(link)
        guide = _placed_guide(st, link) if slide and not known else None
        if (not slide and len(known) != 1) or (slide and guide is None):
            continue
        trial = st.copy()
        if guide is None:
            assume_angle(trial, link, known[0])
        else:
            assume_slide(trial, link, guide)
        trial = _search(trial, depth - 1, allowed, budget)
        done = _complete(trial) or (allowed is not None and allowed <= trial.placed)
        if done and (best is None or _cost(trial) < _cost(best)):
            best = trial
    return best if best is not None else st


def _placed_guide(st: PlanState, link: str) -> str | None:
    """A guide (not a driver) of ``link`` on a placed link."""
    for g in st.topo.guides[link]:
        if any(x != link and x in st.placed for x in st.m.joint(g).links):
            return g
    return None


def _cost(st: PlanState) -> tuple[int, int]:
    eq = sum(s.equations for s in st.steps)
    return (st.unknowns, abs(eq - st.unknowns))


def _run(
    m: Mechanism,
    geom: Geometry,
    topo: Topology,
    reference: str,
    groups: list[set[str]] | None,
    per_group: bool = False,
    budget: list[int] | None = None,
) -> PlanState:
    """Propagate group by group, then search for assumed angles where links are left.

    ``per_group``: place the driven links first, then search each group as soon as
    propagation leaves it open (any number of unknowns in all, at most three per
    group); else one search at the end (at most three unknowns in all, the plans of
    the first pass).
    """
    st = PlanState(m, geom, topo)
    step = st.add(Step("reference", (reference,)))
    st.place(reference, step, ())
    if per_group:
        driven = {x for d in topo.drivers for x in m.joint(d).links[:2]}
        _propagate(st, driven)
    # the decomposition fixes the order; assumptions only where it leaves links open
    for group in groups or ():
        _propagate(st, set(group))
        if per_group and not set(group) <= st.placed:
            st = _search(st, MAX_SEARCH_DEPTH, set(group))
    return _search(st, MAX_SEARCH_DEPTH, None, budget)


def plan_kinematics(
    m: Mechanism,
    drivers: Iterable[str] | None = None,
    decomposition: Decomposition | None = None,
    geometry: Geometry | None = None,
) -> Plan:
    """Plan the position analysis of ``m`` with the given drivers.

    Parameters
    ----------
    m : a mechanism with geometry (``at`` on every joint).
    drivers : joint ids of the generalised coordinates (default: the file's drivers).
    decomposition : an Assur decomposition to follow; default:
        :func:`mjstruct.structure.assur.assur_groups` when the drivers balance the
        chain generically, else propagation alone.
    geometry : the reference configuration, when already read.

    Raises
    ------
    MechanismError
        the drivers do not determine the mechanism (too few, too many, or a group this
        planner cannot solve).
    """
    from mjstruct.errors import expect_ids
    from mjstruct.mechanism import expect_mechanism

    expect_mechanism(m)
    expect_ids(drivers, "drivers")
    drv = validate_drivers(m, drivers, balance=False)
    geom = geometry if geometry is not None else geometry_of(m, drv)
    return plan_checked(m, drv, geom, decomposition)


def plan_checked(
    m: Mechanism,
    drv: tuple[str, ...],
    geom: Geometry,
    decomposition: Decomposition | None = None,
) -> Plan:
    """:func:`plan_kinematics` of a mechanism whose drivers and geometry are checked.

    For entry points that check their inputs once (:meth:`KinematicModel.build
    <mjstruct.kinematics.model.KinematicModel.build>`): ``drv`` came from
    :func:`~mjstruct.structure.drivers.validate_drivers` and ``geom`` from
    :func:`~mjstruct.kinematics.geometry.geometry_of` for them.
    """
    if not drv:
        raise MechanismError("drivers: kinematics needs at least one driver joint")
    assert m.frame is not None  # the geometry's reading checked it
    # one pebble game for the drivers' check and the decomposition
    balance = driver_balance(m, drv)
    geared = bool(m.extra.get("gears"))  # checked by rank with the gear pairs instead
    generic = not geared and _check_drivers(m, geom, balance)
    if geared:
        geared_dof(m, drv)
    topo = Topology(m, drv)
    groups, source, dec_ref = _groups_from(m, decomposition, balance if generic else None)
    refs = [m.frame] if dec_ref is None else [dec_ref, m.frame]
    # an inner driver (not on the frame) suggests solving in its first link's frame
    for d in drv:
        refs += [link for link in m.joint(d).links if link not in refs]
    trials: list[tuple[str, list[set[str]] | None, str]] = []
    if groups is not None:
        trials += [(ref, groups, source) for ref in refs]
    trials += [(ref, None, "propagation") for ref in refs]
    best: PlanState | None = None
    # shared by the trials of the first pass; a propagation costs about n
    budget = [max(SEARCH_MIN, SEARCH_WORK // len(m.links))]
    for ref, grp, src in trials:
        st = _run(m, geom, topo, ref, grp, budget=budget)
        if _complete(st) and (best is None or _cost(st) < _cost(best)):
            best, source = st, src
            if st.unknowns == 0:
                break  # triangles only: nothing better to find
    if best is None and groups is not None:
        # more open groups than one search can take: search group by group
        for ref in refs:
            st = _run(m, geom, topo, ref, groups, per_group=True)
            if _complete(st):
                best, source = st, "assur"
                break
    if best is None:
        st = _run(m, geom, topo, m.frame, None)
        missing = sorted(set(m.links) - st.placed)
        raise MechanismError(
            f"drivers: {', '.join(drv)} do not determine links {', '.join(missing)} "
            "(no triangle or closure sequence found)"
        )
    eqs = sum(s.equations for s in best.steps)
    notes: tuple[str, ...] = ()
    if eqs != best.unknowns:
        dof = geared_dof(m, drv) if geared else _jacobian_dof(m, geom)
        # more equations than unknowns is fine when the constraints themselves are
        # redundant (rank J < Nu) and the drivers match the refined DOF
        redundant = eqs > best.unknowns and best.unknowns == 0 and len(drv) == dof
        if not redundant:
            what = "over-constrained" if eqs > best.unknowns else "under-constrained"
            raise MechanismError(
                f"drivers: the mechanism is {what} with drivers {', '.join(drv)} "
                f"({eqs} closure equation(s) for {best.unknowns} unknown(s); "
                f"the constraint Jacobian gives {dof} DOF)"
            )
        notes = (
            f"{eqs} closure equation(s) with no unknown: redundant constraints "
            f"(Jacobian DOF {dof}), checked along the motion",
        )
    ref = best.steps[0].links[0]
    return Plan(
        frame=m.frame,
        reference=ref,
        drivers=drv,
        steps=tuple(best.steps),
        unknowns=best.unknowns,
        source=source,
        notes=notes,
    )


def _check_drivers(m: Mechanism, geom: Geometry, balance: DriverBalance) -> bool:
    """Refuse drivers that over- or under-drive the mechanism at its reference.

    The generic count and independence (the pebble game's ``balance``) first; where
    they refuse, the geometry may still be special (a parallelogram whose redundant
    constraint the pebble game cannot see): then the constraint Jacobian at the
    reference decides, its mobility against the driver count, and each driver row
    against the rank of the constraints and the drivers before it (a driver already
    fixed is refused).  Returns True when the generic balance accepts the drivers.
    """
    drv = balance.drivers
    try:
        check_balance(balance)
        return True
    except MechanismError as generic:
        refusal = generic
    J, D = _normalised_jacobian(m, geom, drv)
    tol = PLAN_RANK_TOL * np.sqrt(J.shape[1])
    rank = int(np.linalg.matrix_rank(J, tol=tol)) if J.size else 0
    dof = J.shape[1] - rank
    check_balance(balance, mobility=dof)  # the count against the real mobility
    fixed = []
    rows = J
    for d, row in zip(drv, D, strict=True):
        grown = np.vstack([rows, row[None, :]])
        if int(np.linalg.matrix_rank(grown, tol=tol)) == rank:
            fixed.append(d)
        else:
            rows, rank = grown, rank + 1
    if fixed:
        them = "them" if len(fixed) > 1 else "it"
        raise MechanismError(
            f"drivers: with {', '.join(drv)} the mechanism is over-constrained "
            f"({', '.join(fixed)} already fixed by the structure and the drivers before "
            f"{them} at the reference configuration; Jacobian mobility F = {dof})"
        )
    if dof != len(drv):  # pragma: no cover - check_balance with mobility refused it
        raise refusal
    return False


def _normalised_jacobian(
    m: Mechanism, geom: Geometry, drivers: tuple[str, ...] = ()
) -> tuple[FloatArray, FloatArray]:
    """The constraint Jacobian and driver rows at the reference, in units of the size.

    Positions are taken relative to the first joint and divided by the size, so the
    rank does not depend on where the mechanism sits or what unit it is written in.
    """
    from mjstruct.kinematics.jacobian import constraint_jacobian, reference_poses

    o, k = next(iter(geom.centres.values())), 1.0 / geom.scale
    unit = dataclasses.replace(
        geom,
        centres={j: (z - o) * k for j, z in geom.centres.items()},
        points={p: (link, (z - o) * k) for p, (link, z) in geom.points.items()},
        scale=1.0,
    )
    J, D = constraint_jacobian(m, unit, reference_poses(m), drivers)
    # rows of unit length: the tolerance compares directions, not magnitudes
    for A in (J, D):
        norm = np.linalg.norm(A[0], axis=1, keepdims=True)
        A[0] /= np.where(norm > 0, norm, 1.0)
    return J[0], D[0]


def _jacobian_dof(m: Mechanism, geom: Geometry) -> int:
    """Mobility from the rank of the constraint Jacobian at the reference configuration."""
    J, _ = _normalised_jacobian(m, geom)
    return int(J.shape[1] - np.linalg.matrix_rank(J, tol=PLAN_RANK_TOL * np.sqrt(J.shape[1])))


def _groups_from(
    m: Mechanism, decomposition: Decomposition | None, balance: DriverBalance | None
) -> tuple[list[set[str]] | None, str, str | None]:
    """Group order, plan source and reference link from an Assur decomposition, if
    usable (else no groups: plan by propagation).

    ``balance``: the drivers' pebble game when it accepts them (None: refused).
    """
    dec = decomposition
    if dec is None:
        if balance is None:
            # not balanced generically (a special geometry such as a parallelogram):
            # plan by propagation alone, the Jacobian decides
            return None, "propagation", None
        try:
            dec = decompose(m, balance)
        except MechanismError:
            # redundant constraints in the chain itself: propagation alone
            return None, "propagation", None
    if not dec.groups:
        return None, "propagation", None
    sets = [set(g.links) for g in dec.groups]
    moving = set(m.links) - {m.frame}
    if not set().union(*sets) <= moving | {m.frame}:
        return None, "propagation", None
    refs = {g.reference for g in dec.groups} - {m.frame}
    ref = next(iter(refs)) if len(refs) == 1 else None
    return sets, "assur", ref
