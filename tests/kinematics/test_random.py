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
from mjstruct.kinematics.closure import closure_jacobian
from mjstruct.kinematics.evaluate import evaluate
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.kinematics.tolerances import STALL_ERROR

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


@settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.filter_too_much],
)
@given(
    name=st.sampled_from(sorted(TOPOLOGIES)),
    xy=st.lists(st.floats(-1.0, 1.0), min_size=14, max_size=14),
)
def test_any_reference_configuration_moves_consistently(name, xy):
    """Any placement of the joint centres is a valid reference configuration."""
    pts = [complex(xy[2 * k], xy[2 * k + 1]) for k in range(7)]
    # generic geometry: no two centres nearly coincide (that is a singular position)
    assume(min(abs(a - b) for i, a in enumerate(pts) for b in pts[i + 1 :]) > 0.05)
    try:
        m, drivers = _random_mechanism(name, xy)
        r0 = kinematic_analysis(m, drivers=drivers, frames=1, checks="full")
    except MechanismError:
        assume(False)  # coincident centres: bad input, tested elsewhere
        return
    # a reference with extra mobility (rank-deficient Jacobian) is a singular position
    assume(r0.checks["jacobian"]["dof"] == len(drivers))
    q0 = r0.q[0, 0]
    h = 2e-4
    # closed to 1e-14: second differences at h / 2 = 1e-4 amplify the closure error
    # by about 1e9 (at the default 1e-12 they would be noise of order 1e-3)
    steps = q0 + h * np.array([-1.0, -0.5, 0.0, 0.5, 1.0])
    r = kinematic_analysis(m, drivers=drivers, q=steps, tol=1e-14)
    assume(r.valid.all())
    # away from dead points: every dyad's sine, and the closure's conditioning
    ev = evaluate(r.model, r.q[2:3], order=0)
    assume(all(abs(det[0]) > 0.05 for _, det in ev.diag.values()))
    assume(r.closure is None or np.abs(r.closure.t1[2]).max() < 20)
    if r.plan.unknowns:
        # nor at a fold of the closure (its Jacobian in the unknowns near singular
        # at the reference: the branch through it ends there)
        _, Rt = closure_jacobian(r.model, r.model.q_ref[None, :], np.zeros((1, r.plan.unknowns)))
        assume(np.linalg.svd(Rt[0], compute_uv=False).min() > 0.1 * r.geometry.scale)
    # the reference is reproduced, and the links keep their lengths, to what the
    # closure accepts: tol × STALL_ERROR of the size (1e-11; measured at most 3.3e-14
    # over these derandomized cases)
    lim = 1e-14 * STALL_ERROR * r.geometry.scale
    for j in m.joints:
        assert r.joints[j.id]["x"][2] == pytest.approx(j.at[0], abs=lim)
        assert r.joints[j.id]["y"][2] == pytest.approx(j.at[1], abs=lim)
    assert r.checks["link_lengths"]["max_error"] < lim
    # analogs against central differences: halving h must shrink the gap about 4x
    # (it would stall at the analog's own error if that were wrong)
    for j in m.joints:
        for c, s, k in (("x", "sx", "kx"), ("y", "sy", "ky")):
            x = r.joints[j.id][c]
            sig, kap = r.joints[j.id][s][2], r.joints[j.id][k][2]
            e1 = abs((x[4] - x[0]) / (2 * h) - sig)
            e2 = abs((x[3] - x[1]) / h - sig)
            assert e2 <= 0.35 * e1 + 1e-7 * (1 + abs(sig)), (j.id, c, e1, e2)
            k1 = abs((x[4] - 2 * x[2] + x[0]) / h**2 - kap)
            k2 = abs((x[3] - 2 * x[2] + x[1]) / (h / 2) ** 2 - kap)
            assert k2 <= 0.35 * k1 + 1e-3 * (1 + abs(kap)), (j.id, c, k1, k2)


def test_radial_engine_multiple_joint_against_closed_form():
    m = read_mechanism(example_path("kin-radial-engine-5"))
    assert max(len(j.links) for j in m.joints) == 6  # one pin for the crank and 5 rods
    r = kinematic_analysis(m, frames=360, speed=3.0)
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
