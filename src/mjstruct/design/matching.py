"""Untimed targets: matching them, in their order, to a path sampled over one cycle.

Owns :func:`ordered_match`: for each candidate, the assignment of targets 1 … T to
strictly increasing samples of its path (one driver cycle, cut where the first
target is best met) that minimises the sum of squared distances — a dynamic
programme over (target, sample), O(T·S) per candidate, vectorised over the
population; and :func:`match_indices`, the assignment itself for one candidate
(the start of the local stage, whose driver values it then refines).

Examples
--------
A path of 8 samples on the unit circle; three targets near samples 6, 0 and 2 (in
that order along the cycle):

>>> import numpy as np
>>> z = np.exp(2j * np.pi * np.arange(8) / 8)[None, :]
>>> t = np.array([z[0, 6], z[0, 0], z[0, 2]]) * 1.01
>>> cost, start = ordered_match(z, t)
>>> round(float(cost[0]), 6), match_indices(z[0], t, int(start[0]))
(0.0003, [6, 8, 10])
"""

from __future__ import annotations

import numpy as np

from mjstruct.typing import ComplexArray, FloatArray, IntArray


def _rolled(z: ComplexArray, targets: ComplexArray) -> tuple[ComplexArray, IntArray]:
    """Each path rolled to start one sample before the one nearest the first target."""
    _P, S = z.shape
    d = np.abs(z - targets[0])
    d[~np.isfinite(d)] = np.inf  # a sample that does not assemble is never nearest
    start = (np.argmin(d, axis=1) - 1) % S
    idx = (start[:, None] + np.arange(S)[None, :]) % S
    return np.take_along_axis(z, idx, axis=1), start


def ordered_match(z: ComplexArray, targets: ComplexArray) -> tuple[FloatArray, IntArray]:
    """Least sum of squared distances of the targets to increasing samples of each path.

    ``z``: P × S path samples (one cycle, in driver order; NaN where it does not
    assemble: never matched); ``targets``: T complex.  Returns the cost per
    candidate (inf when S < T) and the sample each candidate's cycle is cut at.
    """
    P, S = z.shape
    T = len(targets)
    zr, start = _rolled(z, targets)
    if S < T:
        return np.full(P, np.inf), start
    cost = None
    for t in range(T):
        d = np.abs(zr - targets[t]) ** 2
        d[~np.isfinite(d)] = np.inf
        if cost is None:
            cost = d
            continue
        best_before = np.minimum.accumulate(cost, axis=1)
        cost = d.copy()
        cost[:, 0] = np.inf  # strictly increasing: sample 0 has nothing before it
        cost[:, 1:] += best_before[:, :-1]
    assert cost is not None
    out: FloatArray = cost.min(axis=1)
    return out, start


def match_indices(z: ComplexArray, targets: ComplexArray, start: int) -> list[int]:
    """The samples (counted from sample 0 of ``z``, increasing, may exceed S - 1 by
    wrapping) that the best ordered assignment gives one candidate's path."""
    S = z.shape[0]
    zr = np.roll(z, -start)
    T = len(targets)
    tables = []
    cost = np.abs(zr - targets[0]) ** 2
    cost[~np.isfinite(cost)] = np.inf
    tables.append(cost)
    for t in range(1, T):
        d = np.abs(zr - targets[t]) ** 2
        d[~np.isfinite(d)] = np.inf
        best_before = np.minimum.accumulate(cost)
        cost = np.full(S, np.inf)
        cost[1:] = d[1:] + best_before[:-1]
        tables.append(cost)
    if not np.isfinite(tables[-1]).any():  # no assignment at all: spread them evenly
        return [start + (k * S) // T for k in range(T)]
    picks = [int(np.argmin(tables[-1]))]
    for t in range(T - 2, -1, -1):
        k = picks[-1]
        picks.append(int(np.argmin(tables[t][:k])))
    return [start + k for k in reversed(picks)]
