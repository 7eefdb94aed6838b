"""Kinematics plug-in: closed forms, seed tables, closure, branches and extreme cases."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mjstruct.catalog_files import example_path
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.kinematics.solver import kinematic_analysis

# -- builders ---------------------------------------------------------------------


def slider_crank(L1: float, L2: float, theta: float, offset: float = 0.0):
    """In-line (or offset) slider-crank with the crank at ``theta`` in the file."""
    A = (L1 * math.cos(theta), L1 * math.sin(theta))
    xb = A[0] + math.sqrt(L2**2 - (A[1] - offset) ** 2)
    return mechanism_from_dict(
        {
            "frame": "0",
            "drivers": ["O1"],
            "joints": [
                {"id": "O1", "links": ["0", "1"], "at": [0.0, 0.0]},
                {"id": "A", "links": ["1", "2"], "at": list(A)},
                {"id": "B", "links": ["2", "3"], "at": [xb, offset]},
                {"id": "O4", "links": ["0", "3"], "type": "P", "at": [xb, offset], "axis": [1, 0]},
            ],
        }
    )


def four_bar(a: float, b: float, c: float, d: float, theta: float, mode: int = 1):
    """Four-bar O1 A B O2 (crank a, coupler b, rocker c, frame d along x)."""
    A = a * complex(math.cos(theta), math.sin(theta))
    O2 = complex(d, 0)
    D = abs(O2 - A)
    al = (D * D + b * b - c * c) / (2 * D)
    B = A + (al + 1j * mode * math.sqrt(b * b - al * al)) * (O2 - A) / D
    return mechanism_from_dict(
        {
            "frame": "0",
            "drivers": ["O1"],
            "joints": [
                {"id": "O1", "links": ["0", "1"], "at": [0.0, 0.0]},
                {"id": "A", "links": ["1", "2"], "at": [A.real, A.imag]},
                {"id": "B", "links": ["2", "3"], "at": [B.real, B.imag]},
                {"id": "O2", "links": ["3", "0"], "at": [d, 0.0]},
            ],
        }
    )


def slider_closed_form(L1, L2, th, w=1.0):
    """x, v, a of an in-line slider for crank angle th at constant speed w."""
    s, c = np.sin(th), np.cos(th)
    g = L2**2 - (L1 * s) ** 2
    gp = -(L1**2) * np.sin(2 * th)
    gpp = -2 * L1**2 * np.cos(2 * th)
    x = L1 * c + np.sqrt(g)
    dx = -L1 * s + gp / (2 * np.sqrt(g))
    ddx = -L1 * c + gpp / (2 * np.sqrt(g)) - gp**2 / (4 * g**1.5)
    return x, dx * w, ddx * w * w


# -- seed 001 slider-crank ----------------------------------------------------------


def test_seed001_table():
    m = read_mechanism(example_path("slider-crank"))
    r = kinematic_analysis(m, q=np.radians([0, 90, 180, 270]), speed=0.5)
    B = r.joints["B"]
    assert B["x"] == pytest.approx([0.45, 0.335, 0.25, 0.335], abs=6e-4)
    assert B["vx"] == pytest.approx([0.0, -0.05, 0.0, 0.05], abs=1e-12)
    assert np.abs(B["y"]).max() < 1e-15
    assert r.warnings == []


def test_seed001_every_degree_matches_closed_form():
    m = read_mechanism(example_path("slider-crank"))
    r = kinematic_analysis(m, frames=360, speed=0.5)
    th = r.q[:, 0]
    assert np.diff(th) == pytest.approx(np.radians(1.0))
    x, v, a = slider_closed_form(0.1, 0.35, th, 0.5)
    B = r.joints["B"]
    assert np.abs(B["x"] - x).max() < 1e-12
    assert np.abs(B["vx"] - v).max() < 1e-12
    assert np.abs(B["ax"] - a).max() < 1e-12
    # the crank and the slider's angle: crank angle is q, the slider does not turn
    assert np.abs(r.links["1"]["angle"] - th).max() < 1e-12
    assert np.abs(r.links["3"]["omega"]).max() == 0.0
    # the rod's centre (a point of interest) moves as the mean of A and B
    S, A = r.points["S2"], r.joints["A"]
    assert np.abs(S["ax"] - (A["ax"] + B["ax"]) / 2).max() < 1e-12


def test_plan_of_slider_crank_is_two_right_triangles():
    r = kinematic_analysis(read_mechanism(example_path("slider-crank")), frames=8)
    assert r.plan.complexity() == {"general": 0, "right": 2, "checks": 0, "unknowns": 0}
    assert [s.kind for s in r.plan.steps] == ["reference", "driver-R", "RRP"]


def test_reference_configuration_is_reproduced():
    for name in ("slider-crank", "four-bar", "class-iv-seed003", "zhivago"):
        m = read_mechanism(example_path(name))
        r = kinematic_analysis(m, frames=1)
        for j in m.joints:
            assert r.joints[j.id]["x"][0] == pytest.approx(j.at[0], abs=1e-10), (name, j.id)
            assert r.joints[j.id]["y"][0] == pytest.approx(j.at[1], abs=1e-10), (name, j.id)


# -- four-bar against the vector-loop closed form -------------------------------------


def test_four_bar_closed_form_positions_velocities_accelerations():
    a, b, c, d = 0.3, 0.8, 0.7, 1.0
    m = four_bar(a, b, c, d, math.radians(60))
    r = kinematic_analysis(m, frames=720, speed=2.0)
    th = r.q[:, 0]
    # closed form (Freudenstein by half-angle tangent), independent of the solver
    K1, K2, K3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    A_ = np.cos(th) - K1 - K2 * np.cos(th) + K3
    B_ = -2 * np.sin(th)
    C_ = K1 - (K2 + 1) * np.cos(th) + K3
    th4 = 2 * np.arctan((-B_ + np.sqrt(B_**2 - 4 * A_ * C_)) / (2 * A_))
    Bx = d + c * np.cos(th4)
    By = c * np.sin(th4)
    ok = np.abs(Bx - r.joints["B"]["x"]) < 1e-9
    if not ok.all():  # the other root of the quadratic is the other assembly mode
        th4 = 2 * np.arctan((-B_ - np.sqrt(B_**2 - 4 * A_ * C_)) / (2 * A_))
        Bx, By = d + c * np.cos(th4), c * np.sin(th4)
    assert np.abs(Bx - r.joints["B"]["x"]).max() < 1e-12
    assert np.abs(By - r.joints["B"]["y"]).max() < 1e-12
    w1 = 2.0
    Ax, Ay = a * np.cos(th), a * np.sin(th)
    th3 = np.arctan2(By - Ay, Bx - Ax)
    w3 = a * w1 * np.sin(th - th4) / (b * np.sin(th4 - th3))
    w4 = a * w1 * np.sin(th - th3) / (c * np.sin(th4 - th3))
    assert np.abs(r.links["2"]["omega"] - w3).max() < 1e-11
    assert np.abs(r.links["3"]["omega"] - w4).max() < 1e-11
    # accelerations from the differentiated loop equation (a 2x2 solve per frame)
    rhs = a * w1**2 * np.exp(1j * th) + b * w3**2 * np.exp(1j * th3) - c * w4**2 * np.exp(1j * th4)
    # unknowns e3, e4: i b e3 e^{i th3} - i c e4 e^{i th4} = rhs
    g1, g2 = 1j * b * np.exp(1j * th3), -1j * c * np.exp(1j * th4)
    det = g1.real * g2.imag - g1.imag * g2.real
    e3 = (rhs.real * g2.imag - rhs.imag * g2.real) / det
    e4 = (g1.real * rhs.imag - g1.imag * rhs.real) / det
    assert np.abs(r.links["2"]["eps"] - e3).max() < 1e-10
    assert np.abs(r.links["3"]["eps"] - e4).max() < 1e-10


@settings(max_examples=25, deadline=None)
@given(
    a=st.floats(0.1, 0.3),
    b=st.floats(0.9, 1.5),
    c=st.floats(0.9, 1.5),
    theta=st.floats(0.0, 2 * math.pi),
    mode=st.sampled_from([1, -1]),
)
def test_grashof_crank_rocker_keeps_lengths_and_analogs(a, b, c, theta, mode):
    d = 1.0  # s + l <= p + q - 0.1: the crank turns fully, away from change points
    m = four_bar(a, b, c, d, theta, mode)
    r = kinematic_analysis(m, frames=1000, checks="full")
    assert r.valid.all()
    assert r.checks["link_lengths"]["max_error"] < 1e-12
    chk = r.checks["analogs_vs_differences"]
    assert chk["max_error"] < 1e-3 * max(1.0, chk["max_analog"])
    assert r.checks["jacobian"]["rank"] == [8]
    # after a full turn the mechanism is back where it started (same branch)
    r2 = kinematic_analysis(m, q=[theta, theta + 2 * math.pi])
    assert r2.joints["B"]["x"][1] == pytest.approx(r2.joints["B"]["x"][0], abs=1e-9)


# -- seed 003 class-IV mechanism --------------------------------------------------------


def test_seed003_full_72_positions():
    m = read_mechanism(example_path("class-iv-seed003"))
    r = kinematic_analysis(m, frames=72)
    assert r.valid.all() and r.warnings == []
    kinds = [s.kind for s in r.plan.steps]
    # seed 003's strategy: assume link 2's angle, two class-II solutions, compare |DE|
    assert kinds.count("assume") == 1 and "close-distance" in kinds
    assert r.closure is not None and r.closure.error.max() < 1e-12
    assert r.checks["link_lengths"]["max_error"] < 1e-10
    dims = {("O", "A"): 0.279, ("C", "B"): 0.3, ("A", "C"): 0.985, ("D", "E"): 0.554}
    dims |= {("A", "D"): 0.251, ("E", "F"): 1.3, ("B", "F"): 2.06}
    for (p, s), length in dims.items():
        P = r.joints[p]["x"] + 1j * r.joints[p]["y"]
        S = r.joints[s]["x"] + 1j * r.joints[s]["y"]
        assert np.abs(np.abs(P - S) - length).max() < 1e-10, (p, s)
    F = r.joints["F"]
    assert np.abs(F["x"]).max() < 1e-15 and np.abs(F["y"] + 1.08).max() < 1e-15
    # velocities against central differences of positions (h = 1e-4 rad)
    h = 1e-4
    q0 = r.q[:, 0]
    qq = np.column_stack([q0 - h, q0, q0 + h]).ravel()
    rr = kinematic_analysis(m, q=qq)
    for j in ("B", "C", "D", "E"):
        X = rr.joints[j]["x"].reshape(-1, 3) + 1j * rr.joints[j]["y"].reshape(-1, 3)
        fd = (X[:, 2] - X[:, 0]) / (2 * h)
        v = r.joints[j]["vx"] + 1j * r.joints[j]["vy"]
        assert np.abs(fd - v).max() < 1e-7, j
        V = rr.joints[j]["vx"].reshape(-1, 3) + 1j * rr.joints[j]["vy"].reshape(-1, 3)
        fa = (V[:, 2] - V[:, 0]) / (2 * h)
        acc = r.joints[j]["ax"] + 1j * r.joints[j]["ay"]
        assert np.abs(fa - acc).max() < 1e-6, j


# -- extreme cases ------------------------------------------------------------------


@pytest.mark.parametrize("eps", [1e-2, 1e-4, 1e-6, 1e-8])
def test_near_dead_centre_acceleration_follows_inverse_determinant(eps):
    L1 = 0.1
    L2 = L1 * (1 + eps)
    m = slider_crank(L1, L2, math.radians(30))
    q = np.radians(30.0) + np.radians(np.arange(360.0))  # frame 60 is 90 degrees
    q[60] = math.pi / 2
    r = kinematic_analysis(m, q=q, checks="full")
    assert r.valid.all()
    assert all(np.isfinite(v).all() for j in r.joints.values() for v in j.values())
    aB = r.joints["B"]["ax"][60]
    det = abs(r.jacobian.det[60])
    cos_rod = math.sqrt(1 - (L1 / L2) ** 2)
    assert det == pytest.approx(L2 * cos_rod, rel=1e-6)
    # seed 000: normalised slider acceleration = inverse normalised determinant
    assert aB / L1 == pytest.approx(L1 / det, rel=1e-6)
    near = [e for e in r.events if e.joint == "B"]
    assert near and abs(near[0].q - math.pi / 2) < 1e-3
    assert near[0].action == "kept"
    if eps <= 1e-7:  # |det| / max |det| = sqrt(2 eps) < 1e-3: flagged
        assert 60 in r.checks["jacobian"]["near_singular_frames"]
        assert any(w.startswith("near-singular Jacobian") for w in r.warnings)
    assert np.abs(r.joints["B"]["x"] - slider_closed_form(L1, L2, q)[0]).max() < 1e-12


@pytest.mark.parametrize("ratio", [1e-6, 1e6])
def test_extreme_length_ratios(ratio):
    L1, L2 = (ratio, 1.0) if ratio < 1 else (1.0, ratio)
    m = slider_crank(L1, L2, 0.3)
    r = kinematic_analysis(m, frames=90, speed=1.0)
    x, v, a = slider_closed_form(L1, L2, r.q[:, 0])
    B = r.joints["B"]
    assert np.abs(B["x"] - x).max() <= 1e-13 * L2
    assert np.abs(B["vx"] - v).max() <= 1e-9 * L1
    assert np.abs(B["ax"] - a).max() <= 1e-9 * L1


def _jumps(r, link):
    """Largest change of ω between consecutive valid frames."""
    w = r.links[link]["sigma"]
    ok = r.valid[1:] & r.valid[:-1]
    return float(np.abs(np.diff(w))[ok].max())


def test_parallelogram_ms1_passes_change_points_smoothly():
    # seed 004 MS1 = [0.5 1 0.5]: crank 0.5, coupler 1, rocker 0.5, frame 1
    m = four_bar(0.5, 1.0, 0.5, 1.0, math.radians(50), mode=1)
    r = kinematic_analysis(m, frames=360)
    # the reference is the parallelogram: the rocker (vector B -> O2) stays antiparallel
    # to the crank (O1 -> A)
    turn = r.links["3"]["angle"] - r.links["1"]["angle"]
    assert np.abs(np.cos(turn) + 1).max() < 1e-12
    changes = [e for e in r.events if e.kind in ("change point", "singular frame")]
    assert len(changes) == 2
    # the change points: crank along the frame line (q = 0 and q = π)
    assert sorted(round(math.cos(e.q)) for e in changes) == [-1, 1]
    assert all(abs(math.sin(e.q)) < 1e-6 for e in changes)
    assert all(e.action == "switched" for e in changes)
    assert any("change point" in w for w in r.warnings)
    # exactly at a change point the velocity is not determined by the constraints:
    # only those frames are null, and they are reported
    assert set(np.flatnonzero(~r.valid)) <= {e.frame for e in changes}
    # no silent jump: still the parallelogram after both change points, smooth analogs
    assert np.abs(r.links["3"]["omega"] - 1.0)[r.valid].max() < 1e-9
    assert _jumps(r, "3") < 1e-6
    assert r.checks["link_lengths"]["max_error"] < 1e-12


def test_hinged_square_reports_change_points_and_stays_on_branch():
    # seed 004 MS5 = [1 1 1]: the hinged square; at q = 0 the dyad is undefined
    m = four_bar(1.0, 1.0, 1.0, 1.0, math.radians(90), mode=1)
    r = kinematic_analysis(m, frames=360)
    ev = [e for e in r.events if e.kind in ("change point", "singular frame")]
    assert ev, r.warnings
    assert any(abs(math.remainder(e.q, 2 * math.pi)) < 1e-2 for e in ev)
    # the frames that are undefined are reported and null, never NaN in JSON
    d = r.to_dict()
    assert all(
        x is None or math.isfinite(x) for j in d["joints"].values() for v in j.values() for x in v
    )
    ok = r.valid
    assert ok.sum() >= 358
    assert _jumps(r, "3") < 0.05
    assert r.checks["link_lengths"]["max_error"] < 1e-12


def test_infeasible_crank_is_reported_with_its_limits():
    # non-Grashof: crank 0.6, coupler 0.5, rocker 0.7, frame 1 cannot turn fully
    m = four_bar(0.6, 0.5, 0.7, 1.0, math.radians(60), mode=1)
    r = kinematic_analysis(m, frames=360)
    assert not r.valid.all() and r.valid[0]
    assert any(w.startswith("no assembly for q in") for w in r.warnings)
    dead = [e for e in r.events if e.kind == "dead point"]
    assert len(dead) == 2
    # at a dead point the coupler and rocker are aligned: |O2 A| = b + c or |b - c|
    for e in dead:
        A = 0.6 * complex(math.cos(e.q), math.sin(e.q))
        s = abs(A - 1.0)
        assert min(abs(s - 1.2), abs(s - 0.2)) < 1e-6
    d = r.to_dict()
    bad = int(np.flatnonzero(~r.valid)[0])
    assert d["joints"]["B"]["x"][bad] is None


# -- bad input ------------------------------------------------------------------------


def test_missing_geometry_is_bad_input():
    joints = [
        {"id": "a", "links": [0, 1], "at": [0, 0]},
        {"id": "b", "links": [1, 2]},
        {"id": "c", "links": [2, 3], "at": [1, 1]},
        {"id": "d", "links": [3, 0], "at": [1, 0]},
    ]
    m = mechanism_from_dict({"frame": 0, "drivers": ["a"], "joints": joints})
    with pytest.raises(MechanismError, match=r"joints\[1\]\.at"):
        kinematic_analysis(m)


def test_wrong_driver_count_is_bad_input():
    m = read_mechanism(example_path("four-bar"))
    with pytest.raises(MechanismError, match="over-constrained"):
        kinematic_analysis(m, drivers=["O1", "O2"])
    with pytest.raises(MechanismError, match="frames"):
        kinematic_analysis(m, frames=0)


# -- other drivers ------------------------------------------------------------------------


def test_prismatic_driver_moves_the_crank_through_a_dyad():
    L1, L2 = 0.1, 0.35
    m = slider_crank(L1, L2, math.radians(62))
    xb0 = m.joint("B").at[0]
    q = np.linspace(0.0, -0.1, 51)  # the slide from the reference, along the guide
    r = kinematic_analysis(m, drivers=["O4"], q=q)
    assert [s.kind for s in r.plan.steps] == ["reference", "driver-P", "RRR"]
    B, A = r.joints["B"], r.joints["A"]
    assert np.abs(B["x"] - (xb0 + q)).max() < 1e-15
    assert np.abs(B["vx"] - 1.0).max() < 1e-15 and np.abs(B["ax"]).max() < 1e-15
    # the crank angle is the inverse of the closed form x(θ) on this stretch
    th = r.links["1"]["angle"]
    x, v, _ = slider_closed_form(L1, L2, th)
    assert np.abs(x - B["x"]).max() < 1e-13
    assert np.abs(r.links["1"]["sigma"] * v - 1.0).max() < 1e-9  # dθ/dx = 1 / (dx/dθ)
    assert np.abs(np.hypot(A["x"], A["y"]) - L1).max() < 1e-15


def test_two_drivers_five_bar():
    m = read_mechanism(example_path("kin-five-bar"))
    r = kinematic_analysis(m, frames=72, checks="full")
    assert r.q.shape == (72, 2)
    assert r.checks["jacobian"]["dof"] == 2 and r.checks["jacobian"]["rank"] == [10]
    assert r.checks["link_lengths"]["max_error"] < 1e-12
    # both cranks turn at the speed: ω1 = ω4 = 1, and σ is the derivative along (1, 1)
    assert np.abs(r.links["1"]["omega"] - 1).max() < 1e-15
    assert np.abs(r.links["4"]["omega"] - 1).max() < 1e-15
    h = 1e-6
    q0 = r.q[5]
    rr = kinematic_analysis(m, q=np.array([q0 - h, q0 + h]))
    fd = (rr.joints["B"]["x"][1] - rr.joints["B"]["x"][0]) / (2 * h)
    assert fd == pytest.approx(r.joints["B"]["vx"][5], abs=1e-8)
    assert len(r.to_dict()["q"][0]) == 2


def test_zero_length_side_is_bad_input():
    m = four_bar(0.3, 0.8, 0.7, 1.0, 1.0)
    data = mechanism_to_dict(m)
    data["joints"][1]["at"] = data["joints"][2]["at"]  # A onto B: link 2 has no length
    with pytest.raises(MechanismError, match=r"joints\[2\]\.at: joints 'A' and 'B' of link '2'"):
        kinematic_analysis(mechanism_from_dict(data))


def _double_parallelogram(r3: float):
    """Three parallel cranks (0.5, 0.5, r3) on one coupler: Chebyshev says 0 DOF."""
    th = 1.0
    u = complex(math.cos(th), math.sin(th))
    piv = {"O1": 0.0, "O2": 1.0, "O3": 2.0}
    crank = {"O1": 0.5, "O2": 0.5, "O3": r3}
    joints = [{"id": k, "links": ["0", c], "at": [v, 0.0]} for (k, v), c in zip(
        piv.items(), "123", strict=True)]  # fmt: skip
    for (k, v), c in zip(piv.items(), "123", strict=True):
        p = v + crank[k] * u
        joints.append({"id": "A" + k[1], "links": [c, "4"], "at": [p.real, p.imag]})
    return mechanism_from_dict({"frame": "0", "drivers": ["O1"], "joints": joints})


def test_redundant_constraint_refines_mobility():
    r = kinematic_analysis(_double_parallelogram(0.5), frames=90, checks="full")
    jac = r.checks["jacobian"]
    # 12 equations, 12 coordinates, but rank 11: one redundant constraint, DOF 1
    assert (jac["equations"], jac["coordinates"], jac["rank"]) == (12, 12, [11])
    assert jac["redundant_constraints"] == 1 and jac["dof"] == 1
    assert r.valid.all()
    assert any("redundant constraint(s) hold" in w for w in r.warnings)
    assert np.abs(r.links["3"]["omega"] - 1).max() < 1e-9


def test_redundant_constraint_violated_when_not_parallel():
    # the third crank is longer (0.6): with all cranks parallel the Jacobian still
    # loses rank (infinitesimal mobility), but the mechanism cannot move
    r = kinematic_analysis(_double_parallelogram(0.6), frames=90)
    assert r.valid[0] and not r.valid[1:].any()
    assert any(w.startswith("redundant constraint violated") for w in r.warnings)


def test_inverted_slider_crank_rpr_dyad():
    # crank O1A (0.3) carries a block at A that slides on a rocker pivoted at O2 = (1, 0)
    a, th0 = 0.3, 0.7
    A = a * complex(math.cos(th0), math.sin(th0))
    guide = (A - 1.0) / abs(A - 1.0)
    joints = [
        {"id": "O1", "links": ["0", "1"], "at": [0.0, 0.0]},
        {"id": "A", "links": ["1", "2"], "at": [A.real, A.imag]},
        {"id": "S", "links": ["2", "3"], "type": "P", "at": [A.real, A.imag],
         "axis": [guide.real, guide.imag]},
        {"id": "O2", "links": ["3", "0"], "at": [1.0, 0.0]},
    ]  # fmt: skip
    m = mechanism_from_dict({"frame": "0", "drivers": ["O1"], "joints": joints})
    r = kinematic_analysis(m, frames=360, speed=1.5)
    assert [s.kind for s in r.plan.steps] == ["reference", "driver-R", "RPR"]
    assert r.plan.complexity()["right"] == 2
    th = r.q[:, 0]
    Ac = a * np.exp(1j * th)
    # closed form: the rocker points from O2 to A; ω3 = Im(A' / (A - O2)), ε3 likewise
    d = Ac - 1.0
    w3 = (1j * Ac / d).imag * 1.5
    e3 = ((-Ac / d) - (1j * Ac / d) ** 2).imag * 1.5**2
    assert np.abs(r.links["3"]["omega"] - w3).max() < 1e-12
    assert np.abs(r.links["3"]["eps"] - e3).max() < 1e-11
    # the rocker's angle is its guide's direction, from O2 towards A
    assert np.abs(np.exp(1j * r.links["3"]["angle"]) - d / np.abs(d)).max() < 1e-12
    assert r.valid.all() and r.warnings == []
    # the block turns with the rocker and stays on it
    assert np.abs(r.links["2"]["omega"] - r.links["3"]["omega"]).max() == 0


def test_closure_jump_detector():
    from mjstruct.kinematics.closure import branch_jumps as _jumps

    q = np.linspace(0.1, 1.0, 10)[:, None]
    t1 = np.full((10, 1), 0.5)
    t = 0.5 * q  # consistent with t' = 0.5 from t(0) = 0
    ok = np.ones(10, bool)
    assert _jumps(q, np.zeros(1), t, t1, np.array([0.5]), ok, np.ones(1)) == ()
    t[6:] += 1.0  # another branch from frame 6 on
    assert _jumps(q, np.zeros(1), t, t1, np.array([0.5]), ok, np.ones(1)) == (6,)


def test_the_value_checks_run_when_read_and_equal_the_direct_ones():
    from mjstruct.kinematics.checks import value_checks

    r = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=360, checks="full")
    # not computed before the checks are read; the Jacobian's (which word warnings) are
    assert r._on_demand is not None
    assert r.jacobian is not None
    checks = r.checks
    assert r._on_demand is None
    assert list(checks) == ["link_lengths", "analogs_vs_differences", "jacobian"]
    assert {k: checks[k] for k in ("link_lengths", "analogs_vs_differences")} == value_checks(r)
    assert checks["link_lengths"]["max_error"] < 1e-12
    assert checks["analogs_vs_differences"]["max_error"] < 1e-6
    # a deliberately wrong table is caught by the deferred check
    r2 = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=360)
    r2.joints["B"]["x"][100] += 1e-3
    assert r2.checks["link_lengths"]["max_error"] > 9e-4
    assert r2.checks["analogs_vs_differences"]["max_error"] > 1e-2
