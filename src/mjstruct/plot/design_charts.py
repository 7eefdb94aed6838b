"""Charts of a synthesis run: the objective against evaluations and against time.

Owns :func:`draw_history` and :func:`write_history_chart`: the error-against-run-time
report of a :class:`~mjstruct.design.result.DesignResult` (its ``history``: the best
feasible objective after each generation of the global stage, then the verdict of the
local stage), on two panels sharing a logarithmic objective axis: candidate
evaluations, and wall time in seconds.  ``mjstruct synthesize --history CHART``
writes it.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> from mjstruct.design.result import DesignResult
>>> from mjstruct.mechanism import Mechanism
>>> m = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]), ("O2", [3, 0])],
...                     frame=0, drivers=["O1"])
>>> r = DesignResult(m, "path", 1e-3, True, (1e-3,), 900, 0.6, 1,
...                  history=((100, 0.1, 0.5), (500, 0.3, 0.02), (900, 0.6, 1e-3)))
>>> fig = draw_history(r)
>>> [ax.get_xlabel() for ax in fig.axes]
['candidate evaluations', 'time (s)']
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from mjstruct.design.result import DesignResult
from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def draw_history(result: DesignResult, fig: Figure | None = None) -> Figure:
    """The objective (best feasible so far) against evaluations and against time."""
    import matplotlib.pyplot as plt

    if fig is None:
        fig = plt.figure(figsize=(9.0, 3.6))
    points = [(k, t, f) for k, t, f in result.history if math.isfinite(f) and f > 0]
    ax1 = fig.add_subplot(1, 2, 1)
    ax2 = fig.add_subplot(1, 2, 2, sharey=ax1)
    if points:
        ks, ts, fs = zip(*points, strict=True)
        ax1.step(ks, fs, where="post", color="tab:blue")
        ax2.step(ts, fs, where="post", color="tab:blue")
        ax1.set_yscale("log")
    else:
        for ax in (ax1, ax2):
            ax.text(
                0.5, 0.5, "no feasible candidate recorded", ha="center", transform=ax.transAxes
            )
    ax1.set_xlabel("candidate evaluations")
    ax2.set_xlabel("time (s)")
    ax1.set_ylabel("objective (RMS target error)")
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(
        f"{result.task} synthesis: objective {result.objective:.3g} after "
        f"{result.evaluations} evaluations, {result.seconds:.2g} s (seed {result.seed})"
    )
    fig.tight_layout()
    return fig


def write_history_chart(result: DesignResult, path: str, name: str = "path") -> None:
    """Draw :func:`draw_history` into ``path`` (``.svg``, ``.png``, ``.pdf``), atomically."""
    import matplotlib.pyplot as plt

    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output, write_atomically

    check_output(path, FIGURE_SUFFIXES, name=name)
    fig = draw_history(result)
    try:
        write_atomically(path, fig.savefig, name=name)
    except ValueError as exc:  # matplotlib refusing the figure
        raise MechanismError(f"{name}: cannot draw the chart ({exc})") from None
    finally:
        plt.close(fig)
