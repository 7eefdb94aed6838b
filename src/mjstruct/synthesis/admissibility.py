"""The admissibility rule of structural synthesis: no rigid sub-chain.

A chain is *admissible* when every link has >= 2 joints, its link–joint graph is
connected, and for every set S of >= 2 links

    3(|S| - 1) - 2 Σ_joints max(k_j(S) - 1, 0) >= 1,

k_j(S) being the number of links of S on joint j (an MJ counts per joint, never per
expanded simple joint).  The left side is the mobility of the sub-chain S with all the
joints among its links; <= 0 means S is a structure (rigid) inside the chain.  This
also forbids two links sharing two joints (|S| = 2).

:func:`rigid_subchain` is the brute-force check over link subsets (exact, for chains of
up to about 20 links): the independent reference for the atlas's fast test, which
works on the contracted graph (see :mod:`mjstruct.synthesis.atlas`).

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> watt = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0]),
...                         ("e", [3, 4]), ("f", [4, 5]), ("g", [5, 0])])
>>> is_admissible(watt)
True
>>> braced = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 0]), ("d", [2, 3]),
...                           ("e", [3, 4]), ("f", [4, 0])])
>>> rigid_subchain(braced)
('0', '1', '2')
"""

from __future__ import annotations

from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.structure.mobility import dof_grubler, rigid_pair_count

MAX_BRUTE_FORCE_LINKS = 22


def subchain_mobility(m: Mechanism, links: set[str] | frozenset[str]) -> int:
    """3(|S| - 1) - 2 Σ_j max(k_j(S) - 1, 0) for the link set S."""
    c = sum(max(sum(1 for x in j.links if x in links) - 1, 0) for j in m.joints)
    return dof_grubler(len(links), c)


def rigid_subchain(m: Mechanism) -> tuple[str, ...] | None:
    """A smallest link set S (|S| >= 2) with sub-chain mobility <= 0, or None.

    Brute force over all link subsets (bitmask dynamic programme), so exact; refuses
    chains of more than :data:`MAX_BRUTE_FORCE_LINKS` links.
    """
    expect_mechanism(m)
    n = m.n
    if n > MAX_BRUTE_FORCE_LINKS:
        raise ValueError(f"brute force is limited to {MAX_BRUTE_FORCE_LINKS} links, got {n}")
    index = {x: i for i, x in enumerate(m.links)}
    masks = [sum(1 << index[x] for x in j.links) for j in m.joints]
    on_link: list[list[int]] = [[] for _ in range(n)]
    for mask in masks:
        for i in range(n):
            if mask >> i & 1:
                on_link[i].append(mask)
    # c[S] = Σ_j max(k_j(S) - 1, 0); adding link v to S' raises it by the joints of v
    # that already hold a link of S'.
    c = [0] * (1 << n)
    rigid_at = [rigid_pair_count(k) if k else 0 for k in range(n + 1)]
    best: tuple[int, int] | None = None
    for s in range(1, 1 << n):
        v = (s & -s).bit_length() - 1
        rest = s & (s - 1)
        c[s] = c[rest] + sum(1 for mask in on_link[v] if mask & rest)
        size = s.bit_count()
        if size >= 2 and c[s] >= rigid_at[size] and (best is None or size < best[0]):
            best = (size, s)
    if best is None:
        return None
    return tuple(m.links[i] for i in range(n) if best[1] >> i & 1)


def is_admissible(m: Mechanism) -> bool:
    """Every link on >= 2 joints and no rigid sub-chain (connectivity is checked by
    :class:`Mechanism` itself)."""
    expect_mechanism(m)
    if any(len(js) < 2 for js in m.link_joints.values()):
        return False
    return rigid_subchain(m) is None


def is_fractionated(m: Mechanism) -> bool:
    """Whether the link–joint graph has a cut vertex (a link or joint whose removal
    splits the chain).

    >>> from mjstruct.mechanism import Mechanism
    >>> two_loops = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0]),
    ...                              ("e", [0, 4]), ("f", [4, 5]), ("g", [5, 6]), ("h", [6, 0])])
    >>> is_fractionated(two_loops)
    True
    """
    expect_mechanism(m)
    import networkx as nx

    g = m.graph()
    return len(g) > 2 and not nx.is_biconnected(g)
