"""Willis' equation on each fundamental circuit, and the speed ratios of gear trains.

For a gear pair (a, b) whose axes sit on the carrier c (its transfer vertex), the
pitch circles roll:

    r_a (ω_a - ω_c) + s r_b (ω_b - ω_c) = 0,   s = +1 external, -1 internal,

(the ratio seen from the carrier is ``(ω_a - ω_c)/(ω_b - ω_c) = -s r_b / r_a``). The
relation is linear with constant coefficients, so the same holds for the angles turned
from the reference configuration and for the angular accelerations: the velocity and
acceleration analogs are exact. The radii may be replaced by the tooth numbers (one
module per mesh). Everything here is exact rational arithmetic.

References
----------
[Tsai & Freudenstein] in docs/references.md: one Willis equation per fundamental
circuit of an epicyclic gear train.

Examples
--------
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.io import read_mechanism
>>> m = read_mechanism(example_path("planetary-simple"))  # ring (100) in the frame
>>> speed_ratio(m, "1", "3")  # sun 20 to carrier: 1 + 100/20
Fraction(6, 1)
>>> speed_ratio(m, "1", "2")  # sun to planet (40 teeth): w2 = -1.5 wH
Fraction(-4, 1)
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from fractions import Fraction

from mjstruct.errors import MechanismError
from mjstruct.gear_pairs import GearPair, gear_pairs
from mjstruct.gears.structure import fundamental_circuit
from mjstruct.mechanism import Mechanism


def pitch_sizes(g: GearPair) -> tuple[Fraction, Fraction]:
    """The two gears' sizes in Willis' equation: tooth numbers, else pitch radii."""
    if g.teeth is not None:
        return Fraction(g.teeth[0]), Fraction(g.teeth[1])
    if g.radii is not None:
        return Fraction(g.radii[0]), Fraction(g.radii[1])
    raise MechanismError(f"gears: {g.id!r} needs 'teeth' or 'radii' for its ratio")


def willis_rows(m: Mechanism) -> list[dict[str, Fraction]]:
    """One row per gear pair: coefficients of the links' angular velocities."""
    rows = []
    for g in gear_pairs(m):
        c = fundamental_circuit(m, g).carrier
        ra, rb = pitch_sizes(g)
        s = -g.sign  # +1 external, -1 internal
        row: dict[str, Fraction] = {}
        for link, coef in ((g.links[0], ra), (g.links[1], s * rb), (c, -ra - s * rb)):
            row[link] = row.get(link, Fraction(0)) + coef
        rows.append(row)
    return rows


def angular_velocities(
    m: Mechanism, given: dict[str, Fraction | int], held: Iterable[str] = ()
) -> dict[str, Fraction]:
    """Every gear train link's angular velocity from Willis' equations, the frame and
    the ``held`` links at rest and the ``given`` ones prescribed.

    Raises MechanismError naming the links left free when the speeds are not
    determined, and when the prescribed speeds contradict the train.
    """
    fixed: dict[str, Fraction] = {x: Fraction(0) for x in held}
    if m.frame is not None:
        fixed[m.frame] = Fraction(0)
    for link, w in given.items():
        if link not in m.links:
            raise MechanismError(f"link: unknown link {link!r}")
        if link in fixed:
            raise MechanismError(f"link: {link!r} is held; it cannot be given a speed")
        fixed[link] = Fraction(w)
    rows = willis_rows(m)
    involved = sorted({x for r in rows for x in r} | set(fixed), key=m.links.index)
    unknown = [x for x in involved if x not in fixed]
    # rows: sum(coef * w_unknown) = -sum(coef * w_fixed)
    a = [[r.get(x, Fraction(0)) for x in unknown] for r in rows]
    b = [-sum((coef * fixed[x] for x, coef in r.items() if x in fixed), Fraction(0)) for r in rows]
    solution, free = _solve(a, b)
    if solution is None:
        raise MechanismError("held: the given and held speeds contradict the gear train")
    if free:
        names = ", ".join(unknown[k] for k in free)
        raise MechanismError(
            f"held: the speeds are not determined (links {names} stay free); hold or give "
            "more links"
        )
    out = dict(fixed)
    out.update(zip(unknown, solution, strict=True))
    return out


def speed_ratio(m: Mechanism, input: str, output: str, held: Sequence[str] = ()) -> Fraction:
    """``ω_input / ω_output`` with the frame and the ``held`` links at rest.

    Raises MechanismError when the ratio is not determined or the output stands still.
    """
    w = angular_velocities(m, {input: 1}, held)
    if output not in w:
        raise MechanismError(f"output: link {output!r} is not in the gear train")
    if w[output] == 0:
        raise MechanismError(f"output: link {output!r} stands still with these links held")
    return 1 / w[output]


def _solve(a: list[list[Fraction]], b: list[Fraction]) -> tuple[list[Fraction] | None, list[int]]:
    """Gauss–Jordan elimination in exact arithmetic: (a solution with the free unknowns
    at 0, or None when inconsistent; the indices of the free unknowns)."""
    rows = [[*row, rhs] for row, rhs in zip(a, b, strict=True)]
    ncols = len(a[0]) if a else 0
    pivots: list[int] = []
    r = 0
    for col in range(ncols):
        pivot = next((i for i in range(r, len(rows)) if rows[i][col] != 0), None)
        if pivot is None:
            continue
        rows[r], rows[pivot] = rows[pivot], rows[r]
        lead = rows[r][col]
        rows[r] = [x / lead for x in rows[r]]
        for i in range(len(rows)):
            if i != r and rows[i][col] != 0:
                f = rows[i][col]
                rows[i] = [x - f * y for x, y in zip(rows[i], rows[r], strict=True)]
        pivots.append(col)
        r += 1
    if any(row[-1] != 0 for row in rows[r:]):
        return None, []
    x = [Fraction(0)] * ncols
    for i, col in enumerate(pivots):
        x[col] = rows[i][-1]
    return x, [c for c in range(ncols) if c not in pivots]


def driven_rotations(m: Mechanism, drivers: Sequence[str]) -> dict[str, tuple[Fraction, ...]]:
    """The links whose rotation the drivers fix through Willis' equations, each with
    its rotation per unit of each driver coordinate (exact; the frame's are zeros).

    Rows: each gear pair's Willis equation, each revolute driver (its second link's
    rotation less its first's is the coordinate), each prismatic joint (its links turn
    together). A link left free by these rows (a gear on a linkage link) is not listed.

    >>> from mjstruct.catalog_files import example_path
    >>> from mjstruct.io import read_mechanism
    >>> r = driven_rotations(read_mechanism(example_path("planetary-simple")), ["O"])
    >>> {x: str(c[0]) for x, c in r.items()}
    {'0': '0', '1': '1', '3': '1/6', '2': '-1/4'}
    """
    import sympy

    rows = willis_rows(m)
    rhs: list[list[Fraction]] = [[Fraction(0)] * len(drivers) for _ in rows]
    for j in m.joints:
        driven = j.id in drivers and j.kind == "R"
        for other in j.links[1:] if j.kind == "P" or driven else ():
            rows.append({other: Fraction(1), j.links[0]: Fraction(-1)})
            rhs.append([Fraction(int(driven and j.id == d)) for d in drivers])
            if driven:
                break  # the coordinate is the second link's rotation
    unknown = [x for x in m.links if x != m.frame]
    a = [[r.get(x, Fraction(0)) for x in unknown] for r in rows]
    null = (
        sympy.Matrix(a).nullspace()
        if a
        else [sympy.eye(len(unknown))[:, k] for k in range(len(unknown))]
    )
    loose = {unknown[i] for v in null for i in range(len(unknown)) if v[i] != 0}
    out: dict[str, list[Fraction]] = {x: [] for x in unknown if x not in loose}
    for d in range(len(drivers)):
        solution, _ = _solve(a, [r[d] for r in rhs])
        if solution is None:
            raise MechanismError("drivers: the drivers contradict the gear train's ratios")
        for x, w in zip(unknown, solution, strict=True):
            if x in out:
                out[x].append(w)
    result = {x: tuple(c) for x, c in out.items()}
    if m.frame is not None:
        result = {m.frame: (Fraction(0),) * len(drivers), **result}
    return result
