"""How large an enumeration will be, told before it starts.

This module owns the size estimates that keep ``mjstruct atlas`` from starting a job
that cannot finish: the number of chains of an atlas, or of Assur groups, from the
counts known exactly (the shipped catalogs and the longer runs recorded in
``docs/synthesis.md``), extended by the growth of their ratio.  The counts grow
faster than geometrically (F = 1 simple joints: x2, x8, x14, x30 per two links), so
the ratio itself is extrapolated by its last growth; from 4..10 links this predicts
5941 chains at 12 links, where the atlas finds 6856.  An estimate is for a decision
(start or ask), not a result.

Examples
--------
>>> chain_count_estimate(1, 12)        # known: counted once by the atlas
6856
>>> chain_count_estimate(1, 9)         # wrong parity: no chain has F = 1 and 9 links
0
>>> f"{chain_count_estimate(1, 16, mj=True):.1e}"
'2.1e+10'
"""

from __future__ import annotations

import math
from functools import cache

CHAIN_LIMIT = 1_000_000
"""Largest estimated number of chains (or Assur groups) enumerated without asking."""

# counts of longer runs (docs/synthesis.md), beyond the shipped catalogs:
# (F, multiple joints, fractionated included) -> {links: chains}
_LONGER_RUNS: dict[tuple[int, bool, bool], dict[int, int]] = {
    (1, False, False): {12: 6856, 14: 318162},
    (1, False, True): {12: 6856, 14: 318162},  # F = 1 chains are never fractionated
    (1, True, False): {12: 248203},
    (1, True, True): {12: 248203},
    (2, True, False): {11: 13065},
}

SMALL_LOOPS = 3
"""With no count to go by (F > 2), jobs of at most this many loops K still run: at
K = 3 the F = 2 atlas with MJs has 219 chains."""

ASSUR_GROUPS = {2: 1, 4: 2, 6: 10, 8: 173}
"""Assur groups with simple joints by number of links (``mjstruct atlas --assur``)."""


@cache
def _series(F: int, mj: bool, fractionated: bool) -> tuple[tuple[int, int], ...]:
    from mjstruct.synthesis.catalog import SHIPPED, read_catalog

    counts = dict(_LONGER_RUNS.get((F, mj, fractionated), {}))
    for f, n in SHIPPED:
        if f == F:
            records = read_catalog(f, n)
            counts[n] = sum(
                1
                for r in records
                if (mj or r["V"] == 0) and (fractionated or not r["fractionated"])
            )
    return tuple(sorted(counts.items()))


def extrapolate_count(known: tuple[tuple[int, int], ...], n: int, step: int) -> int | None:
    """The count at ``n`` from ``(links, count)`` known every ``step`` links (None: too few).

    >>> extrapolate_count(((4, 1), (6, 2), (8, 16), (10, 230)), 12, 2)  # atlas: 6856
    5941"""
    table = dict(known)
    if n in table:
        return table[n]
    if not known:
        return None
    last_n, last = known[-1]
    if n < last_n:
        return last  # smaller than a known job: small
    counts = [c for _, c in known if c > 0]
    if len(counts) < 2:
        return None
    ratio = counts[-1] / counts[-2]
    growth = max(ratio / (counts[-2] / counts[-3]), 1.0) if len(counts) >= 3 else 1.0
    log_count = math.log(last)
    for _ in range((n - last_n) // step):
        ratio *= growth
        log_count += math.log(ratio)
        if log_count > 690:  # beyond any float: the job is hopeless anyway
            break
    return round(math.exp(min(log_count, 690)))


def chain_count_estimate(
    F: int, n: int, mj: bool = False, fractionated: bool = False
) -> int | None:
    """About how many chains ``atlas(F, n, mj, fractionated)`` will list.

    Exact where the count is known; 0 when no chain exists (n - 1 - F must be an even
    number >= 2, K = (n - 1 - F) / 2 loops); None when there is nothing to go by
    (F > 2 beyond the catalogs).

    >>> chain_count_estimate(3, 9), chain_count_estimate(3, 12)
    (0, None)
    """
    if n - 1 - F < 2 or (n - 1 - F) % 2:
        return 0
    return extrapolate_count(_series(F, mj, fractionated), n, 2)


def assur_group_count_estimate(n: int) -> int | None:
    """About how many Assur groups of ``n`` links (simple joints) there are (0: odd n).

    >>> assur_group_count_estimate(8), assur_group_count_estimate(7)
    (173, 0)
    """
    if n % 2 or n < 2:
        return 0
    return extrapolate_count(tuple(sorted(ASSUR_GROUPS.items())), n, 2)


def size_text(count: int) -> str:
    """A count for a message: exact when small, in powers of ten when large.

    >>> size_text(6856), size_text(54_000_000)
    ('6856', '5.4e+07')
    """
    if count > 10**299:
        return "more than 1e+299"
    return str(count) if count < 100_000 else f"{count:.1e}"


def check_size(
    estimate: int | None, what: str, limit: int | None, parameter: str, loops: int = 0
) -> None:
    """Refuse a job whose estimate exceeds ``limit`` (None: no limit), naming ``parameter``.

    With no estimate, a job of at most :data:`SMALL_LOOPS` ``loops`` runs.

    >>> check_size(5_000_000, "chains", 10**6, "limit")
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: limit: about 5.0e+06 chains expected, more than 1000000
    """
    from mjstruct.errors import MechanismError

    if limit is None or (estimate is not None and estimate <= limit):
        return
    if estimate is None and loops <= SMALL_LOOPS:
        return
    if estimate is None:
        raise MechanismError(
            f"{parameter}: no estimate of the number of {what} ({loops} loops, more than "
            f"{SMALL_LOOPS})"
        )
    raise MechanismError(f"{parameter}: {_about(estimate)} {what} expected, more than {limit}")


def _about(count: int) -> str:
    text = size_text(count)
    return text if text.startswith("more") else f"about {text}"
