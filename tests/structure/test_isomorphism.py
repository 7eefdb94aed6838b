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
from mjstruct.synthesis.atlas import atlas
from mjstruct.synthesis.canonical_chains import chain_code
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


def _file(tmp_path, name: str, **changes: object) -> str:
    """A shipped example with some top-level keys changed, written to ``tmp_path``."""
    data = json.loads((ROOT / "catalogs" / "examples" / f"{name}.json").read_text())
    data.update(changes)
    path = tmp_path / f"{name}-{len(list(tmp_path.iterdir()))}.json"
    path.write_text(json.dumps(data))
    return str(path)


def _iso(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[dict[str, object], str]:
    assert main(["iso", *argv, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert main(["iso", *argv]) == 0
    return d, capsys.readouterr().out


def test_two_inversions_of_one_chain_say_what_differs(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # the Zhivago mechanism and the Stephenson six-bar: one chain, another frame and driver
    files = [str(ROOT / "catalogs" / "examples" / f"{n}.json") for n in ("zhivago", "stephenson")]
    d, text = _iso(capsys, *files, "--level", "mechanism")
    assert d["isomorphic"] is False and d["level"] == "mechanism"
    assert d["levels"] == {"chain": True, "kinds": True, "mechanism": False}
    assert d["differences"] == ["frame", "drivers"]
    assert "NOT isomorphic: the invariants" not in text  # the chains ARE isomorphic
    assert "the chains are isomorphic; the mechanisms differ in:" in text
    assert "Stephenson II six-bar" in text and "Stephenson I six-bar" in text
    # the chain level's answer is printed too, whatever level was asked
    assert any(line.split()[:1] == ["chain"] and "NOT" not in line for line in text.splitlines())


def test_only_the_frame_differs(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    # Watt: frame 0 is ternary (Watt II), link 1 binary (Watt I); the driver O1 joins both
    a, b = _file(tmp_path, "watt"), _file(tmp_path, "watt", frame="1")
    d, text = _iso(capsys, a, b, "--level", "mechanism")
    assert d["levels"] == {"chain": True, "kinds": True, "mechanism": False}
    assert d["differences"] == ["frame"]
    assert "link 0 with 3 joints, a Watt II six-bar" in text
    assert "link 1 with 2 joints, a Watt I six-bar" in text


def test_drivers_elsewhere_relative_to_the_frame(
    tmp_path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a four-bar driven at a frame joint or at the crank–coupler joint: every joint of
    # the bare cycle looks alike, so neither the frame nor the driver differs alone
    a, b = _file(tmp_path, "four-bar"), _file(tmp_path, "four-bar", drivers=["A"])
    d, _ = _iso(capsys, a, b, "--level", "mechanism")
    assert d["levels"]["chain"] and not d["levels"]["mechanism"]
    assert d["differences"] == ["arrangement"]
    d, text = _iso(capsys, a, a, "--level", "mechanism")
    assert d["isomorphic"] and d["differences"] == []
    assert "differ in" not in text


PLAIN_AND_SLIDER = ("four-bar", "slider-crank")


def test_a_slider_in_place_of_a_pin(capsys: pytest.CaptureFixture[str]) -> None:
    files = [str(ROOT / "catalogs" / "examples" / f"{n}.json") for n in PLAIN_AND_SLIDER]
    d, text = _iso(capsys, *files, "--level", "kinds")
    assert d["levels"] == {"chain": True, "kinds": False, "mechanism": False}
    assert "joint kinds" in d["differences"]
    assert "revolute and prismatic joints" in text


def test_chains_that_differ_list_no_mechanism_difference(
    capsys: pytest.CaptureFixture[str],
) -> None:
    d, text = _iso(capsys, *map(str, PAIR), "--level", "mechanism")
    assert d["levels"]["chain"] is False and d["differences"] == []
    assert "the structural invariants agree but the chains are NOT isomorphic" in text
