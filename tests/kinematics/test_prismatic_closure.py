"""Newton closure through prismatic joints (issue 12, "Also in scope").

A class-III triad with a slider inside the group, solved by closure, against an
independent scipy fsolve of its loop equations; an inverted slider-crank driven at
its slide against its closed form.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest
from scipy.optimize import fsolve

from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_from_dict
from mjstruct.kinematics.solver import kinematic_analysis


def _rot(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s], [s, c]])


def _triad(prismatic: str, axis: list[float]) -> dict[str, Any]:
    d: dict[str, Any] = json.loads(example_path("triad-class-iii").read_text(encoding="utf-8"))
    for j in d["joints"]:
        if j["id"] == prismatic:
            j["type"], j["axis"] = "P", axis
    return d


def _ref(d: dict[str, Any]) -> dict[str, np.ndarray]:
    return {j["id"]: np.array(j["at"], dtype=float) for j in d["joints"]}


def _xy(r: Any, jid: str) -> np.ndarray:
    return np.stack([r.joints[jid]["x"], r.joints[jid]["y"]], axis=1)


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


# --- (1a) slider B between leg 3 and the ternary link 2 --------------------------------
# The crank (O1 A, angle q) is placed; the group 2-3-4-5 has no triangle sequence.
# Loop equations in the rotations from the reference: phi (links 3 and 2 together,
# the prismatic pair keeps their relative angle), s (the slide of 2 on 3 along the
# guide), phi4, phi5 (the legs about O2, O3).
AXIS_B = np.array([1.0, 1.5])


def _triad_b_positions(q: float, x: np.ndarray, P: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    phi, s, phi4, phi5 = x
    R = _rot(phi)
    a = _rot(q) @ P["A"]  # q_ref = 0: A - O1 lies on +x at the reference
    b = a + R @ (P["B"] - P["A"]) + s * (R @ AXIS_B) / np.linalg.norm(AXIS_B)
    return {
        "A": a,
        "B": b,
        "C": b + R @ (P["C"] - P["B"]),
        "D": b + R @ (P["D"] - P["B"]),
        "C4": P["O2"] + _rot(phi4) @ (P["C"] - P["O2"]),
        "D5": P["O3"] + _rot(phi5) @ (P["D"] - P["O3"]),
    }


def _triad_b_residual(x: np.ndarray, q: float, P: dict[str, np.ndarray]) -> np.ndarray:
    p = _triad_b_positions(q, x, P)
    return np.concatenate([p["C"] - p["C4"], p["D"] - p["D5"]])


@pytest.fixture(scope="module")
def slider_b():  # type: ignore[no-untyped-def]
    d = _triad("B", list(AXIS_B))
    return d, kinematic_analysis(mechanism_from_dict(d), frames=360, speed=1.0)


def test_the_slider_triad_is_solved_by_closure(slider_b):
    _, r = slider_b
    plan = r.model.plan
    kinds = [s.kind for s in plan.steps]
    assert plan.unknowns == 1 and r.closure is not None
    assert "assume" in kinds and any(k.startswith("close-") for k in kinds)
    # the slider sits inside the closed group: after the assumed angle of leg 3 a
    # slider dyad on B's guide (carried by leg 3) is solved inside the iteration
    assert any(s.kind == "RRP" and "B" in s.inputs and s.base == "3" for s in plan.steps)


def test_the_slider_triad_keeps_lengths_and_guide_on_every_frame(slider_b):
    d, r = slider_b
    P = _ref(d)
    ok = r.valid
    assert ok.all()  # the crank turns fully on this branch (360/360 frames)
    A, B, C, D = (_xy(r, j) for j in "ABCD")
    O2, O3 = P["O2"], P["O3"]
    for got, want in (
        (np.linalg.norm(A, axis=1), np.linalg.norm(P["A"])),
        (np.linalg.norm(C - O2, axis=1), np.linalg.norm(P["C"] - O2)),
        (np.linalg.norm(D - O3, axis=1), np.linalg.norm(P["D"] - O3)),
        (np.linalg.norm(C - D, axis=1), np.linalg.norm(P["C"] - P["D"])),
        (np.linalg.norm(B - C, axis=1), np.linalg.norm(P["B"] - P["C"])),
        (np.linalg.norm(B - D, axis=1), np.linalg.norm(P["B"] - P["D"])),
    ):
        assert np.abs(got - want).max() < 1e-9
    # guide: link 2 turns by phi (from C, D); leg 3 turns by the same phi and B (on 2)
    # stays on leg 3's guide line through A + R(phi)(B0 - A0), direction R(phi) axis
    dc = D - C
    phi = np.arctan2(dc[:, 1], dc[:, 0]) - np.arctan2(*(P["D"] - P["C"])[::-1])
    guide = np.stack(
        [
            np.cos(phi) * AXIS_B[0] - np.sin(phi) * AXIS_B[1],
            np.sin(phi) * AXIS_B[0] + np.cos(phi) * AXIS_B[1],
        ],
        axis=1,
    )
    off = P["B"] - P["A"]
    base = A + np.stack(
        [np.cos(phi) * off[0] - np.sin(phi) * off[1], np.sin(phi) * off[0] + np.cos(phi) * off[1]],
        axis=1,
    )
    assert np.abs(_cross(B - base, guide)).max() / np.linalg.norm(AXIS_B) < 1e-9
    # the slide really moves (the guide is used, not frozen at the reference)
    assert np.ptp(np.einsum("ij,ij->i", B - base, guide)) > 0.1


def test_the_slider_triad_matches_fsolve_of_its_loop_equations(slider_b):
    d, r = slider_b
    P = _ref(d)
    q = r.q[:, 0]
    x = np.zeros(4)  # the reference configuration
    compared = 0
    for k in range(0, 360):
        # continuation in 1 deg steps, split in 4 so fsolve stays on the branch
        for sub in np.linspace(q[k - 1] if k else q[0], q[k], 5)[1:] if k else [q[0]]:
            x = fsolve(_triad_b_residual, x, args=(float(sub), P))
            # judged by the residual (fsolve's flag complains when it starts converged)
            assert np.abs(_triad_b_residual(x, float(sub), P)).max() < 1e-9
        if k % 45 == 7:
            p = _triad_b_positions(float(q[k]), x, P)
            for j in "ABCD":
                assert np.abs(_xy(r, j)[k] - p[j]).max() < 1e-7, (k, j)
            compared += 1
    assert compared == 8


# --- (1b) slider O3 between leg 5 and the frame: the closure unknown is a slide ------
AXIS_O3 = np.array([1.0, 1.5])


def _triad_o3_positions(
    q: float, x: np.ndarray, P: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    phi3, phi2, phi4, t = x
    a = _rot(q) @ P["A"]
    b = a + _rot(phi3) @ (P["B"] - P["A"])
    R2 = _rot(phi2)
    return {
        "A": a,
        "B": b,
        "C": b + R2 @ (P["C"] - P["B"]),
        "D": b + R2 @ (P["D"] - P["B"]),
        "C4": P["O2"] + _rot(phi4) @ (P["C"] - P["O2"]),
        # leg 5 translates along the frame's guide (its angle is the frame's)
        "D5": P["D"] + t * AXIS_O3 / np.linalg.norm(AXIS_O3),
    }


def _triad_o3_residual(x: np.ndarray, q: float, P: dict[str, np.ndarray]) -> np.ndarray:
    p = _triad_o3_positions(q, x, P)
    return np.concatenate([p["C"] - p["C4"], p["D"] - p["D5"]])


def test_a_frame_slider_in_the_triad_closes_on_its_slide_and_matches_fsolve():
    d = _triad("O3", list(AXIS_O3))
    P = _ref(d)
    r = kinematic_analysis(mechanism_from_dict(d), frames=360, speed=1.0)
    kinds = [s.kind for s in r.model.plan.steps]
    assert "assume-slide" in kinds and r.model.plan.unknowns == 1
    ok = r.valid
    assert ok[0] and 40 < ok.sum() < 360  # the crank rocks on this branch
    B, C, D = (_xy(r, j) for j in "BCD")
    # leg 5 slides on the frame's guide without turning: D - D0 along the guide
    assert np.abs(_cross(D[ok] - P["D"], AXIS_O3)).max() < 1e-9
    assert np.ptp((D[ok] - P["D"]) @ AXIS_O3) > 0.05
    assert (
        np.abs(np.linalg.norm(C[ok] - P["O2"], axis=1) - np.linalg.norm(P["C"] - P["O2"])).max()
        < 1e-9
    )
    assert (
        np.abs(np.linalg.norm(B[ok] - C[ok], axis=1) - np.linalg.norm(P["B"] - P["C"])).max()
        < 1e-9
    )
    # the frames reached from the reference increasing q: follow them with fsolve
    run = int(np.argmin(ok)) if not ok.all() else 360
    assert run > 20
    q = r.q[:, 0]
    x = np.zeros(4)
    for k in range(1, run):
        for sub in np.linspace(q[k - 1], q[k], 5)[1:]:
            x = fsolve(_triad_o3_residual, x, args=(float(sub), P))
            # judged by the residual (fsolve's flag complains when it starts converged)
            assert np.abs(_triad_o3_residual(x, float(sub), P)).max() < 1e-9
        if k in (1, run // 3, 2 * run // 3, run - 3):
            p = _triad_o3_positions(float(q[k]), x, P)
            for j in "ABCD":
                assert np.abs(_xy(r, j)[k] - p[j]).max() < 1e-7, (k, j)


# --- (2) inverted slider-crank driven at its slide ------------------------------------
# Crank O1 A (length rc), block 2 pinned at A and sliding on the rocker 3 that turns
# about O2 = (b, 0); the guide passes through O2. Driven at the slide S: q is the slide
# of the block along the guide (pointing from O2 to A), so rho = |A - O2| = rho0 + q.
# Closed form: |A|^2 = b^2 + 2 b rho cos(psi) + rho^2 = rc^2.
def _inverted(rho: np.ndarray, b: float, rc: float) -> tuple[np.ndarray, np.ndarray]:
    cpsi = (rc**2 - b**2 - rho**2) / (2 * b * rho)
    spsi = np.sqrt(1 - cpsi**2)  # the reference has A above the line of centres
    dcpsi = -(rc**2 - b**2) / (2 * b * rho**2) - 1 / (2 * b)
    dpsi = -dcpsi / spsi
    pos = np.stack([b + rho * cpsi, rho * spsi], axis=1)
    vel = np.stack([cpsi - rho * spsi * dpsi, spsi + rho * cpsi * dpsi], axis=1)
    return pos, vel


@pytest.mark.parametrize("speed", [1.0, -2.5])
def test_inverted_slider_crank_driven_at_its_slide_matches_the_closed_form(speed):
    b, rc, th = 2.0, 1.0, 1.1
    a0 = np.array([rc * np.cos(th), rc * np.sin(th)])
    u = a0 - [b, 0.0]
    d = {
        "frame": "0",
        "joints": [
            {"id": "O1", "links": ["0", "1"], "at": [0.0, 0.0]},
            {"id": "A", "links": ["1", "2"], "at": list(a0)},
            {"id": "S", "links": ["3", "2"], "type": "P", "at": list(a0), "axis": list(u)},
            {"id": "O2", "links": ["3", "0"], "at": [b, 0.0]},
        ],
        "drivers": ["S"],
    }
    rho0 = float(np.linalg.norm(u))
    # rho in (b - rc, b + rc) = (1, 3); rho0 = 1.63: stay inside
    q = np.linspace(-0.55, 1.2, 41)
    r = kinematic_analysis(mechanism_from_dict(d), q=q, speed=speed)
    assert r.valid.all() and not r.warnings
    pos, vel = _inverted(rho0 + q, b, rc)
    A = _xy(r, "A")
    assert np.abs(A - pos).max() < 1e-10
    # the block's point S coincides with A (the joint's at is carried by the block)
    assert np.abs(_xy(r, "S") - pos).max() < 1e-10
    v = np.stack([r.joints["A"]["vx"], r.joints["A"]["vy"]], axis=1)
    assert np.abs(v - speed * vel).max() < 1e-9
    # the closed form's derivative is itself right (central differences)
    h = 1e-6
    fd = (_inverted(rho0 + q + h, b, rc)[0] - _inverted(rho0 + q - h, b, rc)[0]) / (2 * h)
    assert np.abs(fd - vel).max() < 1e-6
