"""Link assortment [LA], MJ assortment [MJA], MJ factor V and simple-joint count p.

:class:`Assortment` is the code-level view of a chain (what a structural code says);
:func:`assortment` reads it off a mechanism's graph.

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
>>> a = assortment(m)
>>> a.LA, a.MJA, a.V
((3, 1), (1,), 1)
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from mjstruct.mechanism import Mechanism, expect_mechanism


@dataclass(frozen=True)
class Assortment:
    """Counts of links by joint number and of joints by multiplicity.

    ``LA[k]`` is n_(k+2), the number of links with k + 2 joints; ``MJA[k]`` is
    ν_(k+2), the number of joints of multiplicity k + 2 (joining k + 3 links).
    ``n1`` counts links with a single joint (open chains only).
    """

    LA: tuple[int, ...]
    MJA: tuple[int, ...] = ()
    n1: int = 0

    @property
    def n(self) -> int:
        """Number of links, frame included."""
        return self.n1 + sum(self.LA)

    @property
    def V(self) -> int:
        """MJ factor V = Σ (j - 1) ν_j."""
        return sum((k + 1) * nu for k, nu in enumerate(self.MJA))

    @property
    def excess(self) -> int:
        """Σ (i - 2) n_i over all links (the joints beyond binary)."""
        return sum(k * ni for k, ni in enumerate(self.LA)) - self.n1

    @property
    def sides(self) -> int:
        """Σ i n_i: every link counted once per joint it takes part in."""
        return sum((k + 2) * ni for k, ni in enumerate(self.LA)) + self.n1

    @property
    def max_multiplicity(self) -> int:
        """The largest joint multiplicity j (1 for a simple-joint chain)."""
        nz = [k for k, nu in enumerate(self.MJA) if nu]
        return nz[-1] + 2 if nz else 1


def _counts(values: list[int], start: int) -> tuple[int, ...]:
    c = Counter(values)
    top = max((v for v in c if v >= start), default=start - 1)
    return tuple(c.get(i, 0) for i in range(start, top + 1))


def link_assortment(m: Mechanism) -> list[int]:
    """[LA] = [n2, n3, ...]: links counted by their number of joints.

    >>> from mjstruct.mechanism import Mechanism
    >>> link_assortment(Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 0])]))
    [3]
    """
    expect_mechanism(m)
    return list(_counts([len(v) for v in m.link_joints.values()], 2))


def mj_assortment(m: Mechanism) -> list[int]:
    """[MJA] = [ν2, ν3, ...]: multiple joints counted by multiplicity j = m - 1."""
    expect_mechanism(m)
    return list(_counts([j.multiplicity for j in m.joints], 2))


def mj_factor(m: Mechanism) -> int:
    """V = Σ (j - 1) over all joints (0 for a simple-joint chain)."""
    expect_mechanism(m)
    return sum(j.multiplicity - 1 for j in m.joints)


def simple_joint_count(m: Mechanism) -> int:
    """p = Σ j: the number of simple joints the chain's joints are equivalent to."""
    expect_mechanism(m)
    return sum(j.multiplicity for j in m.joints)


def assortment(m: Mechanism) -> Assortment:
    """The code-level view of ``m``."""
    expect_mechanism(m)
    degrees = [len(v) for v in m.link_joints.values()]
    return Assortment(
        LA=tuple(link_assortment(m)),
        MJA=tuple(mj_assortment(m)),
        n1=degrees.count(1),
    )
