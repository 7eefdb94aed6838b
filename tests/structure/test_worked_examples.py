"""The spec's worked-example table (seed 002), reproduced from the example files."""

from __future__ import annotations

import pytest

from mjstruct.io import read_mechanism
from mjstruct.report import structural_report

# Rows of ../shared/spec/01-structure.md, "Worked examples from the seed".
TABLE = [
    # file, LA, MJA, V, K, L, AVC, F, S_L, [L], N, rc, Code, Code*
    (
        "seed002-ex1-needle-drive",
        [8, 1, 1],
        [3],
        3,
        4,
        5,
        0,
        1,
        23,
        [4, 4, 5, 5, 5],
        1,
        0,
        "[8110]/3",
        "[8110]/[3·0·0]",
    ),
    (
        "radial-engine-5",
        [11, 0, 0, 0, 1],
        [0, 0, 0, 1],
        4,
        5,
        6,
        0,
        1,
        28,
        [4, 4, 5, 5, 5, 5],
        1,
        0,
        "[11.0001]/4",
        "[11.0001]/[0·0·0·1]",
    ),
    (
        "seed002-ex3-excavator",
        [10, 0, 1, 1],
        [1],
        1,
        4,
        5,
        0,
        3,
        29,
        [4, 4, 4, 4, 13],
        3,
        0,
        "[10.011]/1",
        "[10.011]/[1·0·0]",
    ),
    (
        "seed002-ex4-swivel-bucket",
        [8, 0, 0, 1],
        [1],
        1,
        3,
        4,
        0,
        2,
        21,
        [4, 4, 4, 9],
        2,
        0,
        "[8001]/1",
        "[8001]/[1·0]",
    ),
    ("seed002-ex5-24-link", [6, 18], None, 2, 11, 12, 0, 1, None, None, 1, 0, None, None),
]
COLUMNS = ["LA", "MJA", "V", "K", "L", "AVC", "F", "S_L", "loops", "N", "rc", "code", "code_star"]


@pytest.mark.parametrize("row", TABLE, ids=[r[0] for r in TABLE])
def test_seed_table_row(examples, row):
    name, *expected = row
    d = structural_report(read_mechanism(examples / f"{name}.json")).to_dict()
    for column, value in zip(COLUMNS, expected, strict=True):
        if value is not None:
            assert d[column] == value, column
    n_expected = sum(row[1])
    assert d["n"] == n_expected


@pytest.mark.parametrize("row", TABLE[:4], ids=[r[0] for r in TABLE[:4]])
def test_both_formulas_agree(examples, row):
    d = structural_report(read_mechanism(examples / f"{row[0]}.json")).to_dict()
    c = d["checks"]
    assert len(set(c["K"].values())) == 1
    assert len(set(c["F"].values())) == 1
    assert len(set(c["S_L"].values())) == 1
    assert c["rc"]["N-F"] == c["rc"]["assortment"]
    assert c["rc"]["seed"] == c["rc"]["assortment"]  # the 0.1.0 key stays for scripts
    assert d["violations"] == []


def test_radial_engine_mj_multiplicity(examples):
    m = read_mechanism(examples / "radial-engine-5.json")
    mj = [j for j in m.joints if j.is_multiple]
    assert len(mj) == 1 and mj[0].multiplicity == 5
    d = structural_report(m).to_dict()
    assert d["p"] == 16


@pytest.mark.parametrize(
    "name, LA, K, F",
    [
        ("four-bar", [4], 1, 1),
        ("watt", [4, 2], 2, 1),
        ("stephenson", [4, 2], 2, 1),
        ("five-bar", [5], 1, 2),
        ("slider-crank", [4], 1, 1),
        ("zhivago", [4, 2], 2, 1),
        ("class-iv-seed003", [4, 2], 2, 1),
        ("radial-engine-9", [19, 0, 0, 0, 0, 0, 0, 0, 1], 9, 1),
    ],
)
def test_classic_chains(examples, name, LA, K, F):
    d = structural_report(read_mechanism(examples / f"{name}.json")).to_dict()
    assert (d["LA"], d["K"], d["F"], d["AVC"]) == (LA, K, F, 0)
