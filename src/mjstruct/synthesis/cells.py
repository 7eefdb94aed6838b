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
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from mjstruct.errors import MechanismError, expect_int
from mjstruct.structure.mobility import link_count

ENUMERATION_LIMIT = 20_000
"""Largest estimated number of chains :func:`code_counts` enumerates (beyond the shipped
catalogs) without being asked: a few seconds on one core of a 2-core machine."""

#: chains enumerated per second and worker, slowest and fastest measured (atlas with
#: MJs and fractionated chains, F = 1 at 10 and 12 links and F = 2 at 11 links: wall
#: time at load 7 on 2 cores, CPU time)
CHAINS_PER_SECOND = (2500, 20000)


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


def largest_parts(K: int, F: int | None = None) -> tuple[int, int]:
    """The largest excess (joints - 2) of one link, and (links - 2) of one MJ, in a chain
    of K loops; with F, of a fractionated chain of F DOF too.

    Removing a vertex of degree d from the link–joint graph leaves c components and
    K - d + c >= 0 loops, so d <= K + c.  Without a cut vertex c = 1: d <= K + 1 [1]_.
    A cut link splits the chain into c parts of F_p >= 1 each (admissible sub-chains)
    with F = Σ F_p, so c <= F; a cut joint gives F = Σ F_p + c - 1, so c <= (F + 1)/2.

    >>> largest_parts(3), largest_parts(3, F=2), largest_parts(3, F=3)
    ((2, 2), (3, 2), (4, 3))
    """
    if F is None:
        return K - 1, K - 1
    return K - 2 + max(F, 1), K - 2 + max((F + 1) // 2, 1)


def mj_assortments(K: int, V: int, largest: int | None = None) -> tuple[tuple[int, ...], ...]:
    """[MJA] = (ν2, ..., ν_K) of a cell: partitions of V into parts j - 1 <= K - 1.

    ``largest``: the largest part instead of K - 1 (MJs of a fractionated chain,
    :func:`largest_parts`); a tuple runs past ν_K only as far as its largest MJ.
    """
    top = K - 1 if largest is None else largest
    mjas = (_pad(_as_counts(p, top), K - 1) for p in _partitions(V, top))
    return tuple(sorted(mjas, reverse=True))


def cells(kmax: int) -> list[Cell]:
    """All cells (K, V) with 2 <= K <= kmax and 1 <= V <= 2(K - 1)."""
    expect_int(kmax, "kmax")
    return [
        Cell(K, V, mj_assortments(K, V)) for K in range(2, kmax + 1) for V in range(1, 2 * K - 1)
    ]


def link_assortments(
    K: int, V: int, F: int, fractionated: bool = False
) -> tuple[tuple[int, ...], ...]:
    """[LA] = (n2, n3, ..., n_(K+1)) with n = F + 1 + 2K links and Σ (i-2) n_i = 2(K-1) - V.

    Links with more than K + 1 joints are left out: such a link would be a cut vertex.
    With ``fractionated`` the cut links stay, up to K + F joints (:func:`largest_parts`);
    a tuple runs past n_(K+1) only as far as its largest link.

    >>> link_assortments(3, 1, 2)
    ((7, 1, 1), (6, 3, 0))
    >>> link_assortments(3, 1, 2, fractionated=True)  # [8001]: a swivel bucket drive
    ((8, 0, 0, 1), (7, 1, 1), (6, 3, 0))
    """
    n = link_count(F, K)
    excess = 2 * (K - 1) - V
    top = largest_parts(K, F if fractionated else None)[0]
    out = []
    for p in _partitions(excess, top):
        if len(p) <= n:
            out.append(_pad((n - len(p), *_as_counts(p, top)), K))
    return tuple(sorted(out, reverse=True))


def _pad(t: tuple[int, ...], length: int) -> tuple[int, ...]:
    """``t`` without trailing zeros, then padded with zeros to at least ``length``."""
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


@dataclass(frozen=True)
class Enumeration:
    """The part of :func:`code_counts` that the shipped catalogs do not hold: one atlas
    of ``n`` links (K loops) with about ``chains`` chains (None: no estimate)."""

    K: int
    n: int
    chains: int | None


def enumerations(F: int, kmax: int) -> list[Enumeration]:
    """The atlases :func:`code_counts` has to enumerate for F DOF and K <= ``kmax``.

    >>> enumerations(1, 4)           # K <= 4: 6..10 links, all shipped
    []
    >>> enumerations(1, 5)           # K = 5: 12 links, counted once by the atlas
    [Enumeration(K=5, n=12, chains=248203)]
    """
    from mjstruct.synthesis.catalog import SHIPPED
    from mjstruct.synthesis.job_size import chain_count_estimate

    out = []
    for K in range(2, kmax + 1):
        n = link_count(F, K)
        if (F, n) not in SHIPPED:
            out.append(Enumeration(K, n, chain_count_estimate(F, n, mj=True, fractionated=True)))
    return out


def check_enumeration_size(F: int, kmax: int, limit: int | None, workers: int = 1) -> None:
    """Refuse (``MechanismError`` naming ``limit``) a :func:`code_counts` job whose
    enumeration is estimated above ``limit`` chains, or cannot be estimated beyond
    K = 3; None: no limit.

    >>> check_enumeration_size(1, 5, 20_000)
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: limit: K = 5 (12 links) is not in the shipped \
catalogs: about 2.5e+05 chains to enumerate (more than 20000), about 12 to 99 s on \
one worker
    """
    from mjstruct.synthesis.job_size import SMALL_LOOPS, size_text

    if limit is None:
        return
    jobs = enumerations(F, kmax)
    unknown = [e for e in jobs if e.chains is None and e.K > SMALL_LOOPS]
    if unknown:
        e = unknown[0]
        raise MechanismError(
            f"limit: K = {e.K} ({e.n} links) is not in the shipped catalogs and there is "
            f"no estimate of its size for F = {F} (only up to K = {SMALL_LOOPS} runs unasked)"
        )
    total = sum(e.chains or 0 for e in jobs)
    if total <= limit:
        return
    where = ", ".join(f"K = {e.K} ({e.n} links)" for e in jobs)
    verb = "is" if len(jobs) == 1 else "are"
    raise MechanismError(
        f"limit: {where} {verb} not in the shipped catalogs: about {size_text(total)} "
        f"chains to enumerate (more than {limit}), {duration_text(total, workers)}"
    )


def duration_text(chains: int, workers: int = 1) -> str:
    """How long enumerating ``chains`` takes, as the range measured (CHAINS_PER_SECOND).

    >>> duration_text(248203)
    'about 12 to 99 s on one worker'
    >>> duration_text(2_000, 2), duration_text(10**10)
    ('about 0.05 to 0.4 s on 2 workers', 'about 5.8 to 46 days on one worker')
    """
    slow, fast = (chains / (rate * workers) for rate in CHAINS_PER_SECOND)
    unit, size = next(
        ((u, s) for u, s in (("days", 86400), ("h", 3600), ("min", 60)) if fast >= s),
        ("s", 1),
    )
    on = "one worker" if workers == 1 else f"{workers} workers"
    return f"about {fast / size:.2g} to {slow / size:.2g} {unit} on {on}"


def code_counts(
    F: int,
    kmax: int,
    fractionated: bool = False,
    workers: int = 1,
    with_sj: bool = False,
    limit: int | None = ENUMERATION_LIMIT,
    progress: Callable[[int, int], None] | None = None,
) -> list[CodeCount]:
    """Realisation counts of every (cell, [MJA], [LA]) for F DOF, K <= kmax.

    Uses the shipped catalog when (F, n) is shipped and not ``fractionated`` beyond
    it, else enumerates with :func:`mjstruct.synthesis.atlas.atlas` (``mj=True``).
    ``with_sj`` adds the simple-joint rows (V = 0).

    An enumeration estimated above ``limit`` chains (:func:`check_enumeration_size`)
    is refused before any work; ``limit=None`` runs it anyway. ``progress(done,
    total)`` is called after each task of each enumeration.
    """
    expect_int(F, "F", 0)
    expect_int(kmax, "kmax")
    expect_int(workers, "workers", 1)
    check_enumeration_size(F, kmax, limit, workers)
    out = []
    for K in range(2, kmax + 1):
        n = link_count(F, K)
        tally: Counter[tuple[int, tuple[int, ...], tuple[int, ...]]] = Counter()
        planar: Counter[tuple[int, tuple[int, ...], tuple[int, ...]]] = Counter()
        for LA, MJA, V, is_planar, is_frac in _chains(F, n, workers, progress):
            if is_frac and not fractionated:
                continue
            key = (V, _pad(MJA, K - 1), _pad(LA, K))
            tally[key] += 1
            planar[key] += bool(is_planar)
        mj_top = largest_parts(K, F if fractionated else None)[1]
        listed = set()
        for V in range(0 if with_sj else 1, 2 * K - 1):
            for mja in mj_assortments(K, V, mj_top) if V else ((0,) * (K - 1),):
                for la in link_assortments(K, V, F, fractionated):
                    key = (V, mja, la)
                    listed.add(key)
                    out.append(CodeCount(K, V, mja, la, tally[key], planar[key]))
        # every chain counted lies in a row: a row the equations miss would lose it
        lost = [key for key in tally if key not in listed and (with_sj or key[0])]
        if lost:
            V, mja, la = lost[0]
            raise RuntimeError(
                f"the cells table for F = {F}, K = {K} has no row for V = {V}, "
                f"[MJA] {list(mja)}, [LA] {list(la)}, which {tally[lost[0]]} chains have"
            )
    return out


def _chains(
    F: int, n: int, workers: int, progress: Callable[[int, int], None] | None = None
) -> list[tuple[Any, ...]]:
    from mjstruct.synthesis.catalog import SHIPPED, read_catalog

    if (F, n) in SHIPPED:
        recs = read_catalog(F, n)
        if recs:
            return [
                (tuple(r["LA"]), tuple(r["MJA"]), r["V"], r["planar"], r["fractionated"])
                for r in recs
            ]
    from mjstruct.synthesis.atlas import atlas

    # the size was checked for the whole job (check_enumeration_size)
    a = atlas(F, n, mj=True, fractionated=True, workers=workers, progress=progress, limit=None)
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
