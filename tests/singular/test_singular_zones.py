"""Clearance zones in the result: formula (3)'s lambda and delta on every four-bar
zone, and one zone entry per collinear pair of moving links (none without a pair)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.io import read_mechanism
from mjstruct.singular.analysis import singular_analysis
from mjstruct.singular.curve import ClosureEquations


def _psi3(lam: float, delta: float, stretched: bool) -> float:
    """Formula (3) in the spec's lambda/delta form, written out here."""
    sign = 1.0 if stretched else -1.0
    arg = 1 - delta * (2 * lam + delta) / (2 * (1 + sign * lam))
    return 2 * math.acos(max(-1.0, min(1.0, arg)))


@pytest.mark.parametrize("name", ["fourbar-ms3", "fourbar-ms4", "four-bar"])
def test_fourbar_zones_carry_lambda_and_delta_of_formula_3(name):
    m = read_mechanism(example_path(name))
    D = 0.013
    r = singular_analysis(m, clearance=D)
    eq = ClosureEquations.build(m, r.input, r.output)
    at = {j.id: complex(*j.at) for j in m.joints}
    n_zones = 0
    for p in r.singular:
        x = list(p.configuration)
        for z in p.zone:
            # the pair's shared joint and outer joints, lengths from the file
            a, b = z.pair
            (shared,) = set(m.link_joints[a]) & set(m.link_joints[b])
            ja = next(j for j in m.link_joints[a] if j != shared)
            jb = next(j for j in m.link_joints[b] if j != shared)
            la, lb = abs(at[ja] - at[shared]), abs(at[jb] - at[shared])
            assert z.link == (a if la >= lb else b)
            assert z.lam == pytest.approx(min(la, lb) / max(la, lb), rel=1e-12)
            assert z.delta == pytest.approx(D / max(la, lb), rel=1e-12)
            # first kind when the outer joints lie on either side of the shared one
            pos = {j: eq.joint_position(np.array(x), j) for j in (ja, jb, shared)}
            u, v = pos[ja] - pos[shared], pos[jb] - pos[shared]
            stretched = (u.conjugate() * v).real < 0
            assert z.psi == pytest.approx(_psi3(z.lam, z.delta, stretched), abs=1e-12)
            n_zones += 1
    assert n_zones >= len(r.singular)


def test_lambda_delta_in_json_and_text(capsys):
    path = str(example_path("fourbar-ms4"))
    assert main(["singular", path, "--clearance", "0.01", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    zones = [z for p in d["singular"] for z in p["zone"]]
    assert zones and all({"lambda", "delta"} <= set(z) for z in zones)
    # the pair 1-2 of MS4 (input 0.5, coupler 1): lambda 0.5, delta D / 1
    z12 = [z for z in zones if z["pair"] == ["1", "2"]]
    assert z12 and all(z["lambda"] == pytest.approx(0.5) for z in z12)
    assert all(z["delta"] == pytest.approx(0.01) for z in z12)
    assert main(["singular", path, "--clearance", "0.01"]) == 0
    assert "lambda 0.5, delta 0.01" in capsys.readouterr().out


def test_one_zone_entry_per_collinear_pair_and_none_without_a_pair():
    r = singular_analysis(read_mechanism(example_path("triad-class-iii")), clearance=1e-3)
    assert any(not p.collinear for p in r.singular), "the example has a pairless position"
    for p in r.singular:
        assert len(p.zone) == len(p.pairs)
        assert [z.pair for z in p.zone] == list(p.pairs)
        for z in p.zone:
            assert z.method == "leading-order" and z.lam is None and z.delta is None
        d = p.to_dict()
        assert all(z["pair"] is not None for z in d["zone"])
        if not p.collinear:
            assert d["zone"] == []
