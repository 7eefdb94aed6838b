"""Task values a double cannot work with as the task means them, and tasks with nothing
left to design: bad input naming the field, before any search (issue 37 A2, B9)."""

from __future__ import annotations

import json
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


@pytest.mark.parametrize(
    ("task", "field", "words"),
    [  # issue 37 C14: messages that named the wrong field or gave a wrong range
        ({"ms": "MS4", "frame_length": 1e300}, "frame_length", "outside the sizes analysed"),
        ({"ms": "MS4", "coupler_point": [1e300, 0.0]}, "coupler_point", "1e+08 sizes"),
        (
            {"change_point": "4.2", "swing_deg": 180},
            "swing_deg",
            "180 deg is an end of that range, approached but not reached",
        ),
        (
            {"change_point": "4.2", "time_ratio": 1e300},
            "time_ratio",
            "those there give about 3 to 5",
        ),
        (
            {"change_point": "4.3", "swing_deg": 240, "time_ratio": 1e300},
            "time_ratio",
            "those there give about 1.0",
        ),
    ],
)
def test_fourbar_ms_messages_name_the_field_and_the_reachable_range(task, field, words):
    with pytest.raises(MechanismError) as exc:
        synthesize({"task": "fourbar-ms", **task})
    message = str(exc.value)
    assert message.startswith(f"{field}: ") and words in message, message


def test_a_json_task_with_a_byte_order_mark_is_read_and_broken_json_is_called_json(tmp_path):
    from mjstruct.design.task import read_task

    m = mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json"))
    body = json.dumps({"task": "path", "mechanism": m, "point": "M", "targets": TARGETS})
    path = tmp_path / "t.json"
    path.write_bytes(b"\xef\xbb\xbf" + body.encode())
    assert read_task(path).kind == "path"  # was "not valid TOML"
    for broken in ('{"task": "path",}', "[1, 2", "task = path"):
        path.write_text(broken)
        with pytest.raises(MechanismError, match="not valid JSON"):
            read_task(path)
    toml = tmp_path / "t.toml"
    toml.write_bytes(b"\xef\xbb\xbf" + b'task = "fourbar-ms"\nms = "MS4"\n')
    assert read_task(toml).kind == "fourbar-ms"
    mech = tmp_path / "m.json"
    mech.write_bytes(b"\xef\xbb\xbf" + (EXAMPLES / "four-bar.json").read_bytes())
    assert read_mechanism(mech).name == "four-bar"


def test_two_timed_targets_at_one_driver_value_must_be_one_target():
    with pytest.raises(MechanismError, match=r"^timing\[2\]: the driver value of timing\[0\]"):
        task_from_dict(_task(timing=[1.0, 2.0, 1.0]))
    t = task_from_dict(_task(targets=[TARGETS[0], TARGETS[1], TARGETS[0]], timing=[1.0, 2.0, 1.0]))
    assert t.timing is not None  # the same target twice is one target
    m = mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json"))
    with pytest.raises(MechanismError, match=r"^targets\[1\]: "):
        task_from_dict({"task": "function", "mechanism": m, "targets": [[0, 0], [0, 1]]})
