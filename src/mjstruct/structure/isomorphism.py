"""Exact isomorphism of chains and mechanisms by canonical labelling (pynauty).

The bipartite link–joint graph is coloured (links vs joints; at the ``"kinds"`` level
also R vs P joints; at the ``"mechanism"`` level also the frame and the driven joints)
and put in nauty's canonical form.  The canonical code is a short stable string: the
colour-class sizes and a SHA-256 digest of nauty's certificate, so two files get the
same code exactly when their coloured graphs are isomorphic (up to a 128-bit digest
collision).

References
----------
.. [1] B. D. McKay, A. Piperno, "Practical graph isomorphism, II", Journal of
   Symbolic Computation, vol. 60, pp. 94–112, 2014. [McKay & Piperno 2014] in
   docs/references.md.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> a = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0])])
>>> b = Mechanism.build(
...     [("x", ["p", "q"]), ("y", ["r", "q"]), ("z", ["s", "p"]), ("w", ["r", "s"])]
... )
>>> canonical_code(a) == canonical_code(b)
True
"""

from __future__ import annotations

import hashlib
from collections.abc import Collection, Sequence
from typing import Literal

import pynauty

from mjstruct.errors import MechanismError
from mjstruct.mechanism import Mechanism, expect_mechanism

Level = Literal["chain", "kinds", "mechanism"]
LEVELS: tuple[str, ...] = ("chain", "kinds", "mechanism")


def nauty_graph(
    n: int, joints: Sequence[Sequence[int]], colours: Sequence[Collection[int]] | None = None
) -> pynauty.Graph:
    """The nauty graph of an incidence structure: every structure of the package.

    Vertices ``0..n-1`` are the links (or the vertices of a multigraph), vertex
    ``n + k`` is joint ``k`` (or edge ``k``), adjacent to the vertices it joins; a
    joint of one vertex is a loop of a multigraph.  ``colours`` partition the vertices
    (default: links, joints); empty classes are dropped.

    >>> g = nauty_graph(3, [[0, 1], [1, 2], [2, 0]])
    >>> g.number_of_vertices, len(pynauty.autgrp(g)[0])  # a triangle: 3 generators
    (6, 2)
    """
    p = len(joints)
    if colours is None:
        colours = [range(n), range(n, n + p)]
    return pynauty.Graph(
        n + p,
        directed=False,
        adjacency_dict={n + k: list(js) for k, js in enumerate(joints)},
        vertex_coloring=[set(c) for c in colours if c],
    )


def code_of(level_prefix: str, n: int, p: int, sizes: str, certificate: bytes) -> str:
    """The canonical code string: prefix, counts and a 128-bit digest of the certificate.

    ``sizes`` are the colour-class sizes (they make the certificate comparable).
    """
    digest = hashlib.sha256(sizes.encode() + b"|" + certificate).hexdigest()[:32]
    return f"{level_prefix}{n}.{p}-{digest}"


def colour_classes(m: Mechanism, level: str) -> list[list[int]]:
    """Vertex colour classes of ``m`` at ``level`` (links first, then joints, file order).

    >>> from mjstruct.mechanism import Mechanism
    >>> m = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 0], "P")], frame=0)
    >>> colour_classes(m, "chain"), colour_classes(m, "mechanism")
    ([[0, 1, 2], [3, 4, 5]], [[0], [1, 2], [], [], [3, 4], [5]])
    """
    n = len(m.links)
    link_ix = {link: i for i, link in enumerate(m.links)}
    if level == "chain":
        return [list(range(n)), list(range(n, n + len(m.joints)))]
    if level not in ("kinds", "mechanism"):
        raise MechanismError(f"level: must be one of {', '.join(LEVELS)}, got {level!r}")
    mech = level == "mechanism"
    frame = [link_ix[m.frame]] if mech and m.frame is not None else []
    others = [i for i in range(n) if i not in frame]
    drivers = set(m.drivers) if mech else set()
    classes = [frame, others]
    for driven in (True, False):
        for kind in ("R", "P"):
            classes.append(
                [
                    n + k
                    for k, j in enumerate(m.joints)
                    if j.kind == kind and (j.id in drivers) == driven
                ]
            )
    return classes


def link_joint_lists(m: Mechanism) -> list[list[int]]:
    """Each joint of ``m`` as the indices of its links (the input of :func:`nauty_graph`)."""
    link_ix = {link: i for i, link in enumerate(m.links)}
    return [[link_ix[x] for x in j.links] for j in m.joints]


def canonical_code(m: Mechanism, level: Level = "chain") -> str:
    """Stable string identifying ``m`` up to isomorphism at the given colour level.

    ``"chain"``: links and joints only (what structural synthesis and the catalogs
    use); ``"kinds"``: also R/P; ``"mechanism"``: also frame and drivers.
    """
    expect_mechanism(m)
    classes = colour_classes(m, level)
    g = nauty_graph(len(m.links), link_joint_lists(m), classes)
    sizes = ".".join(str(len(c)) for c in classes)
    prefix = {"chain": "c", "kinds": "k", "mechanism": "m"}[level]
    return code_of(prefix, len(m.links), len(m.joints), sizes, pynauty.certificate(g))


def is_isomorphic(a: Mechanism, b: Mechanism, level: Level = "chain") -> bool:
    """Exact isomorphism test at the given colour level."""
    expect_mechanism(a, "a")
    expect_mechanism(b, "b")
    return canonical_code(a, level) == canonical_code(b, level)
