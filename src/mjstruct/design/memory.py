"""The memory a synthesis needs, estimated before it starts, and its populations judged
in chunks.

Owns :func:`synthesis_bytes` (the peak of a fitting task's search, by part),
:func:`check_synthesis_memory`, which refuses a search beyond the limit (the
kinematics' :func:`~mjstruct.kinematics.memory.memory_limit`: 2 GiB, the environment
variable ``MJSTRUCT_MAX_MEMORY_BYTES`` or ``max_memory=``) naming the task field that
needs it, and :func:`assess_in_chunks`, which judges a population a bounded number of
frames at a time: memory stays bounded whatever the population, and an interrupt
lands between two chunks (each a few tens of milliseconds), not after one call over
every frame.

The estimate's parts, measured with ``tracemalloc`` (four-bar and Watt path tasks,
populations of 500 to 2000, 5 to 1000 targets, 18 to 4000 samples per candidate):

* a population's frames: the kinematics' bytes per table item and frame
  (:data:`~mjstruct.kinematics.memory.RESULT_BYTES`; measured 351-386 bytes per frame
  of the four-bar's 9 items), for one chunk (:data:`CHUNK_FRAMES` frames);
* the target costs: 24 bytes per candidate, target and sample (untimed: P × T × S, the
  matching's table and its two temporaries; timed: P × T × T), for one chunk;
* the first population's Latin hypercube: :data:`SCREEN_BYTES` per sample and
  variable (its strata, their order and the uniform draws), ``SCREEN`` (10) samples
  per member;
* the local stage: its Jacobian (rows: two per target and the penalties, columns: the
  variables and, untimed, one driver value per target) about 10 times over in
  ``least_squares`` (measured 8.8-9.2), plus the 2n + 1 candidates its columns
  evaluate.

Examples
--------
>>> from mjstruct.design.api import load_task
>>> from mjstruct.design.path import path_problem
>>> from mjstruct.io import mechanism_to_dict, read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> m = mechanism_to_dict(read_mechanism(example_path("four-bar")))
>>> task = load_task({"task": "path", "mechanism": m, "point": "M",
...                   "targets": [[0.4, 0.6], [0.2, 0.9]]})
>>> parts = synthesis_bytes(path_problem(task), task.solver)
>>> sorted(parts), sum(parts.values()) < 2**27
(['solver.population', 'solver.samples', 'targets'], True)
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, TypeVar, cast

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.kinematics.memory import MEMORY_ENV, memory_limit, sweep_bytes
from mjstruct.typing import FloatArray

#: an assessment of a population: ``energy`` and ``margins`` per candidate
#: (:class:`mjstruct.design.search.Assessment`)
A = TypeVar("A")

#: frames of one chunk of a population judged at once (about 40 ms for a four-bar)
CHUNK_FRAMES = 50_000
#: target costs (candidate x target x sample) of one chunk at most
CHUNK_COSTS = 2_000_000
#: bytes per target cost (measured 24: the table and two temporaries)
COST_BYTES = 24
#: bytes per sample and variable of the first population's Latin hypercube
SCREEN_BYTES = 48
#: bytes per member and variable of the differential evolution's own arrays
MEMBER_BYTES = 64
#: copies of the local stage's Jacobian alive in least squares (measured 8.8-9.2)
JACOBIAN_COPIES = 10
#: whatever the task: the models, the caches and the search's own bookkeeping
#: (a four-bar's whole run with 5 targets peaked at 44 MB)
FIXED_BYTES = 2**25


def _shape(problem: Any) -> tuple[int, int, int, bool]:
    """(variables, targets, samples per candidate, timed) of a fitting problem."""
    lo, _ = problem.bounds()
    return len(lo), int(problem.targets), int(problem.samples), bool(problem.timed)


def chunk_rows(problem: Any) -> int:
    """Candidates judged at once: :data:`CHUNK_FRAMES` frames and :data:`CHUNK_COSTS`
    target costs at most (one candidate at least)."""
    _, T, S, timed = _shape(problem)
    frames = S + (T if timed else 0)
    costs = T * (T if timed else S)
    return max(1, min(CHUNK_FRAMES // max(frames, 1), CHUNK_COSTS // max(costs, 1)))


def assess_in_chunks(assess: Callable[[FloatArray], A], X: FloatArray, rows: int) -> A:
    """``assess`` on ``rows`` candidates of ``X`` at a time, the answers joined (each
    candidate is judged on its own, so the answer is the one of a single call)."""
    X = np.atleast_2d(X)
    if len(X) <= rows:
        return assess(X)
    parts: list[Any] = [assess(X[k : k + rows]) for k in range(0, len(X), rows)]
    energy = np.concatenate([p.energy for p in parts])
    margins = {name: np.concatenate([p.margins[name] for p in parts]) for name in parts[0].margins}
    return cast(A, type(parts[0])(energy, margins))


def synthesis_bytes(problem: Any, solver: Mapping[str, int | float]) -> dict[str, int]:
    """Estimated peak bytes of a fitting task's search, by the task field that sets
    each part: ``solver.population`` (the first population's screening and the
    evolution's arrays), ``solver.samples`` (a chunk of frames, or the local stage's
    Jacobian evaluation), ``targets`` (a chunk's target costs, or the local stage's
    Jacobian in least squares)."""
    from mjstruct.design import search

    # the search's own numbers (wherever the search keeps them)
    screen_per_member = int(getattr(search, "SCREEN", 10))
    local_starts = int(getattr(search, "LOCAL_STARTS", 4))
    n, T, S, timed = _shape(problem)
    model = problem.space.model
    members = max(int(solver["population"]) * n, 5)
    screen = screen_per_member * members + len(problem.starts())
    per_candidate = S + (T if timed else 0)
    rows = min(chunk_rows(problem), screen)
    frames = sweep_bytes(model, rows * per_candidate, checks=False)
    costs = COST_BYTES * rows * T * (T if timed else S)
    columns = n + (0 if timed else T)
    jacobian = JACOBIAN_COPIES * 8 * (3 * T + local_starts) * columns
    local_frames = sweep_bytes(model, 2 * (2 * n + 1) * (T + S), checks=False)
    population = SCREEN_BYTES * screen * n + MEMBER_BYTES * members * n
    return {
        "solver.population": FIXED_BYTES + population,
        "solver.samples": max(frames, local_frames),
        "targets": max(costs, jacobian),
    }


def check_synthesis_memory(
    problem: Any, solver: Mapping[str, int | float], limit: int | None = None
) -> int:
    """Refuse a search whose estimate exceeds the limit; return the estimate (bytes).

    Raises
    ------
    MechanismError
        naming the task field of the largest part, with the estimate and the limit.
    """
    cap = memory_limit(limit)
    parts = synthesis_bytes(problem, solver)
    need = sum(parts.values())
    if need > cap:
        field = max(parts, key=parts.__getitem__)
        _, T, S, _ = _shape(problem)
        value = {
            "solver.population": f"{int(solver['population'])} members per variable",
            "solver.samples": f"{S} samples per candidate",
            "targets": f"{T} targets",
        }[field]
        raise MechanismError(
            f"{field}: {value} need about {need:.2g} bytes, over the limit of {cap:.3g} "
            f"bytes (max_memory, --max-memory, or {MEMORY_ENV})"
        )
    return need
