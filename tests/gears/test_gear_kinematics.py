"""The gear-mesh step: geared mechanisms move, with exact analogs.

Oracles: the geared five-bar in closed form with sympy (gear 2 turned by -Z1/Z2 of the
crank, the dyad by the circle intersection, derivatives symbolic); the planetary
trains against Willis' ratios (themselves checked against a sympy solve of the
rolling constraints) and the rolling of each pitch circle over the frames."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import sympy as sp

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.gear_pairs import gear_pairs
from mjstruct.gears.structure import fundamental_circuit
from mjstruct.gears.willis import speed_ratio
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.solver import kinematic_analysis


def five_bar_oracle(q: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """C, its first and second derivatives in q, of the shipped geared five-bar."""
    t = sp.Symbol("t")
    qref = sp.pi / 2
    A = sp.Matrix([15 * sp.cos(t), 15 * sp.sin(t)])  # crank 1: |O1A| = 15, angle q
    theta2 = sp.pi / 2 - sp.Rational(40, 80) * (t - qref)  # gear 2: -Z1/Z2 of the crank
    B = sp.Matrix([60 + 25 * sp.cos(theta2), 25 * sp.sin(theta2)])
    l3 = sp.sqrt(25**2 + 55**2)  # |AC| with A = (0, 15), C = (25, 70)
    l4 = sp.sqrt(35**2 + 45**2)  # |BC| with B = (60, 25)
    d = B - A
    dist = sp.sqrt(d.dot(d))
    a = (l3**2 - l4**2 + dist**2) / (2 * dist)
    h = sp.sqrt(l3**2 - a**2)
    mid = A + a * d / dist
    perp = sp.Matrix([-d[1], d[0]]) / dist
    C = mid + h * perp  # the branch of the reference (C left of A->B)
    vals = [C, C.diff(t), C.diff(t, 2)]
    return tuple(np.array([float(e.subs(t, q)) for e in v]) for v in vals)  # type: ignore[return-value]


def test_geared_five_bar_matches_the_closed_form():
    m = read_mechanism(example_path("geared-five-bar"))
    r = kinematic_analysis(m, frames=12, speed=1.0)
    C = r.joints["C"]
    for k in range(12):
        q = float(r.q[k, 0])
        p, v, a = five_bar_oracle(q)
        assert np.allclose([C["x"][k], C["y"][k]], p, atol=1e-9)
        assert np.allclose([C["vx"][k], C["vy"][k]], v, atol=1e-9)
        assert np.allclose([C["ax"][k], C["ay"][k]], a, atol=1e-8)
    assert np.allclose(r.links["2"]["omega"], -0.5) and np.allclose(r.links["2"]["eps"], 0)


@pytest.mark.parametrize("name", ["planetary-simple", "planetary-2aa"])
def test_planetary_turns_at_willis_ratios_and_pitch_circles_roll(name):
    m = read_mechanism(example_path(name))
    r = kinematic_analysis(m, frames=90, speed=2.0)
    input_link = m.joint(m.drivers[0]).links[1]
    angle = {x: np.unwrap(np.asarray(r.links[x]["angle"], float)) for x in m.links}
    for x in m.links:
        if x == m.frame:
            continue
        ratio = float(speed_ratio(m, input_link, x))
        assert np.allclose(r.links[x]["omega"], 2.0 / ratio, rtol=1e-12)
    # rolling: the arcs turned relative to the carrier are equal at every frame
    for g in gear_pairs(m):
        c = fundamental_circuit(m, g).carrier
        a, b = g.links
        ra, rb = g.radii
        da = (angle[a] - angle[a][0]) - (angle[c] - angle[c][0])
        db = (angle[b] - angle[b][0]) - (angle[c] - angle[c][0])
        assert np.allclose(ra * da, g.sign * rb * db, atol=1e-9)
    # the satellites' axes stay on their circles about the main axis
    for j in m.joints:
        if j.id != "O":
            radius = math.hypot(*j.at)
            assert np.allclose(np.hypot(r.joints[j.id]["x"], r.joints[j.id]["y"]), radius)


def test_drivers_must_match_the_geared_mobility():
    data = json.loads(example_path("geared-five-bar").read_text())
    data["drivers"] = ["O1", "O2"]
    with pytest.raises(
        MechanismError, match=r"^drivers: O1, O2 \(2\) for a geared mechanism of F = 1"
    ):
        kinematic_analysis(mechanism_from_dict(data), frames=4)


SUN_AND_PLANET = json.loads(example_path("sun-and-planet").read_text())


def test_sun_and_planet_follows_the_rod():
    """The sun turns by the crank's turn plus the rod's turn relative to the crank,
    mirrored (equal gears): θ4 = 2 θ1 - θ3; the rod's angle from the four-bar in
    closed form (sympy), its derivatives symbolic."""
    t = sp.Symbol("t")
    A = sp.Matrix([30 * sp.cos(t), 30 * sp.sin(t)])
    O2 = sp.Matrix([40, 0])
    d = O2 - A
    dist = sp.sqrt(d.dot(d))
    l3, l5 = sp.sqrt(1700), 40
    a = (l3**2 - l5**2 + dist**2) / (2 * dist)
    B = A + a * d / dist + sp.sqrt(l3**2 - a**2) * sp.Matrix([-d[1], d[0]]) / dist
    th3 = sp.atan2(B[1] - A[1], B[0] - A[0])
    th4 = 2 * t - th3  # plus a constant
    m = mechanism_from_dict(SUN_AND_PLANET)
    r = kinematic_analysis(m, frames=24)
    assert [s.kind for s in m_plan_steps(m)].count("gear-link") == 1
    w4, e4 = sp.lambdify(t, th4.diff(t)), sp.lambdify(t, th4.diff(t, 2))
    q = r.q[:, 0]
    assert np.allclose(r.joints["B"]["x"], [float(B[0].subs(t, x)) for x in q], atol=1e-9)
    assert np.allclose(r.links["4"]["omega"], [w4(x) for x in q], atol=1e-9)
    assert np.allclose(r.links["4"]["eps"], [e4(x) for x in q], atol=1e-8)
    turned = np.unwrap(np.asarray(r.links["4"]["angle"], float))
    f4 = sp.lambdify(t, th4)
    expected = np.unwrap([f4(x) for x in q])
    assert np.allclose(turned - turned[0], expected - expected[0], atol=1e-9)


def m_plan_steps(m):
    from mjstruct.kinematics.planner import plan_kinematics

    return plan_kinematics(m).steps


def test_a_mesh_without_a_carrier_is_bad_input():
    from mjstruct.gears.structure import geared_structure

    data = json.loads(json.dumps(SUN_AND_PLANET))
    data["gears"] = [{"id": "g", "links": ["1", "5"], "radii": [10, 20]}]
    m = mechanism_from_dict(data)
    for run in (lambda: kinematic_analysis(m, frames=4), lambda: geared_structure(m)):
        with pytest.raises(MechanismError, match=r"^gears: the carrier of 'g' is not determined"):
            run()


def test_cli_kinematics_of_a_planetary_train(capsys):
    assert (
        main(["kinematics", str(example_path("planetary-simple")), "--frames", "4", "--json"]) == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert out["links"]["3"]["omega"] == pytest.approx([1 / 6] * 4)
    assert "gear mesh: link 3 turns about O on link 0 by Willis" in out["plan"]["steps"][2]
    assert main(["singular", str(example_path("planetary-simple"))]) == 2
    assert "gears: singular positions" in capsys.readouterr().err


def test_rack_pairs_are_refused_by_the_kinematics():
    rack = {
        "frame": "0",
        "joints": [{"id": "O", "links": ["0", "1"], "at": [0, 0]},
                   {"id": "S", "links": ["0", "2"], "type": "P", "at": [0, -10], "axis": [1, 0]}],
        "drivers": ["O"],
        "gears": [{"id": "r", "links": ["1", "2"], "type": "rack", "teeth": [20], "module": 1,
                   "centres": ["O"], "line": {"at": [5, -10], "axis": [1, 0]}}],
    }  # fmt: skip
    with pytest.raises(MechanismError, match=r"^gears: 'r' is a rack pair"):
        kinematic_analysis(mechanism_from_dict(rack), frames=4)
