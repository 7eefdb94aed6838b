"""``synthesize(task, seed=...)``: one entry point for every task kind.

Owns the dispatch from a task (a :class:`~mjstruct.design.task.Task`, a task object
as read from a file, or a file name) to the module of its kind: path synthesis
(:mod:`mjstruct.design.path`), function and motion synthesis, and the four-bar matrix
synthesis ``fourbar-ms`` (:mod:`mjstruct.design.fourbar_ms`).

Examples
--------
>>> from mjstruct.io import mechanism_to_dict, read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> m = mechanism_to_dict(read_mechanism(example_path("four-bar")))
>>> task = {"task": "path", "mechanism": m, "point": "M",
...         "targets": [[0.40, 0.60], [0.25, 0.85], [0.00, 0.85]],
...         "timing": [1.05, 1.55, 2.05], "fixed": ["O1", "O2"],
...         "solver": {"population": 6, "generations": 30, "restarts": 1}}
>>> r = synthesize(task, seed=1)
>>> r.feasible, len(r.errors), r.mechanism.extra["synthesis"]["point"]
(True, 3, 'M')
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from mjstruct.design.result import DesignResult
from mjstruct.design.task import Task, read_task, task_from_dict
from mjstruct.errors import MechanismError


def load_task(task: Task | Mapping[str, Any] | str | Path) -> Task:
    """A checked :class:`Task` from a task, a task object or a task file's name."""
    if isinstance(task, Task):
        return task
    if isinstance(task, (str, Path)):
        return read_task(task)
    return task_from_dict(task)


def synthesize(
    task: Task | Mapping[str, Any] | str | Path,
    seed: int | None = None,
    workers: int = 1,
    scheduler: str | None = None,
    progress: Callable[[int, int], None] | None = None,
    max_memory: int | None = None,
) -> DesignResult:
    """Synthesise the mechanism a task asks for.

    Parameters
    ----------
    task : a :class:`Task`, a task object (the task file's keys) or a task file name.
    seed : the random seed: the same task and seed give the same design.
    workers : processes for the independent restarts (at most the number of cores).
    scheduler : a Dask scheduler address to run the restarts on instead.
    progress : called as ``progress(done, total)`` while the search runs.
    max_memory : the limit (bytes) on the search's estimated memory (default 2 GiB, or
        the environment variable ``MJSTRUCT_MAX_MEMORY_BYTES``).

    Raises
    ------
    MechanismError
        bad task input (one line naming the field), or a search whose estimated
        memory exceeds the limit (naming the task field that needs it).
    NumericalError
        no feasible design was found (``no feasible design: ...``).
    """
    if workers < 1:
        raise MechanismError(f"workers: need at least 1, got {workers}")
    t = load_task(task)
    if t.kind == "fourbar-ms":
        from mjstruct.design.fourbar_ms import synthesize_fourbar_ms

        return synthesize_fourbar_ms(t.data, seed=seed)
    if t.kind == "path":
        from mjstruct.design.path import path_problem

        problem: Any = path_problem(t)
    elif t.kind == "function":
        from mjstruct.design.function import function_problem

        problem = function_problem(t)
    elif t.kind == "motion":
        from mjstruct.design.motion import motion_problem

        problem = motion_problem(t)
    from mjstruct.design.memory import check_synthesis_memory
    from mjstruct.design.search import solve

    check_synthesis_memory(problem, t.solver, max_memory)
    result = solve(
        problem, seed, t.solver, workers=workers, scheduler=scheduler, progress=progress
    )
    _final_verdict(t, result, max(360, 4 * int(getattr(problem, "samples", 90))))
    return result


def _final_verdict(task: Task, result: DesignResult, frames: int) -> None:
    """Refuse a result that breaks a promise of the contract, judged from the design as
    it will be written (:func:`mjstruct.design.verify.final_verdict`)."""
    import json

    from mjstruct.design.verify import final_verdict
    from mjstruct.errors import NumericalError
    from mjstruct.io import mechanism_from_dict, mechanism_to_dict

    written = mechanism_from_dict(json.loads(json.dumps(mechanism_to_dict(result.mechanism))))
    timing = result.details.get("timing", [])
    offset = float(result.details.get("angle_offset", 0.0))
    broken = final_verdict(task, written, timing, result.errors, offset, frames)
    if broken:
        raise NumericalError(
            f"no feasible design: the final verdict refused the best ({broken[0]})"
        )
