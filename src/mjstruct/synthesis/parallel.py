"""Running independent enumeration tasks: in-process, on a process pool, or on Dask;
and the progress bar of long runs (tqdm: a widget in Jupyter, a bar on a terminal).

Results come back in task order whatever the number of workers, so the caller's
output is deterministic.

Examples
--------
>>> list(run_tasks(abs, [-1, 2, -3]))
[1, 2, 3]
"""

from __future__ import annotations

import gc
import os
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any, TextIO


def core_count() -> int:
    """Cores this process may run on (the scheduler's affinity where known)."""
    if hasattr(os, "sched_getaffinity"):
        return max(len(os.sched_getaffinity(0)), 1)
    return os.cpu_count() or 1


@contextmanager
def collection_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector inside the block.

    An enumeration creates hundreds of thousands of small lists and tuples and keeps
    many of them: every few hundred allocations the collector would walk what is kept
    (40% of the time of labelling chains).  They hold no reference cycles, so reference
    counting frees them all the same.
    """
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def run_tasks(
    fn: Callable[[Any], Any],
    tasks: Sequence[Any],
    workers: int = 1,
    progress: Callable[[int, int], None] | None = None,
    scheduler: str | None = None,
    as_done: bool = False,
) -> Iterator[Any]:
    """Yield ``fn(task)`` for every task, in task order (``as_done``: as each result
    comes in, so that the caller's work on it overlaps the workers' on the rest).

    ``workers > 1`` uses a :class:`multiprocessing.pool.Pool` (terminated on any
    early exit);
    ``scheduler`` (an address such as ``"tcp://host:8786"``) sends the tasks to a Dask
    cluster instead (needs the optional ``dask[distributed]``).  Local workers are
    capped at :func:`core_count` (more processes than cores only add overhead).
    """
    total = len(tasks)
    workers = min(workers, core_count())
    if scheduler is not None:
        yield from _run_dask(fn, tasks, scheduler, progress, as_done)
        return
    if workers <= 1 or total <= 1:
        for k, task in enumerate(tasks):
            yield fn(task)
            if progress:
                progress(k + 1, total)
        return
    import multiprocessing

    results: dict[int, Any] = {}
    # a Pool (not concurrent.futures) so that leaving early (Ctrl-C, SIGTERM, an
    # error) terminates the workers at once instead of waiting for their tasks
    with multiprocessing.Pool(workers, initializer=_quiet_worker, initargs=(os.getpid(),)) as pool:
        calls = [(fn, k, task) for k, task in enumerate(tasks)]
        results_in = pool.imap_unordered(_indexed_call, calls)
        pool.close()  # no more tasks: each worker ends (its memory freed) after its last
        for done, (k, value) in enumerate(results_in, 1):
            if progress:
                progress(done, total)
            if as_done:
                yield value
            else:
                results[k] = value
    for k in range(total) if not as_done else ():
        yield results[k]


def _quiet_worker(parent: int) -> None:
    """Workers leave signals to the parent, which terminates the pool; and they end
    with the parent whatever ends it (on Linux: even SIGKILL, or a signal landing
    while the pool starts, where the parent's cleanup cannot run)."""
    import signal

    from mjstruct.structure.isomorphism import die_with_parent

    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent(parent)


def _indexed_call(call: tuple[Callable[[Any], Any], int, Any]) -> tuple[int, Any]:
    fn, k, task = call
    return k, fn(task)


def _run_dask(
    fn: Callable[[Any], Any],
    tasks: Sequence[Any],
    scheduler: str,
    progress: Callable[[int, int], None] | None,
    as_done: bool = False,
) -> Iterator[Any]:
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        from mjstruct.errors import MechanismError

        raise MechanismError(
            "scheduler: needs dask.distributed (pip install 'dask[distributed]')"
        ) from None
    with Client(scheduler) as client:
        futures = client.map(fn, list(tasks), pure=False)
        index = {f.key: k for k, f in enumerate(futures)}
        results: dict[int, Any] = {}
        for done, fut in enumerate(as_completed(futures), 1):
            if progress:
                progress(done, len(tasks))
            if as_done:
                yield fut.result()
            else:
                results[index[fut.key]] = fut.result()
    for k in range(len(tasks)) if not as_done else ():
        yield results[k]


class ProgressBar:
    """Progress of long work through ``tqdm.auto``: a widget in Jupyter, a bar on a
    terminal (``label ▕████▏ 12/40 tasks 00:03`` on stderr, redrawn in place); silent
    unless enabled (the CLI enables it only on a terminal and without ``--json``).

    Called as ``bar(done, total)``; pass one as ``progress=`` to long functions
    (``atlas``, animations), e.g. ``ProgressBar("atlas", enabled=True)`` in a notebook.
    """

    def __init__(self, label: str, enabled: bool, stream: TextIO | None = None) -> None:
        self.label = label
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self._bar: Any = None

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled or total <= 0:
            return
        if self._bar is None:
            from tqdm.auto import tqdm  # imported here: quiet runs never load it

            self._bar = tqdm(
                total=total,
                desc=self.label,
                file=self.stream,
                leave=True,
                bar_format="{desc} {bar} {n_fmt}/{total_fmt} tasks {elapsed}",
            )
        self._bar.update(done - self._bar.n)
        if done >= total:
            self._bar.close()
            self._bar = None

    @classmethod
    def for_cli(cls, label: str, json_output: bool) -> ProgressBar:
        return cls(label, enabled=not json_output and sys.stderr.isatty())
