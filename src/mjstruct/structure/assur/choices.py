"""Choices of driven joints, ranked by the class of the mechanism they give.

This module owns :func:`driver_choices`: every choice of ``count`` driven joints among
the frame joints (or all joints), with its status from
:func:`mjstruct.structure.drivers.driver_balance` and, for the admissible ones, the
Assur decomposition.
"""

from __future__ import annotations

import itertools
from math import comb

from mjstruct.errors import MechanismError, expect_int
from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.structure.assur.decomposition import decompose
from mjstruct.structure.assur.results import DriverChoice
from mjstruct.structure.drivers import add_driver_bars
from mjstruct.structure.pebble import chain_joints, play_chain

STATUS_RANK = {"ok": 0, "under-driven": 1, "over-driven": 2, "over- and under-driven": 3}


def _status(redundant: int, dof_left: int) -> str:
    if redundant and dof_left:
        return "over- and under-driven"
    if redundant:
        return "over-driven"
    if dof_left:
        return "under-driven"
    return "ok"


def driver_choices(
    m: Mechanism, any_joint: bool = False, count: int | None = None, limit: int = 5000
) -> list[DriverChoice]:
    """Every choice of ``count`` driven joints (default: the generic DOF), lowest class first.

    Candidates are the frame joints, or every joint with ``any_joint``.  Admissible
    choices (status ``"ok"``) come first, by mechanism class; the others follow with
    their status (under- or over-driven).  ``redundant`` counts the redundant drivers
    and the chain's own redundant constraints.

    Examples
    --------
    >>> from mjstruct.mechanism import Mechanism
    >>> m = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
    ...                      ("O2", [3, 0])], frame=0)
    >>> [(c.drivers, c.status, c.mechanism_class) for c in driver_choices(m)]
    [(('O1',), 'ok', 2), (('O2',), 'ok', 2)]
    """
    expect_mechanism(m)
    if count is not None:
        expect_int(count, "count", 0)
    if m.frame is None:
        raise MechanismError("frame: choosing drivers needs a frame link")
    if count is None:
        from mjstruct.structure.pebble import generic_dof

        count = generic_dof(m)
    if count < 0:
        raise MechanismError(f"drivers: the chain is rigid (generic F = {count})")
    cands = [j.id for j in m.joints if any_joint or m.frame in j.links]
    total = comb(len(cands), count) if count <= len(cands) else 0
    if total > limit:
        raise MechanismError(
            f"limit: {total} choices of {count} among {len(cands)} joints exceed the limit {limit}"
        )
    out = []
    index = {x: k for k, x in enumerate(m.links)}
    chain_game, _, chain = play_chain(m.links, chain_joints(m, index))
    for combo in itertools.combinations(cands, count):
        # the chain's game is played once; each choice adds its driver bars to a copy
        _, b = add_driver_bars(m, combo, chain_game.copy(), index, chain)
        redundant = len(b.redundant_drivers) + b.structural_redundant
        status = _status(redundant, b.dof_left)
        if status == "ok":
            d = decompose(m, b)
            out.append(DriverChoice(combo, status, d.mechanism_class, d))
        else:
            out.append(DriverChoice(combo, status, None, None, max(b.dof_left, 0), redundant))
    out.sort(key=lambda c: (STATUS_RANK[c.status], c.mechanism_class or 0))
    return out
