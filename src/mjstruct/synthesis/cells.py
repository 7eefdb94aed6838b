"""Synthesis cells (K, V) of [MJ structure 2020], Fig. 10, their assortments and
realisable codes.

A chain with multiple joints has K >= 2 loops and MJ factor 1 <= V <= 2(K - 1); the
pair (K, V) is its *cell*.  Inside a cell the [MJA] are the partitions of V into parts
j - 1 with 2 <= j <= K, and for F DOF the [LA] are the ways to give n = F + 1 + 2K
links Σ (i - 2) n_i = 2(K - 1) - V extra joints.  Counting the non-isomorphic
admissible chains of each (cell, [MJA], [LA]) gives the table of correct structural
codes (the "universal table" of [MJ structure 2020]): a code with count 0 has no admissible chain.

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
>>> len(cells(5))
20
>>> cells(3)[-1]
Cell(K=3, V=4, MJA=((4, 0), (2, 1), (0, 2)))
>>> link_assortments(K=2, V=1, F=1)
((5, 1),)
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from mjstruct.errors import expect_int
from mjstruct.structure.mobility import link_count


@dataclass(frozen=True)
class Cell:
    """One cell: K loops, MJ factor V, and its [MJA] as (ν2, ..., ν_K) tuples."""

    K: int
    V: int
    MJA: tuple[tuple[int, ...], ...]


def _partitions(total: int, largest: int) -> Iterator[list[int]]:
    """Partitions of ``total`` into parts <= ``largest`` (non-increasing lists)."""
    if total == 0:
        yield []
        return
    for part in range(min(total, largest), 0, -1):
        for rest in _partitions(total - part, part):
            yield [part, *rest]


def _as_counts(parts: list[int], length: int) -> tuple[int, ...]:
    c = Counter(parts)
    return tuple(c.get(k, 0) for k in range(1, length + 1))


def mj_assortments(K: int, V: int) -> tuple[tuple[int, ...], ...]:
    """[MJA] = (ν2, ..., ν_K) of a cell: partitions of V into parts j - 1 <= K - 1."""
    return tuple(sorted((_as_counts(p, K - 1) for p in _partitions(V, K - 1)), reverse=True))


def cells(kmax: int) -> list[Cell]:
    """All cells (K, V) with 2 <= K <= kmax and 1 <= V <= 2(K - 1)."""
    expect_int(kmax, "kmax")
    return [
        Cell(K, V, mj_assortments(K, V)) for K in range(2, kmax + 1) for V in range(1, 2 * K - 1)
    ]


def link_assortments(K: int, V: int, F: int) -> tuple[tuple[int, ...], ...]:
    """[LA] = (n2, n3, ..., n_(K+1)) with n = F + 1 + 2K links and Σ (i-2) n_i = 2(K-1) - V.

    Links with more than K + 1 joints are left out (such a link would be a cut vertex).
    """
    n = link_count(F, K)
    excess = 2 * (K - 1) - V
    out = []
    for p in _partitions(excess, K - 1):
        if len(p) <= n:
            out.append((n - len(p), *_as_counts(p, K - 1)))
    return tuple(sorted(out, reverse=True))


def _pad(t: tuple[int, ...], length: int) -> tuple[int, ...]:
    t = tuple(t)
    while t and t[-1] == 0:
        t = t[:-1]
    return t + (0,) * (length - len(t))


@dataclass(frozen=True)
class CodeCount:
    """How many non-isomorphic admissible chains realise (cell, [MJA], [LA])."""

    K: int
    V: int
    MJA: tuple[int, ...]
    LA: tuple[int, ...]
    count: int
    planar: int


def code_counts(
    F: int, kmax: int, fractionated: bool = False, workers: int = 1, with_sj: bool = False
) -> list[CodeCount]:
    """Realisation counts of every (cell, [MJA], [LA]) for F DOF, K <= kmax.

    Uses the shipped catalog when (F, n) is shipped and not ``fractionated`` beyond
    it, else enumerates with :func:`mjstruct.synthesis.atlas.atlas` (``mj=True``).
    ``with_sj`` adds the simple-joint rows (V = 0).
    """
    expect_int(F, "F", 0)
    expect_int(kmax, "kmax")
    expect_int(workers, "workers", 1)
    out = []
    for K in range(2, kmax + 1):
        n = link_count(F, K)
        tally: Counter[tuple[int, tuple[int, ...], tuple[int, ...]]] = Counter()
        planar: Counter[tuple[int, tuple[int, ...], tuple[int, ...]]] = Counter()
        for LA, MJA, V, is_planar, is_frac in _chains(F, n, workers):
            if is_frac and not fractionated:
                continue
            key = (V, _pad(MJA, K - 1), _pad(LA, K))
            tally[key] += 1
            planar[key] += bool(is_planar)
        for V in range(0 if with_sj else 1, 2 * K - 1):
            for mja in mj_assortments(K, V) if V else ((0,) * (K - 1),):
                for la in link_assortments(K, V, F):
                    key = (V, mja, la)
                    out.append(CodeCount(K, V, mja, la, tally[key], planar[key]))
    return out


def _chains(F: int, n: int, workers: int) -> list[tuple[Any, ...]]:
    from mjstruct.synthesis.catalog import SHIPPED, read_catalog

    if (F, n) in SHIPPED:
        recs = read_catalog(F, n)
        if recs:
            return [
                (tuple(r["LA"]), tuple(r["MJA"]), r["V"], r["planar"], r["fractionated"])
                for r in recs
            ]
    from mjstruct.synthesis.atlas import atlas

    a = atlas(F, n, mj=True, fractionated=True, workers=workers)
    return [(c.LA, c.MJA, c.V, c.planar, c.fractionated) for c in a.chains]


def code_table_markdown(F: int, kmax: int, workers: int = 1) -> str:
    """The table of correct structural codes (non-fractionated chains) as Markdown."""
    from mjstruct.structure.assortments import Assortment
    from mjstruct.structure.codes import full_code

    rows = code_counts(F, kmax, workers=workers, with_sj=True)
    lines = [
        "| K | V | n | Code* | chains | planar |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        code = full_code(Assortment(LA=r.LA, MJA=r.MJA), r.K)
        lines.append(f"| {r.K} | {r.V} | {sum(r.LA)} | `{code}` | {r.count} | {r.planar} |")
    return "\n".join(lines)
