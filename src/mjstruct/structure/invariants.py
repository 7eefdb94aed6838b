"""Structural invariants for isomorphism: [LA], [MJA], [L] and the link sets at each MJ.

[MJ structure 2020] decides whether two drawings are the same structure by comparing
these; :func:`seed_invariants` computes them (a historical name, kept for
compatibility).  They are necessary conditions only: equal invariants do not make two chains
isomorphic (``catalogs/examples/iso-counterexample-a.json`` and ``-b.json`` are such a
pair).  The exact test is :func:`mjstruct.structure.isomorphism.canonical_code`.

"Link sets at MJs": for every multiple joint, the sorted numbers of joints of the
links it joins (e.g. ``(2, 2, 3)``: two binary links and a ternary one); the list of
these over all MJs, sorted.

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
>>> m = Mechanism.build([("a", [0, 1]), ("b", [1, 2, 3]), ("c", [2, 0]), ("d", [3, 0])])
>>> inv = seed_invariants(m)
>>> inv.LA, inv.MJA, inv.mj_link_sets
((3, 1), (1,), ((2, 2, 2),))
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from mjstruct.mechanism import Mechanism, expect_mechanism


@dataclass(frozen=True)
class SeedInvariants:
    """The structural invariants of a chain (see :func:`seed_invariants`); ``loops`` is
    None for a non-planar chain."""

    LA: tuple[int, ...]
    MJA: tuple[int, ...]
    loops: tuple[int, ...] | None
    mj_link_sets: tuple[tuple[int, ...], ...]

    def to_dict(self) -> dict[str, Any]:
        return {
            "LA": list(self.LA),
            "MJA": list(self.MJA),
            "loops": None if self.loops is None else list(self.loops),
            "mj_link_sets": [list(s) for s in self.mj_link_sets],
        }


def mj_link_sets(m: Mechanism) -> tuple[tuple[int, ...], ...]:
    """For each MJ, the sorted joint counts of its links; sorted over the MJs."""
    degree = {link: len(js) for link, js in m.link_joints.items()}
    return tuple(
        sorted(tuple(sorted(degree[x] for x in j.links)) for j in m.joints if j.is_multiple)
    )


def seed_invariants(m: Mechanism) -> SeedInvariants:
    """The structural invariants of a chain: [LA], [MJA], [L] and the MJ link sets.

    These are the quantities [MJ structure 2020] compares to decide whether two
    drawings are the same structure ([L] as sorted face sizes, outer face included).
    Equal invariants are necessary for isomorphism, not sufficient: the exact test is
    :func:`mjstruct.structure.isomorphism.canonical_code`.  (The name is historical
    and kept for compatibility.)
    """
    expect_mechanism(m)
    from mjstruct.structure.assortments import link_assortment, mj_assortment
    from mjstruct.structure.loops import loop_assortment

    la = loop_assortment(m)
    return SeedInvariants(
        LA=tuple(link_assortment(m)),
        MJA=tuple(mj_assortment(m)),
        loops=None if la is None else tuple(la.sizes),
        mj_link_sets=mj_link_sets(m),
    )
