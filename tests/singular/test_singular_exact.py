"""Exact clearance zones (the feasibility search) at the change points of the reference
four-bars, the hinged rhombus MS5's zones, and a failed search reported as a warning."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import mjstruct.singular.analysis as singular_module
from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import NumericalError
from mjstruct.io import read_mechanism
from mjstruct.singular.analysis import singular_analysis
from mjstruct.singular.curve import ClosureEquations


def _psi3(lam: float, delta: float, stretched: bool) -> float:
    """Formula (3) in its lambda/delta form, written out here."""
    sign = 1.0 if stretched else -1.0
    if not stretched and lam == 1.0:
        return 2 * math.pi  # coinciding pivots
    arg = 1 - delta * (2 * lam + delta) / (2 * (1 + sign * lam))
    return 2 * math.acos(max(-1.0, min(1.0, arg)))


@pytest.mark.parametrize("name", ["fourbar-ms1", "fourbar-ms2", "fourbar-ms4", "fourbar-ms5"])
def test_exact_zone_equals_formula_3_on_the_reference_fourbars(name, capsys):
    # MS1 (parallelogram), MS2 and MS5 (rhombus) stopped with "Iteration limit reached":
    # a folded pair of equal links turns freely (the search now ends at its bound of
    # half a turn each way), and at a change point each pair holds the link outside it
    path = str(example_path(name))
    assert main(["singular", path, "--clearance", "0.01", "--exact", "--json"]) == 0
    out = capsys.readouterr()
    d = json.loads(out.out)
    assert "Iteration limit" not in out.out + out.err
    assert not [w for w in d["warnings"] if "exact zone" in w]
    zones = [z for p in d["singular"] for z in p["zone"]]
    assert zones
    for z in zones:
        assert z["psi_exact"] == pytest.approx(z["psi"], abs=1e-9)


def test_ms5_stretched_pair_is_narrow_and_only_the_folded_equal_pair_turns_fully():
    m = read_mechanism(example_path("fourbar-ms5"))
    D = 0.01
    r = singular_analysis(m, clearance=D)
    eq = ClosureEquations.build(m, r.input, r.output)
    narrow = _psi3(1.0, D, stretched=True)
    assert narrow == pytest.approx(0.2006, abs=1e-4)  # "about 0.2 rad for delta = 0.01"
    kinds = []
    for p in r.singular:
        assert p.kind == "change_point"
        x = np.array(p.configuration)
        for z in p.zone:
            a, b = z.pair
            (shared,) = set(m.link_joints[a]) & set(m.link_joints[b])
            ja = next(j for j in m.link_joints[a] if j != shared)
            jb = next(j for j in m.link_joints[b] if j != shared)
            # the outer joints coincide (folded, equal links) or lie 2 apart (stretched)
            gap = abs(eq.joint_position(x, ja) - eq.joint_position(x, jb)) * eq.size
            if gap < 1e-9:
                assert z.psi == 2 * math.pi
                kinds.append("folded")
            else:
                assert gap == pytest.approx(2.0, abs=1e-9)
                assert z.psi == pytest.approx(narrow, abs=1e-12)
                kinds.append("stretched")
    # three change points: two with one pair of each kind, one with both pairs folded
    assert sorted(kinds) == ["folded"] * 4 + ["stretched"] * 2


def test_a_failed_exact_search_is_a_warning_and_a_null(monkeypatch, capsys):
    def fail(*args, **kwargs):
        raise NumericalError("exact zone: the search ended on no placement (test)")

    monkeypatch.setattr(singular_module, "exact_zone", fail)
    path = str(example_path("fourbar-ms3"))
    assert main(["singular", path, "--clearance", "0.01", "--exact", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    zones = [z for p in d["singular"] for z in p["zone"]]
    assert zones and all(z["psi_exact"] is None and z["psi"] > 0 for z in zones)
    notes = [w for w in d["warnings"] if w.startswith("exact zone at the ")]
    assert len(notes) == len(zones)
    assert all("psi_exact is null, psi (formula-3) stands" in w for w in notes)
