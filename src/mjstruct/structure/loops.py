"""Loop assortment [L]: face sizes of a planar drawing of the link–joint graph.

A face of the bipartite graph alternates links and joints; its size is the number of
links on it (half its boundary walk).  There are L = K + 1 faces, the outer one
included, and their sizes add up to S_L.

Which drawing?  A graph that is not (a subdivision of) a 3-connected one has several
planar embeddings with different face sizes.  Rule, in order:

1. ``"minimal"``: over all embeddings, the sorted face-size list that is smallest
   lexicographically (most small loops first: the drawing a designer makes, e.g.
   [4 4 4 4 13] for the excavator of [MJ structure 2020]).  This is a graph invariant.  It is
   found by enumerating rotation systems of the graph with degree-2 vertices
   suppressed, when there are at most :data:`EXACT_LIMIT` of them.
2. ``"canonical"``: otherwise, the embedding networkx finds for the graph relabelled
   in nauty's canonical order: deterministic and independent of labels and input
   order, but one embedding among several.

A non-planar chain has no [L]: :func:`loop_assortment` returns ``None``.

Parallel chains are drawn side by side.  A *chain* is a path of vertices of degree
two between two different vertices of another degree (its ends): a joint between two
links, a binary link between two joints, or a binary link joining links 0 and 1
through two joints.  Two chains with the same ends and the same length l (in edges of
the link–joint graph) bound a face of l links (a boundary walk of 2l edges).  Of k >= 3
such chains the face search keeps two, and the minimal [L] of the whole is that of the
chain with two of them plus k − 2 loops of l links (k parallel joints: k − 1 loops of
two links in all; k binary links between links 0 and 1: k − 1 loops of four).
Thousands of parallel joints or paths then cost what one does, where every rotation
of them was a case before.

Proof.  Drawing a chain beside one of its class, inside the face along that one, adds
a face of l links and leaves the other faces as they were: the minimum is at most the
claimed one.  Conversely, in any drawing the k chains cut the plane into k regions
between consecutive ones, and the rest of the graph lies in them; a region with
nothing in it is a face of l links.  Where two regions are not empty, move what one
holds into the other, beside what is there: the two faces that met along a chain,
of sizes (a + l)/2 and (b + l)/2 (a, b the walks of the two parts facing each other
from end to end), become one face of (a + b)/2 and an empty region of l.  The sums
agree, and when a and b are both at most l or both at least l the smaller new size
is at most the smaller old one, so the sorted sizes do not grow lexicographically.
Of three non-empty regions two always have facing sides that agree so (a part with
no way from end to end counts as long on both its sides; either part may be
mirrored).  Repeating leaves at most two non-empty regions.  Then removing, one at a
time, k − 2 chains beside an empty region removes one face of l links each and
changes no other face (a chain of the same length takes its place along the region
beyond); what remains is a drawing of the chain with two of them.

References
----------
.. [1] A paper on the system analysis of the structure and mobility of planar
   multi-loop linkage mechanisms with multiple joints (in Russian, with an English
   abstract; authors and exact title not given in the available copy), Izvestiya
   vysshikh uchebnykh zavedenii. Mashinostroenie (Proceedings of Higher Educational
   Institutions. Machine Building), no. 2 (719), 2020. [MJ structure 2020] in
   docs/references.md.
.. [2] I. I. Artobolevsky, Theory of Mechanisms and Machines (in Russian), Moscow:
   Nauka, 1988. [Artobolevsky 1988] in docs/references.md.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> four_bar = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0])])
>>> loop_assortment(four_bar)
LoopAssortment(sizes=(4, 4), rule='minimal')
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Hashable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from mjstruct.mechanism import Mechanism, expect_mechanism

Adjacency = Mapping[Any, Sequence[Any]]

EXACT_LIMIT = 20_000


@dataclass(frozen=True)
class LoopAssortment:
    """Sorted face sizes (in links) and the rule that chose the embedding."""

    sizes: tuple[int, ...]
    rule: str


def is_planar(m: Mechanism) -> bool:
    """Whether the link–joint graph has a planar drawing."""
    expect_mechanism(m)
    import networkx as nx

    return bool(nx.check_planarity(m.graph())[0])


def _suppressed(g: Adjacency) -> tuple[list[Hashable], list[tuple[Hashable, Hashable, int]]]:
    """Branch vertices (degree != 2) and the paths between them as weighted edges."""
    branch = [v for v in g if len(g[v]) != 2]
    is_branch = set(branch)
    seen: set[frozenset[Hashable]] = set()
    edges = []
    for u in branch:
        for w in g[u]:
            if frozenset((u, w)) in seen:
                continue
            prev, cur, length = u, w, 1
            seen.add(frozenset((u, w)))
            while cur not in is_branch:
                nxt = next(x for x in g[cur] if x != prev)
                seen.add(frozenset((cur, nxt)))
                prev, cur, length = cur, nxt, length + 1
            edges.append((u, cur, length))
    return branch, edges


def _rotation_count(g: Adjacency, branch: list[Hashable]) -> int:
    return math.prod(math.factorial(max(len(g[v]) - 1, 0)) for v in branch)


class _TooMany(Exception):
    """More rotation systems than :data:`EXACT_LIMIT`."""


def _minimal_faces(g: Adjacency) -> tuple[int, ...] | None:
    """Lexicographically smallest sorted face sizes over all embeddings; None if not planar.

    Raises :class:`_TooMany` when the rotation systems are too many to enumerate.
    """
    branch, edges = _suppressed(g)
    if not branch:  # a single cycle
        half = sum(len(v) for v in g.values()) // 4
        return (half, half)
    if _rotation_count(g, branch) > EXACT_LIMIT:
        raise _TooMany
    # half-edge h = 2 * edge + end; end 0 sits at edges[e][0], end 1 at edges[e][1]
    at: dict[object, list[int]] = {v: [] for v in branch}
    for e, (u, v, _) in enumerate(edges):
        at[u].append(2 * e)
        at[v].append(2 * e + 1)
    lengths = [length for _, _, length in edges]
    n_half = 2 * len(edges)
    faces_needed = len(edges) - len(branch) + 2
    choices = [[(hs[0], *perm) for perm in itertools.permutations(hs[1:])] for hs in at.values()]
    best: tuple[int, ...] | None = None
    nxt = [0] * n_half
    for rotation in itertools.product(*choices):
        for cyc in rotation:
            for k, h in enumerate(cyc):
                nxt[h] = cyc[(k + 1) % len(cyc)]
        visited = [False] * n_half
        sizes = []
        for start in range(n_half):
            if visited[start]:
                continue
            walk, h = 0, start
            while not visited[h]:
                visited[h] = True
                walk += lengths[h >> 1]
                h = nxt[h ^ 1]  # cross the edge, then turn to the next half-edge
            sizes.append(walk // 2)
            if len(sizes) > faces_needed:
                break
        if len(sizes) == faces_needed:
            key = tuple(sorted(sizes))
            if best is None or key < best:
                best = key
    return best


def _canonical_faces(g: Adjacency | Mechanism) -> tuple[int, ...] | None:
    """Face sizes of networkx's embedding of ``g`` (a mechanism's adjacency, or a part
    of it) relabelled in nauty's canonical order; None if not planar."""
    import networkx as nx

    if isinstance(g, Mechanism):
        g = g.adjacency

    from mjstruct.mechanism import LINK
    from mjstruct.structure.isomorphism import nauty_call

    nodes = list(g)
    if not nx.check_planarity(nx.Graph([(u, v) for u in g for v in g[u]]))[0]:
        return None  # before nauty: a large non-planar graph needs no canonical order
    links = [v for v in nodes if v[0] == LINK]
    joints = [v for v in nodes if v[0] != LINK]
    index = {v: i for i, v in enumerate(links)}
    index.update({v: len(links) + k for k, v in enumerate(joints)})
    n = len(links)
    lists = [[index[x] for x in g[j]] for j in joints]
    order = nauty_call("canon_label", n, lists)  # order[k] = original vertex placed k-th
    assert isinstance(order, list)
    rank = {v: k for k, v in enumerate(order)}
    cg = nx.Graph()
    cg.add_nodes_from(range(len(nodes)))
    cg.add_edges_from(
        sorted(tuple(sorted((rank[n + k], rank[x]))) for k, xs in enumerate(lists) for x in xs)
    )
    planar, emb = nx.check_planarity(cg)
    if not planar:
        return None
    seen: set[tuple[int, int]] = set()
    sizes = []
    for u, v in sorted(emb.edges()):
        if (u, v) not in seen:
            face = emb.traverse_face(u, v, mark_half_edges=seen)
            sizes.append(len(face) // 2)
    return tuple(sorted(sizes))


def without_parallel(g: Adjacency) -> tuple[dict[Any, tuple[Any, ...]], tuple[int, ...]]:
    """``g`` with every class of parallel chains (see the module text: paths of vertices
    of degree two with the same two ends and length) kept twice, and the size of the
    loop that each removed chain is in the minimal drawing (its length in edges).

    >>> g = {"a": ("x", "y", "z"), "b": ("x", "y", "z"), "x": ("a", "b"),
    ...      "y": ("a", "b"), "z": ("a", "b")}
    >>> without_parallel(g)
    ({'a': ('x', 'y'), 'b': ('x', 'y'), 'x': ('a', 'b'), 'y': ('a', 'b')}, (2,))
    """
    inner = {v for v, around in g.items() if len(around) == 2}
    seen: set[Any] = set()
    classes: dict[tuple[frozenset[Any], int], int] = {}
    dropped: set[Any] = set()
    faces: list[int] = []
    for u, around in g.items():
        if u in inner:
            continue
        for w in around:
            if w not in inner or w in seen:
                continue
            path, prev, cur = [], u, w
            while cur in inner:
                seen.add(cur)
                path.append(cur)
                a, b = g[cur]
                prev, cur = cur, (b if a == prev else a)
            if cur == u:
                continue  # a cycle through one vertex: not a chain between two
            key = (frozenset((u, cur)), len(path) + 1)
            # two of each class stay: they keep the class's loop in the graph, so a
            # chain whose only loops are parallel chains still has its faces
            classes[key] = classes.get(key, 0) + 1
            if classes[key] > 2:
                dropped.update(path)
                faces.append(len(path) + 1)
    if not dropped:
        return dict(g), ()
    out = {
        v: tuple(x for x in around if x not in dropped)
        for v, around in g.items()
        if v not in dropped
    }
    return out, tuple(faces)


def loop_assortment(m: Mechanism) -> LoopAssortment | None:
    """[L] of a planar chain (see the module text for which drawing); None if not planar."""
    expect_mechanism(m)
    g, parallel = without_parallel(m.adjacency)
    try:
        exact = _minimal_faces(g)
    except _TooMany:
        sizes = _canonical_faces(g)
        if sizes is None:
            return None
        return LoopAssortment(tuple(sorted(sizes + parallel)), "canonical")
    # exhaustive: no genus-0 rotation system means the graph is not planar
    return None if exact is None else LoopAssortment(tuple(sorted(exact + parallel)), "minimal")
