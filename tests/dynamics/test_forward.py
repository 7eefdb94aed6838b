"""Lagrange's equations for any number of drivers, force elements, forward dynamics in time.

The oracle is an independent model in full coordinates with Lagrange multipliers
(``full_coordinates.py``): it shares nothing with mjstruct's dynamics but the file; its
multipliers are the pins' loads, against which the joint reactions are checked.
"""

from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.dynamics.analysis import dynamic_analysis
from mjstruct.dynamics.data import read_dynamics
from mjstruct.dynamics.element_loads import element_loads
from mjstruct.dynamics.equation import coefficients
from mjstruct.dynamics.forward import STIFF_RATIO, forward_dynamics
from mjstruct.dynamics.inputs import read_inputs
from mjstruct.dynamics.lagrange import motion_terms
from mjstruct.dynamics.matrices import link_motion
from mjstruct.dynamics.motion import moving_links
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism

sys.path.insert(0, str(Path(__file__).parent))
from full_coordinates import FullModel

FIVE_BAR = example_path("five-bar-springs-dynamics")
LEG = example_path("prosthesis-leg-dynamics")
SEED = example_path("slider-crank-seed000-dynamics")


@pytest.mark.parametrize(
    ("path", "qdot0", "t_end"),
    [(FIVE_BAR, [1.0, -0.5], 0.3), (LEG, [2.0, 0.0, -3.0, 0.1], 0.2)],
)
def test_the_motion_agrees_with_a_full_coordinate_model(path, qdot0, t_end):
    times = np.linspace(0.0, t_end, 4)
    ref = FullModel(path).run(np.array(qdot0), times)
    r = forward_dynamics(
        read_mechanism(path), t_end, frames=4, qdot0=qdot0, rtol=1e-10, estimate=False
    )
    # the oracle's coordinates are measured from the reference configuration
    assert np.abs((r.q - r.q[0]) - ref["q"]).max() < 1e-8
    assert np.abs(r.qdot - ref["qdot"]).max() < 1e-7
    moved = np.abs(r.q - r.q[0]).max()
    assert moved > 0.05  # it moved: the agreement is not that of two resting models
    # the joint reactions along the motion are the oracle's Lagrange multipliers
    for (jid, link), pin in ref["pins"].items():
        comps = r.loads.reactions[jid][link]
        mine = np.stack([comps["x"], comps["y"]], axis=1)
        assert np.abs(mine - pin).max() < 1e-7 * np.abs(pin).max(), (jid, link)


def test_energy_is_conserved_without_dampers_to_the_reported_accuracy():
    loose = forward_dynamics(read_mechanism(FIVE_BAR), 0.5, frames=11, rtol=1e-6)
    tight = forward_dynamics(read_mechanism(FIVE_BAR), 0.5, frames=11, rtol=1e-10, estimate=False)
    E = tight.kinetic + tight.potential
    assert not tight.work.any()  # no dampers, no loads, no motors
    assert np.abs(E - E[0]).max() / np.abs(tight.kinetic).max() < 1e-8
    assert tight.energy_residual < loose.energy_residual < 1e-4
    # the error estimate bounds the actual error (against the tight run)
    actual = np.abs(loose.q - tight.q).max()
    assert loose.error is not None and actual <= 10 * loose.error


def test_one_driver_gives_the_reduced_inertia_and_its_w_term():
    model, data = read_inputs(read_mechanism(SEED), parameters={"p": 3.0})
    q = model.sweep(9)
    mo = model.motion(q, order=2)
    V, W = coefficients(mo, data, moving_links(model))
    for k in (0, 3, 7):
        t = motion_terms(model, data, data.parameter_values(), q[k : k + 1], [[2.5]])
        assert t.M[0, 0, 0] == pytest.approx(V[k], rel=1e-12)
        assert t.h[0, 0] == pytest.approx(W[k] * 2.5**2, rel=1e-10, abs=1e-12)


def test_the_several_frames_path_agrees_with_the_single_state_path():
    model, data = read_inputs(read_mechanism(LEG))
    rng = np.random.default_rng(3)
    q = model.q_ref + rng.normal(0, 0.05, (3, 4))
    qd = rng.normal(0, 1.0, (3, 4))
    p = data.parameter_values()
    many = motion_terms(model, data, p, q, qd)
    for k in range(3):
        one = motion_terms(model, data, p, q[k : k + 1], qd[k : k + 1])
        for a, b in ((one.M, many.M), (one.h, many.h), (one.Q, many.Q)):
            assert np.allclose(a[0], b[k], rtol=1e-9, atol=1e-9)


def test_an_elastic_slide_measures_the_prismatic_driver():
    model, data = read_inputs(read_mechanism(LEG))
    q = model.q_ref + np.array([[0.3, 0.02, -0.4, -0.01]])
    lm = link_motion(model, data.inertia, q, [[0.0, 0.5, 0.0, -0.2]])
    out = element_loads(data, lm)
    # the springs' energy C s²/2 with s the driver coordinate (both free at s = 0)
    assert out.potential[0] == pytest.approx(0.5 * 20000 * 0.02**2 + 0.5 * 15000 * 0.01**2)


def test_inverse_dynamics_along_the_motion_needs_no_actuator():
    r = forward_dynamics(read_mechanism(LEG), 0.1, frames=5, qdot0=[1.0, 0, -1.0, 0])
    assert r.loads is not None and r.loads.reactions is not None
    largest = max(
        float(np.abs(c["x"]).max()) for per in r.loads.reactions.values() for c in per.values()
    )
    for tau in r.loads.driving.values():
        assert np.abs(tau).max() < 1e-10 * largest
    # the knee's pin loads on its two links are equal and opposite
    knee = r.loads.reactions["K"]
    assert np.allclose(knee["2"]["x"], -knee["3"]["x"])


def stiff_leg(rate: float = 0.0):
    d = mechanism_to_dict(read_mechanism(LEG))
    for link in d["inertia"].values():
        link.update(mass=1.0, J=0.01)
    d["elements"][0]["stiffness"] = d["elements"][1]["stiffness"] = 1e6  # on unit masses
    if rate:
        d["elements"].append({"type": "slide_damper", "joint": "S1", "rate": rate})
    return mechanism_from_dict(d)


@pytest.mark.parametrize(
    ("rate", "rtol", "solver", "says"),
    [
        (0.0, 1e-3, "Radau", "steps over it"),  # the vibration is below the tolerance
        (5000.0, 1e-6, "Radau", "decay times"),  # an overdamped fast mode
        (0.0, 1e-6, "DOP853", "must resolve it"),  # every method resolves the vibration
    ],
)
def test_a_stiff_spring_chooses_the_method_and_says_so(rate, rtol, solver, says):
    r = forward_dynamics(
        stiff_leg(rate), 0.18, frames=3, estimate=False, reactions=False, rtol=rtol
    )
    assert r.stiffness_ratio > STIFF_RATIO and r.solver == solver
    assert any(w.startswith("stiff:") and says in w for w in r.warnings), r.warnings
    assert r.energy_residual < 100 * rtol


def test_a_soft_chain_is_not_stiff():
    soft = forward_dynamics(read_mechanism(LEG), 0.05, frames=3, estimate=False, reactions=False)
    assert soft.solver == "DOP853" and soft.stiffness_ratio < STIFF_RATIO
    assert not any(w.startswith("stiff:") for w in soft.warnings)


def test_turning_points_are_events():
    seen = []
    r = forward_dynamics(
        read_mechanism(FIVE_BAR),
        0.2,
        frames=5,
        qdot0=[1.0, -0.5],
        estimate=False,
        reactions=False,
        progress=lambda d, n: seen.append((d, n)),
    )
    turns = {d: t for t, kind, d in r.events if kind == "turn"}
    assert set(turns) == {"O1", "O2"}
    # at the event the driver's speed is zero: it changes sign between the frames around it
    k = int(np.searchsorted(r.t, turns["O1"]))
    assert r.qdot[k - 1, 0] * r.qdot[k, 0] < 0
    # the progress of the run in percent of t_end, increasing to 100
    assert seen[-1] == (100, 100) and [d for d, _ in seen] == sorted({d for d, _ in seen})


def test_leaving_the_assembly_ends_the_run_with_a_warning():
    # couplers AB = BC = 0.55: A and C may be at most 1.1 apart, the cranks thrown
    # apart pass that limit
    d = json.loads(FIVE_BAR.read_text())
    A, C = complex(*d["joints"][1]["at"]), complex(*d["joints"][3]["at"])
    half = abs(C - A) / 2
    B = (A + C) / 2 + 1j * (C - A) / abs(C - A) * np.sqrt(0.55**2 - half**2)
    d["joints"][2]["at"] = [B.real, B.imag]
    d["elements"] = []
    r = forward_dynamics(
        mechanism_from_dict(d), 1.0, frames=11, qdot0=[5.0, -5.0], estimate=False, reactions=False
    )
    assert r.stopped == "assembly" and 0 < r.t[-1] < 1.0
    assert any("leaves its assembly" in w for w in r.warnings)
    assert np.isfinite(r.q).all() and np.isfinite(r.qddot).all()


def bad_file(tmp_path, change):
    d = json.loads(FIVE_BAR.read_text())
    change(d)
    f = tmp_path / "bad.json"
    f.write_text(json.dumps(d))
    return f


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda d: d["elements"][0].update(stiffness=-5), "elements[0].stiffness: must be >= 0"),
        (
            lambda d: d["elements"][0].update(
                between=[{"link": "2", "at": [0, 0]}, {"joint": "A"}]
            ),
            "elements[0].between: both points belong to link '2'",
        ),
        (
            lambda d: d["elements"].append(
                {"type": "damper", "between": [{"joint": "A"}, {"joint": "C"}]}
            ),
            "elements[3].rate: missing",
        ),
        (
            lambda d: d["elements"].append({"type": "torsion_damper", "joint": "B"}),
            "elements[3].rate: missing",
        ),
        (
            lambda d: d["elements"].append(
                {"type": "elastic_slide", "joint": "B", "stiffness": 1}
            ),
            "elements[3].joint: an elastic slide needs a prismatic joint",
        ),
        (lambda d: d["elements"].append({"type": "spring"}), "elements[3].stiffness: missing"),
        (lambda d: d["elements"].append({"type": "rope"}), "elements[3].type: must be one of"),
        (
            lambda d: d["elements"].append({"type": "motor", "joint": "O1", "law": "q.real"}),
            "elements[3].law:",
        ),
    ],
)
@pytest.mark.parametrize("mode", [["--time", "0.1"], ["--speed", "1"]])
def test_bad_elements_exit_2_naming_the_field(tmp_path, capsys, change, message, mode):
    status = main(["dynamics", str(bad_file(tmp_path, change)), *mode, "--frames", "3"])
    out, err = capsys.readouterr()
    assert (status, out) == (2, "")
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"mjstruct dynamics: {message}"), err


def test_the_command_runs_several_drivers_in_time(capsys, tmp_path):
    csv = tmp_path / "leg.csv"
    status = main(
        [
            "dynamics",
            str(LEG),
            "--time",
            "0.05",
            "--qdot0",
            "1,0,-1,0",
            "--frames",
            "3",
            "--json",
            "--csv",
            str(csv),
        ]
    )
    out, err = capsys.readouterr()
    assert status == 0, err
    obj = json.loads(out)
    assert obj["equations"] == "lagrange" and obj["drivers"] == ["H", "S1", "K", "S2"]
    assert obj["qdot"]["H"][0] == 1.0 and obj["qdot"]["K"][0] == -1.0
    assert obj["error"]["energy"] < 1e-6 and obj["stopped"] == "t_end"
    assert set(obj["reactions"]) == {"H", "S1", "K", "S2"}
    assert csv.read_text().splitlines()[0].startswith("t,q_H,qdot_H,qddot_H,q_S1")
    # the number of speeds must match the drivers
    assert main(["dynamics", str(LEG), "--time", "0.05", "--qdot0", "1,0"]) == 2
    assert capsys.readouterr().err.startswith("mjstruct dynamics: --qdot0: give one value per")
    # free motion in q is one driver's: several drivers are sent to --time
    assert main(["dynamics", str(LEG), "--qdot0", "1"]) == 2
    assert "--time T --qdot0 W1,W2" in capsys.readouterr().err


def test_the_elements_do_not_change_a_file_without_them():
    m = read_mechanism(SEED)
    assert read_dynamics(m).elements == ()


def test_inverse_dynamics_of_several_drivers_matches_lagrange():
    # at constant speed q̈ = 0: the actuators' loads are h − Q (elements included)
    m = read_mechanism(FIVE_BAR)
    s = dynamic_analysis(m, speed=1.5, frames=6)
    model, data = read_inputs(m)
    t = motion_terms(model, data, data.parameter_values(), s.q, np.full(s.q.shape, 1.5))
    tau = np.stack([s.driving[d] for d in model.drivers], axis=1)
    assert np.allclose(tau, t.h - t.Q, rtol=1e-9, atol=1e-9 * np.abs(t.Q).max())
    # the springs matter: without them the loads differ
    d = mechanism_to_dict(m)
    d["elements"] = []
    bare = dynamic_analysis(mechanism_from_dict(d), speed=1.5, frames=6)
    assert np.abs(bare.driving["O1"] - s.driving["O1"]).max() > 0.1


def test_one_driver_with_an_element_moves_by_lagrange(capsys):
    d = mechanism_to_dict(read_mechanism(SEED))
    d["parameters"] = {"M": 10.0, "p": 3.0}
    d["elements"] = [
        {
            "type": "spring",
            "stiffness": 50.0,
            "between": [{"joint": "B"}, {"link": "0", "at": [0.0, 0.0]}],
        }
    ]
    m = mechanism_from_dict(d)
    r = forward_dynamics(m, 0.2, frames=3, estimate=False, reactions=False)
    assert r.drivers == ("O1",) and r.energy_residual < 1e-6
    # free motion integrated in q does not take elements: it names the way that does
    with pytest.raises(MechanismError, match=r"^qdot0: .*force elements.*--time"):
        dynamic_analysis(m, qdot0=5.0, frames=12)
    # nor does steady motion fix an unknown with them
    d["parameters"] = {"M": 10.0, "p": None}
    with pytest.raises(MechanismError, match=r"^parameters\.p: steady motion"):
        dynamic_analysis(mechanism_from_dict(d), speed=1.0, frames=12)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda d: d["elements"][0].update(stiffness=1e308), "elements[0].stiffness: 1e+308"),
        (
            lambda d: d["elements"].append(
                {
                    "type": "damper",
                    "rate": 1.0,
                    "between": [{"link": "2", "at": [1e9, 0]}, {"joint": "O2"}],
                }
            ),
            "elements[3].between[0]: ",
        ),
    ],
)
def test_elements_beyond_a_double_are_refused_naming_the_field(tmp_path, capsys, change, message):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no RuntimeWarning leaks
        status = main(["dynamics", str(bad_file(tmp_path, change)), "--time", "0.05"])
    out, err = capsys.readouterr()
    assert (status, out) == (2, "") and err.startswith(f"mjstruct dynamics: {message}"), err
