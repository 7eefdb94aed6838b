"""Assur-group decomposition that keeps multiple joints whole, and the choice of drivers.

This module owns the split of a mechanism (frame + drivers) into its initial
mechanisms and an ordered sequence of minimal Assur groups, the class and order of
each group, and the list of admissible driver choices ranked by mechanism class.

Rules (see ``docs/assur.md``):

* A driven joint fixes the relative position of its first two links, so they act as
  one body (for a frame joint: the crank joins the frame).  These are the *initial
  mechanisms* ``(driver, base link, driven link)``.
* Rigid clusters among the moving bodies (for instance links welded by an inner
  driver and closed by a triangle of pins, as in the Zhivago mechanism driven at E)
  are solved first in the frame of one of their links (``reference``), recursively,
  and then move as one body.
* The rest is decomposed relative to the frame by the pebble game (Sljoka, Shai and
  Whiteley): in the pinned orientation of an isostatic framework every moving body
  has its 3 pebbles on out-edges, and the strongly connected components, taken
  dependencies first, are the minimal Assur groups in solving order.  An MJ joining
  three or more bodies is a point vertex (2 pebbles) tied to each body by 2 edges,
  so the decomposition never tears it and does not depend on a star expansion.
* A group *owns* its links; an MJ whose position is already known is an external pin
  for every group link meeting there (the order counts those pins); an MJ inside a
  group counts its simple-joint equivalents.
* Class (Artobolevsky): the largest number of links in an elementary closed contour
  of internal joints, or the largest number of internal joints on one link (base
  link of a triad: 3), at least 2 (dyad).  The mechanism class is the highest one.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> four_bar = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
...                             ("O2", [3, 0])], frame=0, drivers=["O1"])
>>> d = assur_groups(four_bar)
>>> [(g.links, g.klass, g.order) for g in d.groups], d.mechanism_class
([(('2', '3'), 2, 2)], 2)
"""

from __future__ import annotations

import itertools
import random
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from mjstruct.errors import MechanismError
from mjstruct.mechanism import Joint, Mechanism
from mjstruct.structure.drivers import validate_drivers
from mjstruct.structure.pebble import PebbleGame, body_components, pin_edges

ROMAN = {1: "I", 2: "II", 3: "III", 4: "IV", 5: "V", 6: "VI", 7: "VII", 8: "VIII", 9: "IX"}


def roman(k: int) -> str:
    """Roman numeral of a class (falls back to digits beyond IX)."""
    return ROMAN.get(k, str(k))


@dataclass(frozen=True)
class AssurGroup:
    """One minimal Assur group, in the honest MJ form.

    ``links`` are the links the group places (owned; the groups and initial
    mechanisms partition the moving links); ``bodies`` are the rigid bodies it moves,
    each as all its links (a body can be a link welded by a driver or a rigid cluster
    solved earlier); ``external`` joints attach it to links already placed and
    ``internal`` joints join its own bodies.  ``reference`` is the link in whose frame
    the group is solved (the frame, or a link of the rigid cluster ``within``).
    """

    links: tuple[str, ...]
    joints: tuple[str, ...]
    external: tuple[str, ...]
    klass: int
    order: int
    reference: str
    internal: tuple[str, ...] = ()
    bodies: tuple[tuple[str, ...], ...] = ()
    within: tuple[str, ...] = ()
    pairs: int = 0  # simple-joint equivalents, external pins included (3 n_g = 2 p_g)

    def to_dict(self) -> dict[str, Any]:
        return {
            "links": list(self.links),
            "joints": list(self.joints),
            "class": self.klass,
            "order": self.order,
            "external": list(self.external),
            "internal": list(self.internal),
            "reference": self.reference,
            "bodies": [list(b) for b in self.bodies],
            "within": list(self.within),
            "pairs": self.pairs,
        }


@dataclass(frozen=True)
class Decomposition:
    """Initial mechanisms and Assur groups in solving order; see :func:`assur_groups`."""

    frame: str
    drivers: tuple[str, ...]
    initial: tuple[tuple[str, str, str], ...]
    groups: tuple[AssurGroup, ...]
    mechanism_class: int
    name: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "frame": self.frame,
            "drivers": list(self.drivers),
            "initial": [{"driver": d, "base": a, "driven": b} for d, a, b in self.initial],
            "groups": [g.to_dict() for g in self.groups],
            "mechanism_class": self.mechanism_class,
        }

    def render(self) -> str:
        """Plain text for a course report."""
        title = f" of {self.name}" if self.name else ""
        lines = [
            f"Assur-group decomposition{title}",
            f"frame: link {self.frame}; drivers: {', '.join(self.drivers) or '(none)'}",
            "",
            "Initial mechanism(s):",
        ]
        for d, a, b in self.initial:
            base = f"the frame {a}" if a == self.frame else f"link {a}"
            lines.append(f"  {d}: link {b} driven relative to {base}")
        lines.append("")
        lines.append("Assur groups, in solving order:")
        for k, g in enumerate(self.groups, 1):
            kind = {2: "dyad"}.get(len(g.bodies), f"{len(g.bodies)} bodies")
            lines.append(
                f"  {k}. class {roman(g.klass)}, order {g.order} ({kind}): "
                f"links {', '.join(g.links)}"
            )
            welded = [b for b in g.bodies if len(b) > 1]
            if welded:
                lines.append(
                    "     moving as bodies: " + "; ".join("{" + ", ".join(b) + "}" for b in welded)
                )
            lines.append(
                f"     external joints: {', '.join(g.external)}; "
                f"internal joints: {', '.join(g.internal) or '-'}"
            )
            if g.reference == self.frame:
                lines.append(f"     solved relative to the frame {self.frame}")
            else:
                lines.append(
                    f"     solved in the frame of link {g.reference}, inside the rigid "
                    f"cluster {{{', '.join(g.within)}}}"
                )
        lines.append("")
        lines.append(f"Mechanism class: {roman(self.mechanism_class)} ({self.mechanism_class})")
        return "\n".join(lines)


@dataclass(frozen=True)
class DriverChoice:
    """One choice of driven joints and what it gives.

    ``status`` is ``"ok"``, ``"under-driven"`` (``dof_left`` > 0), ``"over-driven"``
    (``redundant`` > 0) or ``"over- and under-driven"``.
    """

    drivers: tuple[str, ...]
    status: str
    mechanism_class: int | None
    decomposition: Decomposition | None
    dof_left: int = 0
    redundant: int = 0

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "drivers": list(self.drivers),
            "status": self.status,
            "mechanism_class": self.mechanism_class,
            "dof_left": self.dof_left,
            "redundant": self.redundant,
        }
        if self.decomposition is not None:
            d = self.decomposition.to_dict()
            out["initial"] = d["initial"]
            out["groups"] = d["groups"]
        return out


# -- the working model: bodies after welding the driven joints -----------------------


@dataclass
class _Body:
    links: tuple[str, ...]
    root: str  # the link that stands for the body (the one a group owns)


_LevelJoint = tuple[Joint, list[int]]  # a joint and the distinct bodies it touches


class _Model:
    def __init__(self, m: Mechanism, drivers: Sequence[str]) -> None:
        if m.frame is None:
            raise MechanismError("frame: the decomposition needs a frame link")
        parent = {x: x for x in m.links}

        def find(x: str) -> str:
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        self.initial: list[tuple[str, str, str]] = []
        self.welded_twice: list[str] = []
        driven: set[str] = set()
        for d in drivers:
            a, b = m.joint(d).links[:2]
            self.initial.append((d, a, b))
            driven.add(b)
            if find(a) == find(b):
                self.welded_twice.append(d)  # this driver closes a loop of drivers
            parent[find(b)] = find(a)
        groups: dict[str, list[str]] = {}
        for x in m.links:
            groups.setdefault(find(x), []).append(x)
        self.bodies: list[_Body] = []
        self.body_of: dict[str, int] = {}
        for members in groups.values():
            if m.frame in members:
                root = m.frame
            else:
                root = next((x for x in members if x not in driven), members[0])
            for x in members:
                self.body_of[x] = len(self.bodies)
            self.bodies.append(_Body(tuple(members), root))
        self.frame_body = self.body_of[m.frame]
        self.joints: list[_LevelJoint] = []
        for j in m.joints:
            touched = list(dict.fromkeys(self.body_of[x] for x in j.links))
            if len(touched) >= 2:
                self.joints.append((j, touched))
        self.order = {j.id: k for k, j in enumerate(m.joints)}

    def merge(self, members: Sequence[int], root: str) -> int:
        links = tuple(sorted((x for b in members for x in self.bodies[b].links), key=_link_key))
        self.bodies.append(_Body(links, root))
        return len(self.bodies) - 1


def _game(bodies: Sequence[int], joints: Sequence[_LevelJoint]) -> tuple[PebbleGame, int]:
    """Play the game on ``bodies`` (vertex k = bodies[k]); return the game and rejections."""
    index = {b: k for k, b in enumerate(bodies)}
    capacities, edges = pin_edges(len(bodies), _indexed(joints, index))
    game = PebbleGame(capacities)
    rejected = sum(not game.add_edge(u, v) for u, v, _ in edges)
    return game, rejected


def _indexed(
    joints: Sequence[_LevelJoint], index: dict[int, int]
) -> list[tuple[str, str, list[int]]]:
    return [(j.id, j.kind, [index[b] for b in touched]) for j, touched in joints]


def _restrict(joints: Sequence[_LevelJoint], keep: set[int]) -> list[_LevelJoint]:
    out = []
    for j, touched in joints:
        inside = [b for b in touched if b in keep]
        if len(inside) >= 2:
            out.append((j, inside))
    return out


def _rigid_clusters(members: Sequence[int], joints: Sequence[_LevelJoint]) -> list[list[int]]:
    """Maximal rigid sets of >= 2 bodies among ``members`` (pins to others ignored)."""
    sub = _restrict(joints, set(members))
    if not sub:
        return []
    index = {b: k for k, b in enumerate(members)}
    game, _ = _game(members, sub)
    comps = body_components(game, len(members), _indexed(sub, index))
    return [[members[w] for w in c] for c in comps if len(c) >= 2]


def _tarjan(out: Sequence[Sequence[int]], skip: int) -> list[list[int]]:
    """Strongly connected components, dependencies (sinks) first; vertex ``skip`` ignored."""
    n = len(out)
    index = [-1] * n
    low = [0] * n
    on_stack = [False] * n
    stack: list[int] = []
    sccs: list[list[int]] = []
    counter = 0
    for s in range(n):
        if index[s] != -1 or s == skip:
            continue
        index[s] = low[s] = counter
        counter += 1
        stack.append(s)
        on_stack[s] = True
        work = [(s, 0)]
        while work:
            v, i = work[-1]
            if i < len(out[v]):
                work[-1] = (v, i + 1)
                w = out[v][i]
                if w == skip:
                    continue
                if index[w] == -1:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack[w] = True
                    work.append((w, 0))
                elif on_stack[w]:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                u = work[-1][0]
                low[u] = min(low[u], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack[w] = False
                    comp.append(w)
                    if w == v:
                        break
                sccs.append(comp)
    return sccs


def group_class(bodies: Sequence[Any], internal: Sequence[Sequence[Any]]) -> int:
    """Artobolevsky class of a group from its bodies and internal joints (body lists).

    >>> group_class(["a", "b"], [["a", "b"]])                       # dyad
    2
    >>> group_class("abcd", [["a", "d"], ["b", "d"], ["c", "d"]])   # triad
    3
    >>> group_class("abcd", [["a", "b"], ["b", "c"], ["c", "d"], ["d", "a"]])
    4
    """
    per_body = {b: 0 for b in bodies}
    for touched in internal:
        for b in touched:
            per_body[b] += 1
    base = max(per_body.values(), default=0)
    edges = sum(len(t) for t in internal)
    if edges - len(internal) - len(per_body) + 1 <= 0:  # bipartite graph is a tree
        return max(2, base)
    return max(2, base, _longest_contour(internal))


def _longest_contour(internal: Sequence[Sequence[Any]]) -> int:
    """Largest number of links on the shortest closed contour through any incidence.

    The contour graph is bipartite (links, internal joints), so an MJ is one vertex and
    a contour never passes twice through it; a contour of k links has 2k edges.
    """
    adj: dict[Any, list[Any]] = {}
    for k, touched in enumerate(internal):
        joint = ("joint", k)
        for b in touched:
            adj.setdefault(joint, []).append(("body", b))
            adj.setdefault(("body", b), []).append(joint)
    longest = 0
    for k, touched in enumerate(internal):
        joint = ("joint", k)
        for b in touched:
            # shortest path body -> joint that avoids the edge itself, by BFS
            start, goal = ("body", b), joint
            dist = {start: 0}
            frontier = [start]
            found = None
            while frontier and found is None:
                nxt = []
                for x in frontier:
                    for y in adj[x]:
                        if (x, y) == (start, goal) or y in dist:
                            continue
                        dist[y] = dist[x] + 1
                        if y == goal:
                            found = dist[y]
                            break
                        nxt.append(y)
                    if found is not None:
                        break
                frontier = nxt
            if found is not None:
                longest = max(longest, (found + 1) // 2)
    return longest


def _level(
    model: _Model,
    pinned: int,
    members: list[int],
    joints: list[_LevelJoint],
    within: tuple[str, ...],
) -> list[AssurGroup]:
    """Decompose ``members`` relative to the placed body ``pinned``.

    The plain pinned decomposition is kept unless solving the rigid clusters of the
    moving bodies first (each in the frame of one of its links) lowers the class.
    """
    plain = _pinned_groups(model, pinned, members, joints, within)
    plain_class = max((g.klass for g in plain), default=1)
    if plain_class <= 2:
        return plain
    clusters = _rigid_clusters(members, joints)
    if not clusters:
        return plain
    groups: list[AssurGroup] = []
    replace: dict[int, int] = {}
    for comp in clusters:
        sub_groups, ref = _solve_cluster(model, comp, joints)
        groups += sub_groups
        merged = model.merge(comp, model.bodies[ref].root)
        replace.update(dict.fromkeys(comp, merged))
    members = list(dict.fromkeys(replace.get(b, b) for b in members))
    remapped = []
    for j, touched in joints:
        t = list(dict.fromkeys(replace.get(b, b) for b in touched))
        if len(t) >= 2:
            remapped.append((j, t))
    groups += _pinned_groups(model, pinned, members, remapped, within)
    if max(g.klass for g in groups) < plain_class:
        return groups
    return plain


def _pinned_groups(
    model: _Model,
    pinned: int,
    members: list[int],
    joints: list[_LevelJoint],
    within: tuple[str, ...],
) -> list[AssurGroup]:
    """Strongly connected components of the pinned pebble orientation, in order."""
    groups: list[AssurGroup] = []
    order = [pinned, *members]
    game, rejected = _game(order, joints)
    game.pin(0)
    if rejected or any(game.pebbles[1:]):
        raise RuntimeError("a sub-chain is not isostatic although the whole is")
    placed = {pinned}
    reference = model.bodies[pinned].root
    for scc in _tarjan(game.out, skip=0):
        mine = [order[v] for v in scc if v < len(order)]
        if not mine:
            continue  # a pin centre fixed on placed bodies: nothing to place
        mine_set = set(mine)
        external, internal, pins, pairs = [], [], 0, 0
        internal_bodies = []
        for j, touched in joints:
            at = [b for b in touched if b in mine_set]
            if not at:
                continue
            if any(b in placed for b in touched):
                external.append(j.id)
                pins += len(at)
            elif len(at) >= 2:
                internal.append(j.id)
                internal_bodies.append(at)
                pairs += len(at) - 1
        bodies = sorted(mine, key=lambda b: _link_key(model.bodies[b].root))
        klass = group_class(bodies, internal_bodies)
        ids = sorted(external + internal, key=model.order.__getitem__)
        groups.append(
            AssurGroup(
                links=tuple(sorted((model.bodies[b].root for b in bodies), key=_link_key)),
                joints=tuple(ids),
                external=tuple(sorted(external, key=model.order.__getitem__)),
                klass=klass,
                order=pins,
                reference=reference,
                internal=tuple(sorted(internal, key=model.order.__getitem__)),
                bodies=tuple(model.bodies[b].links for b in bodies),
                within=within,
                pairs=pins + pairs,
            )
        )
        placed |= mine_set
    return groups


def _solve_cluster(
    model: _Model, comp: list[int], joints: list[_LevelJoint]
) -> tuple[list[AssurGroup], int]:
    """Solve a rigid cluster in the frame of its best body: lowest class, welded first."""
    sub = _restrict(joints, set(comp))
    links = tuple(sorted((x for b in comp for x in model.bodies[b].links), key=_link_key))
    pins = {b: sum(b in t for _, t in sub) for b in comp}
    candidates = sorted(comp, key=lambda b: (-len(model.bodies[b].links), -pins[b]))[:4]
    best: tuple[tuple[int, int, int], list[AssurGroup], int] | None = None
    for rank, ref in enumerate(candidates):
        rest = [b for b in comp if b != ref]
        groups = _level(model, ref, rest, sub, links)
        score = (max((g.klass for g in groups), default=1), len(groups) and -len(groups), rank)
        if best is None or score < best[0]:
            best = (score, groups, ref)
    assert best is not None
    return best[1], best[2]


def _link_key(x: str) -> tuple[int, str]:
    return (0, f"{int(x):012d}") if x.isdigit() else (1, x)


def _check_drivers(m: Mechanism, drivers: Sequence[str]) -> None:
    known = {j.id for j in m.joints}
    for d in drivers:
        if d not in known:
            raise MechanismError(f"drivers: {d!r} is not a joint id")
    if len(set(drivers)) != len(drivers):
        raise MechanismError("drivers: a joint is listed twice")


def _balance(model: _Model) -> tuple[int, int]:
    """(redundant constraints, DOF left) with the drivers held."""
    bodies = list(range(len(model.bodies)))
    game, rejected = _game(bodies, model.joints)
    dof_left = game.free_pebbles - 3
    return rejected + len(model.welded_twice), dof_left


def assur_groups(m: Mechanism, drivers: Sequence[str] | None = None) -> Decomposition:
    """Initial mechanisms and minimal Assur groups in solving order.

    ``drivers`` overrides the mechanism's drivers.  Raises :class:`MechanismError`
    when the mechanism has no frame, or when with these drivers it is under-driven
    (some links still move) or over-constrained (redundant constraints).

    >>> from mjstruct.io import read_mechanism
    >>> from mjstruct.catalog_files import example_path
    >>> d = assur_groups(read_mechanism(example_path("class-iv-seed003")))
    >>> [(g.links, g.klass, g.order) for g in d.groups]
    [(('2', '3', '4', '5'), 4, 2)]
    """
    if m.frame is None:
        raise MechanismError("frame: the decomposition needs a frame link")
    drivers = validate_drivers(m, drivers)
    model = _Model(m, drivers)
    redundant, dof_left = _balance(model)
    if redundant or dof_left:
        raise MechanismError(_balance_message(drivers, redundant, dof_left))
    members = [b for b in range(len(model.bodies)) if b != model.frame_body]
    groups = _level(model, model.frame_body, members, list(model.joints), ())
    cls = max((g.klass for g in groups), default=1)
    assert m.frame is not None
    return Decomposition(m.frame, drivers, tuple(model.initial), tuple(groups), cls, m.name)


def _balance_message(drivers: Sequence[str], redundant: int, dof_left: int) -> str:
    parts = []
    if dof_left:
        parts.append(f"under-driven ({dof_left} DOF left with the drivers held)")
    if redundant:
        parts.append(f"over-constrained ({redundant} redundant constraint(s) with them held)")
    return f"drivers: with {', '.join(drivers) or 'no drivers'} the mechanism is " + (
        " and ".join(parts)
    )


def _status(redundant: int, dof_left: int) -> str:
    if redundant and dof_left:
        return "over- and under-driven"
    if redundant:
        return "over-driven"
    if dof_left:
        return "under-driven"
    return "ok"


def driver_choices(
    m: Mechanism, any_joint: bool = False, count: int | None = None, limit: int = 5000
) -> list[DriverChoice]:
    """Every choice of ``count`` driven joints (default: the generic DOF), lowest class first.

    Candidates are the frame joints, or every joint with ``any_joint``.  Admissible
    choices (status ``"ok"``) come first, by mechanism class; the others follow with
    their status (under- or over-driven).

    >>> from mjstruct.mechanism import Mechanism
    >>> m = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
    ...                      ("O2", [3, 0])], frame=0)
    >>> [(c.drivers, c.status, c.mechanism_class) for c in driver_choices(m)]
    [(('O1',), 'ok', 2), (('O2',), 'ok', 2)]
    """
    if m.frame is None:
        raise MechanismError("frame: choosing drivers needs a frame link")
    if count is None:
        from mjstruct.structure.pebble import generic_dof

        count = generic_dof(m)
    if count < 0:
        raise MechanismError(f"drivers: the chain is rigid (generic F = {count})")
    cands = [j.id for j in m.joints if any_joint or m.frame in j.links]
    total = _n_choose(len(cands), count)
    if total > limit:
        raise MechanismError(
            f"--all-choices: {total} choices of {count} among {len(cands)} joints "
            f"exceed the limit {limit}"
        )
    out = []
    for combo in itertools.combinations(cands, count):
        model = _Model(m, combo)
        redundant, dof_left = _balance(model)
        status = _status(redundant, dof_left)
        if status == "ok":
            d = assur_groups(m, combo)
            out.append(DriverChoice(combo, status, d.mechanism_class, d))
        else:
            out.append(DriverChoice(combo, status, None, None, max(dof_left, 0), redundant))
    rank = {"ok": 0, "under-driven": 1, "over-driven": 2, "over- and under-driven": 3}
    out.sort(key=lambda c: (rank[c.status], c.mechanism_class or 0))
    return out


def _n_choose(n: int, k: int) -> int:
    from math import comb

    return comb(n, k) if 0 <= k <= n else 0


# -- random mechanisms with a known decomposition (tests, benchmarks) ----------------


@dataclass
class _Grower:
    rng: random.Random
    joints: list[tuple[str, list[str], str]] = field(default_factory=list)
    placed: list[str] = field(default_factory=list)
    used: set[str] = field(default_factory=set)  # joints extended by the current group
    count: int = 0

    def new_link(self) -> str:
        self.count += 1
        return str(self.count)

    def attach(self, link: str, mj: float, known: int) -> None:
        """Pin ``link`` to a placed link: on a known R joint (making an MJ) or anew."""
        # a joint takes one link of a group at most: two would be pinned twice together
        rj = [j for j in self.joints[:known] if j[2] == "R" and j[0] not in self.used]
        if rj and self.rng.random() < mj:
            joint = self.rng.choice(rj)
            joint[1].append(link)
            self.used.add(joint[0])
        else:
            kind = "P" if self.rng.random() < 0.1 else "R"
            self.joints.append(
                (f"J{len(self.joints)}", [self.rng.choice(self.placed), link], kind)
            )

    def pin(self, a: str, b: str) -> None:
        self.joints.append((f"J{len(self.joints)}", [a, b], "R"))


def random_mechanism(groups: int, seed: int = 0, mj: float = 0.3) -> Mechanism:
    """A random one-DOF mechanism grown from a crank by dyads, triads and class-IV groups.

    External pins land on an existing revolute joint with probability ``mj`` (which
    makes multiple joints).  Frame ``"0"``, driver ``"J0"``.

    >>> m = random_mechanism(5, seed=1)
    >>> m.frame, m.drivers, len(m.links) > 10
    ('0', ('J0',), True)
    """
    g = _Grower(random.Random(seed), placed=["0"])
    crank = g.new_link()
    g.joints.append(("J0", ["0", crank], "R"))
    g.placed.append(crank)
    for _ in range(groups):
        known = len(g.joints)  # joints whose position is known before this group
        g.used.clear()
        kind = g.rng.random()
        if kind < 0.6:  # dyad
            a, b = g.new_link(), g.new_link()
            g.attach(a, mj, known)
            g.attach(b, mj, known)
            g.pin(a, b)
            new = [a, b]
        elif kind < 0.85:  # triad: ternary base and three legs
            base = g.new_link()
            legs = [g.new_link() for _ in range(3)]
            for leg in legs:
                g.pin(base, leg)
                g.attach(leg, mj, known)
            new = [base, *legs]
        else:  # class IV: two ternary links and two binary links in a 4-contour
            t1, b1, t2, b2 = (g.new_link() for _ in range(4))
            g.pin(t1, b1)
            g.pin(b1, t2)
            g.pin(t2, b2)
            g.pin(b2, t1)
            g.attach(t1, mj, known)
            g.attach(t2, mj, known)
            new = [t1, b1, t2, b2]
        g.placed += new
    return Mechanism.build(
        [(jid, links, kind) for jid, links, kind in g.joints],
        frame="0",
        drivers=["J0"],
        name=f"random-{groups}-{seed}",
    )
