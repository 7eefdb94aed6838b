"""What a synthesis run returns: the designed mechanism and the numbers that judge it.

Owns :class:`DesignResult`, shared by every task kind (path, function, motion and the
four-bar matrix synthesis), and its JSON object (the keys of ``mjstruct synthesize
--json`` in the contract: ``objective``, ``feasible``, ``errors``, ``evaluations``,
``seconds``, ``seed``, and more).  The designed mechanism carries the task's targets
under its ``synthesis`` key, so a drawing of the written file can show them.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> m = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]), ("O2", [3, 0])],
...                     frame=0, drivers=["O1"])
>>> r = DesignResult(m, "path", 1e-3, True, (1e-3, 2e-4), 640, 0.5, 1)
>>> sorted(r.to_dict())[:4]
['details', 'errors', 'evaluations', 'feasible']
>>> r.to_dict()["max_error"]
0.001
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from mjstruct.mechanism import Mechanism
from mjstruct.output_numbers import json_number

#: the key of a mechanism file under which a synthesised design keeps its task's targets
SYNTHESIS_KEY = "synthesis"


@dataclass(frozen=True)
class DesignResult:
    """A synthesised mechanism and how well it does the task.

    Attributes
    ----------
    mechanism : the designed mechanism (its reference geometry set; the task's targets
        under ``extra["synthesis"]``).
    task : the task kind (``"path"``, ``"function"``, ``"motion"``, ``"fourbar-ms"``).
    objective : the value of the task's objective at the design (for the fitting
        tasks the root mean square of ``errors``; in the task's units).
    feasible : True when every constraint of the task holds at the design.
    errors : per target, the distance (or angle) between the target and what the
        design does there.
    evaluations : objective evaluations spent (candidates × targets counted once per
        candidate).
    seconds : wall time of the run.
    seed : the random seed (the same task and seed give the same design).
    history : (evaluations, seconds, best objective) after each stage or generation:
        the error-against-run-time record of the run.
    margins : per constraint, its margin at the design (>= 0: satisfied).
    details : task-specific numbers (the four-bar matrix, singular positions, zones,
        the timing found for untimed targets, ...), JSON-ready.
    """

    mechanism: Mechanism
    task: str
    objective: float
    feasible: bool
    errors: tuple[float, ...]
    evaluations: int
    seconds: float
    seed: int | None
    history: tuple[tuple[int, float, float], ...] = ()
    margins: Mapping[str, float] = field(default_factory=dict)
    details: Mapping[str, Any] = field(default_factory=dict)

    @property
    def max_error(self) -> float | None:
        """The largest per-target error (None without targets)."""
        return max(self.errors) if self.errors else None

    def to_dict(self) -> dict[str, Any]:
        """The ``synthesize --json`` object (finite numbers or null)."""
        return {
            "task": self.task,
            "objective": json_number(self.objective),
            "feasible": self.feasible,
            "errors": [json_number(e) for e in self.errors],
            "max_error": None if self.max_error is None else json_number(self.max_error),
            "evaluations": self.evaluations,
            "seconds": json_number(self.seconds),
            "seed": self.seed,
            "history": [[k, json_number(t), json_number(f)] for k, t, f in self.history],
            "margins": {k: json_number(v) for k, v in self.margins.items()},
            "details": dict(self.details),
        }
