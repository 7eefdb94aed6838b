"""Loops K, the AVC check, DOF F, redundant constraints rc and loop side sums S_L.

Each quantity [MJ structure 2020] gives two ways is computed both ways, so a report can show
that they agree.  Values are :class:`~fractions.Fraction` where an inconsistent code
can make them non-integral (K from an assortment whose parity is wrong).

λ is the dimension of the motion space (3 for planar mechanisms); with one-freedom
pairs F = λ(n - 1) - (λ - 1) p = (n - 1) - (λ - 1) K.

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
>>> a = Assortment(LA=(8, 1, 1), MJA=(3,))
>>> loops_by_formula(a), dof_by_loops(a.n, 4), dof_by_assortment(a)
(Fraction(4, 1), Fraction(1, 1), 1)
"""

from __future__ import annotations

from fractions import Fraction

from mjstruct.mechanism import Mechanism, components
from mjstruct.structure.assortments import Assortment


def loops_by_formula(a: Assortment) -> Fraction:
    """K = 1 + (V + Σ (i - 2) n_i) / 2."""
    return 1 + Fraction(a.V + a.excess, 2)


def cycle_rank(m: Mechanism) -> int:
    """Cycle rank of the bipartite link–joint graph: E - vertices + components."""
    edges = sum(len(j.links) for j in m.joints)
    return edges - (len(m.links) + len(m.joints)) + len(components(m))


def loops_by_joints(n: int, p: int) -> int:
    """K = p - n + 1 (Euler's formula on the simple-joint equivalents)."""
    return p - n + 1


def avc(a: Assortment, K: Fraction | int) -> Fraction:
    """Assembly verification criterion 2(K - 1) - (V + Σ (i - 2) n_i); 0 when consistent."""
    return 2 * (Fraction(K) - 1) - (a.V + a.excess)


def dof_by_loops(n: int, K: Fraction | int, lam: int = 3) -> Fraction:
    """F = (n - 1) - (λ - 1) K."""
    return (n - 1) - (lam - 1) * Fraction(K)


def dof_by_assortment(a: Assortment) -> int:
    """F = n2 - 3 - V - n4 - 2 n5 - 3 n6 - ... (planar, λ = 3)."""
    n2 = a.LA[0] if a.LA else 0
    beyond = sum((k - 1) * ni for k, ni in enumerate(a.LA) if k >= 2)
    return n2 - 3 - a.V - beyond + 2 * a.n1


def dof_grubler(n: int, p: int, lam: int = 3) -> int:
    """Chebyshev–Grübler F = λ(n - 1) - (λ - 1) p over simple-joint equivalents."""
    return lam * (n - 1) - (lam - 1) * p


def link_count(F: int, K: int) -> int:
    """n = F + 1 + 2K: the links of a chain with F DOF and K loops (planar, one-freedom).

    >>> link_count(1, 2)  # Watt and Stephenson chains
    6
    """
    return F + 1 + 2 * K


def rigid_pair_count(links: int) -> int:
    """The fewest simple-joint equivalents that make ``links`` links immobile by Grübler.

    A sub-chain of ``links`` links holding at least this many simple joints has
    Grübler mobility F <= 0 (its joints to the rest of the chain not counted).

    >>> [rigid_pair_count(k) for k in (2, 3, 4, 5)], dof_grubler(3, 3), dof_grubler(4, 4)
    ([2, 3, 5, 6], 0, 1)
    """
    return -(-3 * (links - 1) // 2)


def redundant_constraints(N: int, F: Fraction | int) -> Fraction:
    """rc = N - F: drivers beyond the mobility (negative: under-driven)."""
    return N - Fraction(F)


def redundant_constraints_by_assortment(a: Assortment, N: int) -> int:
    """rc from the assortment, (N + V + 3) - (n2 - n4 - 2 n5 - ...), planar.

    The second form of rc in [MJ structure 2020]; it equals N - F for a consistent code.
    """
    n2 = a.LA[0] if a.LA else 0
    beyond = sum((k - 1) * ni for k, ni in enumerate(a.LA) if k >= 2)
    return (N + a.V + 3) - (n2 - beyond + 2 * a.n1)


# the name this function had in 0.1.0, kept for scripts that import it
redundant_constraints_seed = redundant_constraints_by_assortment


def side_sum(a: Assortment) -> int:
    """S_L = Σ i n_i."""
    return a.sides


def side_sum_by_dof(F: Fraction | int, K: Fraction | int, V: int) -> Fraction:
    """S_L = 2(F + 3K) - V (planar)."""
    return 2 * (Fraction(F) + 3 * Fraction(K)) - V


def theorem_violations(a: Assortment, K: Fraction | int) -> list[str]:
    """The consistency conditions of [MJ structure 2020] that fail for this assortment and K."""
    K = Fraction(K)
    out = []
    if (a.V + a.excess) % 2:
        out.append(
            f"parity: V + Σ(i-2)n_i = {a.V + a.excess} is odd, so no closed chain has this code"
        )
    av = avc(a, K)
    if av != 0:
        out.append(
            f"AVC = {number_text(av)} != 0: "
            f"no closed chain with K = {number_text(K)} has this code"
        )
    if a.max_multiplicity > K:
        out.append(f"j <= K fails: a joint of multiplicity {a.max_multiplicity} needs K >= it")
    if a.V > 2 * (K - 1):
        out.append(f"V <= 2(K - 1) fails: V = {a.V} > {number_text(2 * (K - 1))}")
    if K < 0:
        out.append(f"K = {number_text(K)} < 0")
    return out


def number_text(x: Fraction | int | float) -> str:
    """A value for a report: an integer as is, a non-integral fraction as a decimal.

    >>> number_text(Fraction(4, 1)), number_text(Fraction(7, 2)), number_text(3)
    ('4', '3.5', '3')
    """
    f = Fraction(x)
    return str(f.numerator) if f.denominator == 1 else f"{float(f):g}"
