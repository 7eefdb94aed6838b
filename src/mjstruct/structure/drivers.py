"""The choice of driven joints: one check shared by every command and library entry.

This module owns what makes a list of drivers acceptable for a mechanism: every
driver is a joint id named once, and, for an analysis that moves the mechanism, the
drivers are as many as the mobility and independent of each other and of the
structure.  A driven joint fixes the relative position of its first two links: one
more bar between them in the (3,3) pebble game of :mod:`mjstruct.structure.pebble`.
A bar the game rejects is a *redundant* driver (its motion is already fixed by the
structure and the drivers before it); the pebbles left over after all drivers are
the DOF still free (*under-driven*).  The count alone is not enough: two drivers
on a two-DOF chain are one redundant and one missing when one of them sits inside a
rigid sub-chain; and a slider-crank driven at ``O1`` and ``A`` is over-constrained
(the slider is held by the welded rod and the guide), not under-driven.

References
----------
.. [1] A. Lee, I. Streinu, "Pebble game algorithms and sparse graphs", Discrete
   Mathematics, vol. 308, no. 8, pp. 1425–1437, 2008. [Lee & Streinu 2008] in
   docs/references.md.
.. [2] D. J. Jacobs, B. Hendrickson, "An algorithm for two-dimensional rigidity
   percolation: the pebble game", Journal of Computational Physics, vol. 137,
   pp. 346–365, 1997. [Jacobs & Hendrickson 1997] in docs/references.md.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> four_bar = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
...                             ("O2", [3, 0])], frame=0, drivers=["O1"])
>>> validate_drivers(four_bar)
('O1',)
>>> driver_balance(four_bar, ["O1", "B"]).redundant_drivers
('B',)
>>> validate_drivers(four_bar, ["O1", "A", "B"])  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: drivers: ... over-constrained (A, B already fixed ...
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from mjstruct.errors import MechanismError
from mjstruct.mechanism import checked_driver_ids

if TYPE_CHECKING:
    from mjstruct.mechanism import Mechanism
    from mjstruct.structure.pebble import PebbleGame, RigidityResult


@dataclass(frozen=True)
class DriverBalance:
    """How a choice of drivers meets the generic mobility of the chain.

    ``F_generic`` is the chain's pebble-game DOF (drivers ignored);
    ``redundant_drivers`` the drivers whose bar the game rejects, in the order given;
    ``dof_left`` the DOF still free with every driver held; ``structural_redundant``
    the redundant constraints of the chain itself (drivers ignored).
    """

    drivers: tuple[str, ...]
    F_generic: int
    redundant_drivers: tuple[str, ...]
    dof_left: int
    structural_redundant: int

    @property
    def balanced(self) -> bool:
        """True when the drivers place every link, none of them redundant."""
        return not self.redundant_drivers and self.dof_left == 0


def driver_balance(m: Mechanism, drivers: Iterable[str]) -> DriverBalance:
    """Play the pebble game on the chain, then one bar per driver (in the order given).

    ``drivers`` must be joint ids of ``m`` (see :func:`validate_drivers`).

    >>> from mjstruct.mechanism import Mechanism
    >>> slider_crank = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
    ...                                 ("P", [3, 0], "P")], frame=0)
    >>> b = driver_balance(slider_crank, ["O1", "A"])
    >>> b.redundant_drivers, b.dof_left
    (('A',), 0)
    """
    from mjstruct.structure.pebble import chain_joints, play_chain

    index = {x: k for k, x in enumerate(m.links)}
    game, _, chain = play_chain(m.links, chain_joints(m, index))
    return add_driver_bars(m, drivers, game, index, chain)[1]


def add_driver_bars(
    m: Mechanism,
    drivers: Iterable[str],
    game: PebbleGame,
    index: dict[str, int],
    chain: RigidityResult,
) -> tuple[list[tuple[str, str, list[int]]], DriverBalance]:
    """Add one bar per driver to ``game`` (played on the chain, bodies ``index``).

    Returns the welds ``(driver id, "weld", [a, b])`` and the balance; ``chain`` is the
    game's result on the chain alone.
    """
    drivers = tuple(drivers)
    welds: list[tuple[str, str, list[int]]] = []
    redundant = []
    for d in drivers:
        a, b = (index[x] for x in m.joint(d).links[:2])
        welds.append((d, "weld", [a, b]))
        if not game.add_edge(a, b):
            redundant.append(d)
    dof_left = chain.dof - (len(drivers) - len(redundant))
    balance = DriverBalance(drivers, chain.dof, tuple(redundant), dof_left, len(chain.redundant))
    return welds, balance


def validate_drivers(
    m: Mechanism,
    drivers: Iterable[str] | None = None,
    *,
    balance: bool = True,
    mobility: int | None = None,
) -> tuple[str, ...]:
    """The drivers (default: the mechanism's) as a tuple, or a one-line error.

    Parameters
    ----------
    m : the mechanism.
    drivers : driven joint ids; ``None`` takes ``m.drivers``.
    balance : when False, only check that every driver is a joint id named once (a
        file may name any drivers; the structural report states their balance).
        When True, also refuse no drivers, redundant drivers (over-constrained) and
        too few drivers (under-driven) against the generic mobility.
    mobility : the mechanism's DOF when known better than generically (the rank of
        the constraint Jacobian at a special geometry, such as a parallelogram
        linkage that the pebble game finds rigid).  When it differs from the generic
        DOF only the count of drivers is checked against it; independence is then
        the caller's (the Jacobian with the driver rows).

    Raises
    ------
    MechanismError
        naming the parameter ``drivers``.

    Examples
    --------
    >>> from mjstruct.mechanism import Mechanism
    >>> five_bar = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
    ...                             ("C", [3, 4]), ("O2", [4, 0])], frame=0)
    >>> validate_drivers(five_bar, ["O1", "O2"])
    ('O1', 'O2')
    >>> validate_drivers(five_bar, ["O1"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: drivers: ... under-driven (1 DOF left ...); generic F = 2, ...
    """
    if not balance:
        return checked_driver_ids(m, drivers)
    return checked_balance(m, drivers, mobility=mobility).drivers


def checked_balance(
    m: Mechanism, drivers: Iterable[str] | None = None, *, mobility: int | None = None
) -> DriverBalance:
    """:func:`validate_drivers` (with the balance), returning the :class:`DriverBalance`.

    For callers that need the balance as well (the Assur decomposition reads the
    chain's own redundant constraints from it).
    """
    return check_balance(driver_balance(m, checked_driver_ids(m, drivers)), mobility=mobility)


def check_balance(b: DriverBalance, *, mobility: int | None = None) -> DriverBalance:
    """Refuse a :class:`DriverBalance` the way :func:`validate_drivers` does, else return it.

    For callers that play the game once and judge its result more than once (the
    kinematic planner: the generic balance, then the Jacobian's ``mobility``).

    >>> from mjstruct.mechanism import Mechanism
    >>> four_bar = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
    ...                             ("O2", [3, 0])], frame=0)
    >>> check_balance(driver_balance(four_bar, ["O1"])).drivers
    ('O1',)
    """
    out = b.drivers
    F = b.F_generic if mobility is None else mobility
    if not out and F > 0:
        raise MechanismError(
            f"drivers: none given; the mechanism is under-driven (F = {F}: name {F} driven "
            f"joint{'s' if F != 1 else ''})"
        )
    if mobility is not None and mobility != b.F_generic:
        redundant = max(len(out) - mobility, 0)
        left = max(mobility - len(out), 0)
        why = f"mobility F = {mobility}, {_count(out)}"
        if redundant:
            raise MechanismError(
                f"drivers: with {', '.join(out)} the mechanism is over-constrained ({why})"
            )
        if left:
            raise MechanismError(
                f"drivers: with {', '.join(out)} the mechanism is under-driven ({why})"
            )
        return b
    parts = []
    if b.redundant_drivers:
        red = b.redundant_drivers
        them = "them" if len(red) > 1 else "it"
        parts.append(
            f"over-constrained ({', '.join(red)} already fixed by the structure and the "
            f"drivers before {them})"
        )
    if b.dof_left > 0:
        parts.append(f"under-driven ({b.dof_left} DOF left with the drivers held)")
    if parts:
        raise MechanismError(
            f"drivers: with {', '.join(out)} the mechanism is {' and '.join(parts)}; "
            f"generic F = {b.F_generic}, {_count(out)}"
        )
    return b


def _count(drivers: tuple[str, ...]) -> str:
    return f"{len(drivers)} driver{'s' if len(drivers) != 1 else ''}"
