"""Planner: turn a mechanism and its drivers into a sequence of triangle steps.

Owns the *plan*: the ordered steps that place every link (seed 000's rule of adjacent
triangles), the unknown angles a closure must iterate on when no triangle sequence
exists (seed 003), and the plan's complexity in triangles.

Every step has three known parameters and solves three (a dyad: two known centres
and two side lengths give the inner joint).  All steps are computed in the frame of
one *reference* link; when a driver is an inner joint (seed 000's Zhivago joint E)
the reference is that joint's first link, the frame itself becomes one more link to
place, and the whole cluster is carried to the frame at the end.

The sequence is found by propagation of known points (a link with two known points
is placed; two links each with one known centre meeting at an unknown joint form a
dyad).  When the Assur decomposition is given the propagation runs group by group
in its order, and the decomposition's ``reference`` link is used; the same step
kinds result either way.

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

from collections.abc import Iterable
from dataclasses import dataclass, field

import networkx as nx

from mjstruct.errors import MechanismError
from mjstruct.kinematics.geometry import COINCIDE, Geometry, read_geometry
from mjstruct.mechanism import Mechanism

#: step kinds and what they do, for the plan in words
STEP_KINDS = {
    "reference": "link {links[0]} is the reference (fixed in the solving frame)",
    "driver-R": "joint {joint} turns link {links[0]} about {joint} on link {base} by q{n}",
    "driver-P": "joint {joint} slides link {links[0]} along link {base} by q{n}",
    "assume": "assume the angle t{n} of link {links[0]} about {joint} (closure unknown)",
    "RRR": "dyad RRR: links {links[0]}, {links[1]} from centres {inputs[0]}, {inputs[1]} "
    "meet at {joint} (one general triangle)",
    "RRP": "dyad RRP: link {links[0]} from centre {inputs[0]} meets slider {links[1]} at "
    "{joint} on the guide {inputs[1]} of link {base} (one right triangle)",
    "RPR": "dyad RPR: links {links[0]}, {links[1]} from centres {inputs[0]}, {inputs[1]} "
    "slide on each other at {joint} (one right triangle)",
    "PRP": "dyad PRP: sliders {links[0]}, {links[1]} on the guides {inputs[0]}, {inputs[1]} "
    "meet at {joint} (line–line intersection: one right triangle)",
    "RPP": "dyad RPP: link {links[0]} from centre {inputs[0]} slides at {joint} in link "
    "{links[1]}, which slides on the guide {inputs[1]} of link {base} (line–line "
    "intersection: one right triangle)",
    "place": "link {links[0]} placed by its known centres {inputs[0]}, {inputs[1]}",
    "close-distance": "closure: |{inputs[0]}{inputs[1]}| on link {links[0]} must equal its length",
    "close-point": "closure: centre {joint} from link {links[0]} must coincide with link "
    "{links[1]}'s",
}


#: steps counted as right triangles (a guide takes part)
LINE_KINDS = ("RRP", "RPR", "PRP", "RPP")
#: |sine| between two guides of a dyad PRP / RPP at the reference below this: parallel
PARALLEL_REF = 1e-9


@dataclass(frozen=True)
class Step:
    """One step of a plan.

    ``links`` are the links the step places (for a closure: the links whose
    disagreement it measures), ``joint`` the joint it solves or drives, ``inputs`` the
    known joints it starts from, ``base`` the link a driver or guide belongs to,
    ``index`` the driver or unknown number, ``diagonal`` the triangles the seed's rule
    spends to find a dyad's base side across the cluster, ``checks`` the triangles that
    find the same base along the other shortest paths (the seed computes them as a check).
    """

    kind: str
    links: tuple[str, ...]
    joint: str = ""
    inputs: tuple[str, ...] = ()
    base: str = ""
    index: int = -1
    diagonal: int = 0
    checks: int = 0

    def describe(self) -> str:
        return STEP_KINDS[self.kind].format(n=self.index + 1, **self.__dict__)

    @property
    def is_closure(self) -> bool:
        return self.kind.startswith("close")

    @property
    def equations(self) -> int:
        return {"close-distance": 1, "close-point": 2}.get(self.kind, 0)


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

    @property
    def equations(self) -> int:
        return sum(s.equations for s in self.steps)

    def complexity(self) -> dict[str, int]:
        """Triangles of the seed's rule: ``general`` and ``right`` ones, and closure unknowns.

        A dyad RRR is one general triangle, a dyad RRP, RPR, PRP or RPP one right triangle
        (the last two intersect two guides: linear, no assembly mode); finding the
        dyad's base side across already placed links costs one triangle per
        intermediate joint (seed 000: the crank's right triangle of the slider-crank).
        ``checks``: triangles that find a base again along another shortest path (seed
        000's Zhivago count, 7, is ``general + checks``).
        """
        general = sum(1 + s.diagonal for s in self.steps if s.kind == "RRR")
        right = sum(1 + s.diagonal for s in self.steps if s.kind in LINE_KINDS)
        checks = sum(s.checks for s in self.steps)
        return {"general": general, "right": right, "checks": checks, "unknowns": self.unknowns}

    def describe(self) -> list[str]:
        """The plan in words, one line per step."""
        lines = [f"{k + 1}. {s.describe()}" for k, s in enumerate(self.steps)]
        if self.reference != self.frame:
            lines.append(
                f"{len(self.steps) + 1}. carry the cluster solved in link {self.reference}'s "
                f"frame to the frame {self.frame} (rigid motion)"
            )
        return lines


class _State:
    """Placed links and known joints during propagation (copyable for the search)."""

    def __init__(self, m: Mechanism, geom: Geometry) -> None:
        self.m, self.geom = m, geom
        self.placed: set[str] = set()
        self.known: set[str] = set()
        self.steps: list[Step] = []
        self.unknowns = 0

    def copy(self) -> _State:
        s = _State(self.m, self.geom)
        s.placed, s.known = set(self.placed), set(self.known)
        s.steps, s.unknowns = list(self.steps), self.unknowns
        return s

    def revolute(self, link: str) -> list[str]:
        return [j for j in self.m.link_joints[link] if self.m.joint(j).kind == "R"]

    def known_on(self, link: str) -> list[str]:
        """Known revolute centres of ``link`` at distinct points."""
        out: list[str] = []
        tol = COINCIDE * self.geom.scale
        for j in self.revolute(link):
            if j in self.known and all(
                abs(self.geom.centres[j] - self.geom.centres[k]) > tol for k in out
            ):
                out.append(j)
        return out

    def place(self, link: str, step: Step, used: Iterable[str]) -> None:
        """Mark ``link`` placed; its centres already known elsewhere become closures."""
        used = set(used)
        self.placed.add(link)
        for j in self.revolute(link):
            if j in self.known and j not in used:
                other = next(x for x in self.m.joint(j).links if x in self.placed and x != link)
                self.steps.append(Step("close-point", (link, other), joint=j))
            self.known.add(j)

    def diagonal(self, a: str, b: str) -> int:
        """Intermediate joints on the shortest path between known centres a and b."""
        return self.paths(a, b)[0]

    def paths(self, a: str, b: str) -> tuple[int, int]:
        """(triangles along one shortest path a–b, triangles along the other ones)."""
        g = nx.Graph()
        for j in self.known:
            for link in self.m.joint(j).links:
                if link in self.placed:
                    g.add_edge(("j", j), ("l", link))
        try:
            paths = list(nx.all_shortest_paths(g, ("j", a), ("j", b)))
        except (nx.NetworkXNoPath, nx.NodeNotFound):
            return 0, 0
        each = max(0, (len(paths[0]) - 1) // 2 - 1)
        return each, each * (len(paths) - 1)


def _propagate(st: _State, drivers: tuple[str, ...], allowed: set[str] | None = None) -> None:
    """Apply the triangle rules until nothing more can be placed."""
    m = st.m
    free = [x for x in m.links if allowed is None or x in allowed]
    progress = True
    while progress:
        progress = False
        # drivers: the driven link turns or slides on an already placed one
        for i, d in enumerate(drivers):
            j = m.joint(d)
            a, b = j.links[0], j.links[1]
            for base, driven in ((a, b), (b, a)):
                if base in st.placed and driven not in st.placed and driven in free:
                    kind = "driver-P" if j.kind == "P" else "driver-R"
                    step = Step(kind, (driven,), joint=d, base=base, index=i)
                    st.steps.append(step)
                    st.place(driven, step, (d,))
                    progress = True
        if progress:
            continue
        # a link with two known centres is placed (its length closes a loop)
        for link in free:
            if link in st.placed:
                continue
            known = st.known_on(link)
            if len(known) >= 2:
                step = Step("place", (link,), inputs=(known[0], known[1]))
                st.steps.append(step)
                st.steps.append(Step("close-distance", (link,), inputs=(known[0], known[1])))
                st.place(link, step, known[:2])
                progress = True
                break
        if progress:
            continue
        # dyads: two links, one known centre each, meeting at an unknown revolute joint
        for j in m.joints:
            if j.kind != "R" or j.id in st.known:
                continue
            cands = [x for x in j.links if x in free and x not in st.placed]
            found = False
            for ib, b in enumerate(cands):
                kb = st.known_on(b)
                if len(kb) != 1 or _coincide(st, kb[0], j.id):
                    continue
                for c in cands[ib + 1 :]:
                    kc = st.known_on(c)
                    if len(kc) != 1 or _coincide(st, kc[0], j.id) or _coincide(st, kb[0], kc[0]):
                        continue
                    step = Step(
                        "RRR", (b, c), joint=j.id, inputs=(kb[0], kc[0]),
                        diagonal=st.paths(kb[0], kc[0])[0],
                        checks=st.paths(kb[0], kc[0])[1],
                    )  # fmt: skip
                    st.steps.append(step)
                    st.place(b, step, (kb[0], j.id))
                    st.place(c, step, (kc[0], j.id))
                    found = True
                    break
                if found:
                    break
                # RRP: b has a known centre, its partner c slides on a placed link
                for c in j.links:
                    if c == b or c in st.placed or c not in free or st.known_on(c):
                        continue
                    guides = [
                        g
                        for g in m.link_joints[c]
                        if m.joint(g).kind == "P" and g not in drivers
                        for other in m.joint(g).links
                        if other != c and other in st.placed
                    ]
                    if not guides:
                        continue
                    guide = guides[0]
                    base = next(x for x in m.joint(guide).links if x != c)
                    step = Step(
                        "RRP", (b, c), joint=j.id, inputs=(kb[0], guide), base=base,
                        diagonal=_line_diagonal(st, kb[0], base),
                    )  # fmt: skip
                    st.steps.append(step)
                    st.place(b, step, (kb[0], j.id))
                    st.place(c, step, (j.id,))
                    found = True
                    break
                if found:
                    break
            if found:
                progress = True
                break
        if progress:
            continue
        # RPR: two links, one known centre each, sliding on each other (a guide pair)
        for j in m.joints:
            if j.kind != "P" or j.id in drivers:
                continue
            b, c = j.links
            if b in st.placed or c in st.placed or b not in free or c not in free:
                continue
            kb, kc = st.known_on(b), st.known_on(c)
            if len(kb) != 1 or len(kc) != 1 or _coincide(st, kb[0], kc[0]):
                continue
            step = Step(
                "RPR", (b, c), joint=j.id, inputs=(kb[0], kc[0]),
                diagonal=st.paths(kb[0], kc[0])[0], checks=st.paths(kb[0], kc[0])[1],
            )  # fmt: skip
            st.steps.append(step)
            st.place(b, step, kb)
            st.place(c, step, kc)
            progress = True
            break
        if progress:
            continue
        # PRP / RPP: two prismatic pairs, the solved point on two guides
        progress = _prismatic_dyads(st, drivers, free)


def _prismatic_dyads(st: _State, drivers: tuple[str, ...], free: list[str]) -> bool:
    """Place one dyad PRP or RPP (two prismatic pairs: a line–line intersection)."""
    m = st.m

    def open_(link: str) -> bool:
        return link in free and link not in st.placed

    # PRP: two sliders with no known centre, each on a guide of a placed link, pinned
    for j in m.joints:
        if j.kind != "R" or j.id in st.known:
            continue
        cands = [x for x in j.links if open_(x) and not st.known_on(x)]
        for ib, b in enumerate(cands):
            for c in cands[ib + 1 :]:
                gb, gc = _guide(st, b, drivers, c), _guide(st, c, drivers, b)
                if gb is None or gc is None:
                    continue
                _check_parallel(st, "PRP", j.id, gb, gc)
                bb, bc = _other(m, gb, b), _other(m, gc, c)
                step = Step(
                    "PRP", (b, c), joint=j.id, inputs=(gb, gc), base=bb,
                    diagonal=_guides_diagonal(st, bb, bc),
                )  # fmt: skip
                st.steps.append(step)
                st.place(b, step, (j.id,))
                st.place(c, step, (j.id,))
                return True
    # RPP (or PPR read from the other end): b with one known centre slides in c, which
    # slides on a guide of a placed link
    for j in m.joints:
        if j.kind != "P" or j.id in drivers:
            continue
        for b, c in (tuple(j.links), tuple(j.links[::-1])):
            if not open_(b) or not open_(c) or st.known_on(c):
                continue
            kb = st.known_on(b)
            gc = _guide(st, c, drivers, b)
            if len(kb) != 1 or gc is None:
                continue
            _check_parallel(st, "RPP", kb[0], j.id, gc)
            base = _other(m, gc, c)
            step = Step(
                "RPP", (b, c), joint=j.id, inputs=(kb[0], gc), base=base,
                diagonal=_line_diagonal(st, kb[0], base),
            )  # fmt: skip
            st.steps.append(step)
            st.place(b, step, kb)
            st.place(c, step, ())
            return True
    return False


def _other(m: Mechanism, joint: str, link: str) -> str:
    return next(x for x in m.joint(joint).links if x != link)


def _guide(st: _State, link: str, drivers: tuple[str, ...], partner: str) -> str | None:
    """A prismatic joint (not a driver) of ``link`` on a placed link other than ``partner``."""
    for g in st.m.link_joints[link]:
        j = st.m.joint(g)
        if j.kind == "P" and g not in drivers:
            other = _other(st.m, g, link)
            if other != partner and other in st.placed:
                return g
    return None


def _check_parallel(st: _State, kind: str, at: str, g1: str, g2: str) -> None:
    """Bad input when the two guides of a dyad PRP / RPP are parallel at the reference."""
    a1, a2 = st.geom.axes[g1], st.geom.axes[g2]
    if abs((a1.conjugate() * a2).imag) <= PARALLEL_REF:
        k = next(i for i, j in enumerate(st.m.joints) if j.id == g2)
        raise MechanismError(
            f"joints[{k}].axis: guides {g1!r} and {g2!r} of the dyad {kind} at {at!r} are "
            "parallel; their intersection does not exist (the dyad is not determined)"
        )


def _guides_diagonal(st: _State, base1: str, base2: str) -> int:
    """Triangles to relate guides on two placed links (0 on one link or a shared centre)."""
    k1 = [j for j in st.revolute(base1) if j in st.known]
    k2 = [j for j in st.revolute(base2) if j in st.known]
    if base1 == base2 or set(k1) & set(k2):
        return 0
    return min((1 + st.diagonal(a, b) for a in k1 for b in k2), default=1)


def _line_diagonal(st: _State, joint: str, base: str) -> int:
    """Triangles to find the distance from a known centre to a guide on link ``base``."""
    on_base = [j for j in st.revolute(base) if j in st.known]
    if joint in on_base:
        return 0
    return min((1 + st.diagonal(joint, j) for j in on_base), default=1)


def _coincide(st: _State, a: str, b: str) -> bool:
    return abs(st.geom.centres[a] - st.geom.centres[b]) <= COINCIDE * st.geom.scale


def _complete(st: _State) -> bool:
    return len(st.placed) == len(st.m.links)


def _search(st: _State, drivers: tuple[str, ...], depth: int, allowed: set[str] | None) -> _State:
    """Propagate; when stalled assume one link angle (fewest unknowns first)."""
    _propagate(st, drivers, allowed)
    if _complete(st) or (allowed is not None and allowed <= st.placed) or depth == 0:
        return st
    best: _State | None = None
    for link in st.m.links:
        if link in st.placed or (allowed is not None and link not in allowed):
            continue
        known = st.known_on(link)
        if len(known) != 1:
            continue
        trial = st.copy()
        step = Step("assume", (link,), joint=known[0], index=trial.unknowns)
        trial.unknowns += 1
        trial.steps.append(step)
        trial.place(link, step, known)
        trial = _search(trial, drivers, depth - 1, allowed)
        done = _complete(trial) or (allowed is not None and allowed <= trial.placed)
        if done and (best is None or _cost(trial) < _cost(best)):
            best = trial
    return best if best is not None else st


def _cost(st: _State) -> tuple[int, int]:
    eq = sum(s.equations for s in st.steps)
    return (st.unknowns, abs(eq - st.unknowns))


def _run(
    m: Mechanism,
    geom: Geometry,
    drivers: tuple[str, ...],
    reference: str,
    groups: list[set[str]] | None,
) -> _State:
    st = _State(m, geom)
    st.steps.append(Step("reference", (reference,)))
    st.place(reference, st.steps[0], ())
    # the decomposition fixes the order; assumptions only where it leaves links open
    for group in groups or ():
        _propagate(st, drivers, set(group) | st.placed)
    return _search(st, drivers, 3, None)


def plan_kinematics(
    m: Mechanism,
    drivers: Iterable[str] | None = None,
    decomposition: object | None = None,
    geometry: Geometry | None = None,
) -> Plan:
    """Plan the position analysis of ``m`` with the given drivers.

    Parameters
    ----------
    m : a mechanism with geometry (``at`` on every joint).
    drivers : joint ids of the generalised coordinates (default: the file's drivers).
    decomposition : an Assur decomposition (``groups`` with ``links`` and ``reference``);
        default: :func:`mjstruct.structure.assur.assur_groups` when that module exists
        and agrees with the drivers, else propagation alone.

    Raises
    ------
    MechanismError
        the drivers do not determine the mechanism (too few, too many, or a group this
        planner cannot solve).
    """
    drv = tuple(m.drivers if drivers is None else drivers)
    if not drv:
        raise MechanismError("drivers: kinematics needs at least one driver joint")
    geom = geometry if geometry is not None else read_geometry(m, drv)
    assert m.frame is not None  # read_geometry checked it
    groups, source, dec_ref = _groups_from(m, drv, decomposition)
    refs = [m.frame] if dec_ref is None else [dec_ref, m.frame]
    # an inner driver (not on the frame) suggests solving in its first link's frame
    for d in drv:
        refs += [link for link in m.joint(d).links if link not in refs]
    trials: list[tuple[str, list[set[str]] | None, str]] = []
    if groups is not None:
        trials += [(ref, groups, source) for ref in refs]
    trials += [(ref, None, "propagation") for ref in refs]
    best: _State | None = None
    for ref, grp, src in trials:
        st = _run(m, geom, drv, ref, grp)
        if _complete(st) and (best is None or _cost(st) < _cost(best)):
            best, source = st, src
            if st.unknowns == 0:
                break  # triangles only: nothing better to find
    if best is None:
        st = _run(m, geom, drv, m.frame, None)
        missing = sorted(set(m.links) - st.placed)
        raise MechanismError(
            f"drivers: {', '.join(drv)} do not determine links {', '.join(missing)} "
            "(no triangle or closure sequence found)"
        )
    eqs = sum(s.equations for s in best.steps)
    notes: tuple[str, ...] = ()
    if eqs != best.unknowns:
        dof = _jacobian_dof(m, geom)
        # more equations than unknowns is fine when the constraints themselves are
        # redundant (rank J < Nu, seed 000) and the drivers match the refined DOF
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


def _jacobian_dof(m: Mechanism, geom: Geometry) -> int:
    """Mobility from the rank of the constraint Jacobian at the reference configuration."""
    import numpy as np

    from mjstruct.kinematics.jacobian import constraint_jacobian
    from mjstruct.kinematics.triangles import Pose

    z = np.zeros(1, complex)
    poses = {x: Pose(0j, [z], np.ones(1, complex), []) for x in m.links}
    J, _ = constraint_jacobian(m, geom, poses)
    return int(J.shape[2] - np.linalg.matrix_rank(J[0], tol=1e-9 * max(1.0, geom.scale)))


def _groups_from(
    m: Mechanism, drivers: tuple[str, ...], decomposition: object | None
) -> tuple[list[set[str]] | None, str, str | None]:
    """Group order (and reference link) from an Assur decomposition, if usable."""
    dec = decomposition
    if dec is None:
        try:
            from mjstruct.structure.assur import assur_groups
        except ImportError:
            return None, "propagation", None
        try:
            dec = assur_groups(m, drivers=drivers)
        except Exception:  # the decomposition is advisory: fall back to propagation
            return None, "propagation", None
    groups = getattr(dec, "groups", None)
    if not groups:
        return None, "propagation", None
    sets = [set(getattr(g, "links", ())) for g in groups]
    moving = set(m.links) - {m.frame}
    if set().union(*sets) - set(m.links):
        return None, "propagation", None
    refs = {str(getattr(g, "reference", m.frame)) for g in groups} - {str(m.frame)}
    ref = next(iter(refs)) if len(refs) == 1 else None
    if not set().union(*sets) <= moving | {m.frame}:
        return None, "propagation", None
    return sets, "assur", ref
