"""The atlas of one-DOF epicyclic gear trains (EGTs): every non-isomorphic rotation
graph with n links, each with its displacement graphs.

The graph of an EGT [Tsai & Freudenstein]: vertices are links, edges are
turning pairs and gear pairs. A one-DOF train of n links has n - 1 turning pairs that
form a spanning tree and n - 2 gear pairs (F = 3 (n - 1) - 2 (n - 1) - (n - 2) = 1).
Each gear edge (a, b) closes a fundamental circuit with the tree path from a to b
(rule 1). The other rules (their reasons are in docs/gears.md, "The atlas of
epicyclic gear trains"):

2. Each turning edge lies on a *level* (the axis of the pair). On the path of each
   fundamental circuit there is exactly one *transfer vertex* c (the carrier): the
   edges from a to c lie on one level (a turns about it relative to c), those from c
   to b on another. Two edges share a level only when a circuit puts them in one run.
3. With generic tooth ratios, the Willis equations of the circuits,
   ``(ω_a - ω_c) + k (ω_b - ω_c) = 0``, leave exactly one speed free besides a
   rotation of the whole train (F = 1), and no two links turn alike in every motion
   (no rigid sub-chain, no link that is not driven).

The *rotation graph* of a train is its gear edges, each with its carrier: it fixes the
Willis equations. The *displacement graph* adds the axes: the sets of coaxial links
(the links met by the turning edges of one level). Trains are the same rotation
(displacement) graph when a relabelling of the links maps one onto the other; the
arrangement of the turning pairs inside a set of coaxial links is not part of either.

References
----------
[Tsai & Freudenstein] (Buchsbaum & Freudenstein 1970, Freudenstein 1971), [Tsai 1987],
[PGT nine links 2019] in docs/references.md.

Examples
--------
>>> [len(egt_atlas(n).trains) for n in (4, 5, 6)]
[2, 6, 27]
>>> egt_atlas(6).displacement_count
81
"""

from __future__ import annotations

import itertools
import multiprocessing
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import networkx as nx
import numpy as np

from mjstruct.errors import MechanismError, expect_int
from mjstruct.structure.isomorphism import certificate_of, code_of, nauty_call

#: the largest atlas computed (7 links: about 6 s; 8 links: minutes, 1070 and 6360 graphs)
MAX_LINKS = 8

#: generic tooth ratios of the Willis equations (fixed seed: the atlas is deterministic)
RATIO_SEED = 34

Pair = tuple[int, int]


@dataclass(frozen=True)
class Displacement:
    """A displacement graph: the rotation graph with its axes, each the sorted links
    on one axis; ``turning`` one arrangement of the turning pairs (link pairs) with
    ``levels``, the index of each pair's axis in ``axes``; links numbered as in its
    train."""

    canonical: str
    axes: tuple[tuple[int, ...], ...]
    turning: tuple[Pair, ...]
    levels: tuple[int, ...]

    def to_dict(self) -> dict[str, object]:
        return {
            "canonical": self.canonical,
            "axes": [list(a) for a in self.axes],
            "turning": [list(p) for p in self.turning],
            "levels": list(self.levels),
        }


@dataclass(frozen=True)
class Train:
    """A rotation graph: links 0..n-1, ``gears`` as (a, b, carrier) triples, and its
    displacement graphs (the first one's turning pairs are a representative)."""

    canonical: str
    n: int
    gears: tuple[tuple[int, int, int], ...]
    displacements: tuple[Displacement, ...]

    def to_dict(self) -> dict[str, object]:
        return {
            "canonical": self.canonical,
            "n": self.n,
            "gears": [list(g) for g in self.gears],
            "carriers": sorted({g[2] for g in self.gears}),
            "displacements": [d.to_dict() for d in self.displacements],
        }


@dataclass(frozen=True)
class EGTAtlas:
    """The rotation graphs with n links, and the number of displacement graphs."""

    n: int
    trains: tuple[Train, ...]

    @property
    def count(self) -> int:
        return len(self.trains)

    @property
    def displacement_count(self) -> int:
        return sum(len(t.displacements) for t in self.trains)


def egt_atlas(
    n: int, progress: Callable[[int, int], None] | None = None, workers: int = 1
) -> EGTAtlas:
    """Every one-DOF EGT rotation graph with ``n`` links (3 <= n <= 8), each with its
    displacement graphs, sorted by canonical code. ``progress(done, total)`` is called
    after each spanning tree (work counted in trees); ``workers`` processes share the
    trees (the result does not depend on their number).

    >>> a = egt_atlas(4)
    >>> [t.gears for t in a.trains] == [t.gears for t in egt_atlas(4).trains]
    True
    >>> sorted(len(t.displacements) for t in a.trains)
    [1, 2]
    """
    n = expect_int(n, "n")
    workers = expect_int(workers, "workers", 1)
    if not 3 <= n <= MAX_LINKS:
        raise MechanismError(f"n: the gear-train atlas has 3 to {MAX_LINKS} links, got {n}")
    rng = np.random.default_rng(RATIO_SEED)
    ratios = rng.uniform(0.3, 3.0, n) * rng.choice([-1.0, 1.0], n)
    trees = [
        (n, sorted((min(e), max(e)) for e in t.edges()), ratios) for t in nx.nonisomorphic_trees(n)
    ]
    if progress is not None:
        progress(0, len(trees))
    if workers == 1:
        parts = []
        for t in trees:
            parts.append(_tree_part(t))
            if progress is not None:
                progress(len(parts), len(trees))
    else:
        with multiprocessing.get_context("spawn").Pool(min(workers, len(trees))) as pool:
            parts = []
            for part in pool.imap(_tree_part, trees):
                parts.append(part)
                if progress is not None:
                    progress(len(parts), len(trees))
    # merged in tree order: the same first representatives as one process finds
    rotation: dict[str, tuple[tuple[tuple[int, int, int], ...], list[int]]] = {}
    displaced: dict[str, dict[str, Displacement]] = {}
    for edges, firsts, found in parts:
        for r, triples, lab in firsts:
            rotation.setdefault(r, (triples, lab))
        for r, d, triples, levels, axes in found:
            if d not in displaced.setdefault(r, {}):
                displaced[r][d] = _renumbered(n, d, rotation[r][1], triples, edges, levels, axes)
    trains = tuple(
        Train(r, n, rotation[r][0], tuple(displaced[r][d] for d in sorted(displaced[r])))
        for r in sorted(rotation)
    )
    return EGTAtlas(n, trains)


Found = tuple[
    str, str, tuple[tuple[int, int, int], ...], tuple[int, ...], tuple[tuple[int, ...], ...]
]


def _tree_part(
    job: tuple[int, list[Pair], np.ndarray],
) -> tuple[list[Pair], list[tuple[str, tuple[tuple[int, int, int], ...], list[int]]], list[Found]]:
    """The trains on one spanning tree: each rotation graph's first graph (with its
    canonical link order) and each displacement graph's first, in the order found."""
    n, edges, ratios = job
    tree = nx.Graph(edges)
    firsts: list[tuple[str, tuple[tuple[int, int, int], ...], list[int]]] = []
    found: list[Found] = []
    seen: set[str] = set()
    for gears, carriers, runs in _trains_on(tree, edges, n):
        if not willis_determined(n, gears, carriers, ratios):
            continue
        triples = tuple((a, b, c) for (a, b), c in zip(gears, carriers, strict=True))
        r = _code("r", n, triples, ())
        if r not in seen:
            seen.add(r)
            firsts.append((r, triples, _canonical_links(n, triples)))
        levels, axes = _levels(edges, runs)
        d = _code("d", n, triples, axes)
        if d not in seen:
            seen.add(d)
            found.append((r, d, triples, levels, axes))
    return edges, firsts, found


def _renumbered(
    n: int,
    d: str,
    first_lab: list[int],
    triples: tuple[tuple[int, int, int], ...],
    edges: list[Pair],
    levels: tuple[int, ...],
    axes: tuple[tuple[int, ...], ...],
) -> Displacement:
    """A displacement graph with its links numbered as in its train's first graph
    (equal positions in nauty's canonical order)."""
    lab = _canonical_links(n, triples)
    to = {x: first_lab[lab.index(x)] for x in range(n)}
    turning = [(min(to[a], to[b]), max(to[a], to[b])) for a, b in edges]
    order = sorted(range(len(turning)), key=turning.__getitem__)
    moved = [tuple(sorted(to[x] for x in axis)) for axis in axes]
    names = sorted(range(len(moved)), key=moved.__getitem__)
    return Displacement(
        d,
        tuple(moved[i] for i in names),
        tuple(turning[k] for k in order),
        tuple(names.index(levels[k]) for k in order),
    )


def _trains_on(
    tree: nx.Graph, edges: list[Pair], n: int
) -> Iterator[tuple[tuple[Pair, ...], tuple[int, ...], list[list[int]]]]:
    """Every choice of n - 2 gear edges on ``tree`` and of a transfer vertex on each
    circuit that meets rule 2; with the runs of equal level (edge-index lists)."""
    index = {e: k for k, e in enumerate(edges)}
    paths = {
        (a, b): nx.shortest_path(tree, a, b)
        for a, b in itertools.combinations(range(n), 2)
        if not tree.has_edge(a, b)
    }
    path_edges = {
        g: [index[(min(p[i], p[i + 1]), max(p[i], p[i + 1]))] for i in range(len(p) - 1)]
        for g, p in paths.items()
    }
    every = set(range(len(edges)))
    for gears in itertools.combinations(sorted(paths), n - 2):
        # a turning edge on no circuit splits the train in two parts that turn
        # independently (rule 3 refuses it): skip without trying the cuts
        if set().union(*(path_edges[g] for g in gears)) != every:
            continue
        yield from _cuts(gears, paths, path_edges, len(edges))


def _cuts(
    gears: tuple[Pair, ...],
    paths: dict[Pair, list[int]],
    path_edges: dict[Pair, list[int]],
    m: int,
) -> Iterator[tuple[tuple[Pair, ...], tuple[int, ...], list[list[int]]]]:
    """Depth first over the gear edges: each transfer vertex merges its two runs into
    two levels; a branch stops as soon as some circuit's two levels coincide."""

    def deeper(
        k: int, level: list[int], apart: list[tuple[int, int]], cut: list[int]
    ) -> Iterator[tuple[int, ...]]:
        if k == len(gears):
            yield tuple(cut)
            return
        es = path_edges[gears[k]]
        for i in range(1, len(es)):
            new = level[:]
            for run in (es[:i], es[i:]):
                names = {new[e] for e in run}
                keep = min(names)
                new = [keep if x in names else x for x in new]
            pairs = [*apart, (es[i - 1], es[i])]
            if all(new[x] != new[y] for x, y in pairs):
                yield from deeper(k + 1, new, pairs, [*cut, i])

    for cut in deeper(0, list(range(m)), [], []):
        runs: list[list[int]] = []
        for g, i in zip(gears, cut, strict=True):
            runs += [path_edges[g][:i], path_edges[g][i:]]
        carriers = tuple(paths[g][i] for g, i in zip(gears, cut, strict=True))
        yield gears, carriers, runs


def _classes(m: int, runs: list[list[int]]) -> list[int]:
    """The level of each of m tree edges: edges in one run share a level (union-find,
    each level named by its smallest edge)."""
    parent = list(range(m))

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for run in runs:
        for e in run[1:]:
            a, b = find(run[0]), find(e)
            parent[max(a, b)] = min(a, b)
    return [find(x) for x in range(m)]


def _levels(
    edges: list[Pair], runs: list[list[int]]
) -> tuple[tuple[int, ...], tuple[tuple[int, ...], ...]]:
    """Each turning edge's axis index, and the axes as sorted link tuples."""
    level = _classes(len(edges), runs)
    names = sorted(set(level))
    axes = tuple(
        tuple(sorted({x for k, e in enumerate(edges) if level[k] == v for x in e})) for v in names
    )
    return tuple(names.index(v) for v in level), axes


def willis_determined(
    n: int, gears: tuple[Pair, ...], carriers: tuple[int, ...], ratios: np.ndarray
) -> bool:
    """Rule 3: the Willis equations with the generic ``ratios`` have rank n - 2, and no
    two links have equal speeds in both solutions of their null space."""
    m = np.zeros((len(gears), n))
    for row, ((a, b), c) in enumerate(zip(gears, carriers, strict=True)):
        k = ratios[row]
        m[row, a] += 1.0
        m[row, b] += k
        m[row, c] -= 1.0 + k
    _, s, vt = np.linalg.svd(m)
    if int(np.sum(s > 1e-9 * s[0])) != n - 2:
        return False
    null = vt[n - 2 :]
    diff = null[:, :, None] - null[:, None, :]
    apart = np.linalg.norm(diff, axis=0) > 1e-9
    return bool(np.all(apart | np.eye(n, dtype=bool)))


def _code(
    prefix: str, n: int, gears: tuple[tuple[int, int, int], ...], axes: tuple[tuple[int, ...], ...]
) -> str:
    """Canonical code of a rotation graph (``axes`` empty) or a displacement graph."""
    sizes, cert = certificate_of(*_incidence(n, gears, axes))
    return code_of(f"egt-{prefix}", n, len(gears) * 2 + len(axes), sizes, cert)


def _canonical_links(n: int, gears: tuple[tuple[int, int, int], ...]) -> list[int]:
    """nauty's canonical order of the links of a rotation graph (the link at each
    position)."""
    lab = nauty_call("canon_label", *_incidence(n, gears, ()))
    assert isinstance(lab, list)
    return lab[:n]


def _incidence(
    n: int, gears: tuple[tuple[int, int, int], ...], axes: tuple[tuple[int, ...], ...]
) -> tuple[int, list[list[int]], list[range]]:
    """The coloured incidence structure of a rotation or displacement graph."""
    # vertices: links, then one marker per gear edge; hyperedges: the gear edges (with
    # their marker), the carrier of each (with the marker), the axes
    g = len(gears)
    joints = [[a, b, n + k] for k, (a, b, _) in enumerate(gears)]
    joints += [[c, n + k] for k, (_, _, c) in enumerate(gears)]
    joints += [list(a) for a in axes]
    v = n + g
    colours = [
        range(n),
        range(n, v),
        range(v, v + g),
        range(v + g, v + 2 * g),
        range(v + 2 * g, v + 2 * g + len(axes)),
    ]
    return v, joints, [c for c in colours if len(c)]
