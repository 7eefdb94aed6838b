"""Task values a double cannot work with as the task means them, and tasks with nothing
left to design: bad input naming the field, before any search (issue 37 A2, B9)."""

from __future__ import annotations

import warnings

import pytest

from mjstruct.design.api import synthesize
from mjstruct.design.task import task_from_dict
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_to_dict, read_mechanism
from project_paths import EXAMPLES

TARGETS = [[0.5, 1.1], [0.3, 1.1], [0.1, 0.9]]


def _task(**extra):
    m = mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json"))
    return {"task": "path", "mechanism": m, "point": "M", "targets": TARGETS, **extra}


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        ({"timing": [1e300, 2e300, 5e300]}, "timing[0]"),  # A2: was reported feasible
        ({"timing": [1.0, 2.0, 3e6]}, "timing[2]"),
        ({"targets": [[0.5, 1.1], [1e308, 1.1], [0.1, 0.9]]}, "targets[1]"),  # B9
        ({"targets": [[0.5, 1.1], [1e308, 1.1], [-1e308, 0.9]]}, "targets[1]"),
        ({"region": {"B": [[-1e308, -1.0], [1e308, 1.0]]}}, "region.B"),
        ({"fixed": ["O1", "A", "B", "O2", "M"]}, "fixed"),  # B9: every position fixed
    ],
)
def test_refused_naming_the_field_without_a_warning(extra, field):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no leaked numpy RuntimeWarning
        with pytest.raises(MechanismError) as exc:
            synthesize(_task(**extra), seed=0)
    assert str(exc.value).startswith(f"{field}: ")


def test_function_and_motion_angles_and_driver_values_are_bounded():
    m = mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json"))
    with pytest.raises(MechanismError, match=r"^targets\[1\]: "):
        task_from_dict({"task": "function", "mechanism": m,
                        "targets": [[1.0, 0.1], [2.0, 1e300]]})  # fmt: skip
    with pytest.raises(MechanismError, match=r"^targets\[0\]: "):
        task_from_dict({"task": "function", "mechanism": m,
                        "targets": [[-1e7, 0.1], [2.0, 0.2]]})  # fmt: skip
    with pytest.raises(MechanismError, match=r"^targets\[1\]: "):
        task_from_dict({"task": "motion", "mechanism": m, "point": "M",
                        "targets": [[0.5, 1.1, 0.0], [0.3, 1.0, -1e9]]})  # fmt: skip


def test_values_within_the_limits_are_accepted():
    t = task_from_dict(_task(timing=[1.0, 2.0, 1e5], targets=[[0.5, 1.1], [1e3, 1.1], [0, 0]]))
    assert t.timing is not None and t.targets.shape == (3, 2)
    t = task_from_dict(_task(fixed=["O1", "A", "B", "O2"]))  # the point is still free
    assert t.fixed == ("O1", "A", "B", "O2")
