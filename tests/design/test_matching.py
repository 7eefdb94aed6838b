"""Ordered matching of untimed targets against an exhaustive search."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mjstruct.design.matching import match_indices, ordered_match, point_costs


def _brute(z, targets):
    """Least cost over every cut of the cycle and every increasing assignment."""
    S = len(z)
    best = np.inf
    for cut in range(S):
        zr = np.roll(z, -cut)
        for pick in itertools.combinations(range(S), len(targets)):
            best = min(
                best, float(sum(abs(zr[k] - t) ** 2 for k, t in zip(pick, targets, strict=False)))
            )
    return best


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 4), st.integers(5, 8))
def test_cost_is_the_least_over_assignments_from_the_cut(seed, T, S):
    rng = np.random.default_rng(seed)
    z = rng.standard_normal(S) + 1j * rng.standard_normal(S)
    targets = rng.standard_normal(T) + 1j * rng.standard_normal(T)
    D = point_costs(z[None, :], targets)
    cost, start = ordered_match(D)
    # the cut is one sample before the sample nearest the first target: the programme
    # is exact for that cut, and never better than the best over all cuts
    zr = np.roll(z, -int(start[0]))
    exact = min(
        float(sum(abs(zr[k] - t) ** 2 for k, t in zip(p, targets, strict=False)))
        for p in itertools.combinations(range(S), T)
    )
    assert np.isclose(cost[0], exact)
    assert cost[0] >= _brute(z, targets) - 1e-12
    idx = match_indices(D[0], int(start[0]))
    assert all(b > a for a, b in itertools.pairwise(idx))
    assert idx[-1] - idx[0] < S
    got = sum(abs(z[k % S] - t) ** 2 for k, t in zip(idx, targets, strict=False))
    assert np.isclose(got, cost[0])


def test_samples_that_do_not_assemble_are_never_matched():
    z = np.exp(2j * np.pi * np.arange(12) / 12)
    z[3] = np.nan
    targets = np.array([z[2], np.exp(2j * np.pi * 3 / 12), z[5]])
    D = point_costs(z[None, :], targets)
    cost, start = ordered_match(D)
    idx = match_indices(D[0], int(start[0]))
    assert 3 not in [k % 12 for k in idx] and np.isfinite(cost[0])
