"""nauty calls for the many small graphs of an enumeration, without per-call overhead.

``pynauty.Graph`` checks and copies its adjacency on construction, which costs several
times nauty's own work on a graph of 30 vertices.  The C functions behind
``pynauty.certificate``, ``canon_label`` and ``autgrp`` read four attributes of the
object they are given; :class:`LightGraph` is just those attributes, so the atlas's
hot loops pay for nauty only.  The answers are the same as through
``pynauty.Graph`` (the tests compare them on every chain of the shipped atlases);
should a pynauty release no longer expose its C module, ``pynauty.Graph`` is used.

Examples
--------
>>> canon_label(light_graph(3, [[0, 1], [1, 2]]))  # a path: its middle link last
[0, 2, 1, 3, 4]
>>> triangle = light_graph(3, [[0, 1], [1, 2], [2, 0]])
>>> import pynauty
>>> from mjstruct.structure.isomorphism import nauty_graph
>>> certificate(triangle) == pynauty.certificate(nauty_graph(3, [[0, 1], [1, 2], [2, 0]]))
True
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Sequence
from typing import Any

import pynauty

try:  # the C module pynauty's own functions call
    from pynauty import nautywrap as _c
except ImportError:  # pragma: no cover - a pynauty without it: the public API
    _c = None


class LightGraph:
    """The attributes pynauty's C functions read: vertices, adjacency, colouring."""

    __slots__ = ("adjacency_dict", "directed", "number_of_vertices", "vertex_coloring")

    def __init__(
        self,
        order: int,
        adjacency: dict[int, list[int]],
        colours: list[Collection[int]],
    ) -> None:
        self.number_of_vertices = order
        self.directed = False
        self.adjacency_dict = adjacency
        self.vertex_coloring = colours


def light_graph(
    n: int, joints: Sequence[Sequence[int]], colours: Sequence[Collection[int]] | None = None
) -> LightGraph:
    """As :func:`mjstruct.structure.isomorphism.nauty_graph`: vertices ``0..n-1`` and
    one vertex ``n + k`` per joint k, adjacent to its links; ``colours`` partition the
    vertices (default links, joints); empty classes are dropped."""
    p = len(joints)
    if colours is None:
        colours = [range(n), range(n, n + p)]
    return LightGraph(
        n + p, {n + k: list(js) for k, js in enumerate(joints)}, [c for c in colours if c]
    )


def _public(g: LightGraph) -> Any:
    return pynauty.Graph(
        g.number_of_vertices,
        adjacency_dict=g.adjacency_dict,
        vertex_coloring=[set(c) for c in g.vertex_coloring],
    )


def certificate(g: LightGraph) -> bytes:
    """nauty's certificate (the canonical graph's adjacency rows), as pynauty's."""
    out: bytes = _c.graph_cert(g) if _c is not None else pynauty.certificate(_public(g))
    return out


def canon_label(g: LightGraph) -> list[int]:
    """nauty's canonical labelling: entry i is the vertex put at position i."""
    out: list[int] = _c.graph_canonlab(g) if _c is not None else pynauty.canon_label(_public(g))
    return out


def canon_labels(g: LightGraph, adjacencies: Iterable[dict[int, list[int]]]) -> list[list[int]]:
    """:func:`canon_label` of ``g`` with each adjacency in turn (the graphs of one
    order and colouring: one object, one C call each)."""
    if _c is None:  # pragma: no cover - a pynauty without its C module
        return [
            canon_label(LightGraph(g.number_of_vertices, a, g.vertex_coloring))
            for a in adjacencies
        ]
    label = _c.graph_canonlab
    out = []
    for adjacency in adjacencies:
        g.adjacency_dict = adjacency
        out.append(label(g))
    return out


def automorphism_generators(g: LightGraph) -> list[list[int]]:
    """Generators of the automorphism group (permutations of the vertices)."""
    out = _c.graph_autgrp(g) if _c is not None else pynauty.autgrp(_public(g))
    generators: list[list[int]] = out[0]
    return generators
