"""Assur-group decomposition that keeps multiple joints whole.

This module owns the split of a mechanism (frame + drivers) into its initial
mechanisms and an ordered sequence of minimal Assur groups, with the class and order
of each group (rules in ``docs/assur.md``):

* Driven joints weld their first two links (:class:`BodyModel`).
* Rigid clusters among the moving bodies (for instance links welded by an inner
  driver and closed by a triangle of pins, as in the Zhivago mechanism driven at E)
  are solved first in the frame of one of their links (``reference``), recursively,
  and then move as one body.
* The rest is decomposed relative to the frame by the pebble game: in the pinned
  orientation of an isostatic framework every moving body has its 3 pebbles on
  out-edges, and the strongly connected components, taken dependencies first, are the
  minimal Assur groups in solving order.  An MJ joining three or more bodies is a
  point vertex (2 pebbles) tied to each body by 2 edges, so the decomposition never
  tears it and does not depend on a star expansion.
* A group *owns* its links; an MJ whose position is already known is an external pin
  for every group link meeting there (the order counts those pins); an MJ inside a
  group counts its simple-joint equivalents.  The class is
  :func:`~mjstruct.structure.assur.contours.group_class`.

References
----------
.. [1] L. V. Assur, "Investigation of planar bar mechanisms with lower pairs from the
   point of view of their structure and classification" (in Russian), Bulletin of
   the Petrograd Polytechnic Institute, 1913–1914. [Assur 1914] in docs/references.md.
.. [2] I. I. Artobolevsky, Theory of Mechanisms and Machines (in Russian), Moscow:
   Nauka, 1988. [Artobolevsky 1988] in docs/references.md.
.. [3] A. Sljoka, O. Shai, W. Whiteley, "Checking mobility and decomposition of
   linkages via pebble game algorithm", Proc. ASME IDETC/CIE 2011, Washington, DC,
   2011. [Sljoka et al. 2011] in docs/references.md.
.. [4] R. E. Tarjan, "Depth-first search and linear graph algorithms", SIAM Journal
   on Computing, vol. 1, no. 2, pp. 146–160, 1972 (strongly connected components).
   [Tarjan 1972] in docs/references.md.

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

from collections.abc import Sequence

from mjstruct.errors import MechanismError
from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.structure.assur.bodies import BodyModel, LevelJoint, link_key
from mjstruct.structure.assur.contours import group_class
from mjstruct.structure.assur.results import AssurGroup, Decomposition
from mjstruct.structure.drivers import DriverBalance, checked_balance
from mjstruct.structure.pebble import PebbleGame, body_components, pin_edges


def _game(bodies: Sequence[int], joints: Sequence[LevelJoint]) -> tuple[PebbleGame, int]:
    """Play the game on ``bodies`` (vertex k = bodies[k]); return the game and rejections."""
    index = {b: k for k, b in enumerate(bodies)}
    capacities, edges = pin_edges(len(bodies), _indexed(joints, index))
    game = PebbleGame(capacities)
    rejected = sum(not game.add_edge(u, v) for u, v, _ in edges)
    return game, rejected


def _indexed(
    joints: Sequence[LevelJoint], index: dict[int, int]
) -> list[tuple[str, str, list[int]]]:
    return [(j.id, j.kind, [index[b] for b in touched]) for j, touched in joints]


def _restrict(joints: Sequence[LevelJoint], keep: set[int]) -> list[LevelJoint]:
    out = []
    for j, touched in joints:
        inside = [b for b in touched if b in keep]
        if len(inside) >= 2:
            out.append((j, inside))
    return out


def _rigid_clusters(members: Sequence[int], joints: Sequence[LevelJoint]) -> list[list[int]]:
    """Maximal rigid sets of >= 2 bodies among ``members`` (pins to others ignored)."""
    sub = _restrict(joints, set(members))
    if not sub:
        return []
    index = {b: k for k, b in enumerate(members)}
    game, _ = _game(members, sub)
    comps = body_components(game, len(members), _indexed(sub, index))
    return [[members[w] for w in c] for c in comps if len(c) >= 2]


def _level(
    model: BodyModel,
    pinned: int,
    members: list[int],
    joints: list[LevelJoint],
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
    model: BodyModel,
    pinned: int,
    members: list[int],
    joints: list[LevelJoint],
    within: tuple[str, ...],
) -> list[AssurGroup]:
    """Strongly connected components of the pinned pebble orientation, in order."""
    groups: list[AssurGroup] = []
    order = [pinned, *members]
    game, rejected = _game(order, joints)
    game.pin(0)
    if rejected or any(game.pebbles[1:]):
        raise RuntimeError("a sub-chain is not isostatic although the whole is")
    reference = model.bodies[pinned].root
    joints_of: dict[int, list[int]] = {}  # body -> indices of the joints touching it
    for k, (_, touched) in enumerate(joints):
        for body in touched:
            joints_of.setdefault(body, []).append(k)
    # per joint: how many of its bodies are placed (an MJ of many bodies is not
    # rescanned for every group that meets it)
    placed_at = [0] * len(joints)
    for k in joints_of.get(pinned, ()):
        placed_at[k] += 1
    for scc in _dependency_order(game.out, skip=0):
        mine = [order[v] for v in scc if v < len(order)]
        if not mine:
            continue  # a pin centre fixed on placed bodies: nothing to place
        at_of: dict[int, list[int]] = {}  # joint -> the group's bodies on it
        for body in mine:
            for k in joints_of.get(body, ()):
                at_of.setdefault(k, []).append(body)
        external, internal, pins, pairs = [], [], 0, 0
        internal_bodies = []
        for k in sorted(at_of):
            j, touched = joints[k]
            at = at_of[k]
            if len(at) > 1:  # in the joint's order
                mine_set = set(at)
                at = [b for b in touched if b in mine_set]
            if placed_at[k]:
                external.append(j.id)
                pins += len(at)
            elif len(at) >= 2:
                internal.append(j.id)
                internal_bodies.append(at)
                pairs += len(at) - 1
        bodies = sorted(mine, key=lambda b: link_key(model.bodies[b].root))
        klass = group_class(bodies, internal_bodies)
        where = model.order.__getitem__
        external.sort(key=where)
        internal.sort(key=where)
        groups.append(
            AssurGroup(
                # the roots in the bodies' order: sorted by the same key (stable sort)
                links=tuple(model.bodies[b].root for b in bodies),
                joints=tuple(sorted(external + internal, key=where)),
                external=tuple(external),
                klass=klass,
                order=pins,
                reference=reference,
                internal=tuple(internal),
                bodies=tuple(model.bodies[b].links for b in bodies),
                within=within,
                pairs=pins + pairs,
            )
        )
        for k in at_of:
            placed_at[k] += len(at_of[k])
    return groups


def _solve_cluster(
    model: BodyModel, comp: list[int], joints: list[LevelJoint]
) -> tuple[list[AssurGroup], int]:
    """Solve a rigid cluster in the frame of its best body: lowest class, welded first."""
    sub = _restrict(joints, set(comp))
    links = tuple(sorted((x for b in comp for x in model.bodies[b].links), key=link_key))
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


def _dependency_order(out: Sequence[Sequence[int]], skip: int) -> list[list[int]]:
    """Strongly connected components, dependencies (sinks) first; vertex ``skip`` ignored.

    The order is fixed here, not by a library's iteration order: components in the
    order a depth-first search completes them (roots in increasing order, successors
    in the order of ``out``; a component is complete when the last of its vertices
    is), which puts every component after those it depends on.  Tarjan's algorithm
    on that search emits each component exactly then: when its first vertex, the
    last of them to complete, does.  Each component's vertices are listed in
    increasing order.

    >>> _dependency_order([[1], [2], [1], [0, 4], [3], []], skip=5)
    [[1, 2], [0], [3, 4]]
    """
    n = len(out)
    index = [-1] * n
    low = [0] * n
    on_stack = [False] * n
    stack: list[int] = []
    found: list[list[int]] = []
    count = 0
    for root in range(n):
        if root == skip or index[root] >= 0:
            continue
        index[root] = low[root] = count
        count += 1
        stack.append(root)
        on_stack[root] = True
        work = [(root, iter(out[root]))]
        while work:
            v, heads = work[-1]
            for w in heads:
                if w == skip:
                    continue
                if index[w] < 0:
                    index[w] = low[w] = count
                    count += 1
                    stack.append(w)
                    on_stack[w] = True
                    work.append((w, iter(out[w])))
                    break
                if on_stack[w] and index[w] < low[v]:
                    low[v] = index[w]
            else:
                work.pop()
                if work:
                    u = work[-1][0]
                    if low[v] < low[u]:
                        low[u] = low[v]
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on_stack[w] = False
                        comp.append(w)
                        if w == v:
                            break
                    found.append(sorted(comp))
    return found


def assur_groups(m: Mechanism, drivers: Sequence[str] | None = None) -> Decomposition:
    """Initial mechanisms and minimal Assur groups in solving order.

    ``drivers`` overrides the mechanism's drivers.  Raises :class:`MechanismError`
    when the mechanism has no frame, when the drivers fail
    :func:`~mjstruct.structure.drivers.validate_drivers` (under-driven or
    over-constrained), or when the chain itself has redundant constraints.

    Examples
    --------
    >>> from mjstruct.io import read_mechanism
    >>> from mjstruct.catalog_files import example_path
    >>> d = assur_groups(read_mechanism(example_path("class-iv-seed003")))
    >>> [(g.links, g.klass, g.order) for g in d.groups]
    [(('2', '3', '4', '5'), 4, 2)]
    """
    expect_mechanism(m)
    if m.frame is None:
        raise MechanismError("frame: the decomposition needs a frame link")
    return decompose(m, checked_balance(m, drivers))


def decompose(m: Mechanism, balance: DriverBalance) -> Decomposition:
    """:func:`assur_groups` for drivers already checked (``balance`` of ``m``)."""
    if m.frame is None:
        raise MechanismError("frame: the decomposition needs a frame link")
    redundant = balance.structural_redundant
    if redundant:
        raise MechanismError(
            f"joints: the mechanism is over-constrained ({redundant} redundant "
            "constraint(s) in the chain itself); an Assur decomposition needs none"
        )
    drivers = balance.drivers
    model = BodyModel(m, drivers)
    members = [b for b in range(len(model.bodies)) if b != model.frame_body]
    groups = _level(model, model.frame_body, members, list(model.joints), ())
    cls = max((g.klass for g in groups), default=1)
    return Decomposition(m.frame, drivers, tuple(model.initial), tuple(groups), cls, m.name)
