"""Familiar names: Watt I/II and Stephenson I/II/III for every frame choice of the two
six-bar chains, checked against the textbook criterion (is the frame ternary, and
which ternary links does it touch), computed here from the joints alone."""

from __future__ import annotations

import json
import random

import pytest

from mjstruct.cli.main import main
from mjstruct.mechanism import Mechanism
from mjstruct.structure.isomorphism import canonical_code
from mjstruct.synthesis.atlas import atlas
from mjstruct.synthesis.names import chain_inversions, inversion_name
from project_paths import EXAMPLES


def _by_adjacency(joints: list[list[str]], frame: str) -> str:
    """The textbook name from the chain's incidence: Watt when the two ternary links
    share a joint, Stephenson otherwise; then by the frame's joints and neighbours."""
    degree = {link: sum(link in js for js in joints) for js in joints for link in js}
    ternary = [link for link, d in degree.items() if d == 3]
    assert len(ternary) == 2 and sorted(degree.values()) == [2, 2, 2, 2, 3, 3]

    def touch(a: str, b: str) -> bool:
        return any(a in js and b in js for js in joints)

    watt = touch(*ternary)
    if degree[frame] == 3:
        return "Watt II six-bar" if watt else "Stephenson III six-bar"
    if watt:
        return "Watt I six-bar"
    beside = sum(touch(frame, t) for t in ternary)
    return {2: "Stephenson I six-bar", 1: "Stephenson II six-bar"}[beside]


def _relabelled(joints: list[list[int]], rng: random.Random) -> list[list[str]]:
    """The same chain with link ids shuffled and joints (and their links) reordered."""
    ids = [f"L{k}" for k in range(6)]
    rng.shuffle(ids)
    out = [[ids[i] for i in js] for js in joints]
    rng.shuffle(out)
    for js in out:
        rng.shuffle(js)
    return out


def test_every_frame_of_both_six_bar_chains_is_named_as_the_textbooks_do() -> None:
    rng = random.Random(7)
    chains = atlas(1, 6).chains
    assert len(chains) == 2  # Watt and Stephenson: every one-DOF six-bar chain
    seen: dict[str, set[str]] = {}
    for chain in chains:
        for _ in range(3):  # any drawing of the chain
            joints = _relabelled([list(j) for j in chain.joints], rng)
            for frame in sorted({x for js in joints for x in js}):
                m = Mechanism.build([(f"J{k}", js) for k, js in enumerate(joints)], frame=frame)
                name = inversion_name(m)
                assert name == _by_adjacency(joints, frame), (joints, frame)
                seen.setdefault(name, set()).add(canonical_code(m, "mechanism"))
    # five inversions, each one mechanism up to isomorphism
    assert sorted(seen) == [
        "Stephenson I six-bar",
        "Stephenson II six-bar",
        "Stephenson III six-bar",
        "Watt I six-bar",
        "Watt II six-bar",
    ]
    assert all(len(codes) == 1 for codes in seen.values())


def test_drivers_and_sliders_do_not_change_the_name() -> None:
    joints = [("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0])]
    joints += [("e", [3, 4]), ("f", [4, 5], "P"), ("g", [5, 0])]
    plain = Mechanism.build([(j[0], j[1]) for j in joints], frame=0, drivers=["a"])
    slider = Mechanism.build(joints, frame=0, drivers=["g"])
    assert inversion_name(plain) == inversion_name(slider) == "Watt II six-bar"


def test_no_name_without_a_frame_or_beyond_the_six_bars() -> None:
    chain = atlas(1, 6).chains[0].mechanism()
    assert chain.frame is None and inversion_name(chain) is None
    with_mj = [c.mechanism() for c in atlas(1, 6, mj=True).chains if c.V]
    assert with_mj  # six links with a multiple joint: no textbook name, whatever the frame
    for m in with_mj:
        for frame in m.links:
            framed = Mechanism.build([(j.id, j.links) for j in m.joints], frame=frame)
            assert inversion_name(framed) is None
    four = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0])], frame=0)
    assert inversion_name(four) is None


def test_chain_inversions_list_each_frame_once() -> None:
    for c in atlas(1, 6).chains:
        m = c.mechanism()
        inv = chain_inversions(m)
        frames = sorted(link for links in inv.values() for link in links)
        assert frames == sorted(m.links)
        joints = [list(j.links) for j in m.joints]
        for name, links in inv.items():
            assert all(_by_adjacency(joints, link) == name for link in links)


@pytest.mark.parametrize(
    ("example", "name"),
    [("watt", "Watt II six-bar"), ("stephenson", "Stephenson I six-bar"), ("four-bar", None)],
)
def test_analyze_and_lookup_report_the_inversion_name(
    example: str, name: str | None, capsys: pytest.CaptureFixture[str]
) -> None:
    path = str(EXAMPLES / f"{example}.json")
    for command in ("analyze", "lookup"):
        assert main([command, path, "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["inversion_name"] == name
        assert main([command, path]) == 0
        text = capsys.readouterr().out
        assert (name in text) if name else ("six-bar" not in text)


def test_atlas_lists_the_inversions_with_their_frame_links(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["atlas", "--links", "6", "--json"]) == 0
    chains = json.loads(capsys.readouterr().out)["chains"]
    named = 0
    for c in chains:
        joints = [[str(x) for x in js] for js in c["joints"]]
        frames = sorted(f for inv in c["inversions"] for f in inv["frames"])
        assert frames == list(range(6))  # every link is the frame of one inversion
        for inv in c["inversions"]:
            assert all(_by_adjacency(joints, str(f)) == inv["name"] for f in inv["frames"])
            named += 1
    assert named == 5
    assert main(["atlas", "--links", "4", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["chains"][0]["inversions"] == []
