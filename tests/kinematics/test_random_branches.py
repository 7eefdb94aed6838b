"""Short sweeps of random mechanisms keep the branch of a fine sweep (7, 23, 41, 53; any)."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.testing import random_geometry, random_mechanism

#: the benchmark's short sweep (benchmarks/bench_kinematics_completeness.py): ±3°, 13 frames
SPAN, FRAMES = np.radians(3.0), 13
#: the fine sweep from the reference to either end of it: 120 steps of 0.025°
FINE = 121


def _groups(seed: int) -> int:
    """The benchmark's group count of mechanism ``seed`` (one draw per mechanism)."""
    rng = np.random.default_rng(2026)
    for _ in range(seed + 1):
        groups = int(rng.integers(1, 21))
    return groups


@cache
def _sweeps(seed: int) -> tuple[KinematicModel, Motion, dict[int, Motion]]:
    """The model, its short sweep, and the fine sweep from the reference on each side."""
    return _sweeps_of(_groups(seed), seed)


def _sweeps_of(groups: int, seed: int) -> tuple[KinematicModel, Motion, dict[int, Motion]]:
    """:func:`_sweeps` for random mechanism ``seed`` of ``groups`` groups."""
    m = random_geometry(random_mechanism(groups, seed=seed), seed)
    model = KinematicModel.build(m)
    q0 = float(model.q_ref[0])
    coarse = model.motion(q0 + np.linspace(-SPAN, SPAN, FRAMES))
    fine = {side: model.motion(q0 + side * np.linspace(0.0, SPAN, FINE)) for side in (1, -1)}
    return model, coarse, fine


def _centres(model: KinematicModel, motion: Motion, frame: int) -> np.ndarray:
    """Every revolute joint centre of ``motion`` at ``frame`` (x + iy)."""
    m = model.mechanism
    return np.array([motion.centre(j.id)[0][frame] for j in m.joints if j.kind == "R"])


def _fine_frame(coarse_frame: int) -> tuple[int, int]:
    """The side and the fine frame at the driver value of a frame of the short sweep."""
    half = FRAMES // 2
    steps = (FINE - 1) // half  # fine frames per frame of the short sweep
    side = 1 if coarse_frame >= half else -1
    return side, abs(coarse_frame - half) * steps


def _fine_limit(fine: Motion) -> int:
    """Frames of a fine sweep that assemble, counted from the reference."""
    return int(np.argmin(fine.valid)) if not fine.valid.all() else FINE


@pytest.mark.parametrize("seed", [7, 23, 41, 53])
def test_the_fine_sweep_from_the_reference_assembles_on_one_run(seed: int) -> None:
    model, _, fine = _sweeps(seed)
    at = np.array([complex(*j.at) for j in model.mechanism.joints if j.kind == "R"])
    for side, f in fine.items():
        gap = np.abs(_centres(model, f, 0) - at).max() / model.scale
        assert gap <= 1e-9, (side, gap)
        n = _fine_limit(f)
        # valid from the reference up to where it stops, and nothing after
        assert n >= 1 and f.valid[:n].all() and not f.valid[n:].any(), (side, f.valid)


@pytest.mark.parametrize("seed", [7, 23, 41, 53])
def test_every_valid_frame_of_the_short_sweep_is_the_fine_sweeps_configuration(
    seed: int,
) -> None:
    model, coarse, fine = _sweeps(seed)
    assert coarse.valid[FRAMES // 2]
    for i in np.flatnonzero(coarse.valid):
        side, k = _fine_frame(int(i))
        assert abs(fine[side].q[k, 0] - coarse.q[i, 0]) <= 1e-12
        assert fine[side].valid[k], (i, k)
        gap = np.abs(_centres(model, coarse, i) - _centres(model, fine[side], k)).max()
        gap /= model.scale
        # another branch puts some joint a sizeable part of the mechanism's size away
        assert gap <= 1e-9, (i, gap)


@pytest.mark.parametrize("seed", [7, 23, 41, 53])
def test_frames_the_short_sweep_misses_lie_beyond_where_the_fine_sweep_stops(
    seed: int,
) -> None:
    _, coarse, fine = _sweeps(seed)
    missed = np.flatnonzero(~coarse.valid)
    assert missed.size > 0  # both mechanisms meet the edge of their range on one side
    for i in missed:
        side, k = _fine_frame(int(i))
        assert k >= _fine_limit(fine[side]), (i, k)


def _consistent(model: KinematicModel, coarse: Motion, fine: dict[int, Motion]) -> None:
    """Up to where the fine sweeps stop assembling, the short sweep assembles and gives
    their configurations.  (Past that edge frames are missing, or found by continuation
    across a downstream group's gap, which the analysis words as no physical motion.)"""
    for i in range(FRAMES):
        side, k = _fine_frame(i)
        if k >= _fine_limit(fine[side]):
            continue
        assert coarse.valid[i], (i, k)
        gap = np.abs(_centres(model, coarse, i) - _centres(model, fine[side], k)).max()
        assert gap <= 1e-9 * model.scale, (i, gap / model.scale)


@settings(max_examples=10, deadline=None, derandomize=True)
@given(groups=st.integers(1, 10), seed=st.integers(0, 10**6))
def test_a_short_sweep_of_any_random_mechanism_keeps_the_branch_of_a_fine_one(
    groups: int, seed: int
) -> None:
    """Random mechanisms with random geometry (dyads, triads, class-IV groups, multiple
    joints, sliders): the ±3° sweep in 13 frames agrees with sweeps 24 times finer."""
    _consistent(*_sweeps_of(groups, seed))
