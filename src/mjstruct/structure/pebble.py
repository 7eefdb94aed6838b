"""The (3,3) pebble game: generic rank, redundant constraints and rigid parts of a chain.

This module owns the combinatorial rigidity of planar body-and-pin chains.  A planar
chain of rigid links joined by one-freedom pairs is generically a *body-bar*
framework: every simple joint (R or P) is two bars between its two links (Tay: the
independent bar sets are the (3,3)-sparse multigraphs).  A revolute multiple joint
(MJ) joining m links is m - 1 simple joints, but *which* pairs matters for sub-chains:
a star from one link hides a redundancy between two others (links 3, 4 sharing the MJ
and a second pin are over-constrained whatever the third link does).  So an MJ is a
point vertex with 2 pebbles tied to each of its links by 2 edges: every sub-chain
holding k of its links counts 2(k - 1) constraints, the body-and-pin count.  The
pebble game of Lee and Streinu (one vertex capacity per vertex) finds a maximal
independent set in O(n·m):

* rank = number of accepted bars; generic DOF ``F = 3(n - 1) - rank``;
* every rejected edge is a redundant constraint; the set of links the failed pebble
  search reached is a rigid sub-chain holding it (*where* the redundancy sits);
* maximal rigid sub-chains (rigid components) come from the final pebble orientation.

:class:`PebbleGame` is the plain game on integer vertices (each vertex carries its own
number of pebbles, 3 for a body, 2 for a point) and is reused by the Assur-group
decomposition in :mod:`mjstruct.structure.assur`.

References
----------
.. [1] A. Lee, I. Streinu, "Pebble game algorithms and sparse graphs", Discrete
   Mathematics, vol. 308, no. 8, pp. 1425–1437, 2008. [Lee & Streinu 2008] in
   docs/references.md.
.. [2] D. J. Jacobs, B. Hendrickson, "An algorithm for two-dimensional rigidity
   percolation: the pebble game", Journal of Computational Physics, vol. 137,
   pp. 346–365, 1997. [Jacobs & Hendrickson 1997] in docs/references.md.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> four_bar = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
...                             ("O2", [3, 0])], frame=0)
>>> generic_dof(four_bar), pebble_rank(four_bar)
(1, 8)
>>> triangle = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 0])])
>>> rigid_components(triangle)
[('0', '1', '2')]
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from mjstruct.mechanism import Mechanism, expect_mechanism

BODY_PEBBLES = 3  # planar rigid body: x, y, angle
POINT_PEBBLES = 2  # a pin centre: x, y
TRIVIAL = 3  # (k, l) = (3, 3): a free rigid chain keeps its 3 rigid-body motions


class PebbleGame:
    """Pebble game for count matroids ``|E'| <= Σ k_v - 3`` on a multigraph.

    ``capacities[v]`` is the number of pebbles of vertex v (3 for a rigid body, 2 for
    a point).  Edges are inserted one by one with :meth:`add_edge`; an edge is accepted
    when 4 pebbles can be gathered on its two ends.  The state is the orientation:
    ``out[v]`` lists the heads of the accepted edges covered by a pebble of v.

    Examples
    --------
    >>> g = PebbleGame([3, 3])
    >>> [g.add_edge(0, 1) for _ in range(4)]
    [True, True, True, False]
    >>> g.rank, g.free_pebbles
    (3, 3)
    """

    def __init__(self, capacities: Sequence[int]) -> None:
        self.pebbles: list[int] = list(capacities)
        self.out: list[list[int]] = [[] for _ in capacities]
        self.rank = 0
        self.free_pebbles = sum(capacities)
        self._seen: list[int] = [0] * len(capacities)
        self._parent: list[int] = [-1] * len(capacities)
        self._stamp = 0
        self.last_region: list[int] = []  # vertices reached by the last failed gathering

    def copy(self) -> PebbleGame:
        """An independent game in the same state (to try further edges on)."""
        other = PebbleGame(self.pebbles)
        other.out = [list(heads) for heads in self.out]
        other.rank = self.rank
        other.free_pebbles = self.free_pebbles
        return other

    def _find_pebble(self, root: int, reached: list[int]) -> bool:
        """Move one free pebble to ``root`` along a reversed path (DFS over out-edges)."""
        seen, parent, pebbles, out, stamp = (
            self._seen,
            self._parent,
            self.pebbles,
            self.out,
            self._stamp,
        )
        stack = [root]
        while stack:
            x = stack.pop()
            for y in out[x]:
                if seen[y] == stamp:
                    continue
                seen[y] = stamp
                parent[y] = x
                reached.append(y)
                if pebbles[y] > 0:
                    pebbles[y] -= 1
                    while y != root:  # reverse the path root -> ... -> y
                        x = parent[y]
                        out[x].remove(y)
                        out[y].append(x)
                        y = x
                    pebbles[root] += 1
                    return True
                stack.append(y)
        return False

    def gather(self, u: int, v: int, want: int) -> int:
        """Collect up to ``want`` pebbles on u and v; return how many they hold."""
        pebbles = self.pebbles
        while pebbles[u] + pebbles[v] < want:
            self._stamp += 1
            self._seen[u] = self._seen[v] = self._stamp
            reached = [u, v]
            if not (self._find_pebble(u, reached) or self._find_pebble(v, reached)):
                self.last_region = reached
                break
        return pebbles[u] + pebbles[v]

    def add_edge(self, u: int, v: int) -> bool:
        """Insert edge uv; True when independent (accepted), False when redundant."""
        if u == v:
            raise ValueError("a loop edge carries no constraint")
        pebbles = self.pebbles
        # enough pebbles already on u and v: no search (gather would return at once)
        if pebbles[u] + pebbles[v] <= TRIVIAL and self.gather(u, v, TRIVIAL + 1) <= TRIVIAL:
            return False
        tail, head = (u, v) if pebbles[u] > 0 else (v, u)
        pebbles[tail] -= 1
        self.out[tail].append(head)
        self.rank += 1
        self.free_pebbles -= 1
        return True

    def pin(self, root: int) -> int:
        """Gather as many pebbles as possible on ``root`` (up to its capacity).

        After pinning a vertex of an isostatic (rigid, no redundancy) graph every
        other vertex has all its pebbles on out-edges: the *pinned orientation* whose
        strongly connected components are the Assur components.
        """
        while True:
            self._stamp += 1
            self._seen[root] = self._stamp
            if not self._find_pebble(root, []):
                return self.pebbles[root]

    def rigid_component(self, u: int, v: int) -> list[int] | None:
        """The maximal rigid set holding u and v, or None when u, v are not rigid together.

        Lee–Streinu: with 3 pebbles gathered on u, v, the component is u, v and every
        vertex that cannot reach a free pebble elsewhere.  Valid for vertices of 3
        pebbles (bodies); call after all edges are in.
        """
        if self.gather(u, v, TRIVIAL + 1) > TRIVIAL:
            return None
        n = len(self.pebbles)
        incoming: list[list[int]] = [[] for _ in range(n)]
        for x, heads in enumerate(self.out):
            for y in heads:
                incoming[y].append(x)
        loose = [False] * n  # can reach a free pebble other than the 3 on u, v
        stack = [w for w in range(n) if self.pebbles[w] > 0 and w != u and w != v]
        for w in stack:
            loose[w] = True
        while stack:
            y = stack.pop()
            for x in incoming[y]:
                if not loose[x] and x != u and x != v:
                    loose[x] = True
                    stack.append(x)
        return [w for w in range(n) if not loose[w]]


# -- the body-and-pin model of a chain -----------------------------------------------


def pin_edges(
    n_bodies: int, joints: Iterable[tuple[str, str, Sequence[int]]]
) -> tuple[list[int], list[tuple[int, int, str]]]:
    """Vertices and edges of the game for bodies ``0..n_bodies-1``.

    ``joints`` are ``(joint id, kind, distinct bodies)``.  A joint of two bodies (and a
    prismatic MJ, as a star from its first body) is two bars per pair; a revolute MJ
    of m >= 3 bodies is a point vertex (2 pebbles) tied to each body by two edges, so
    that it counts 2(k - 1) constraints inside every sub-chain holding k of its bodies
    (a fixed star would not: a star from a third link hides a redundancy between two).
    Returns the pebble capacities and the edges ``(u, v, joint id)``.
    """
    capacities = [BODY_PEBBLES] * n_bodies
    edges: list[tuple[int, int, str]] = []
    for jid, kind, bodies in joints:
        if len(bodies) < 2:
            continue
        if len(bodies) == 2 or kind != "R":
            edges += [(bodies[0], w, jid) for w in bodies[1:] for _ in range(2)]
        else:
            point = len(capacities)
            capacities.append(POINT_PEBBLES)
            edges += [(point, w, jid) for w in bodies for _ in range(2)]
    return capacities, edges


def chain_joints(m: Mechanism, index: dict[str, int]) -> list[tuple[str, str, list[int]]]:
    """The chain's joints as ``(joint id, kind, body indices)`` for :func:`pin_edges`."""
    return [(j.id, j.kind, [index[x] for x in j.links]) for j in m.joints]


@dataclass(frozen=True)
class RigidityResult:
    """Outcome of the pebble game on a chain.

    ``rank`` counts independent constraints (2 per simple-joint equivalent when none is
    redundant); ``redundant`` lists the joint of every redundant constraint (with
    repetition); ``regions`` are the over-constrained sub-chains (link sets, each
    rigid) with the number of redundant constraints each holds.
    """

    n: int
    rank: int
    redundant: tuple[str, ...]
    regions: tuple[tuple[tuple[str, ...], int], ...]

    @property
    def dof(self) -> int:
        """Generic DOF of the chain: 3(n - 1) - rank."""
        return 3 * (self.n - 1) - self.rank


def play_chain(
    links: Sequence[str], joints: Iterable[tuple[str, str, Sequence[int]]]
) -> tuple[PebbleGame, list[tuple[int, int, str]], RigidityResult]:
    """Play the game on a chain: the final game, its edges and the rigidity result.

    ``joints`` as from :func:`chain_joints`; bodies are ``0..len(links)-1``.  The game
    is returned so that callers can add further bars (drivers) or read components.
    """
    n = len(links)
    capacities, edges = pin_edges(n, joints)
    game = PebbleGame(capacities)
    rejected: list[str] = []
    regions: list[set[int]] = []
    counts: list[int] = []
    for u, v, jid in edges:
        if game.add_edge(u, v):
            continue
        rejected.append(jid)
        region = {w for w in game.last_region if w < n}  # bodies only, not pin points
        # overlapping rigid regions merge into one rigid region (they share a body)
        keep_regions, keep_counts, total = [], [], 1
        for r, c in zip(regions, counts, strict=True):
            if r & region:
                region |= r
                total += c
            else:
                keep_regions.append(r)
                keep_counts.append(c)
        regions, counts = [*keep_regions, region], [*keep_counts, total]
    named = tuple(
        (tuple(links[k] for k in sorted(r)), c)
        for r, c in sorted(zip(regions, counts, strict=True), key=lambda rc: min(rc[0]))
    )
    points = len(capacities) - n
    rank = game.rank - POINT_PEBBLES * points  # a pin point's own 2 DOF are always taken
    return game, edges, RigidityResult(n, rank, tuple(rejected), named)


def rigidity(m: Mechanism) -> RigidityResult:
    """Run the (3,3) pebble game on the chain (drivers ignored).

    A four-bar with a fifth pin across it: formula F = -1, generic F = 0, one
    redundant constraint, and the whole chain is the over-constrained region.

    >>> from mjstruct.mechanism import Mechanism
    >>> double = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
    ...                           ("O2", [3, 0]), ("C", [1, 3])], frame=0)
    >>> r = rigidity(double)
    >>> r.dof, r.redundant, r.regions
    (0, ('C',), ((('0', '1', '2', '3'), 1),))
    """
    expect_mechanism(m)
    index = {x: k for k, x in enumerate(m.links)}
    return play_chain(m.links, chain_joints(m, index))[2]


def pebble_rank(m: Mechanism) -> int:
    """Rank of the chain's constraints for generic geometry."""
    return rigidity(m).rank


def generic_dof(m: Mechanism) -> int:
    """Generic DOF F = 3(n - 1) - rank; equals the formula F when nothing is redundant."""
    return rigidity(m).dof


def rigid_components(m: Mechanism, min_links: int = 2) -> list[tuple[str, ...]]:
    """Maximal rigid sub-chains with at least ``min_links`` links (drivers ignored)."""
    expect_mechanism(m)
    index = {x: k for k, x in enumerate(m.links)}
    joints = chain_joints(m, index)
    game, _, _ = play_chain(m.links, joints)
    comps = body_components(game, len(m.links), joints)
    out = [tuple(m.links[w] for w in c) for c in comps if len(c) >= min_links]
    return sorted(out, key=lambda c: (-len(c), c))


def body_components(
    game: PebbleGame, n_bodies: int, joints: Iterable[tuple[str, str, Sequence[int]]]
) -> list[list[int]]:
    """Maximal sets of mutually rigid bodies (of >= 2 bodies) after all edges are in.

    Bodies u, v sharing a joint are rigid together when no fourth pebble reaches them;
    their component is every body that cannot reach a free pebble elsewhere.
    """
    comp_of = [-1] * n_bodies
    comps: list[list[int]] = []
    tried: set[tuple[int, int]] = set()
    for _, _, bodies in joints:
        for u, v in itertools.combinations(bodies, 2):
            if comp_of[u] >= 0 and comp_of[u] == comp_of[v]:
                continue
            key = (min(u, v), max(u, v))
            if key in tried:
                continue
            tried.add(key)
            comp = game.rigid_component(u, v)
            if comp is None:
                continue
            found = sorted(w for w in comp if w < n_bodies)
            for w in found:
                comp_of[w] = len(comps)
            comps.append(found)
    return comps
