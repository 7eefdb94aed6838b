"""Exact isomorphism against the seed's invariants; canonical codes under relabelling;
the shipped counterexample pair; fast chain codes equal to canonical_code."""

from __future__ import annotations

import json

import networkx as nx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.strategies import chains, relabelled

from mjstruct.cli.main import main
from mjstruct.io import read_mechanism
from mjstruct.mechanism import Mechanism
from mjstruct.structure.invariants import mj_link_sets, seed_invariants
from mjstruct.structure.isomorphism import canonical_code
from mjstruct.synthesis.atlas import atlas, chain_code
from project_paths import ROOT

PAIR = [ROOT / "catalogs" / "examples" / f"iso-counterexample-{k}.json" for k in "ab"]


def _vf2(a: Mechanism, b: Mechanism) -> bool:
    return nx.is_isomorphic(
        a.graph(), b.graph(), node_match=lambda x, y: x["bipartite"] == y["bipartite"]
    )


def test_counterexample_pair_has_equal_seed_invariants_but_differs() -> None:
    a, b = (read_mechanism(p) for p in PAIR)
    ia, ib = seed_invariants(a), seed_invariants(b)
    assert ia == ib
    assert ia.MJA and ia.loops is not None  # it has an MJ and is planar
    assert canonical_code(a) != canonical_code(b)
    assert not _vf2(a, b)  # independent check


def test_cli_iso_reports_the_counterexample(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["iso", str(PAIR[0]), str(PAIR[1]), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["isomorphic"] is False and out["invariants_agree"] is True
    assert {"canonical_a", "canonical_b", "level"} <= set(out)
    assert main(["iso", str(PAIR[0]), str(PAIR[1])]) == 0
    assert "NOT isomorphic" in capsys.readouterr().out


def test_atlas_chains_relabelled_keep_their_code() -> None:
    for c in atlas(2, 9, mj=True).chains[::7]:
        m = c.mechanism()
        for seed in range(3):
            assert canonical_code(relabelled(m, seed)) == c.canonical


@settings(max_examples=60, deadline=None)
@given(chains(max_links=10), st.integers(0, 10**6))
def test_canonical_code_stable_across_relabelling(m: Mechanism, seed: int) -> None:
    assert canonical_code(relabelled(m, seed)) == canonical_code(m)
    assert seed_invariants(relabelled(m, seed)).mj_link_sets == mj_link_sets(m)


@settings(max_examples=60, deadline=None)
@given(chains(max_links=8), chains(max_links=8))
def test_canonical_code_agrees_with_vf2(a: Mechanism, b: Mechanism) -> None:
    assert (canonical_code(a) == canonical_code(b)) == _vf2(a, b)


@settings(max_examples=40, deadline=None)
@given(chains(max_links=10))
def test_fast_chain_code_equals_canonical_code(m: Mechanism) -> None:
    index = {x: i for i, x in enumerate(m.links)}
    joints = [[index[x] for x in j.links] for j in m.joints]
    assert chain_code(m.n, joints)[0] == canonical_code(m, "chain")


def test_seed_invariants_disagree_on_watt_and_stephenson() -> None:
    watt = read_mechanism(ROOT / "catalogs" / "examples" / "watt.json")
    steph = read_mechanism(ROOT / "catalogs" / "examples" / "stephenson.json")
    iw, istp = seed_invariants(watt), seed_invariants(steph)
    assert iw.LA == istp.LA == (4, 2)
    assert iw.loops == (4, 4, 6) and istp.loops == (4, 5, 5)
