"""Exact isomorphism of chains and mechanisms by canonical labelling (pynauty).

The bipartite link–joint graph is coloured (links vs joints; at the ``"kinds"`` level
also R vs P joints; at the ``"mechanism"`` level also the frame and the driven joints)
and put in nauty's canonical form.  The canonical code is a short stable string: the
colour-class sizes and a SHA-256 digest of nauty's certificate, so two files get the
same code exactly when their coloured graphs are isomorphic (up to a 128-bit digest
collision).

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
from typing import Literal

import pynauty

from mjstruct.mechanism import Mechanism

Level = Literal["chain", "kinds", "mechanism"]
LEVELS: tuple[str, ...] = ("chain", "kinds", "mechanism")


def _colour_classes(
    m: Mechanism, level: str
) -> tuple[list[list[int]], dict[str, int], dict[str, int]]:
    link_ix = {link: i for i, link in enumerate(m.links)}
    joint_ix = {j.id: len(m.links) + k for k, j in enumerate(m.joints)}
    if level == "chain":
        classes = [list(link_ix.values()), list(joint_ix.values())]
    elif level in ("kinds", "mechanism"):
        mech = level == "mechanism"
        frame = [link_ix[m.frame]] if mech and m.frame is not None else []
        others = [i for link, i in link_ix.items() if i not in frame]
        drivers = set(m.drivers) if mech else set()
        classes = [frame, others]
        for driven in (True, False):
            for kind in ("R", "P"):
                classes.append(
                    [
                        joint_ix[j.id]
                        for j in m.joints
                        if j.kind == kind and (j.id in drivers) == driven
                    ]
                )
    else:
        raise ValueError(f"level must be one of {LEVELS}, got {level!r}")
    return classes, link_ix, joint_ix


def canonical_code(m: Mechanism, level: Level = "chain") -> str:
    """Stable string identifying ``m`` up to isomorphism at the given colour level.

    ``"chain"``: links and joints only (what structural synthesis and the catalogs
    use); ``"kinds"``: also R/P; ``"mechanism"``: also frame and drivers.
    """
    classes, link_ix, joint_ix = _colour_classes(m, level)
    adjacency: dict[int, list[int]] = {i: [] for i in range(len(link_ix) + len(joint_ix))}
    for j in m.joints:
        adjacency[joint_ix[j.id]] = [link_ix[x] for x in j.links]
    g = pynauty.Graph(
        len(adjacency),
        directed=False,
        adjacency_dict=adjacency,
        vertex_coloring=[set(c) for c in classes if c],
    )
    sizes = ".".join(str(len(c)) for c in classes)
    digest = hashlib.sha256(sizes.encode() + b"|" + pynauty.certificate(g)).hexdigest()[:32]
    prefix = {"chain": "c", "kinds": "k", "mechanism": "m"}[level]
    return f"{prefix}{len(m.links)}.{len(m.joints)}-{digest}"


def is_isomorphic(a: Mechanism, b: Mechanism, level: Level = "chain") -> bool:
    """Exact isomorphism test at the given colour level."""
    return canonical_code(a, level) == canonical_code(b, level)
