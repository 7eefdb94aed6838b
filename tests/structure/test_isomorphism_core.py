"""Canonical codes on the shipped examples."""

from __future__ import annotations

from mjstruct.io import read_mechanism
from mjstruct.structure.isomorphism import canonical_code, is_isomorphic


def test_watt_and_stephenson_differ(examples):
    watt = read_mechanism(examples / "watt.json")
    steph = read_mechanism(examples / "stephenson.json")
    assert not is_isomorphic(watt, steph)


def test_zhivago_and_seed003_share_stephenson_chain(examples):
    steph = read_mechanism(examples / "stephenson.json")
    for name in ("zhivago", "class-iv-seed003"):
        assert is_isomorphic(steph, read_mechanism(examples / f"{name}.json"))


def test_mechanism_level_sees_frame_and_drivers(examples):
    sc = read_mechanism(examples / "four-bar.json")
    other_driver = sc.with_drivers(["O2"])
    assert canonical_code(sc) == canonical_code(other_driver)
    # O1 and O2 are symmetric in the four-bar graph, so driving either is the same
    assert canonical_code(sc, "mechanism") == canonical_code(other_driver, "mechanism")
    coupler_driven = sc.with_drivers(["A"])
    assert canonical_code(sc, "mechanism") != canonical_code(coupler_driven, "mechanism")


def test_kinds_level_sees_prismatic(examples):
    four = read_mechanism(examples / "four-bar.json")
    slider = read_mechanism(examples / "slider-crank.json")
    assert canonical_code(four) == canonical_code(slider)
    assert canonical_code(four, "kinds") != canonical_code(slider, "kinds")
