"""Contracted graphs: the skeleton of a chain once its degree-2 nodes are suppressed.

Owns the enumeration of the coloured multigraphs that the atlas expands into chains.
Suppressing every degree-2 node (binary link or simple joint) of a chain's bipartite
link–joint graph leaves a multigraph whose vertices are the links with >= 3 joints
(colour ``"L"``) and the multiple joints (colour ``"J"``), and whose edges are the
paths of binary links between them.  It has the chain's cycle rank K, minimum degree
3, and ``Σ (deg - 2) = 2(K - 1)``; it is an isomorphism invariant of the chain, so
chains built on non-isomorphic contracted graphs are never isomorphic.

A vertex-degree multiset is one enumeration *task*: it fixes [LA] (up to n2) and
[MJA].  Multigraphs with given degrees are built vertex by vertex; partial graphs are
deduplicated by their nauty certificate after each vertex is completed (the set of
completions of a partial graph does not depend on the order in which vertices are
completed), which keeps the search small.

Examples
--------
>>> sequences = degree_sequences(2, mj=False)
>>> sequences
[(('L', 4),), (('L', 3), ('L', 3))]
>>> [len(contracted_graphs(s, fractionated=False)) for s in sequences]
[0, 1]
"""

from __future__ import annotations

from collections.abc import Collection, Iterator
from dataclasses import dataclass

from mjstruct.synthesis.nauty_calls import LightGraph, certificate, light_graph

Vertex = tuple[str, int]  # (colour "L" or "J", degree)


@dataclass(frozen=True)
class ContractedGraph:
    """A coloured multigraph: ``colours[v]`` in {"L", "J"}, ``edges`` as (u, v), u <= v.

    A loop is an edge (u, u).  Parallel edges repeat.
    """

    colours: tuple[str, ...]
    edges: tuple[tuple[int, int], ...]

    @property
    def order(self) -> int:
        return len(self.colours)

    def degrees(self) -> list[int]:
        deg = [0] * self.order
        for u, v in self.edges:
            deg[u] += 1
            deg[v] += 1
        return deg

    def has_loops(self) -> bool:
        return any(u == v for u, v in self.edges)

    def _reach(self, start: int, allowed: int) -> int:
        """Vertices (bitmask) reachable from ``start`` inside the set ``allowed``."""
        near = [0] * self.order
        for u, v in self.edges:
            near[u] |= 1 << v
            near[v] |= 1 << u
        seen = frontier = 1 << start
        while frontier:
            grown = 0
            for u in range(self.order):
                if frontier >> u & 1:
                    grown |= near[u]
            frontier = grown & allowed & ~seen
            seen |= frontier
        return seen

    def is_connected(self) -> bool:
        everyone = (1 << self.order) - 1
        return self.order > 0 and self._reach(0, everyone) == everyone

    def is_fractionated(self) -> bool:
        """Whether the chains built on this graph have a cut vertex (link or joint)."""
        if self.has_loops() or not self.is_connected():
            return True
        if self.order <= 2:
            return False
        everyone = (1 << self.order) - 1
        for cut in range(self.order):
            rest = everyone & ~(1 << cut)
            if self._reach(0 if cut else 1, rest) != rest:
                return True
        return False

    def is_planar(self) -> bool:
        """Planarity of the chains built on it (subdividing edges keeps planarity)."""
        simple = sorted({(u, v) for u, v in self.edges if u != v})
        if len(simple) < 9:  # K5 and K3,3 have 10 and 9 edges
            return True
        # many contracted graphs share their simple graph (an atlas with MJs: 1720
        # tests at 12 links, 39 graphs): one test per graph up to isomorphism
        key = (self.order, len(simple), certificate(light_graph(self.order, simple)))
        if key not in _PLANAR:
            import networkx as nx  # here: 20 MB and 0.1 s that only this test needs

            graph = nx.Graph()  # from edges: nx.Graph(data) would import scipy and pandas
            graph.add_edges_from(simple)
            _PLANAR[key] = bool(nx.check_planarity(graph)[0])
        return _PLANAR[key]


_PLANAR: dict[tuple[int, int, bytes], bool] = {}
"""Planarity of the simple graphs tested so far, by nauty certificate (per process)."""


def degree_sequences(K: int, mj: bool) -> list[tuple[Vertex, ...]]:
    """All multisets of branch vertices (colour, degree >= 3) with Σ (deg - 2) = 2(K - 1).

    Without ``mj`` only links ("L"); with it also multiple joints ("J").  Sorted.
    """
    total = 2 * (K - 1)
    kinds = ("L", "J") if mj else ("L",)
    out: list[tuple[Vertex, ...]] = []

    def rec(left: int, smallest: tuple[int, str], acc: list[Vertex]) -> None:
        if left == 0:
            if acc:
                out.append(tuple(sorted(acc, key=lambda v: (-v[1], v[0]))))
            return
        for excess in range(smallest[0], left + 1):
            for colour in kinds:
                if (excess, colour) < smallest:
                    continue
                acc.append((colour, excess + 2))
                rec(left - excess, (excess, colour), acc)
                acc.pop()

    if total > 0:
        rec(total, (1, ""), [])
    return sorted(set(out), key=lambda s: (len(s), [(-d, c) for c, d in s]))


PartialKey = tuple[tuple[tuple[tuple[str, int, int], int], ...], bytes]
"""A partial multigraph up to isomorphism: its colour classes (key, size) in a fixed
order, and nauty's certificate with the vertices partitioned in that order."""


def _certificate(
    colours: list[str], done: list[bool], residual: list[int], edges: list[tuple[int, int]]
) -> PartialKey:
    """Nauty certificate of a (partial) multigraph; edges become coloured nodes (an
    edge node's colour: "edge", or "loop" for an edge from a vertex to itself)."""
    nv = len(colours)
    keys = [
        (colour, -1 if finished else left, 0)
        for colour, finished, left in zip(colours, done, residual, strict=True)
    ]
    adjacency: dict[int, list[int]] = {}
    plain: list[int] = []
    loops: list[int] = []
    for k, (u, v) in enumerate(edges):
        if u == v:
            adjacency[nv + k] = [u]
            loops.append(nv + k)
        else:
            adjacency[nv + k] = [u, v]
            plain.append(nv + k)
    classes: list[tuple[tuple[str, int, int], int]] = []
    partition: list[Collection[int]] = []
    for key in sorted(set(keys)):
        members = [v for v in range(nv) if keys[v] == key]
        classes.append((key, len(members)))
        partition.append(members)
    for name, members in (("edge", plain), ("loop", loops)):  # after the vertices
        if members:
            classes.append(((name, 0, 1), len(members)))
            partition.append(members)
    return tuple(classes), certificate(LightGraph(nv + len(edges), adjacency, partition))


def _spread(
    i: int, later: list[int], residual: list[int], k: int, left: int, acc: list[tuple[int, int]]
) -> Iterator[list[tuple[int, int]]]:
    """Every way to give ``left`` edges from vertex i to the vertices ``later[k:]``."""
    if left == 0:
        yield list(acc)
        return
    if k == len(later):
        return
    j = later[k]
    for mult in range(min(left, residual[j]), -1, -1):
        acc.extend([(i, j)] * mult)
        yield from _spread(i, later, residual, k + 1, left - mult, acc)
        del acc[len(acc) - mult :]


def _complete_vertex(
    i: int, residual: list[int], loops_ok: bool, colours: list[str]
) -> Iterator[list[tuple[int, int]]]:
    """All ways to spend vertex i's residual degree on loops and edges to later vertices."""
    nv = len(residual)
    r = residual[i]
    later = [j for j in range(i + 1, nv) if residual[j] > 0]
    for nloops in range(r // 2 if loops_ok else 0, -1, -1):
        for edges in _spread(i, later, residual, 0, r - 2 * nloops, []):
            yield [(i, i)] * nloops + edges


def contracted_graphs(sequence: tuple[Vertex, ...], fractionated: bool) -> list[ContractedGraph]:
    """All connected multigraphs, up to isomorphism, with the given coloured degrees.

    Without ``fractionated`` only those whose chains have no cut vertex (no loops,
    2-connected).  Deterministic order (by nauty certificate).
    """
    colours = [c for c, _ in sequence]
    nv = len(colours)
    states: dict[PartialKey, tuple[list[int], list[tuple[int, int]]]] = {}
    partial = [([d for _, d in sequence], list[tuple[int, int]]())]
    for i in range(nv):
        nxt: dict[PartialKey, tuple[list[int], list[tuple[int, int]]]] = {}
        done = [k <= i for k in range(nv)]
        for residual, edges in partial:
            for new in _complete_vertex(i, residual, fractionated, colours):
                res = list(residual)
                res[i] = 0
                for u, v in new:
                    if u != v:
                        res[v] -= 1
                all_edges = edges + new
                cert = _certificate(colours, done, res, all_edges)
                if cert not in nxt:
                    nxt[cert] = (res, all_edges)
        states = nxt
        partial = list(nxt.values())
    out = []
    for cert in sorted(states):
        _, edges = states[cert]
        cg = ContractedGraph(tuple(colours), tuple(sorted(edges)))
        if not cg.is_connected():
            continue
        if not fractionated and cg.is_fractionated():
            continue
        out.append(cg)
    return out
