"""Joint reactions and actuator loads, checked by independent routes.

* Lagrange multipliers of the constraint Jacobian (assembled here from the joint
  definitions, not from the plug-in's link equations) give the same joint loads;
* the energy balance dT/dt = power of the loads and the actuators holds frame by frame
  (loads evaluated here with sympy, dT/dt by differences in time for a general q(t));
* the loads of every joint on its links sum to zero (multiple joints included);
* near a singular position the reactions grow without NaN.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest
import sympy as sp

from mjstruct.dynamics import dynamic_analysis
from mjstruct.dynamics.data import read_dynamics
from mjstruct.dynamics.matrices import incidence, inertia_matrix, link_motion
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from project_paths import EXAMPLES

#: the shipped examples with dynamics data, one of each kind (slider, MJ, class IV)
DYNAMICS_EXAMPLES = [
    "slider-crank-seed000-dynamics",
    "zhivago-dynamics",
    "radial-engine-5-dynamics",
    "class-iv-seed003-dynamics",
]


def load(name: str):
    return read_mechanism(EXAMPLES / f"{name}.json")


def loads_power(m, model, q, speed_rates, params, qdot_load):
    """Power of gravity and the file's loads along a motion (sympy-lambdified here)."""
    mo = model.motion(q, order=1, rates=speed_rates) if speed_rates is not None else None
    return mo, _power(m, mo, params, q[:, 0], qdot_load)


def _power(m, mo, params, qload, qdot_load):
    data = read_dynamics(m)
    P = np.zeros(len(qload))
    for link, li in data.inertia.items():
        v = mo.point(link, li.com)[1]
        P += li.mass * (data.gravity.real * v.real + data.gravity.imag * v.imag)
    qs, qds = sp.symbols("q qdot", real=True)
    for spec in m.extra.get("loads", []):
        link = str(spec["link"])
        subs = {sp.Symbol(k, real=True): v for k, v in params.items()}
        if "force" in spec:
            comps = []
            for text in spec["force"]:
                e = sp.sympify(text, locals={"q": qs, "qdot": qds, **{str(k): k for k in subs}})
                f = sp.lambdify([qs, qds], e.subs(subs), "numpy")
                comps.append(np.broadcast_to(np.asarray(f(qload, qdot_load), float), qload.shape))
            at = complex(*spec["at"]) if "at" in spec else data.inertia[link].com
            v = mo.point(link, at)[1]
            P += comps[0] * v.real + comps[1] * v.imag
        else:
            e = sp.sympify(
                str(spec["moment"]), locals={"q": qs, "qdot": qds, **{str(k): k for k in subs}}
            )
            f = sp.lambdify([qs, qds], e.subs(subs), "numpy")
            P += (
                np.broadcast_to(np.asarray(f(qload, qdot_load), float), qload.shape)
                * mo.angle(link)[1]
            )
    return P


def kinetic_power(m, mo):
    """dT/dt = Σ m v·a + J ω ε from the kinematic jets (velocities and accelerations)."""
    data = read_dynamics(m)
    out = np.zeros(mo.q.shape[0])
    for link, li in data.inertia.items():
        c = mo.point(link, li.com)
        out += li.mass * (c[1].real * c[2].real + c[1].imag * c[2].imag)
        t = mo.angle(link)
        out += li.J * t[1] * t[2]
    return out


def lagrange_reactions(m, model, lm, force, moment):
    """Joint loads from multipliers: Φ_qᵀ λ = M a − F, Φ from the joint definitions."""
    data = read_dynamics(m)
    links = lm.links
    col = {link: 3 * j for j, link in enumerate(links)}
    jrow = {jid: k for k, jid in enumerate(lm.joints)}
    F = lm.q.shape[0]
    rows: list[tuple[str, str, str, dict[int, np.ndarray]]] = []

    def point_row(link, P, d, sign, row):
        if link not in col:
            return
        c = col[link]
        arm = P - lm.com[0][links.index(link)]
        row[c] = row.get(c, 0) + sign * d.real
        row[c + 1] = row.get(c + 1, 0) + sign * d.imag
        # d · (i arm): the direction's component of a rotation about the centre of mass
        row[c + 2] = row.get(c + 2, 0) + sign * (d.real * -arm.imag + d.imag * arm.real)

    def turn_row(link, sign, row):
        if link in col:
            row[col[link] + 2] = row.get(col[link] + 2, 0) + sign * np.ones(F)

    for j in m.joints:
        P = lm.centre[jrow[j.id]]
        if j.kind == "R":
            a = j.links[0]
            for other in j.links[1:]:
                for comp, d in (("x", np.ones(F, complex)), ("y", np.full(F, 1j))):
                    row: dict[int, np.ndarray] = {}
                    point_row(a, P, d, 1.0, row)
                    point_row(other, P, d, -1.0, row)
                    rows.append((j.id, other, comp, row))
        else:
            a, b = j.links
            row = {}
            turn_row(b, 1.0, row)
            turn_row(a, -1.0, row)
            rows.append((j.id, b, "m", row))
            n = 1j * lm.axis[j.id]
            row = {}
            point_row(b, P, n, 1.0, row)
            point_row(a, P, n, -1.0, row)
            rows.append((j.id, b, "n", row))
    for d in model.drivers:
        j = m.joint(d)
        a, b = j.links[0], j.links[1]
        row = {}
        if j.kind == "R":
            turn_row(b, 1.0, row)
            turn_row(a, -1.0, row)
        else:
            P = lm.centre[jrow[d]]
            point_row(b, P, lm.axis[d], 1.0, row)
            point_row(a, P, lm.axis[d], -1.0, row)
        rows.append((d, b, "drive", row))
    Phi = np.zeros((F, len(rows), 3 * len(links)))
    for r, (_, _, _, row) in enumerate(rows):
        for c, v in row.items():
            Phi[:, r, c] = v
    inert = inertia_matrix(links, data.inertia)
    rhs = np.empty((F, 3 * len(links)))
    rhs[:, 0::3] = (inert[0][:, None] * lm.com[2].real - force.real).T
    rhs[:, 1::3] = (inert[1][:, None] * lm.com[2].imag - force.imag).T
    rhs[:, 2::3] = (inert[2][:, None] * lm.angle[2] - moment).T
    lam = np.linalg.solve(np.transpose(Phi, (0, 2, 1)), rhs[..., None])[..., 0]
    out: dict[tuple[str, str, str], np.ndarray] = {}
    for r, (jid, link, comp, _) in enumerate(rows):
        out[(jid, link, comp)] = lam[:, r]
    return out


def active(m, lm, params, qdot):
    from mjstruct.dynamics.matrices import active_forces

    return active_forces(read_dynamics(m), lm, params, lm.q[:, 0], qdot)


@pytest.mark.parametrize(
    "name", ["slider-crank-seed000-dynamics", "radial-engine-5-dynamics", "zhivago-dynamics"]
)
def test_reactions_equal_lagrange_multipliers(name):
    m = load(name)
    r = dynamic_analysis(m, speed=3.0, frames=24)
    model = KinematicModel.build(m)
    lm = link_motion(model, read_dynamics(m).inertia, r.q, 3.0)
    fa, ma = active(m, lm, r.parameters, np.full(24, 3.0))
    lam = lagrange_reactions(m, model, lm, fa, ma)
    big = max(np.abs(v).max() for v in lam.values())
    for j in m.joints:
        if j.kind == "R":
            for link in j.links[1:]:
                # C = z_carrier − z_link: the multiplier is minus the load on the link
                assert (
                    np.abs(r.reactions[j.id][link]["x"] + lam[(j.id, link, "x")]).max()
                    < 1e-10 * big
                )
                assert (
                    np.abs(r.reactions[j.id][link]["y"] + lam[(j.id, link, "y")]).max()
                    < 1e-10 * big
                )
        else:
            b = j.links[1]
            nvec = 1j * lm.axis[j.id] * lam[(j.id, b, "n")]
            assert np.abs(r.reactions[j.id][b]["x"] - nvec.real).max() < 1e-10 * big
            assert np.abs(r.reactions[j.id][b]["y"] - nvec.imag).max() < 1e-10 * big
            assert np.abs(r.reactions[j.id][b]["m"] - lam[(j.id, b, "m")]).max() < 1e-10 * big
    for d in model.drivers:
        b = m.joint(d).links[1]
        assert np.abs(r.driving[d] - lam[(d, b, "drive")]).max() < 1e-10 * big
    assert r.check < 1e-12


@pytest.mark.parametrize("name", DYNAMICS_EXAMPLES)
def test_energy_balance_at_constant_speed(name):
    m = load(name)
    W = 2.5
    r = dynamic_analysis(m, speed=W, frames=36)
    model = KinematicModel.build(m)
    mo = model.motion(r.q, order=2, rates=[W])
    P_loads = _power(m, mo, r.parameters, r.q[:, 0], np.full(36, W))
    P_drive = r.driving[model.drivers[0]] * W
    dT = kinetic_power(m, mo)
    scale = np.abs(dT).max() + np.abs(P_loads).max()
    assert np.abs(dT - P_loads - P_drive).max() < 1e-10 * scale
    assert r.check < 1e-12


def test_loads_of_every_joint_sum_to_zero_including_the_mj():
    m = load("radial-engine-5-dynamics")
    r = dynamic_analysis(m, qdot0=30.0, frames=36)
    mj = r.reactions["A"]
    assert sorted(mj) == ["1", "2", "3", "4", "5", "6"]
    for jid, per in r.reactions.items():
        for c in ("x", "y"):
            total = sum(comp[c] for comp in per.values())
            size = max(np.abs(comp[c]).max() for comp in per.values())
            assert np.abs(total).max() <= 1e-12 * max(size, 1.0), jid
    # each articulated rod carries a different load: the MJ is not one simple joint
    assert len({round(float(np.abs(mj[x]["x"]).max()), 9) for x in "23456"}) > 1


def test_incidence_columns_sum_to_zero_and_expand_the_mj():
    K, cols, kinds = incidence(load("radial-engine-5-dynamics"))
    assert (K.sum(axis=0) == 0).all()
    assert [c for c in cols if c[0] == "A"] == [("A", x) for x in "23456"]
    assert kinds.count("P") == 5


def five_bar() -> Any:
    d = json.loads((EXAMPLES / "kin-five-bar.json").read_text())
    d["inertia"] = {
        "1": {"mass": 1.0, "J": 0.01},
        "2": {"mass": 2.0, "J": 0.1},
        "3": {"mass": 1.5, "J": 0.05},
        "4": {"mass": 0.7},
    }
    d["gravity"] = [0.0, -9.81]
    d["loads"] = [{"link": "3", "force": ["-2*sin(q)", "1"], "at": [0.7, 0.6]}]
    return mechanism_from_dict(d)


def test_two_drivers_at_constant_speed():
    m = five_bar()
    r = dynamic_analysis(m, speed=2.0, frames=36)
    model = KinematicModel.build(m)
    mo = model.motion(r.q, order=2, rates=[2.0, 2.0])
    P = _power(m, mo, {}, r.q[:, 0], np.full(36, 2.0))
    dT = kinetic_power(m, mo)
    P_drive = 2.0 * (r.driving["O1"] + r.driving["O2"])
    assert np.abs(dT - P - P_drive).max() < 1e-10 * (np.abs(dT).max() + np.abs(P).max())
    assert r.check < 1e-12


def test_prescribed_motion_with_accelerations_two_drivers():
    m = five_bar()
    model = KinematicModel.build(m)
    t = np.linspace(0.0, 1.0, 201)
    q0 = model.q_ref
    q = np.column_stack([q0[0] + t + 0.3 * np.sin(3 * t), q0[1] - 0.5 * t + 0.2 * np.cos(2 * t)])
    qd = np.column_stack([1 + 0.9 * np.cos(3 * t), -0.5 - 0.4 * np.sin(2 * t)])
    qdd = np.column_stack([-2.7 * np.sin(3 * t), -0.8 * np.cos(2 * t)])
    r = dynamic_analysis(m, q=q, qdot=qd, qddot=qdd)
    # kinetic energy from first-order analogs only; dT/dt by central differences in t
    data = read_dynamics(m)
    firsts = [model.motion(q, order=1, rates=e) for e in np.eye(2)]
    T = np.zeros(len(t))
    for link, li in data.inertia.items():
        v = sum(f.point(link, li.com)[1] * qd[:, i] for i, f in enumerate(firsts))
        w = sum(f.angle(link)[1] * qd[:, i] for i, f in enumerate(firsts))
        T += 0.5 * (li.mass * abs(v) ** 2 + li.J * w**2)
    dT = np.gradient(T, t, edge_order=2)
    # power of the loads along the same motion
    P = np.zeros(len(t))
    for i, f in enumerate(firsts):
        P += _power(m, f, {}, q[:, 0], qd[:, 0]) * qd[:, i]
    P_drive = r.driving["O1"] * qd[:, 0] + r.driving["O2"] * qd[:, 1]
    inner = slice(2, -2)
    err = np.abs(dT - P - P_drive)[inner].max()
    assert err < 1e-3 * np.abs(dT).max()  # the difference quotient's error, O(h²)
    assert r.check < 1e-12


def slider_crank_eps(eps: float):
    d = json.loads((EXAMPLES / "slider-crank-seed000-dynamics.json").read_text())
    L2 = 1.0 + eps
    d["joints"][2]["at"] = [1.0 + L2, 0.0]
    d["joints"][3]["at"] = [1.0 + L2, 0.0]
    d["parameters"]["p"] = 1.0
    return mechanism_from_dict(d)


def test_reactions_near_the_singular_position_grow_without_nan():
    peaks, conds = [], []
    for eps in (1e-2, 1e-4, 1e-6, 1e-8):
        r = dynamic_analysis(slider_crank_eps(eps), speed=1.0, frames=360)
        values = [
            c for per in r.reactions.values() for comp in per.values() for c in comp.values()
        ]
        assert all(np.isfinite(v).all() for v in values)
        peaks.append(max(np.abs(v).max() for v in values))
        conds.append(np.nanmax(r.condition))
        json.dumps(r.to_dict(), allow_nan=False)
        assert r.check < 1e-12
    # at q = π/2 the rod is nearly perpendicular to the guide: det J ~ sqrt(2ε), and
    # the slider's acceleration (hence every reaction) grows as 1/det J² ~ 1/ε
    ratios = [peaks[k + 1] / peaks[k] for k in range(3)]
    assert 50 < ratios[0] < 120 and all(90 < x < 110 for x in ratios[1:])
    # the link equations lose digits as 1/det J: each 100× smaller ε costs a factor 10
    assert all(8 < conds[k + 1] / conds[k] < 12 for k in range(3))
    assert "near-singular position" in r.warnings[0] and r.to_dict()["condition"] == conds[-1]


@pytest.mark.parametrize("eps", [1e-4, 1e-8])
def test_condition_bounds_the_accuracy_lost(eps):
    import mpmath as mp

    m = slider_crank_eps(eps)
    q = np.array([np.pi / 2 * (1 - 1e-3), np.pi / 2])
    aB = KinematicModel.build(m).motion(q, order=2).centre("B")[2].real
    mp.mp.dps = 40
    L2 = mp.mpf(1) + mp.mpf(eps)
    ref = [float(mp.diff(lambda t: mp.cos(t) + mp.sqrt(L2**2 - mp.sin(t) ** 2), x, 2)) for x in q]
    cond = np.nanmax(dynamic_analysis(m, speed=1.0, frames=360).condition)
    err = np.abs(aB - ref) / np.abs(ref)
    assert err.max() < cond**2 * 1e-15  # between log10(cond) and 2 log10(cond) digits lost


def test_W_is_half_the_derivative_of_V_on_the_zhivago_mechanism():
    # V and W come from σ and κ of an iterated closure: W = (dV/dq)/2, with dV/dq
    # taken here spectrally from V over the frames (V is smooth and periodic)
    r = dynamic_analysis(
        load("zhivago-dynamics"), speed=1.0, frames=2048, outputs=["coefficients"]
    )
    k = np.fft.rfftfreq(2048, d=1 / 2048)
    dV = np.fft.irfft(1j * k * np.fft.rfft(r.V), n=2048)
    assert np.abs(dV / 2 - r.W).max() < 1e-6 * np.abs(r.W).max()


@pytest.mark.parametrize("name", DYNAMICS_EXAMPLES)
def test_condition_estimate_is_a_close_lower_bound(name):
    from mjstruct.dynamics.reactions import solve_stack, system_matrix, unknowns

    m = load(name)
    model = KinematicModel.build(m)
    lm = link_motion(model, read_dynamics(m).inertia, model.sweep(72), 1.0)
    A = system_matrix(model, lm, unknowns(model))
    S = np.random.default_rng(1).normal(size=A.shape[:2])
    x, ok, cond = solve_stack(A, S)
    exact = np.linalg.cond(A, np.inf)  # an SVD-free exact κ∞ (the inverse), per frame
    assert ok.all()
    assert (cond <= exact * (1 + 1e-9)).all() and (cond >= 0.1 * exact).all()
    assert np.abs(A @ x[..., None] + S[..., None]).max() < 1e-12 * np.abs(S).max() * exact.max()


def test_accuracy_grows_with_the_conditioning_and_bounds_the_solve_error():
    from mjstruct.dynamics.reactions import solve_stack, system_matrix, unknowns

    acc, checks = [], []
    for eps in (1e-2, 1e-4, 1e-6, 1e-8):
        m = slider_crank_eps(eps)
        r = dynamic_analysis(m, speed=1.0, frames=360)
        acc.append(r.to_dict()["accuracy"])
        checks.append(r.check)
        # the solve's part, condition × eps, plus the analogs' error it is fed
        assert acc[-1] >= r.to_dict()["condition"] * np.finfo(float).eps
        # the error of the stacked solve, measured: one step of refinement with the
        # residual in extended precision
        model = KinematicModel.build(m)
        lm = link_motion(model, read_dynamics(m).inertia, r.q, 1.0)
        A = system_matrix(model, lm, unknowns(model))
        S = np.random.default_rng(2).normal(size=A.shape[:2])
        x, _, cond = solve_stack(A, S)
        res = np.einsum("fij,fj->fi", A.astype(np.longdouble), x.astype(np.longdouble)) + S
        dx = np.linalg.solve(A, res.astype(float)[..., None])[..., 0]
        err = np.abs(dx).max(axis=1) / np.abs(x).max(axis=1)
        assert (err <= 20 * cond * np.finfo(float).eps).all()
    # the check cannot see the loss (the excluded equation uses the same rounded
    # loads); the accuracy estimate grows at least as the condition, 10× per 100×
    # smaller ε (the analogs' error, which it includes, faster)
    assert max(checks) < 1e-15
    assert all(acc[k + 1] / acc[k] > 8 for k in range(3))


def test_a_singular_frame_is_null_with_a_warning():
    r = dynamic_analysis(slider_crank_eps(0.0), speed=1.0, frames=360)
    d = r.to_dict()
    json.dumps(d, allow_nan=False)
    # at q = π/2 and 3π/2 the slider sits on the crank's pivot with the rod across
    # the guide: the link equations are singular (condition ~1e17)
    null = [k for k, v in enumerate(d["driving"]["O1"]) if v is None]
    assert null == [90, 270]
    assert all(d["reactions"]["A"]["2"]["x"][k] is None for k in null)
    assert "not determined at 2 frame(s)" in r.warnings[0]
    assert d["condition"] > 1e15 and d["accuracy"] < 1e-3
    finite = [abs(v) for v in d["driving"]["O1"] if v is not None]
    assert max(finite) < 1e3  # no 1e17 numbers printed


def test_frames_that_do_not_assemble_give_no_numpy_warning(recwarn):
    r = dynamic_analysis(slider_crank_eps(-0.5), speed=1.0, frames=36)
    assert any("does not assemble at" in w for w in r.warnings)
    assert r.check is not None and r.check < 1e-12
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


@pytest.mark.parametrize("name", DYNAMICS_EXAMPLES)
def test_reactions_equal_lagrange_multipliers_with_acceleration(name):
    # a prescribed q(t) with q̈ ≠ 0 (the inertia loads carry σ q̈ as well as κ q̇²)
    m = load(name)
    model = KinematicModel.build(m)
    data = read_dynamics(m)
    t = np.linspace(0.0, 1.0, 24)
    q = model.q_ref[0] + 2.0 * t + 0.4 * np.sin(5 * t)
    qd = 2.0 + 2.0 * np.cos(5 * t)
    qdd = -10.0 * np.sin(5 * t)
    params = {data.unknown: 1.5} if data.unknown else {}
    r = dynamic_analysis(m, q=q, qdot=qd, qddot=qdd, parameters=params)
    lm = link_motion(model, data.inertia, q, qd, qdd)
    assert np.abs(qdd).max() > 5 and np.abs(lm.angle[2]).max() > 0
    fa, ma = active(m, lm, r.parameters, qd)
    lam = lagrange_reactions(m, model, lm, fa, ma)
    big = max(np.abs(v).max() for v in lam.values())
    for j in m.joints:
        if j.kind == "R":
            for link in j.links[1:]:
                for c in "xy":
                    err = np.abs(r.reactions[j.id][link][c] + lam[(j.id, link, c)]).max()
                    assert err < 1e-10 * big, (j.id, link, c)
        else:
            b = j.links[1]
            nvec = 1j * lm.axis[j.id] * lam[(j.id, b, "n")]
            assert np.abs(r.reactions[j.id][b]["x"] - nvec.real).max() < 1e-10 * big
            assert np.abs(r.reactions[j.id][b]["m"] - lam[(j.id, b, "m")]).max() < 1e-10 * big
    d = model.drivers[0]
    assert np.abs(r.driving[d] - lam[(d, m.joint(d).links[1], "drive")]).max() < 1e-10 * big
    assert r.check < 1e-12


def test_free_motion_energy_balance_from_link_velocities():
    # T = ½ Σ (m |σ_c q̇|² + J (σ_θ q̇)²) from the kinematics' first analogs and the
    # masses of the file, differentiated in q along the motion (fourth-order
    # differences); dT/dq must equal the loads' generalised force, evaluated here
    # with sympy from the file (no V, W or Q of the plug-in)
    m = load("zhivago-dynamics")
    N = 4096
    r = dynamic_analysis(m, qdot0=20.0, frames=N)
    assert not r.warnings and r.qdot.shape[0] == N and r.parameters["p"] > 0
    model = KinematicModel.build(m)
    mo = model.motion(r.q, order=1)
    data = read_dynamics(m)
    qd = r.qdot[:, 0]
    T = np.zeros(N)
    for link, li in data.inertia.items():
        T += 0.5 * qd**2 * (li.mass * np.abs(mo.point(link, li.com)[1]) ** 2)
        T += 0.5 * qd**2 * li.J * mo.angle(link)[1] ** 2
    h = 2 * np.pi / N
    # central fourth-order difference quotient inside the cycle (the loads may jump at
    # its ends)
    dT = (T[:-4] - 8 * T[1:-3] + 8 * T[3:-1] - T[4:]) / (12 * h)
    Qq = _power(m, mo, r.parameters, r.q[:, 0], qd)[2:-2]  # Σ F · σ (power per unit q̇)
    # the file's moment on link 5 jumps at q = π: leave out the stencils across it
    qc = r.q[2:-2, 0]
    smooth = np.abs(qc - np.pi) > 2.5 * h
    assert smooth.sum() >= N - 4 - 5
    assert np.abs(dT - Qq)[smooth].max() < 1e-6 * np.abs(Qq).max()
    assert all(np.abs(r.driving["O"]) == 0)
