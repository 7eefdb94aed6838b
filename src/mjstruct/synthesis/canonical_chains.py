"""The canonical form of a chain given as a link count and its joints.

Owns the chain's canonical code (the same as ``canonical_code(m, "chain")`` of
:mod:`mjstruct.structure.isomorphism`), its nauty certificate, and its joints with the
links renumbered in nauty's canonical order: what the atlas and the expansion of
contracted graphs key chains by.

Examples
--------
>>> a = canonical_chain(4, [[0, 1], [1, 2], [2, 3], [3, 0]])  # a four-bar loop
>>> b = canonical_chain(4, [[2, 0], [0, 3], [3, 1], [1, 2]])  # the same, relabelled
>>> a == b, a[1]
(True, ((0, 1), (0, 2), (1, 3), (2, 3)))
"""

from __future__ import annotations

from collections.abc import Sequence

import pynauty

from mjstruct.structure.isomorphism import (
    QUOTIENT_VERTICES,
    certificate_of,
    code_of,
    nauty_graph,
)

Joints = tuple[tuple[int, ...], ...]


def chain_code(n: int, joints: Sequence[Sequence[int]]) -> tuple[str, bytes, pynauty.Graph]:
    """Canonical code (as ``canonical_code(m, "chain")``), certificate and nauty graph."""
    p = len(joints)
    g = nauty_graph(n, joints)
    if n + p >= QUOTIENT_VERTICES:  # large: as canonical_code (twins, worker process)
        sizes, cert = certificate_of(n, joints, [range(n), range(n, n + p)])
        return code_of("c", n, p, sizes, cert), cert, g
    cert = pynauty.certificate(g)
    return code_of("c", n, p, f"{n}.{p}", cert), cert, g


def canonical_chain(n: int, joints: Sequence[Sequence[int]]) -> tuple[str, Joints]:
    """Canonical code and canonical joints (links in nauty's canonical order, sorted)."""
    code, _, g = chain_code(n, joints)
    return code, _canonical_joints(n, g)


def _canonical_joints(n: int, g: pynauty.Graph) -> tuple[tuple[int, ...], ...]:
    lab = pynauty.canon_label(g)  # lab[i] = original vertex at canonical position i
    where = {v: i for i, v in enumerate(lab)}
    joints = []
    for node in lab[n:]:
        joints.append(tuple(sorted(where[x] for x in g.adjacency_dict[node])))
    return tuple(sorted(joints))
