"""Untimed targets: matching them, in their order, to a path sampled over one cycle.

Owns :func:`ordered_match`: for each candidate, the assignment of targets 1 … T to
strictly increasing samples of its path (one driver cycle, cut just before the sample
nearest the first target) that minimises the sum of the costs (squared distances, or
any per-target cost) — a dynamic programme over (target, sample), O(T·S) per
candidate, vectorised over the population; and :func:`match_indices`, the assignment
itself for one candidate (the start of the local stage, whose driver values it then
refines).  :func:`point_costs` gives the squared distances of points to targets.

Examples
--------
A path of 8 samples on the unit circle; three targets near samples 6, 0 and 2 (in
that order along the cycle):

>>> import numpy as np
>>> z = np.exp(2j * np.pi * np.arange(8) / 8)[None, :]
>>> t = np.array([z[0, 6], z[0, 0], z[0, 2]]) * 1.01
>>> D = point_costs(z, t)
>>> cost, start = ordered_match(D)
>>> round(float(cost[0]), 6), match_indices(D[0], int(start[0]))
(0.0003, [6, 8, 10])
"""

from __future__ import annotations

import numpy as np

from mjstruct.typing import ComplexArray, FloatArray, IntArray


def point_costs(z: ComplexArray, targets: ComplexArray) -> FloatArray:
    """Squared distances, P × T × S, of path samples ``z`` (P × S) to ``targets`` (T);
    inf where a sample does not exist (NaN: the candidate does not assemble there)."""
    D: FloatArray = np.abs(z[:, None, :] - targets[None, :, None]) ** 2
    D[~np.isfinite(D)] = np.inf
    return D


def _cut(D: FloatArray) -> IntArray:
    """Each candidate's cycle cut one sample before the one cheapest for target 1."""
    S = D.shape[-1]
    out: IntArray = (np.argmin(D[:, 0, :], axis=1) - 1) % S
    return out


def ordered_match(D: FloatArray) -> tuple[FloatArray, IntArray]:
    """Least total cost of the targets at increasing samples of each candidate's cycle.

    ``D``: P × T × S costs (inf: never matched).  Returns the cost per candidate (inf
    when S < T) and the sample each candidate's cycle is cut at.
    """
    P, T, S = D.shape
    start = _cut(D)
    if S < T:
        return np.full(P, np.inf), start
    idx = (start[:, None] + np.arange(S)[None, :]) % S
    cost = np.take_along_axis(D[:, 0, :], idx, axis=1)
    for t in range(1, T):
        d = np.take_along_axis(D[:, t, :], idx, axis=1)
        best_before = np.minimum.accumulate(cost, axis=1)
        cost = np.empty_like(d)
        cost[:, 0] = np.inf  # strictly increasing: sample 0 has nothing before it
        cost[:, 1:] = d[:, 1:] + best_before[:, :-1]
    out: FloatArray = cost.min(axis=1)
    return out, start


def match_indices(D: FloatArray, start: int) -> list[int]:
    """The samples (counted from sample 0, increasing, wrapping past S - 1) that the
    best ordered assignment gives one candidate (``D``: its T × S costs)."""
    T, S = D.shape
    Dr = np.roll(D, -start, axis=1)
    tables = [Dr[0]]
    for t in range(1, T):
        best_before = np.minimum.accumulate(tables[-1])
        cost = np.full(S, np.inf)
        cost[1:] = Dr[t, 1:] + best_before[:-1]
        tables.append(cost)
    if not np.isfinite(tables[-1]).any():  # no assignment at all: spread them evenly
        return [start + (k * S) // T for k in range(T)]
    picks = [int(np.argmin(tables[-1]))]
    for t in range(T - 2, -1, -1):
        picks.append(int(np.argmin(tables[t][: picks[-1]])))
    return [start + k for k in reversed(picks)]
