"""The gear-mesh step: a link turned about its axis by Willis' equations.

Owns the kind ``gear`` and its planning rule. In a mechanism with gear pairs (the
file's ``gears``), the links whose rotation the drivers fix through Willis' equations
on the fundamental circuits (:func:`mjstruct.gears.willis.driven_rotations`) are placed
like a driven link: about a joint on an already placed link of that set (its carrier,
or the frame), turned by ``Σ_d (κ_link,d - κ_base,d) (q_d - q_d,ref)``, where κ are the
exact rotations per unit of each driver coordinate. The relation is linear with
constant coefficients, so the velocity analog is the same combination of the drivers'
rates and the acceleration analog adds nothing at constant driver speed: both exact.
The rest of the mechanism (a linkage driven through gears) is planned by the other
kinds as usual.

References
----------
[Tsai & Freudenstein] in docs/references.md: Willis' equation on each fundamental
circuit of a gear train.

Examples
--------
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.kinematics.planner import plan_kinematics
>>> plan_mechanism = read_mechanism(example_path("planetary-simple"))
>>> plan = plan_kinematics(plan_mechanism)
>>> [s.describe() for s in plan.steps[1:]]  # doctest: +NORMALIZE_WHITESPACE
['joint O turns link 1 about O on link 0 by q1',
 'gear mesh: link 3 turns about O on link 0 by Willis',
 'gear mesh: link 2 turns about P on link 3 by Willis']
>>> [str(c) for s in plan.steps[2:] for c in relative(plan_mechanism, ("O",), s.links[0], s.base)]
['1/6', '-5/12']
"""

from __future__ import annotations

import json
from fractions import Fraction
from functools import lru_cache

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.kinematics.steps.base import (
    PlanRule,
    PlanState,
    Run,
    Step,
    StepKind,
    register,
    register_rule,
)
from mjstruct.kinematics.steps.drivers import place_turned
from mjstruct.kinematics.triangles import Jet, Pose
from mjstruct.mechanism import Mechanism


def rotations(m: Mechanism, drivers: tuple[str, ...]) -> dict[str, tuple[Fraction, ...]]:
    """Willis-determined links and their rotation per driver coordinate ({} without
    gears); computed once per mechanism, gear list and drivers."""
    gears = m.extra.get("gears")
    if not gears:
        return {}
    return _rotations(m, json.dumps(gears, sort_keys=True), drivers)


@lru_cache(maxsize=64)
def _rotations(
    m: Mechanism, gears: str, drivers: tuple[str, ...]
) -> dict[str, tuple[Fraction, ...]]:
    from mjstruct.gears.willis import driven_rotations

    return driven_rotations(m, drivers)


def relative(m: Mechanism, drivers: tuple[str, ...], link: str, base: str) -> tuple[Fraction, ...]:
    """The rotation of ``link`` relative to ``base`` per driver coordinate."""
    rot = rotations(m, drivers)
    return tuple(a - b for a, b in zip(rot[link], rot[base], strict=True))


def _gear(s: Step, k: int, run: Run) -> None:
    drivers = tuple(run.geometry.driver_ref)
    coef = relative(run.mechanism, drivers, s.links[0], s.base)
    base = run.poses[s.base]
    dq = np.zeros(run.frames)
    dq1 = 0.0 * run.rates[..., 0]
    for i, (d, c) in enumerate(zip(drivers, coef, strict=True)):
        if c:
            dq = dq + float(c) * (run.q[:, i] - run.geometry.driver_ref[d])
            dq1 = dq1 + float(c) * run.rates[..., i]
    place_turned(run, s.links[0], s.joint, base, dq, dq1)


register(
    StepKind(
        "gear",
        "gear mesh: link {links[0]} turns about {joint} on link {base} by Willis",
        _gear,
        reads=lambda s, m: ((s.base,), (s.joint,)),
    )
)


def _plan_gears(st: PlanState, _: str) -> bool:
    """Each Willis-determined link with a joint on a placed Willis-determined link."""
    rot = rotations(st.m, st.drivers)
    progress = False
    for link in rot:
        if not st.free(link):
            continue
        for j in st.topo.revolute[link]:
            base = next(
                (x for x in st.m.joint(j).links if x != link and x in st.placed and x in rot),
                None,
            )
            if base is not None:
                step = st.add(Step("gear", (link,), joint=j, base=base))
                st.place(link, step, (j,))
                progress = True
                break
    return progress


register_rule(PlanRule("gears", "drivers", 11, _plan_gears))


def _pair(m: Mechanism, s: Step) -> tuple[str, float]:
    """The other gear link of the step's mesh and ρ = (ω_b - ω_c) / (ω_a - ω_c)."""
    from mjstruct.gear_pairs import gear_pairs
    from mjstruct.gears.willis import pitch_sizes

    g = gear_pairs(m)[s.index]
    b = s.links[0]
    a = g.links[1] if g.links[0] == b else g.links[0]
    sa, sb = pitch_sizes(g) if a == g.links[0] else pitch_sizes(g)[::-1]
    # r_a (ω_a - ω_c) - sign r_b (ω_b - ω_c) = 0
    return a, float(sa / sb) * g.sign


def _gear_link(s: Step, k: int, run: Run) -> None:
    a, rho = _pair(run.mechanism, s)
    base, pa = run.poses[s.base], run.poses[a]
    rel = pa.r * np.conj(base.r)  # a's rotation relative to the carrier since the reference
    phi = np.angle(rel)
    if phi.ndim == 1 and phi.size > 1:
        phi = np.unwrap(phi)  # consecutive frames: the relative turn continued
    low = run.lower_pose(s.links[0])
    r = base.r * np.exp(1j * rho * phi) if low is None else low[0]
    w: Jet = [cw + rho * (aw - cw) for cw, aw in zip(base.w, pa.w, strict=True)]
    run.place(s.links[0], Pose(run.geometry.centres[s.joint], run.centre(s.joint), r, w))


def _gear_link_reads(s: Step, m: Mechanism) -> tuple[tuple[str, ...], tuple[str, ...]]:
    return (s.base, _pair(m, s)[0]), (s.joint,)


register(
    StepKind(
        "gear-link",
        "gear mesh {n}: link {links[0]} turns about {joint} on carrier {base} with its "
        "mate's turn relative to the carrier",
        _gear_link,
        reads=_gear_link_reads,
    )
)


def _plan_gear_links(st: PlanState, _: str) -> bool:
    """A mesh whose carrier and one gear link are placed places the other gear link
    about its axis joint on the carrier."""
    from mjstruct.gear_pairs import gear_pairs
    from mjstruct.gears.structure import fundamental_circuit

    if not st.m.extra.get("gears"):
        return False
    for index, g in enumerate(gear_pairs(st.m)):
        if g.kind == "rack":
            continue
        circuit = fundamental_circuit(st.m, g)
        c = circuit.carrier
        if c not in st.placed:
            continue
        for b, a, axis in ((g.links[1], g.links[0], circuit.axes[1]),
                           (g.links[0], g.links[1], circuit.axes[0])):  # fmt: skip
            if a in st.placed and st.free(b) and axis:
                step = st.add(Step("gear-link", (b,), joint=axis, base=c, index=index))
                st.place(b, step, (axis,))
                return True
    return False


register_rule(PlanRule("gear links", "drivers", 12, _plan_gear_links))


def geared_dof(m: Mechanism, drivers: tuple[str, ...]) -> int:
    """The mobility of a geared mechanism by rank, checked against the drivers.

    Raises MechanismError when the geometry does not give it or the drivers do not
    match it (the planner's driver check for a mechanism with gear pairs).
    """
    from mjstruct.gear_pairs import gear_pairs
    from mjstruct.gears.structure import geared_structure

    rack = next((g.id for g in gear_pairs(m) if g.kind == "rack"), None)
    if rack is not None:
        raise MechanismError(
            f"gears: {rack!r} is a rack pair: the kinematics does not move racks yet"
        )
    s = geared_structure(m)
    if s.F_rank is None:
        raise MechanismError(
            "gears: the meshes need 'radii' (or 'teeth' and 'module') and 'centres'"
        )
    if s.F_rank != len(drivers):
        raise MechanismError(
            f"drivers: {', '.join(drivers)} ({len(drivers)}) for a geared mechanism of "
            f"F = {s.F_rank} (rank of the constraints with the gear pairs)"
        )
    return s.F_rank
