"""Parsed and compiled loads are kept per mechanism object: read once, dropped with it."""

from __future__ import annotations

import gc
import json

import numpy as np
import pytest
import sympy

import mjstruct.dynamics.data as data_module
from mjstruct.dynamics import dynamic_analysis
from mjstruct.dynamics.data import read_dynamics
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict
from mjstruct.mechanism import Mechanism
from project_paths import EXAMPLES

SEED = EXAMPLES / "slider-crank-seed000-dynamics.json"


def seed(moment: str | None = None) -> Mechanism:
    d = json.loads(SEED.read_text())
    if moment is not None:
        d["loads"][0]["moment"] = moment
    return mechanism_from_dict(d)


@pytest.fixture
def lambdify_calls(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    calls: list[int] = []
    original = sympy.lambdify

    def counted(*a, **k):
        calls.append(1)
        return original(*a, **k)

    monkeypatch.setattr(sympy, "lambdify", counted)
    return calls


def test_a_second_analysis_of_the_same_mechanism_compiles_nothing(lambdify_calls):
    m = seed()
    first = dynamic_analysis(m, qdot0=10.0, frames=12)
    assert len(lambdify_calls) >= 3  # two loads' components and a switch function
    lambdify_calls.clear()
    dynamic_analysis(m, speed=2.0, frames=12)
    again = dynamic_analysis(m, qdot0=10.0, frames=12)
    assert lambdify_calls == []
    assert read_dynamics(m) is read_dynamics(m)
    # the same numbers from the kept data as from the first reading
    for a, b in ((first.qdot, again.qdot), (first.Q, again.Q), (first.check, again.check)):
        assert np.array_equal(a, b)
    assert first.parameters == again.parameters


def test_equal_mechanisms_with_other_loads_keep_their_own_data():
    # mechanisms compare equal without their extra keys: the cache must not mix them
    a, b = seed(), seed(moment="-20")
    assert a == b and a.extra != b.extra
    ra = dynamic_analysis(a, speed=1.0, frames=8)
    rb = dynamic_analysis(b, speed=1.0, frames=8)
    assert rb.parameters["p"] == pytest.approx(2 * ra.parameters["p"], rel=1e-12)


def test_the_entry_goes_with_the_mechanism():
    m = seed()
    read_dynamics(m)
    key = id(m)
    assert key in data_module._READ
    del m
    gc.collect()
    assert key not in data_module._READ


def test_bad_data_is_not_kept():
    d = json.loads(SEED.read_text())
    d["loads"][0]["moment"] = "-K"
    m = mechanism_from_dict(d)
    for _ in range(2):
        with pytest.raises(MechanismError, match=r"^loads\[0\]\.moment: 'K'"):
            read_dynamics(m)
    assert id(m) not in data_module._READ
