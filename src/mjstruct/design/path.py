"""Path synthesis: a point of a one-DOF mechanism through target points.

Owns :func:`path_problem`: the path task as a :class:`~mjstruct.design.track.
TrackProblem` whose targets are positions of the task's ``point`` — timed (at the
given driver values, with a free common offset under ``timing_offset``) or untimed
(met in their order along one driver cycle; the matching is part of the problem).

Examples
--------
>>> from mjstruct.design.task import task_from_dict
>>> from mjstruct.io import mechanism_to_dict, read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> m = mechanism_to_dict(read_mechanism(example_path("four-bar")))
>>> p = path_problem(task_from_dict({"task": "path", "mechanism": m, "point": "M",
...                                  "targets": [[0.4, 0.6], [0.2, 0.9]]}))
>>> p.kind, p.targets, p.timed
('path', 2, False)
"""

from __future__ import annotations

from mjstruct.design.task import Task
from mjstruct.design.track import TrackProblem


def path_problem(task: Task) -> TrackProblem:
    """The path task ``task`` ready for :func:`~mjstruct.design.search.solve`."""
    assert task.kind == "path" and task.point is not None
    positions = task.targets[:, 0] + 1j * task.targets[:, 1]
    return TrackProblem(task, task.point, positions, None, None, 1.0, task.timing)
