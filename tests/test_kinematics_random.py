"""Kinematics on random geometry of several topologies, and a multiple-joint engine."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from mjstruct.catalog_files import example_path
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.kinematics.solver import kinematics

TOPOLOGIES = {
    # name: (example file, drivers); the random geometry replaces every "at"
    "four-bar": ("four-bar", ["O1"]),
    "watt": ("watt", ["O1"]),
    "stephenson": ("stephenson", ["O1"]),
    "class-iv": ("class-iv-seed003", ["O"]),
    "zhivago-E": ("zhivago", ["E"]),
    "zhivago-O": ("zhivago", ["O"]),
}


def _random_mechanism(name: str, xy: list[float]):
    data = mechanism_to_dict(read_mechanism(example_path(TOPOLOGIES[name][0])))
    data.pop("points", None)
    for k, j in enumerate(data["joints"]):
        j["at"] = [xy[2 * k], xy[2 * k + 1]]
    return mechanism_from_dict(data), TOPOLOGIES[name][1]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(
    name=st.sampled_from(sorted(TOPOLOGIES)),
    xy=st.lists(st.floats(-1.0, 1.0), min_size=14, max_size=14),
)
def test_any_reference_configuration_moves_consistently(name, xy):
    """Any placement of the joint centres is a valid reference configuration."""
    try:
        m, drivers = _random_mechanism(name, xy)
        h = 1e-4
        r0 = kinematics(m, drivers=drivers, frames=1)
    except MechanismError:
        assume(False)  # coincident centres: bad input, tested elsewhere
        return
    q0 = r0.q[0, 0]
    # away from singular reference configurations (the analogs are finite there)
    assume(r0.checks["jacobian"]["min_abs_det"] is not None)
    assume(r0.checks["jacobian"]["min_abs_det"] > 1e-2)
    r = kinematics(m, drivers=drivers, q=q0 + np.array([-h, 0.0, h]))
    assume(r.valid.all())
    for j in m.joints:  # the reference is reproduced
        assert r.joints[j.id]["x"][1] == pytest.approx(j.at[0], abs=1e-9)
        assert r.joints[j.id]["y"][1] == pytest.approx(j.at[1], abs=1e-9)
    assert r.checks["link_lengths"]["max_error"] < 1e-9
    for j in m.joints:  # analogs against central differences
        for c, s, k in (("x", "sx", "kx"), ("y", "sy", "ky")):
            x = r.joints[j.id][c]
            fd = (x[2] - x[0]) / (2 * h)
            fd2 = (x[2] - 2 * x[1] + x[0]) / h**2
            sig, kap = r.joints[j.id][s][1], r.joints[j.id][k][1]
            assert fd == pytest.approx(sig, abs=1e-5 * (1 + abs(sig) + abs(kap)))
            assert fd2 == pytest.approx(kap, abs=1e-2 * (1 + abs(kap)) + 1e-3 * abs(sig))


def test_radial_engine_multiple_joint_against_closed_form():
    m = read_mechanism(example_path("kin-radial-engine-5"))
    assert max(len(j.links) for j in m.joints) == 6  # one pin for the crank and 5 rods
    r = kinematics(m, frames=360, speed=3.0)
    assert r.valid.all() and r.warnings == []
    assert r.plan.complexity()["right"] == 10
    th = r.q[:, 0]
    A = 0.05 * np.exp(1j * th)
    dA, ddA = 1j * A * 3.0, -A * 9.0
    for k in range(1, 6):
        u = cmath.exp(1j * math.radians(90 + 72 * (k - 1)))
        p = (A * np.conj(u)).real
        hgt = (A * np.conj(u)).imag
        root = np.sqrt(0.2**2 - hgt**2)
        s = p + root
        dp, dh = (dA * np.conj(u)).real, (dA * np.conj(u)).imag
        ddp, ddh = (ddA * np.conj(u)).real, (ddA * np.conj(u)).imag
        ds = dp - hgt * dh / root
        dds = ddp - (dh * dh + hgt * ddh) / root - (hgt * dh) ** 2 / root**3
        B = r.joints[f"B{k}"]
        got = B["x"] + 1j * B["y"]
        assert np.abs(got - s * u).max() < 1e-14
        assert np.abs((B["vx"] + 1j * B["vy"]) - ds * u).max() < 1e-13
        assert np.abs((B["ax"] + 1j * B["ay"]) - dds * u).max() < 1e-12
