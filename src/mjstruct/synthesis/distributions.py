"""Distributions of binary links over a contracted graph's edges: one per chain.

Owns the step of the atlas between a contracted graph and its chains: every way to
put the binary links on the edges (how many on each edge) that gives an admissible
chain, exactly one per isomorphism class of chains.

- Two distributions give isomorphic chains exactly when an automorphism of the
  coloured contracted multigraph maps one onto the other (the contracted graph is the
  chain's invariant skeleton, and an isomorphism of chains maps edge paths onto edge
  paths of the same length).  So only the lexicographically smallest member of each
  orbit under the automorphism group's action on the edges (nauty) is kept: no chain
  is built, labelled and compared only to be discarded.
- The distributions are generated edge by edge as numpy arrays, all rows of a level
  at once.  Parallel edges are interchangeable, so their counts are generated
  non-decreasing (the smallest member of an orbit is).  A row is dropped as soon as a
  vertex set W holding at least two links has all its inside edges counted and a
  sub-chain mobility below the threshold, so rows that cannot become admissible are
  not extended; the edges are ordered so that small vertex sets are complete early.
  The sets holding fewer than two links are tested at the end, exactly as in
  :func:`mjstruct.synthesis.atlas.admissible_distributions`.

Examples
--------
>>> from mjstruct.synthesis.contracted import contracted_graphs
>>> theta = contracted_graphs((("L", 3), ("L", 3)), fractionated=False)[0]
>>> theta.edges                   # two ternary links joined by three paths
((0, 1), (0, 1), (0, 1))
>>> cg, rows = chain_distributions(theta, 4)
>>> rows                          # 6 links: the Watt and the Stephenson chains
array([[0, 2, 2],
       [1, 1, 2]], dtype=int16)
>>> len(edge_automorphisms(theta))  # any permutation of the three paths
6
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mjstruct.synthesis.contracted import ContractedGraph
from mjstruct.synthesis.nauty_calls import automorphism_generators, light_graph

ROWS = 2048
"""Rows of partial distributions extended at once (bounds the memory of a level: a
worker of the 12-link MJ atlas peaks 12 MB lower than with 8192, at the same speed)."""

KEY_CELLS = 1 << 21
"""Row x automorphism pairs compared at once when keeping orbit representatives."""

BIG = 10**6  # "no such edge" in a minimum


def edge_minimum(cg: ContractedGraph, u: int, v: int) -> int:
    """The fewest binary links edge uv of a contracted graph must carry (0 allowed
    between a link and a joint; a loop needs links to avoid a link twice on one joint)."""
    cu, cv = cg.colours[u], cg.colours[v]
    if u == v:
        return 1 if cu == "L" else 2  # fewer: a link twice on one joint
    return 1 if cu == cv == "J" else 0


def edge_automorphisms(cg: ContractedGraph) -> np.ndarray:
    """Every automorphism of the coloured multigraph as a permutation of its edges.

    Row g sends edge j to edge ``out[g, j]``; the identity is among the rows.  Vertex
    colours (link or multiple joint) are kept; parallel edges may be exchanged.
    """
    nv, ne = cg.order, len(cg.edges)
    links = [v for v in range(nv) if cg.colours[v] == "L"]
    joints = [v for v in range(nv) if cg.colours[v] != "L"]
    loops = [nv + k for k, (u, v) in enumerate(cg.edges) if u == v]
    others = [nv + k for k, (u, v) in enumerate(cg.edges) if u != v]
    ends = [[u] if u == v else [u, v] for u, v in cg.edges]
    generators = automorphism_generators(light_graph(nv, ends, [links, joints, others, loops]))
    moves = [tuple(g[nv + k] - nv for k in range(ne)) for g in generators]
    identity = tuple(range(ne))
    group = {identity}
    frontier = [identity]
    while frontier:
        grown = []
        for p in frontier:
            for m in moves:
                q = tuple(m[i] for i in p)
                if q not in group:
                    group.add(q)
                    grown.append(q)
        frontier = grown
    return np.array(sorted(group), dtype=np.int64).reshape(len(group), ne)


@dataclass(frozen=True)
class VertexSets:
    """The vertex sets W of a contracted graph that the admissibility test visits:
    those whose inside edges connect them (and hold at least one edge).  Enough: the
    mobility of a disconnected W is the sum of its parts' plus 3 per extra part, and a
    part holding at most one link has mobility >= -1, so a rigid disconnected W always
    contains a rigid connected part.

    ``bits[w, v]``: v in W; ``inside[w, e]``: both ends of edge e in W; ``links``:
    links in W; ``base``: ``3|W_L| + 2|W_J| - 3``.
    """

    bits: np.ndarray
    inside: np.ndarray
    links: np.ndarray
    base: np.ndarray

    @classmethod
    def of(cls, cg: ContractedGraph) -> VertexSets:
        nv = cg.order
        adjacent = [0] * nv
        for u, v in cg.edges:
            adjacent[u] |= 1 << v
            adjacent[v] |= 1 << u
        # near[m]: the neighbours of the vertex set m, built by highest vertex
        near = np.zeros(1 << nv, dtype=np.int64)
        for i in range(nv):
            near[1 << i : 2 << i] = near[: 1 << i] | adjacent[i]
        masks = np.arange(1 << nv, dtype=np.int64)
        seen = masks & -masks  # grow from the lowest vertex inside the set
        while True:
            reach = (seen | near[seen]) & masks
            if np.array_equal(reach, seen):
                break
            seen = reach
        bits = (masks[:, None] >> np.arange(nv)) & 1
        us = np.array([u for u, _ in cg.edges], dtype=np.int64)
        vs = np.array([v for _, v in cg.edges], dtype=np.int64)
        inside = bits[:, us] & bits[:, vs]
        keep = (seen == masks) & inside.any(axis=1)
        bits, inside = bits[keep], inside[keep]
        is_link = np.array([c == "L" for c in cg.colours])
        links = bits[:, is_link].sum(axis=1)
        base = 3 * links + 2 * bits[:, ~is_link].sum(axis=1) - 3
        return cls(bits, inside, links, base)


def mobility_ok(
    sets: VertexSets, binaries: np.ndarray, threshold: int, which: np.ndarray | None = None
) -> np.ndarray:
    """Mask of the rows of ``binaries`` (binary links per edge) whose chains have no
    sub-chain of mobility below ``threshold`` among the vertex sets ``which`` (all by
    default).

    Exact: the least mobility of a link set built on W (W's branch vertices and whole
    edge paths) is ``3|W_L| + 2|W_J| - 3 + Σ_{e inside W, b_e <= 2} (b_e - 2)``; when
    that set holds fewer than two links, the cheapest longer path inside W (``b_e -
    2`` more) is added, or W gives no sub-chain.
    """
    if which is None:
        which = np.arange(len(sets.base))
    links = sets.links[which]
    inside = sets.inside[which].T.astype(np.int64)
    inside_f = inside.astype(np.float64)  # BLAS; small integers stay exact
    ok = np.ones(len(binaries), dtype=bool)
    if not len(which):
        return ok
    step = max(1, (1 << 20) // len(which))
    for start in range(0, len(binaries), step):
        b = binaries[start : start + step].astype(np.int64)
        drop = np.minimum(b - 2, 0).astype(np.float64) @ inside_f
        mobility = sets.base[which] + drop.astype(np.int64)
        low = mobility < threshold
        rows, cols = np.nonzero(low)
        if len(rows):
            size = links[cols] + (np.where(b[rows] <= 2, b[rows], 0) * inside.T[cols]).sum(axis=1)
            few = size < 2
            cost = np.where((b[rows[few]] >= 3) & (inside.T[cols[few]] > 0), b[rows[few]] - 2, BIG)
            rise = np.zeros(len(rows), dtype=np.int64)
            rise[few] = cost.min(axis=1, initial=BIG)
            low[rows, cols] = mobility[rows, cols] + rise < threshold
        ok[start : start + step] = ~low.any(axis=1)
    return ok


def admissible_distributions(
    cg: ContractedGraph, binaries: np.ndarray, threshold: int = 1
) -> np.ndarray:
    """Mask of the rows of ``binaries`` (binary links per edge) giving admissible chains.

    ``threshold`` is the least sub-chain mobility allowed (1: no rigid sub-chain; 0 is
    a necessary condition for the minimal rigid structures behind Assur groups).

    Exact: the minimum sub-chain mobility over all link sets equals the minimum over
    the vertex sets W of :class:`VertexSets` (:func:`mobility_ok`); and a link sits
    on a multiple joint once (at most one direct link–joint edge per pair).
    """
    ok = mobility_ok(VertexSets.of(cg), binaries, threshold)
    seen: dict[tuple[int, int], list[int]] = {}
    for k, (u, v) in enumerate(cg.edges):
        if u != v and cg.colours[u] != cg.colours[v]:
            seen.setdefault((u, v), []).append(k)
    for ks in seen.values():
        if len(ks) > 1:
            ok &= (binaries[:, ks] == 0).sum(axis=1) <= 1
    return ok


def edge_order(cg: ContractedGraph) -> ContractedGraph:
    """``cg`` with its edges reordered so that small vertex sets are complete early:
    vertices in maximum-adjacency order (links first among equals), edges by their
    later end.  Parallel edges stay next to each other."""
    nv = cg.order
    weight = [[0] * nv for _ in range(nv)]
    for u, v in cg.edges:
        if u != v:
            weight[u][v] += 1
            weight[v][u] += 1
    degree = cg.degrees()
    order: list[int] = []
    left = set(range(nv))
    while left:
        best = max(
            left,
            key=lambda v: (
                sum(weight[v][u] for u in order),
                cg.colours[v] == "L",
                degree[v],
                -v,
            ),
        )
        order.append(best)
        left.remove(best)
    place = {v: i for i, v in enumerate(order)}
    edges = sorted(
        cg.edges, key=lambda e: (max(place[e[0]], place[e[1]]), min(place[e[0]], place[e[1]]))
    )
    return ContractedGraph(cg.colours, tuple(edges))


def _extend(rows: np.ndarray, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every row once for each value low..high of the next edge: (rows, which row)."""
    count = np.maximum(high - low + 1, 0)
    total = int(count.sum())
    parent = np.repeat(np.arange(len(rows)), count)
    value = low[parent] + (np.arange(total) - (np.cumsum(count) - count)[parent])
    out = np.empty((total, rows.shape[1] + 1), dtype=rows.dtype)
    out[:, :-1] = rows[parent]
    out[:, -1] = value
    return out, parent


def _checked_sets(cg: ContractedGraph, sets: VertexSets) -> np.ndarray:
    """Indices of the sets the generation checks: all but those with a vertex on one
    inside edge whose removal leaves >= 2 links (that smaller set has a lower
    mobility, by 1 to 3, for every distribution)."""
    incidence = np.zeros((len(cg.edges), cg.order), dtype=np.int64)
    for k, (u, v) in enumerate(cg.edges):
        incidence[k, u] += 1
        incidence[k, v] += 1
    degree = sets.inside @ incidence  # (set, vertex): inside edges at the vertex
    is_link = np.array([c == "L" for c in cg.colours], dtype=np.int64)
    removable = (degree == 1) & (sets.links[:, None] - is_link[None, :] >= 2)
    return np.nonzero(~removable.any(axis=1))[0]


@dataclass
class _Skeletons:
    """What the edge-by-edge generation needs of several contracted graphs with the
    same number of edges, stacked (row c: graph c): per edge its least count, whether
    it repeats the previous edge (and joins a link to a joint), the least count of the
    edges after it; per graph and edge the vertex sets checked (padded)."""

    graphs: list[ContractedGraph]
    sets: list[VertexSets]
    minima: np.ndarray
    parallel: np.ndarray
    mixed: np.ndarray
    tail: np.ndarray
    inside: np.ndarray  # (graph, edge, set): 1 if the edge is inside the set
    base: np.ndarray  # (graph, set): 3|W_L| + 2|W_J| - 3
    size: np.ndarray  # (graph, set): links in the set, at most 2
    need: np.ndarray  # (graph, edge, set): binaries the set's later edges lack for 2 each

    @classmethod
    def of(cls, graphs: list[ContractedGraph]) -> _Skeletons:
        graphs = [edge_order(cg) for cg in graphs]
        ng, ne = len(graphs), len(graphs[0].edges)
        minima = np.array(
            [[edge_minimum(cg, u, v) for u, v in cg.edges] for cg in graphs], dtype=np.int16
        ).reshape(ng, ne)
        tail = np.zeros((ng, ne + 1), dtype=np.int16)
        tail[:, :ne] = np.cumsum(minima[:, ::-1], axis=1)[:, ::-1]
        parallel = np.array(
            [[k > 0 and cg.edges[k] == cg.edges[k - 1] for k in range(ne)] for cg in graphs],
            dtype=bool,
        ).reshape(ng, ne)
        mixed = np.array(
            [[cg.colours[u] != cg.colours[v] for u, v in cg.edges] for cg in graphs], dtype=bool
        ).reshape(ng, ne)
        sets = [VertexSets.of(cg) for cg in graphs]
        chosen = [_checked_sets(cg, s) for cg, s in zip(graphs, sets, strict=True)]
        width = max(len(c) for c in chosen)
        inside = np.zeros((ng, ne, width), dtype=np.int8)
        base = np.full((ng, width), 4 * ne + 1, dtype=np.int8)  # padding: never low
        size = np.full((ng, width), 2, dtype=np.int8)
        for c, (s, idx) in enumerate(zip(sets, chosen, strict=True)):
            inside[c, :, : len(idx)] = s.inside[idx].T
            base[c, : len(idx)] = s.base[idx]
            size[c, : len(idx)] = np.minimum(s.links[idx], 2)
        # after edge k: 2 for each later inside edge, less their least counts (which
        # the other later edges' minima in `tail` do not cover)
        later = np.zeros((ng, ne, width), dtype=np.int16)
        later[:, :-1] = np.cumsum((inside * (2 - minima[:, :, None]))[:, ::-1], axis=1)[:, ::-1][
            :, 1:
        ]
        need = later.astype(np.int8)
        return cls(graphs, sets, minima, parallel, mixed, tail, inside, base, size, need)


def distributions_of(
    graphs: list[ContractedGraph], binaries: int, threshold: int = 1
) -> list[tuple[ContractedGraph, np.ndarray]]:
    """:func:`chain_distributions` of several contracted graphs with the same number
    of edges, generated together (one set of array operations per edge for all)."""
    if not graphs:
        return []
    sk = _Skeletons.of(graphs)
    ne = sk.minima.shape[1]
    found: list[list[tuple[np.ndarray, np.ndarray]]] = [[] for _ in graphs]

    everyone = np.arange(len(graphs))
    # depth first over chunks of rows (a stack, not recursion: a recursive closure
    # would be a reference cycle holding the arrays until the cyclic collector runs)
    stack = [
        (
            np.zeros((len(part), 0), dtype=np.int16),
            part,
            np.full(len(part), binaries, dtype=np.int16),
            sk.base[part],
            sk.size[part],
        )
        for lo in range(0, len(graphs), ROWS)
        for part in [everyone[lo : lo + ROWS]]
    ][::-1]
    while stack:
        rows, graph, left, mobility, size = stack.pop()
        k = rows.shape[1]
        if k == ne:
            # a set of fewer than two links and low mobility: the exact test decides
            unsure = np.asarray(((mobility < threshold) & (size < 2)).any(axis=1))
            for c in np.unique(graph).tolist():
                mine = graph == c
                found[c].append((rows[mine], unsure[mine]))
            continue
        low = sk.minima[graph, k]
        if k:
            previous = rows[:, k - 1]
            after = np.maximum(low, previous)
            # a link sits on a multiple joint once: one direct edge to it
            after = np.where(
                sk.mixed[graph, k], np.maximum(after, np.minimum(previous + 1, 1)), after
            )
            low = np.where(sk.parallel[graph, k], after, low)
        if k == ne - 1:
            low = np.maximum(low, left)
            high = left
        else:
            high = left - sk.tail[graph, k + 1]
        rows, parent = _extend(rows, low, high)
        graph, left = graph[parent], left[parent] - rows[:, k]
        count = rows[:, k]
        inside = sk.inside[graph, k]
        mobility = mobility[parent] + np.minimum(count - 2, 0).astype(np.int8)[:, None] * inside
        grown = np.where(count <= 2, count, 0).astype(np.int8)[:, None] * inside
        size = np.minimum(size[parent] + grown, 2)
        # the best the edges still to count can do: 2 binaries on each inside edge,
        # out of what the other later edges leave beyond their own minima; a set of
        # fewer than two links may still take a longer path (tested at the end)
        spare = (left - sk.tail[graph, k + 1]).astype(np.int8)
        lack = np.maximum(sk.need[graph, k] - spare[:, None], 0)
        bad = ((mobility - lack < threshold) & (size >= 2)).any(axis=1)
        if bad.any():
            good = ~bad
            rows, graph, left = rows[good], graph[good], left[good]
            mobility, size = mobility[good], size[good]
        for lo in reversed(range(0, len(rows), ROWS)):
            part = slice(lo, lo + ROWS)
            stack.append((rows[part], graph[part], left[part], mobility[part], size[part]))
    out = []
    for cg, sets, parts in zip(sk.graphs, sk.sets, found, strict=True):
        if not parts:
            out.append((cg, np.zeros((0, ne), dtype=np.int16)))
            continue
        rows = np.concatenate([r for r, _ in parts])
        unsure = np.concatenate([u for _, u in parts])
        if unsure.any():
            check = np.nonzero(unsure)[0]
            short = np.nonzero(sets.links <= 1)[0]
            keep = np.ones(len(rows), dtype=bool)
            keep[check] = mobility_ok(sets, rows[check], threshold, short)
            rows = rows[keep]
        rows = rows[np.lexsort(rows.T[::-1])]
        rows = rows[orbit_minima(rows, edge_automorphisms(cg), binaries)]
        out.append((cg, rows))
    return out


def chain_distributions(
    cg: ContractedGraph, binaries: int, threshold: int = 1
) -> tuple[ContractedGraph, np.ndarray]:
    """The distributions of ``binaries`` binary links over the edges of ``cg`` that
    give admissible chains (sub-chain mobility >= ``threshold``), one per chain: the
    lexicographically smallest of each orbit of the automorphism group.

    Returns ``cg`` with its edges in the order the rows use (:func:`edge_order`) and
    the rows (int16, in increasing lexicographic order).
    """
    return distributions_of([cg], binaries, threshold)[0]


def orbit_minima(rows: np.ndarray, perms: np.ndarray, largest: int) -> np.ndarray:
    """Mask of the rows that are lexicographically smallest in their orbit.

    ``perms[g, j]``: where automorphism g sends position j, so the image of a row b
    has ``b[j]`` at position ``perms[g, j]``; entries are at most ``largest``.
    """
    ne = rows.shape[1]
    ok = np.ones(len(rows), dtype=bool)
    if len(rows) == 0 or len(perms) <= 1:
        return ok
    radix = largest + 1
    block = max(1, int(62 // np.log2(radix + 1)))  # positions per exact int64 key
    inverse = np.argsort(perms, axis=1)  # image[:, i] = b[:, inverse[g, i]]
    step = max(1, KEY_CELLS // len(perms))
    for lo in range(0, len(rows), step):
        b = rows[lo : lo + step].astype(np.int64)
        less = np.zeros((len(b), len(perms)), dtype=bool)
        equal = np.ones((len(b), len(perms)), dtype=bool)
        for first in range(0, ne, block):
            span = range(first, min(first + block, ne))
            weights = radix ** np.arange(len(span) - 1, -1, -1, dtype=np.int64)
            own = b[:, span.start : span.stop] @ weights
            image = np.zeros(less.shape, dtype=np.int64)
            for w, i in zip(weights.tolist(), span, strict=True):
                image += b[:, inverse[:, i]] * w
            less |= equal & (image < own[:, None])
            equal &= image == own[:, None]
        ok[lo : lo + step] = ~less.any(axis=1)
    return ok
