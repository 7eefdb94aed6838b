"""Structural codes: Code = [LA]/V and Code* = [LA]/[MJA], written and parsed.

Writing follows [MJ structure 2020]: counts as digits, a two-digit leading count closed by a dot
(``[11.0001]/4``); [LA] is padded with zeros up to n_(K+1) and [MJA] up to ν_K (the
widest link and joint a K-loop chain may have), so ``[8110]/[3·0·0]`` for K = 4.
Counts of 10 or more elsewhere than the front are written with ``·`` between all
counts, which the parser also accepts (as it accepts spaces and commas).

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
>>> from mjstruct.structure.assortments import Assortment
>>> a = Assortment(LA=(11, 0, 0, 0, 1), MJA=(0, 0, 0, 1))
>>> structural_code(a, K=5), full_code(a, K=5)
('[11.0001]/4', '[11.0001]/[0·0·0·1]')
>>> parse_code("[10.011]/[1·0·0]")
Assortment(LA=(10, 0, 1, 1), MJA=(1,), n1=0)
>>> parse_code("[8110]/3").MJA
(3,)
"""

from __future__ import annotations

import re

from mjstruct.errors import MechanismError, expect_instance, expect_int
from mjstruct.structure.assortments import Assortment


def _pad(counts: tuple[int, ...], length: int) -> list[int]:
    c = list(counts)
    while c and c[-1] == 0:
        c.pop()
    return c + [0] * max(0, length - len(c))


def format_counts(counts: list[int], sep: str = "") -> str:
    """``[8110]``, ``[10.011]``, or ``[3·12·1]`` when a later count has two digits."""
    if not counts:
        return "[0]"
    if sep or any(c >= 10 for c in counts[1:]):
        return "[" + (sep or "·").join(map(str, counts)) + "]"
    head = str(counts[0]) + ("." if counts[0] >= 10 and len(counts) > 1 else "")
    return "[" + head + "".join(map(str, counts[1:])) + "]"


def _expect_code_args(a: object, K: object) -> None:
    from mjstruct.structure.assortments import Assortment

    expect_instance(a, "a", Assortment, "an Assortment (see parse_code or assortment)")
    expect_int(K, "K", 0)


def structural_code(a: Assortment, K: int) -> str:
    """Code = [LA]/V."""
    _expect_code_args(a, K)
    return f"{format_counts(_pad(a.LA, K))}/{a.V}"


def full_code(a: Assortment, K: int) -> str:
    """Code* = [LA]/[MJA]."""
    _expect_code_args(a, K)
    return f"{format_counts(_pad(a.LA, K))}/{format_counts(_pad(a.MJA, K - 1) or [0], '·')}"


_SEPARATED = re.compile(r"[\s,;·∙•*]+")


def _parse_counts(body: str, what: str) -> tuple[int, ...]:
    body = body.strip()
    if not body:
        raise MechanismError(f"code: empty {what}")
    if _SEPARATED.search(body):
        parts = [x for x in _SEPARATED.split(body) if x]
    elif "." in body:
        head, _, tail = body.partition(".")
        if "." in tail:
            raise MechanismError(
                f"code: {what} [{body}] has more than one dot; separate counts with ·"
            )
        parts = [head, *tail]
    else:
        parts = list(body)
    if not all(p.isdigit() for p in parts):
        raise MechanismError(f"code: {what} [{body}] must hold whole counts")
    return tuple(int(p) for p in parts)


def parse_code(code: str) -> Assortment:
    """Parse ``[LA]/V`` or ``[LA]/[MJA]`` (a bare V becomes V simple-MJs of j = 2).

    A bare V does not say which multiplicities make it up; ``[LA]/V`` is read as V
    joints of multiplicity 2, which gives the same K, F, S_L and rc.
    """
    if not isinstance(code, str):
        raise MechanismError(f"code: expected a string such as '[4 2]/0', got {code!r}")
    m = re.fullmatch(r"\s*\[([^\]]*)\]\s*/\s*(\[([^\]]*)\]|\d+)\s*", code)
    if not m:
        raise MechanismError(f"code: {code!r} is not of the form [LA]/V or [LA]/[MJA]")
    la = _parse_counts(m.group(1), "[LA]")
    if m.group(3) is not None:
        mja = _parse_counts(m.group(3), "[MJA]")
    else:
        v = int(m.group(2))
        mja = (v,) if v else ()
    la_t = tuple(_pad(la, 0))
    mja_t = tuple(_pad(mja, 0))
    return Assortment(LA=la_t, MJA=mja_t)
