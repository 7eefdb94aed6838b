"""Structure of geared linkages: DOF with higher pairs, the equivalent lower-pair chain,
redundant constraints by rank, fundamental circuits and transfer vertices, and a
canonical code that tells pair types apart.

- DOF by Chebyshev–Grübler with higher pairs: ``F = 3 (n - 1) - 2 p5 - p4``, p5 the
  lower pairs (a joint of m links counts m - 1), p4 the gear pairs.
- The equivalent lower-pair chain replaces each mesh by a binary link joined by
  revolute joints to the two gear links (the link joining the meshing profiles'
  centres of curvature, the classical replacement). It has the same F; the structural
  numbers of docs/structure.md ([LA], [MJA], K, codes, Assur groups) are those of
  this chain.
- Redundant constraints by rank: the velocity constraints at the reference
  configuration (each lower pair's, and each mesh's rolling of the pitch circles at
  the pitch point) have rank r; F = 3 (n - 1) - r and rc = rows - r.
- Fundamental circuits [Tsai & Freudenstein]: each gear pair with the turning pairs
  through the carrier that holds both gears' axes, its transfer vertex.

References
----------
[Tsai & Freudenstein] in docs/references.md: the graph of an epicyclic gear train,
fundamental circuits, transfer vertices.
[Artobolevsky 1988] in docs/references.md: Chebyshev's formula with higher pairs and
their replacement by lower pairs.

Examples
--------
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.io import read_mechanism
>>> s = geared_structure(read_mechanism(example_path("planetary-simple")))
>>> (s.n, s.p5, s.p4, s.F, s.F_rank, s.rc)
(4, 3, 2, 1, 1, 0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.gear_pairs import GearPair, gear_pairs
from mjstruct.mechanism import Joint, Mechanism
from mjstruct.structure.isomorphism import (
    Level,
    certificate_of,
    code_of,
    colour_classes,
    link_joint_lists,
)

#: relative rank threshold of the velocity constraint matrix (its singular values
#: scaled by the largest)
RANK_TOLERANCE = 1e-9


@dataclass(frozen=True)
class FundamentalCircuit:
    """A gear pair, the carrier (transfer vertex) that holds both gears' axes, and the
    joints on those axes (the circuit's turning pairs)."""

    gear: GearPair
    carrier: str
    axes: tuple[str, str]


@dataclass(frozen=True)
class GearedStructure:
    """DOF of a geared linkage two ways, and its equivalent lower-pair chain."""

    n: int
    p5: int
    p4: int
    F: int
    F_rank: int | None
    rc: int | None
    equivalent: Mechanism
    circuits: tuple[FundamentalCircuit, ...]


def geared_structure(m: Mechanism) -> GearedStructure:
    """DOF with higher pairs, rank-based DOF and redundant constraints (None without
    the geometry), the equivalent chain and the fundamental circuits of ``m``."""
    gears = gear_pairs(m)
    p5 = sum(j.multiplicity for j in m.joints)
    F = 3 * (m.n - 1) - 2 * p5 - len(gears)
    rank = constraint_rank(m)
    F_rank = rc = None
    if rank is not None:
        r, rows = rank
        F_rank, rc = 3 * (m.n - 1) - r, rows - r
    circuits = tuple(fundamental_circuit(m, g) for g in gears if g.kind != "rack")
    return GearedStructure(m.n, p5, len(gears), F, F_rank, rc, equivalent_chain(m), circuits)


def equivalent_chain(m: Mechanism) -> Mechanism:
    """``m`` with each mesh replaced by a binary link ``mesh:<id>`` and its revolute
    joints ``mesh:<id>:<link>`` to the two gear links (the frame and drivers kept).

    >>> from mjstruct.catalog_files import example_path
    >>> from mjstruct.io import read_mechanism
    >>> e = equivalent_chain(read_mechanism(example_path("planetary-simple")))
    >>> e.n, len(e.joints), [j.id for j in e.joints][-2:]
    (6, 6, ['mesh:g20:2', 'mesh:g20:0'])
    """
    joints = list(m.joints)
    links = list(m.links)
    taken = set(links) | {j.id for j in joints}
    for g in gear_pairs(m):
        bar = f"mesh:{g.id}"
        new = [bar] + [f"{bar}:{x}" for x in g.links]
        if taken & set(new):
            raise MechanismError(f"gears: id {bar!r} is taken by a link or joint of the file")
        taken |= set(new)
        links.append(bar)
        joints += [Joint(f"{bar}:{x}", (x, bar)) for x in g.links]
    return Mechanism(
        links=tuple(links), joints=tuple(joints), frame=m.frame, drivers=m.drivers, name=m.name
    )


def fundamental_circuit(m: Mechanism, g: GearPair) -> FundamentalCircuit:
    """The carrier of gear pair ``g``: the link, other than the two gear links, on both
    gears' axes (the joints named in ``centres``; without them, the one link that
    shares a joint with each gear link)."""
    a, b = g.links
    if g.kind == "rack":
        raise MechanismError(f"gears: {g.id!r} is a rack pair: it has no fundamental circuit")
    if g.centres is not None:
        ja, jb = (m.joint(c) for c in g.centres)
        common = [x for x in ja.links if x in jb.links and x not in (a, b)]
        axes = (ja.id, jb.id)
    else:
        common = sorted(
            {x for j in m.joints if a in j.links for x in j.links}
            & {x for j in m.joints if b in j.links for x in j.links} - {a, b}
        )
        axes = ("", "")
    if len(common) != 1:
        what = "no link" if not common else f"links {', '.join(common)}"
        raise MechanismError(
            f"gears: the carrier of {g.id!r} is not determined ({what} on both gears' axes); "
            "name the joints on the gears' axes in 'centres'"
        )
    c = common[0]
    if g.centres is None:
        axes = tuple(next(j.id for j in m.joints if x in j.links and c in j.links) for x in (a, b))  # type: ignore[assignment]
    return FundamentalCircuit(g, c, axes)


def constraint_rank(m: Mechanism) -> tuple[int, int] | None:
    """(rank, rows) of the velocity constraints at the reference configuration; None
    when a joint's centre, a prismatic axis, or a mesh's radii or centres are missing.

    Unknowns: (vx, vy, ω) of each moving link's point at the origin. A revolute joint
    of m links gives 2 (m - 1) rows (equal velocities at its centre); a prismatic
    joint 2 (m - 1) (equal ω, no relative velocity across the guide); a mesh one (no
    relative velocity along the common tangent at the pitch point).
    """
    gears = gear_pairs(m)
    moving = [x for x in m.links if x != m.frame]
    col = {x: 3 * k for k, x in enumerate(moving)}
    rows: list[np.ndarray] = []

    def velocity(link: str, p: tuple[float, float], direction: tuple[float, float]) -> np.ndarray:
        """Row: the component along ``direction`` of the velocity of point p of link."""
        row = np.zeros(3 * len(moving))
        if link in col:
            c = col[link]
            row[c : c + 3] = (
                direction[0],
                direction[1],
                -p[1] * direction[0] + p[0] * direction[1],
            )
        return row

    for j in m.joints:
        if j.at is None or (j.kind == "P" and j.axis is None):
            return None
        for other in j.links[1:]:
            first = j.links[0]
            if j.kind == "R":
                for d in ((1.0, 0.0), (0.0, 1.0)):
                    rows.append(velocity(first, j.at, d) - velocity(other, j.at, d))
            else:
                ax, ay = j.axis  # type: ignore[misc]
                normal = (-ay / math.hypot(ax, ay), ax / math.hypot(ax, ay))
                rows.append(velocity(first, j.at, normal) - velocity(other, j.at, normal))
                spin = np.zeros(3 * len(moving))
                for link, s in ((first, 1.0), (other, -1.0)):
                    if link in col:
                        spin[col[link] + 2] = s
                rows.append(spin)
    for g in gears:
        point_tangent = pitch_point(m, g)
        if point_tangent is None:
            return None
        q, t = point_tangent
        rows.append(velocity(g.links[0], q, t) - velocity(g.links[1], q, t))
    if not rows:
        return 0, 0
    a = np.array(rows)
    if not moving:
        return 0, len(rows)
    sv = np.linalg.svd(a, compute_uv=False)
    rank = int(np.sum(sv > RANK_TOLERANCE * sv[0])) if sv.size and sv[0] > 0 else 0
    return rank, len(rows)


def pitch_point(
    m: Mechanism, g: GearPair
) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """The pitch point of ``g`` and the unit common tangent there, in the reference
    configuration (None without radii, centres or their positions)."""
    if g.radii is None or g.centres is None:
        return None
    centres = [m.joint(c).at for c in g.centres]
    if any(p is None for p in centres):
        return None
    if g.kind == "rack":
        if g.line is None:
            return None
        (cx, cy) = centres[0]  # type: ignore[misc]
        (px, py), (dx, dy) = g.line
        length = math.hypot(dx, dy)
        ux, uy = dx / length, dy / length
        # foot of the perpendicular from the pinion's centre to the pitch line
        s = (cx - px) * ux + (cy - py) * uy
        fx, fy = px + s * ux, py + s * uy
        return (fx, fy), (ux, uy)
    (x1, y1), (x2, y2) = centres  # type: ignore[misc]
    d = math.hypot(x2 - x1, y2 - y1)
    ex, ey = (x2 - x1) / d, (y2 - y1) / d
    r1, r2 = g.radii
    # external: r1 from centre 1 towards 2; internal: r1 from centre 1 away from 2 when
    # gear 1 is the pinion inside the ring, towards 2 when gear 1 is the ring
    s1 = r1 if g.kind == "external" or r1 > r2 else -r1
    return (x1 + s1 * ex, y1 + s1 * ey), (-ey, ex)


def geared_canonical_code(m: Mechanism, level: Level = "chain") -> str:
    """A canonical code of ``m`` with its gear pairs as vertices of their own colours:
    gear pairs are never confused with joints, and from the ``"kinds"`` level on the
    external, internal and rack pairs are told apart (``"mechanism"``: also frame and
    drivers). Without gears it is :func:`~mjstruct.structure.isomorphism.canonical_code`
    of the linkage with the prefix ``g``.
    """
    gears = gear_pairs(m)
    n, p = len(m.links), len(m.joints)
    classes = colour_classes(m, level)
    index = {x: i for i, x in enumerate(m.links)}
    lists = link_joint_lists(m) + [[index[x] for x in g.links] for g in gears]
    kinds = ("gear",) if level == "chain" else ("external", "internal", "rack")
    for kind in kinds:
        classes.append([n + p + k for k, g in enumerate(gears) if kind in ("gear", g.kind)])
    sizes, cert = certificate_of(n, lists, classes)
    return code_of("g" + level[0], n, p + len(gears), sizes, cert)


def geared_report(m: Mechanism) -> dict[str, Any]:
    """The ``gears`` object of ``mjstruct analyze --json`` (docs/contract.md)."""
    from mjstruct.report import structural_report

    s = geared_structure(m)
    e = structural_report(s.equivalent, with_loops=False)
    return {
        "p4": s.p4,
        "p5": s.p5,
        "F": s.F,
        "F_rank": s.F_rank,
        "rc": s.rc,
        "canonical": geared_canonical_code(m, "kinds"),
        "pairs": [
            {
                "id": c.gear.id,
                "links": list(c.gear.links),
                "type": c.gear.kind,
                "carrier": c.carrier,
                "axes": list(c.axes),
            }
            for c in s.circuits
        ],
        "equivalent": {
            "n": e.assortment.n,
            "LA": list(e.assortment.LA),
            "MJA": list(e.assortment.MJA),
            "K": e.K,
            "F": e.F,
            "code": e.code,
            "code_star": e.code_star,
        },
    }
