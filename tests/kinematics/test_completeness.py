"""Completeness: the sweep returns every frame the mechanism reaches from its reference.

Checked against an independent continuation of the full constraint system
(``full_system_continuation``: every link a rigid body, every joint's constraints at
once, no Assur decomposition, the driver stepped from the reference in small adaptive
steps, stopping at a fold): every frame it reaches must be returned by the sweep at
the same joint centres (1e-9 of the size).  A frame the sweep returns beyond the
continuation's stop must be reached the other way round (the driver's angle modulo 2π,
at the continuation's centres there) or lie past a frame that does not assemble.
Where an inner dyad of a closure group passes its own dead point its mode flips (an
informational event), and no step inside a closure group is reported at a dead point
of its own.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from full_system_continuation import FullSystem, reach
from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from mjstruct.structure.assur import assur_groups
from mjstruct.testing import random_geometry, random_mechanism


def _bench_mechanism(seed: int) -> Mechanism:
    rng = np.random.default_rng(2026)
    groups = [int(rng.integers(1, 21)) for _ in range(seed + 1)][seed]
    return random_geometry(random_mechanism(groups, seed=seed), seed)


def _inside_closures(model: KinematicModel) -> set[int]:
    """Steps inside closure groups: read by a closure equation and placed on an unknown."""
    steps, deps = model.plan.steps, model.step_dependencies
    assumed = {k for k, s in enumerate(steps) if s.kind in ("assume", "assume-slide")}
    read = {j for k, s in enumerate(steps) if s.is_closure for j in deps[k]}
    return {k for k in read if assumed.intersection(deps[k])}


def check_complete(m: Mechanism, span: float, frames: int) -> tuple[int, int]:
    """Sweep ±``span`` rad around the reference in ``frames`` frames against the oracle.

    Returns (frames the oracle reached, mode flips reported).
    """
    model = KinematicModel.build(m)
    system = FullSystem(m)
    assert abs(system.q_ref - model.q_ref[0]) < 1e-12
    q = model.q_ref[0] + np.linspace(-span, span, frames)
    with np.errstate(all="ignore"):
        motion = model.motion(q[:, None])
    got = reach(system, q)
    size = model.scale
    for i, r in got.items():
        assert motion.valid[i], (i, sorted(got))
        err = max(abs(complex(motion.centre(j)[0][i]) - z) for j, z in r.joints.items())
        assert err <= 1e-9 * size, (i, err / size)
    mid = int(np.argmin(np.abs(q - model.q_ref[0])))
    for i in np.flatnonzero(motion.valid):
        if int(i) in got:
            continue
        # beyond the oracle's stop: reached the other way round (a revolute driver's
        # angle modulo 2π), at the oracle's joint centres
        d = q[i] - model.q_ref[0]
        other = model.q_ref[0] + (d - np.sign(d) * 2 * np.pi)
        round_trip = reach(system, np.array([model.q_ref[0], other]))
        if 1 in round_trip:
            err = max(
                abs(complex(motion.centre(j)[0][i]) - z) for j, z in round_trip[1].joints.items()
            )
            assert err <= 1e-9 * size, (int(i), err / size)
            continue
        # otherwise only past a frame that does not assemble
        between = motion.valid[min(i, mid) : max(i, mid) + 1]
        assert not between.all(), (int(i), sorted(got))
    inside = _inside_closures(model)
    for e in motion.events:
        if e.kind == "dead point" and not e.group:
            assert e.step not in inside, e.message()
    return len(got), sum(1 for e in motion.events if e.kind == "mode flip")


@pytest.mark.parametrize(
    ("seed", "degrees", "frames"),
    [
        # a dyad inside the closure reaches its dead point 0.365° below the reference
        (43, 3.0, 13),
        # the closure went on only one way from the reference: both inner dyads flip
        (53, 30.0, 61),
    ],
)
def test_benchmark_mechanisms_reach_every_frame(seed: int, degrees: float, frames: int) -> None:
    reached, flips = check_complete(_bench_mechanism(seed), np.radians(degrees), frames)
    assert reached > 1 and flips > 0


@settings(
    max_examples=12,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow],
)
@given(groups=st.integers(1, 4), seed=st.integers(0, 10**6))
def test_random_mechanisms_with_closures_reach_every_frame(groups: int, seed: int) -> None:
    m = random_geometry(random_mechanism(groups, seed=seed), seed)
    try:
        assur_groups(m)
        model = KinematicModel.build(m)
    except (MechanismError, NumericalError):
        assume(False)
        return
    assume(model.plan.unknowns > 0)
    check_complete(m, np.radians(6.0), 9)
