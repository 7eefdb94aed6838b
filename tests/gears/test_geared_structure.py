"""Geared linkages: DOF with p4, redundant constraints by rank, the equivalent chain,
fundamental circuits, Willis' speed ratios against a sympy solve of the rolling
constraints written in absolute velocities, and pair types in the canonical code."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest
import sympy as sp

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.gear_pairs import gear_pairs
from mjstruct.gears.planetary import planetary_synthesis, two_aa_mechanism
from mjstruct.gears.structure import (
    equivalent_chain,
    fundamental_circuit,
    geared_canonical_code,
    geared_structure,
)
from mjstruct.gears.willis import angular_velocities, speed_ratio
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.report import structural_report


def planetary(planets: int, sun: int = 20, planet: int = 40) -> dict:
    """Sun 1 and carrier 3 on O, ``planets`` planets on the carrier, ring in the frame."""
    ring = sun + 2 * planet
    a = (sun + planet) / 2
    joints = [{"id": "O", "links": ["0", "1", "3"], "at": [0, 0]}]
    gears = []
    for k in range(planets):
        ang = 2 * math.pi * k / planets
        joints.append({"id": f"P{k}", "links": ["3", f"p{k}"],
                       "at": [a * math.cos(ang), a * math.sin(ang)]})  # fmt: skip
        gears.append({"id": f"s{k}", "links": ["1", f"p{k}"], "teeth": [sun, planet],
                      "module": 1, "centres": ["O", f"P{k}"]})  # fmt: skip
        gears.append({"id": f"r{k}", "links": [f"p{k}", "0"], "type": "internal",
                      "teeth": [planet, ring], "module": 1,
                      "centres": [f"P{k}", "O"]})  # fmt: skip
    return {"frame": "0", "joints": joints, "drivers": ["O"], "gears": gears}


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_planets_add_one_redundant_constraint_each(k):
    s = geared_structure(mechanism_from_dict(planetary(k)))
    assert (s.p4, s.F) == (2 * k, 1 - (k - 1))
    assert (s.F_rank, s.rc) == (1, k - 1)


@pytest.mark.parametrize("name", ["planetary-simple", "planetary-2aa", "geared-five-bar"])
def test_equivalent_chain_keeps_the_dof(name):
    m = read_mechanism(example_path(name))
    s = geared_structure(m)
    e = equivalent_chain(m)
    assert e.n == m.n + s.p4 and len(e.joints) == len(m.joints) + 2 * s.p4
    assert structural_report(e, with_loops=False).F == s.F


def test_examples_structure():
    got = {
        name: (lambda s: (s.n, s.p5, s.p4, s.F, s.F_rank, s.rc))(
            geared_structure(read_mechanism(example_path(name)))
        )
        for name in ("planetary-simple", "planetary-2aa", "geared-five-bar")
    }
    assert got == {
        "planetary-simple": (4, 3, 2, 1, 1, 0),
        "planetary-2aa": (9, 8, 9, -1, 1, 2),  # three satellite sets: two redundant
        "geared-five-bar": (5, 5, 1, 1, 1, 0),
    }


def test_carriers_found_with_and_without_centres():
    m = read_mechanism(example_path("planetary-simple"))
    assert [fundamental_circuit(m, g).carrier for g in gear_pairs(m)] == ["3", "3"]
    data = json.loads(example_path("planetary-simple").read_text())
    for g in data["gears"]:
        del g["centres"]
    m = mechanism_from_dict(data)
    circuits = [fundamental_circuit(m, g) for g in gear_pairs(m)]
    assert [(c.carrier, c.axes) for c in circuits] == [("3", ("O", "P")), ("3", ("P", "O"))]


def rolling_oracle(m, input_link: str, output_link: str) -> sp.Rational:
    """ω_in/ω_out from the pitch points' absolute velocities (sympy, exact): each link
    turns about its pivot on its carrier; at each pitch point both gears' velocities
    are equal. Links are pinned in a tree from the frame (a gear train)."""
    w = {x: (0 if x == m.frame else sp.Symbol(f"w_{x}")) for x in m.links}

    def exact(x: float) -> sp.Expr:  # the examples' coordinates: rationals and sqrt(3)
        return sp.nsimplify(x, [sp.sqrt(3)], tolerance=1e-10)

    pos = {j.id: sp.Matrix([exact(j.at[0]), exact(j.at[1])]) for j in m.joints}
    # velocity of each link's pivot: walk the joint tree from the frame
    vel = {m.frame: (sp.zeros(2, 1), sp.zeros(2, 1))}  # link -> (velocity of origin, )

    def v_point(link, p):
        v0, _ = vel[link]
        return v0 + w[link] * sp.Matrix([-p[1], p[0]])

    todo = True
    while todo:
        todo = False
        for j in m.joints:
            known = [x for x in j.links if x in vel]
            for x in j.links:
                if x not in vel and known:
                    vp = v_point(known[0], pos[j.id])
                    # origin velocity of x: vp - w_x × p
                    vel[x] = (vp - w[x] * sp.Matrix([-pos[j.id][1], pos[j.id][0]]), None)
                    todo = True
    eqs = []
    for g in gear_pairs(m):
        ca, cb = (pos[c] for c in g.centres)
        ra, rb = (exact(r) for r in g.radii)
        e = (cb - ca) / sp.sqrt(((cb - ca).T * (cb - ca))[0])
        q = ca + (ra if g.kind == "external" or ra > rb else -ra) * e
        diff = v_point(g.links[0], q) - v_point(g.links[1], q)
        eqs.append(sp.simplify(diff[1] * e[0] - diff[0] * e[1]))  # along the tangent
    sol = sp.solve(
        [e for e in eqs if e != 0],
        [s for s in w.values() if s != 0 and s != w[input_link]],
        dict=True,
    )
    assert len(sol) == 1
    return sp.nsimplify(sp.simplify(w[input_link] / w[output_link].subs(sol[0])))


@pytest.mark.parametrize(
    ("name", "pairs"),
    [("planetary-simple", [("1", "3"), ("1", "2"), ("2", "3")]),
     ("planetary-2aa", [("1", "H"), ("1", "2a"), ("1", "3c"), ("2b", "3b")])],
)  # fmt: skip
def test_willis_ratios_equal_the_rolling_solve(name, pairs):
    m = read_mechanism(example_path(name))
    for a, b in pairs:
        assert sp.Rational(speed_ratio(m, a, b)) == rolling_oracle(m, a, b)


def test_synthesised_2aa_sets_turn_at_their_ratio():
    """Tooth sets from the synthesis, built as mechanisms (the mesh check passes, with
    meshing-angle factors too), turn at 1 + Z4/Z1 by Willis' equations and in the
    kinematics, and k satellite sets leave k - 1 redundant constraints."""
    for t1, t2 in ((1.0, 1.0), (1.1, 1.05)):
        r = planetary_synthesis(4, 3, t1=t1, t2=t2, ratio_tolerance=0.03, z_max=90)
        assert r.count > 0
        for s in r.sets[:4]:
            m = mechanism_from_dict(two_aa_mechanism(s, 3, t1))
            assert speed_ratio(m, "1", "H") == 1 + sp.Rational(s.z4, s.z1)
            g = geared_structure(m)
            assert (g.F_rank, g.rc) == (1, 2)
            omega = kinematic_analysis(m, frames=3).links["H"]["omega"]
            assert np.allclose(omega, 1 / s.ratio, rtol=1e-12)


def test_cli_writes_the_chosen_set(tmp_path, capsys):
    out = tmp_path / "train.json"
    argv = ["planetary", "--ratio", "4", "--t1", "1.1", "--t2", "1.05", "--set", "2"]
    assert main([*argv, "-o", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    chosen = result["sets"][1]
    m = read_mechanism(out)
    assert speed_ratio(m, "1", "H") == 1 + sp.Rational(chosen["Z4"], chosen["Z1"])
    assert main([*argv, "--set", "100000", "-o", str(tmp_path / "x.json")]) == 2
    assert "--set: must be in 1.." in capsys.readouterr().err


def test_differential_needs_a_held_member():
    data = planetary(1)
    data["frame"] = "case"
    data["joints"][0]["links"] = ["case", "1", "3", "0"]  # the ring 0 turns too
    m = mechanism_from_dict(data)
    with pytest.raises(MechanismError, match=r"^held: the speeds are not determined"):
        speed_ratio(m, "1", "3")
    assert speed_ratio(m, "1", "3", held=["0"]) == 6  # ring held: 1 + 100/20
    assert speed_ratio(m, "1", "0", held=["3"]) == -5  # carrier held: -100/20
    w = angular_velocities(m, {"1": 1, "0": 1})  # sun and ring together: all as one
    assert w["3"] == 1 and w["p0"] == 1


def test_canonical_code_tells_pair_types_apart():
    base = planetary(1)
    for g in base["gears"]:
        del g["centres"]
    relabelled = json.loads(json.dumps(base).replace('"p0"', '"planet"').replace('"3"', '"H"'))
    external = copy.deepcopy(base)
    external["gears"][1]["type"] = "external"
    joint = copy.deepcopy(base)  # the ring mesh as a revolute joint instead
    joint["gears"].pop()
    joint["joints"].append({"id": "X", "links": ["p0", "0"], "at": [1, 1]})
    codes = {
        name: (geared_canonical_code(mechanism_from_dict(d)),
               geared_canonical_code(mechanism_from_dict(d), "kinds"))
        for name, d in [("base", base), ("relabelled", relabelled), ("external", external),
                        ("joint", joint)]
    }  # fmt: skip
    assert codes["base"] == codes["relabelled"]
    assert codes["base"][0] == codes["external"][0] and codes["base"][1] != codes["external"][1]
    assert codes["base"][0] != codes["joint"][0]


def test_analyze_reports_the_gears(capsys):
    assert main(["analyze", str(example_path("planetary-2aa")), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    g = out["gears"]
    assert (g["p4"], g["F"], g["F_rank"], g["rc"]) == (9, -1, 1, 2)
    assert out["F"] == g["F"] == g["equivalent"]["F"] and out["n"] == 18
    assert {p["carrier"] for p in g["pairs"]} == {"H"}
    assert main(["analyze", str(example_path("geared-five-bar"))]) == 0
    assert "F = 3(n − 1) − 2·p5 − p4 = 1" in capsys.readouterr().out


def test_assur_lookup_and_iso_of_geared_files(capsys):
    five = str(example_path("geared-five-bar"))
    assert main(["assur", five, "--json"]) == 0
    groups = json.loads(capsys.readouterr().out)["groups"]
    assert [sorted(g["links"]) for g in groups] == [["2", "mesh:g12"], ["3", "4"]]
    assert main(["lookup", five, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["name"] == "Stephenson six-bar"
    simple = str(example_path("planetary-simple"))
    assert main(["iso", simple, simple, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["isomorphic"] and out["canonical_a"].startswith("gc4.4-")
