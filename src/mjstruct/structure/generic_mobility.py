"""Generic mobility: the exact DOF of a chain for generic geometry, from its graph alone.

This module owns the report part of the pebble game (:mod:`mjstruct.structure.pebble`):
the formula F = 3(n - 1) - 2p is only a lower bound, because a sub-chain can carry more
constraints than it needs (a rigid sub-chain with redundant pins) while the rest keeps
extra freedom.  :func:`generic_mobility` gives

* ``F_generic`` (the pebble-game DOF) next to ``F_formula``;
* the redundant constraints and *where* they are: the over-constrained sub-chains;
* rigid sub-chains (links that move as one body although joined by pins);
* with the drivers held: links locked to the frame, links still free (under-driven),
  and drivers whose motion the others or the structure already fix (over-driven).

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
>>> # five-bar 0-1-2-3-4 (F = 2) with a rigid, over-constrained double four-bar on link 4
>>> m = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]), ("C", [3, 4]),
...     ("O2", [4, 0]), ("D", [4, 5]), ("E", [5, 6]), ("G", [6, 7]), ("H", [7, 4]),
...     ("I", [5, 7])], frame=0, drivers=["O1"])
>>> g = generic_mobility(m)
>>> g.F_formula, g.F_generic, g.overconstrained
(1, 2, [(('4', '5', '6', '7'), 1)])
>>> g.free_links
('2', '3', '4', '5', '6', '7')
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.structure.assortments import simple_joint_count
from mjstruct.structure.drivers import add_driver_bars
from mjstruct.structure.mobility import dof_grubler
from mjstruct.structure.pebble import body_components, chain_joints, play_chain


@dataclass(frozen=True)
class GenericMobility:
    """Generic (pebble-game) mobility of a chain or mechanism; see :func:`generic_mobility`."""

    n: int
    p: int
    N: int
    F_formula: int
    F_generic: int
    redundant: int
    overconstrained: list[tuple[tuple[str, ...], int]]
    rigid_subchains: list[tuple[str, ...]]
    locked_links: tuple[str, ...] = ()
    free_links: tuple[str, ...] = ()
    redundant_drivers: tuple[str, ...] = ()
    F_driven: int | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def rc_generic(self) -> int:
        """N - F_generic: drivers beyond the generic mobility (negative: under-driven)."""
        return self.N - self.F_generic

    def to_dict(self) -> dict[str, Any]:
        """JSON keys added to the analyze report."""
        return {
            "F_generic": self.F_generic,
            "F_formula": self.F_formula,
            "rc_generic": self.rc_generic,
            "redundant_constraints": self.redundant,
            "overconstrained": [
                {"links": list(links), "redundant": k} for links, k in self.overconstrained
            ],
            "rigid_subchains": [list(c) for c in self.rigid_subchains],
            "locked_links": list(self.locked_links),
            "free_links": list(self.free_links),
            "redundant_drivers": list(self.redundant_drivers),
            "F_driven": self.F_driven,
        }

    def render(self) -> str:
        """A few text lines for the analyze report."""
        lines = [
            f"- generic mobility (pebble game): F_generic = {self.F_generic} "
            f"(formula F = {self.F_formula}, redundant constraints {self.redundant})"
        ]
        for links, k in self.overconstrained:
            lines.append(
                f"  - over-constrained sub-chain {{{', '.join(links)}}}: "
                f"{k} redundant constraint{'s' if k != 1 else ''}"
            )
        for c in self.rigid_subchains:
            if not any(set(c) <= set(links) for links, _ in self.overconstrained):
                lines.append(f"  - rigid sub-chain {{{', '.join(c)}}} moves as one body")
        if self.F_driven is not None:
            if self.redundant_drivers:
                lines.append(
                    f"  - over-driven: driver(s) {', '.join(self.redundant_drivers)} "
                    "already fixed by the structure or the other drivers"
                )
            if self.F_driven > 0:
                lines.append(
                    f"  - under-driven: {self.F_driven} DOF left with the drivers held; "
                    f"free links {{{', '.join(self.free_links)}}}"
                )
            if not self.redundant_drivers and self.F_driven == 0:
                lines.append("  - with the drivers held every link is placed (rc_generic = 0)")
        if self.locked_links:
            lines.append(f"  - immobile even without drivers: {{{', '.join(self.locked_links)}}}")
        lines += [f"  - {note}" for note in self.notes]
        return "\n".join(lines)


def generic_mobility(m: Mechanism) -> GenericMobility:
    """Generic DOF, redundant constraints and their place, locked and free links.

    With a frame, ``locked_links`` are the moving links rigid with the frame even
    without drivers; with drivers, each driver adds one bar that welds the joint's
    second link to its first, ``redundant_drivers`` are those bars the game rejects and
    ``free_links`` the links still movable with the drivers held.
    """
    expect_mechanism(m)
    index = {x: k for k, x in enumerate(m.links)}
    joints = chain_joints(m, index)
    game, _, res = play_chain(m.links, joints)
    p = simple_joint_count(m)
    F_formula = dof_grubler(m.n, p)
    comps = [
        tuple(m.links[w] for w in c) for c in body_components(game, m.n, joints) if len(c) >= 2
    ]
    comps.sort(key=lambda c: (-len(c), c))
    locked: tuple[str, ...] = ()
    if m.frame is not None:
        home = next((c for c in comps if m.frame in c), ())
        locked = tuple(x for x in home if x != m.frame)
    free: tuple[str, ...] = ()
    redundant_drivers: tuple[str, ...] = ()
    F_driven = None
    if m.frame is not None and m.drivers:
        welds, balance = add_driver_bars(m, m.drivers, game, index, res)
        redundant_drivers, F_driven = balance.redundant_drivers, balance.dof_left
        driven = body_components(game, m.n, joints + welds)
        home_k = next((c for c in driven if index[m.frame] in c), [index[m.frame]])
        free = tuple(x for x in m.links if index[x] not in home_k)
    return GenericMobility(
        n=m.n,
        p=p,
        N=len(m.drivers),
        F_formula=F_formula,
        F_generic=res.dof,
        redundant=len(res.redundant),
        overconstrained=list(res.regions),
        rigid_subchains=comps,
        locked_links=locked,
        free_links=free,
        redundant_drivers=redundant_drivers,
        F_driven=F_driven,
    )
