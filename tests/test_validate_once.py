"""Validate once at the boundary: one public call checks the mechanism, its drivers and
its geometry once, then hands the checked model inward.

Every check is wrapped by a counter wherever a module holds it (module-level and
function-level imports alike), then the public entry points are called.
"""

from __future__ import annotations

import sys
from collections import Counter
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

import mjstruct
import mjstruct.dynamics.analysis
import mjstruct.dynamics.data
import mjstruct.kinematics.solver
import mjstruct.singular.analysis
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from project_paths import EXAMPLES

#: the checks counted: source module -> function names
CHECKS = {
    "mjstruct.mechanism": ("expect_mechanism", "checked_driver_ids"),
    "mjstruct.structure.drivers": ("validate_drivers",),
    "mjstruct.kinematics.geometry": ("geometry_of", "read_geometry"),
    "mjstruct.dynamics.data": ("read_dynamics",),
}


@pytest.fixture
def counted(monkeypatch: pytest.MonkeyPatch) -> Iterator[Counter[str]]:
    calls: Counter[str] = Counter()
    originals = {
        getattr(sys.modules[mod], name): name for mod, names in CHECKS.items() for name in names
    }

    def wrap(f: Callable[..., Any], name: str) -> Callable[..., Any]:
        def counting(*a: Any, **k: Any) -> Any:
            calls[name] += 1
            return f(*a, **k)

        return counting

    for modname, module in list(sys.modules.items()):
        if not modname.startswith("mjstruct"):
            continue
        for attr, value in list(vars(module).items()):
            if callable(value) and value in originals:
                monkeypatch.setattr(module, attr, wrap(value, originals[value]))
    yield calls


ZHIVAGO = EXAMPLES / "zhivago-dynamics.json"


@pytest.mark.parametrize(
    "mode",
    [
        {"qdot0": 20.0},
        {"speed": 2.0},
        {"q": [0.1, 0.2], "qdot": 1.0, "qddot": 0.5, "parameters": {"p": 0.3}},
    ],
)
def test_dynamic_analysis_checks_each_input_once(counted, mode):
    m = read_mechanism(ZHIVAGO)
    counted.clear()
    mjstruct.dynamic_analysis(m, frames=8, **mode)
    assert counted == {
        "expect_mechanism": 1,
        "validate_drivers": 1,
        "checked_driver_ids": 1,
        "geometry_of": 1,
        "read_dynamics": 1,
    }


def test_a_model_given_to_the_dynamics_is_trusted(counted):
    m = read_mechanism(ZHIVAGO)
    model = KinematicModel.build(m)
    assert counted["validate_drivers"] == counted["geometry_of"] == 1
    counted.clear()
    mjstruct.dynamic_analysis(m, speed=2.0, frames=8, model=model)
    # the mechanism's type is checked (it must be the model's); drivers and geometry
    # are the model's own
    assert counted == {"expect_mechanism": 1, "read_dynamics": 1}


def test_kinematic_analysis_checks_each_input_once(counted):
    m = read_mechanism(EXAMPLES / "kin-radial-engine-5.json")
    counted.clear()
    r = mjstruct.kinematic_analysis(m, frames=8)
    assert r.valid.all() and np.isfinite(r.joints["A"]["x"]).all()
    assert counted == {
        "expect_mechanism": 1,
        "validate_drivers": 1,
        "checked_driver_ids": 1,
        "geometry_of": 1,
    }


def test_singular_analysis_checks_each_input_once(counted):
    m = read_mechanism(EXAMPLES / "four-bar.json")
    counted.clear()
    mjstruct.singular_analysis(m)
    assert counted == {
        "expect_mechanism": 1,
        "validate_drivers": 1,
        "checked_driver_ids": 1,
        "geometry_of": 1,
    }


def test_the_counter_sees_every_check(counted):
    # the fixture wraps the checks where the entry points find them: a direct call of
    # the public reader counts its own check and the driver check inside it
    m = read_mechanism(EXAMPLES / "four-bar.json")
    counted.clear()
    mjstruct.read_geometry(m)
    assert counted == {
        "read_geometry": 1,
        "expect_mechanism": 1,
        "validate_drivers": 1,
        "checked_driver_ids": 1,
        "geometry_of": 1,
    }
