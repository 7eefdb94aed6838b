"""Atlas of Assur groups with simple joints: every group of n links, with its class.

Definition used (see ``docs/synthesis.md``): a group is n links, p internal simple
joints between them and e external pairs (each on one group link, attaching it to a
link of known position), with 3n = 2(p + e), and every proper non-empty subset S of
its links keeps mobility >= 1 relative to the known links:
``3|S| - 2(p(S) + e(S)) >= 1``; and no set of >= 2 group links is a rigid sub-chain on
its own.  (So: zero DOF once the external pairs are fixed, minimal, no redundant part.)

Identifying all external attachments with one "ground" link G turns a group into a
*minimal rigid chain* of n + 1 links (F = 0 and every proper sub-chain mobile) with G
marked; so groups are the vertex orbits of those chains.  The chains are enumerated
like the atlas (contracted graphs, binary links distributed, nauty certificates) with
the exact proper-subset test done by brute force (n is small).  A link has at most one
external pair (two would fix it).  Class: Artobolevsky's, as in
:func:`mjstruct.structure.assur.group_class`; order = e.

Examples
--------
>>> [(g.klass, g.order) for g in assur_atlas(2)]
[(2, 2)]
>>> sorted((g.klass, g.order) for g in assur_atlas(4))
[(3, 3), (4, 2)]
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pynauty

from mjstruct.errors import MechanismError, expect_int
from mjstruct.structure.isomorphism import nauty_graph
from mjstruct.structure.mobility import rigid_pair_count
from mjstruct.synthesis.contracted import Vertex, contracted_graphs, degree_sequences
from mjstruct.synthesis.job_size import CHAIN_LIMIT, assur_group_count_estimate, check_size


@dataclass(frozen=True)
class AssurGroupChain:
    """One Assur group: links 0..n-1, internal joints, links with an external pair."""

    canonical: str
    n: int
    joints: tuple[tuple[int, ...], ...]
    external: tuple[int, ...]
    klass: int
    order: int

    def to_dict(self) -> dict[str, Any]:
        return {
            "canonical": self.canonical,
            "n": self.n,
            "joints": [list(j) for j in self.joints],
            "external": list(self.external),
            "class": self.klass,
            "order": self.order,
        }


def _proper_subsets_mobile(n: int, joints: list[list[int]]) -> bool:
    """No proper subset of >= 2 links with mobility <= 0 (brute force, simple joints)."""
    adj = [0] * n
    for a, b in joints:
        adj[a] |= 1 << b
        adj[b] |= 1 << a
    full = (1 << n) - 1
    edges = [0] * (1 << n)
    rigid_at = [rigid_pair_count(k) if k else 0 for k in range(n + 1)]
    for s in range(1, full):
        v = (s & -s).bit_length() - 1
        rest = s & (s - 1)
        edges[s] = edges[rest] + (adj[v] & rest).bit_count()
        size = s.bit_count()
        if size >= 2 and edges[s] >= rigid_at[size]:
            return False
    return True


def _minimal_rigid_task(task: tuple[tuple[Vertex, ...], int]) -> list[list[list[int]]]:
    from mjstruct.synthesis.atlas import compositions, expand
    from mjstruct.synthesis.canonical_chains import chain_code
    from mjstruct.synthesis.distributions import admissible_distributions, edge_minimum

    sequence, n = task
    out = []
    n_branch = sum(1 for c, _ in sequence if c == "L")
    for cg in contracted_graphs(sequence, fractionated=False):
        minima = [edge_minimum(cg, u, v) for u, v in cg.edges]
        dist = compositions(n - n_branch, minima)
        if not len(dist):
            continue
        dist = dist[admissible_distributions(cg, dist, threshold=0)]
        seen: set[bytes] = set()
        for row in dist.tolist():
            nn, joints = expand(cg, row)
            _, cert, _ = chain_code(nn, joints)
            if cert not in seen and _proper_subsets_mobile(nn, joints):
                seen.add(cert)
                out.append(joints)
    return out


def minimal_rigid_chains(m: int, workers: int = 1) -> list[list[list[int]]]:
    """Simple-joint chains of m links with F = 0 whose proper sub-chains all move."""
    if m == 3:
        return [[[0, 1], [1, 2], [2, 0]]]
    if (m - 1) % 2 or m < 3:
        return []
    from mjstruct.synthesis.parallel import run_tasks

    tasks = [(seq, m) for seq in degree_sequences((m - 1) // 2, mj=False)]
    return [c for chains in run_tasks(_minimal_rigid_task, tasks, workers) for c in chains]


def assur_atlas(
    n: int, workers: int = 1, limit: int | None = CHAIN_LIMIT
) -> list[AssurGroupChain]:
    """All Assur groups of n links (simple joints), sorted by (class, order, canonical).

    Refuses (``MechanismError``) when about more than ``limit`` groups are expected
    (None: no limit).
    """
    expect_int(n, "n")
    expect_int(workers, "workers")
    from mjstruct.mechanism import Mechanism
    from mjstruct.structure.assur import group_class
    from mjstruct.structure.isomorphism import canonical_code

    if n < 1:
        raise MechanismError(f"n: need at least one link, got {n}")
    estimate = assur_group_count_estimate(n)
    check_size(estimate, f"Assur groups of {n} links", limit, "limit")
    out = []
    for joints in minimal_rigid_chains(n + 1, workers):
        m = n + 1
        g = nauty_graph(m, joints)
        orbits = pynauty.autgrp(g)[3]
        for ground in sorted({orbits[v] for v in range(m)}):
            keep = [v for v in range(m) if v != ground]
            index = {v: i for i, v in enumerate(keep)}
            internal = sorted(
                tuple(sorted(index[x] for x in js)) for js in joints if ground not in js
            )
            external = sorted(index[x] for js in joints if ground in js for x in js if x != ground)
            mech = Mechanism.build(
                [(f"J{k}", [str(x) for x in js]) for k, js in enumerate(joints)],
                frame=str(ground),
            )
            code = canonical_code(mech, "mechanism")
            klass = group_class(list(range(n)), internal)
            out.append(
                AssurGroupChain(code, n, tuple(internal), tuple(external), klass, len(external))
            )
    out.sort(key=lambda a: (a.klass, a.order, a.canonical))
    return out
