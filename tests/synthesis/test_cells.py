"""Synthesis cells: the seed's 20 cells, assortment formulas, and realisation counts
consistent with the atlas."""

from __future__ import annotations

import json
from collections import Counter

import pytest

from mjstruct.cli.main import main
from mjstruct.synthesis.atlas import atlas
from mjstruct.synthesis.cells import cells, code_counts, link_assortments, mj_assortments


def test_twenty_cells_up_to_five_loops() -> None:
    cs = cells(5)
    assert len(cs) == 20
    assert Counter(c.K for c in cs) == {2: 2, 3: 4, 4: 6, 5: 8}


@pytest.mark.parametrize("K", [2, 3, 4, 5, 6])
def test_mja_are_partitions_of_v(K: int) -> None:
    for V in range(1, 2 * K - 1):
        mjas = mj_assortments(K, V)
        assert len(set(mjas)) == len(mjas)
        for nu in mjas:
            assert len(nu) == K - 1  # ν2 .. ν_K: j <= K
            assert sum((j - 1) * c for j, c in enumerate(nu, start=2)) == V


@pytest.mark.parametrize(("K", "F"), [(2, 1), (3, 1), (4, 1), (3, 2), (4, 2)])
def test_la_satisfy_the_cell_equations(K: int, F: int) -> None:
    for V in range(0, 2 * K - 1):
        for la in link_assortments(K, V, F):
            assert sum(la) == F + 1 + 2 * K
            assert sum(k * n for k, n in enumerate(la)) == 2 * (K - 1) - V
            # the code-level K formula
            assert 1 + (V + sum(k * n for k, n in enumerate(la))) // 2 == K


@pytest.mark.parametrize(("F", "kmax"), [(1, 3), (2, 3)])
def test_counts_match_fresh_enumeration(F: int, kmax: int) -> None:
    rows = code_counts(F, kmax, with_sj=True)
    for K in range(2, kmax + 1):
        a = atlas(F, F + 1 + 2 * K, mj=True)
        assert sum(r.count for r in rows if r.K == K) == a.count
        tally = Counter((c.V, c.LA, c.MJA) for c in a.chains)
        for r in rows:
            if r.K != K:
                continue
            la = tuple(r.LA)
            while la[-1] == 0:
                la = la[:-1]
            mja = tuple(r.MJA)
            while mja and mja[-1] == 0:
                mja = mja[:-1]
            assert r.count == tally[(r.V, la, mja)]


def test_every_atlas_chain_lies_in_a_listed_cell() -> None:
    listed = {(c.K, c.V, m) for c in cells(4) for m in c.MJA}
    for c in atlas(1, 10, mj=True).chains:
        if c.V:
            mja = c.MJA + (0,) * (c.K - 1 - len(c.MJA))
            assert (c.K, c.V, mja) in listed


def test_cli_cells_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["cells", "--kmax", "5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["cells"]) == 20
    assert {"K", "V", "MJA"} <= set(out["cells"][0])
    assert main(["cells", "--kmax", "3", "--dof", "1", "--count", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    total = sum(code["chains"] for c in out["cells"] for code in c["codes"])
    # cells have V >= 1: every chain with an MJ, K = 2 (n = 6) and K = 3 (n = 8)
    assert total == sum(atlas(1, n, mj=True).count - atlas(1, n).count for n in (6, 8))


def test_cli_cells_bad_input(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["cells", "--kmax", "1"]) == 2
    assert "--kmax" in capsys.readouterr().err
    assert main(["cells", "--kmax", "3", "--count"]) == 2


def test_a_count_beyond_the_catalogs_is_refused_with_its_estimate(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # K = 5 at F = 1 means 12-link chains: the catalogs stop at 10 links, and the atlas
    # with MJs counted 248203 chains there (tens of seconds of work)
    assert main(["cells", "--kmax", "5", "--dof", "1", "--count"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    err = captured.err.strip()
    assert "\n" not in err
    assert err.startswith("mjstruct cells: --kmax: K = 5 (12 links)")
    assert "about 2.5e+05 chains" in err and "s on one worker" in err
    assert "--large" in err


def test_the_estimate_names_exactly_the_atlases_not_shipped() -> None:
    from mjstruct.structure.mobility import link_count
    from mjstruct.synthesis.catalog import SHIPPED
    from mjstruct.synthesis.cells import enumerations

    for F in (1, 2, 3):
        jobs = enumerations(F, 6)
        assert [(e.K, e.n) for e in jobs] == [
            (K, link_count(F, K)) for K in range(2, 7) if (F, link_count(F, K)) not in SHIPPED
        ]
    assert [e.chains for e in enumerations(1, 5)] == [248203]  # a count the atlas made


def test_large_lifts_the_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    import mjstruct.synthesis.cells as cells_module

    seen: dict[str, object] = {}

    def fake_counts(*args: object, **kwargs: object) -> list[object]:
        seen.update(kwargs)
        return []

    monkeypatch.setattr(cells_module, "code_counts", fake_counts)
    assert main(["cells", "--kmax", "5", "--dof", "1", "--count", "--large", "--json"]) == 0
    assert seen["limit"] is None
    assert main(["cells", "--kmax", "5", "--dof", "1", "--count", "--json"]) == 0
    assert seen["limit"] == cells_module.ENUMERATION_LIMIT


def test_an_enumeration_shows_progress_on_a_terminal(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import io
    import sys

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    calls: list[tuple[int, int]] = []
    # F = 3, K = 2: 8 links, not shipped, enumerated in a fraction of a second
    rows = code_counts(3, 2, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1][0] == calls[-1][1] > 0
    assert sum(r.count for r in rows) == atlas(3, 8, mj=True).count - atlas(3, 8).count
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    assert main(["cells", "--kmax", "2", "--dof", "3", "--count"]) == 0
    assert "cells F=3 K<=2" in terminal.getvalue() and "tasks" in terminal.getvalue()
    quiet = Terminal()
    monkeypatch.setattr(sys, "stderr", quiet)
    assert main(["cells", "--kmax", "2", "--dof", "3", "--count", "--json"]) == 0
    assert quiet.getvalue() == ""  # JSON output: no bar


def _stripped(t: tuple[int, ...]) -> tuple[int, ...]:
    while t and t[-1] == 0:
        t = t[:-1]
    return t


def _table(F: int, K: int, fractionated: bool) -> tuple[Counter[object], Counter[object]]:
    """The cells table's chains and planar chains per (V, [MJA], [LA]), rows with
    count 0 left out (keys without trailing zeros, as the atlases write them)."""
    rows = [r for r in code_counts(F, K, fractionated, with_sj=True) if r.K == K]
    keys = [(r.V, _stripped(r.MJA), _stripped(r.LA)) for r in rows]
    assert len(set(keys)) == len(keys)  # one row per code
    chains = Counter({k: r.count for k, r in zip(keys, rows, strict=True) if r.count})
    planar = Counter({k: r.planar for k, r in zip(keys, rows, strict=True) if r.planar})
    return chains, planar


def _shipped_with_loops() -> list[tuple[int, int]]:
    from mjstruct.synthesis.catalog import SHIPPED

    # K = 1 (the four-bar, the five-bar) has no cell: cells start at K = 2
    return [(F, n) for F, n in SHIPPED if (n - 1 - F) // 2 >= 2]


@pytest.mark.parametrize("fractionated", [False, True])
@pytest.mark.parametrize(("F", "n"), _shipped_with_loops())
def test_every_table_equals_the_catalog_it_counts(F: int, n: int, fractionated: bool) -> None:
    # issue 35 §3: with --fractionated the table dropped the chains with a cut link of
    # more than K + 1 joints ([8001]/[1·0], [7101]/[0·0] at F = 2, n = 9; [601] at n = 7)
    from mjstruct.synthesis.catalog import read_catalog

    K = (n - 1 - F) // 2
    recs = [r for r in read_catalog(F, n) if fractionated or not r["fractionated"]]
    want = Counter((r["V"], tuple(r["MJA"]), tuple(r["LA"])) for r in recs)
    want_planar = Counter((r["V"], tuple(r["MJA"]), tuple(r["LA"])) for r in recs if r["planar"])
    chains, planar = _table(F, K, fractionated)
    assert chains == want
    assert planar == want_planar
    assert sum(chains.values()) == len(recs)


@pytest.mark.parametrize(("F", "n"), [(3, 8), (3, 10), (4, 9)])
def test_every_enumerated_table_equals_the_atlas(F: int, n: int) -> None:
    # beyond the catalogs the table counts a fresh atlas: F = 3 has cut joints too, and
    # at n = 10 a link of K + 2 joints and an MJ of K + 2 links (the largest_parts bounds)
    K = (n - 1 - F) // 2
    for fractionated in (False, True):
        a = atlas(F, n, mj=True, fractionated=fractionated)
        chains, _ = _table(F, K, fractionated)
        assert chains == Counter((c.V, c.MJA, c.LA) for c in a.chains)
        assert sum(chains.values()) == a.count


def test_the_largest_parts_are_reached() -> None:
    from mjstruct.synthesis.cells import largest_parts

    for F, n in [(2, 7), (2, 9), (3, 10)]:
        K = (n - 1 - F) // 2
        chains = atlas(F, n, mj=True, fractionated=True).chains
        link_top, mj_top = largest_parts(K, F)
        assert max(len(c.LA) - 1 for c in chains) == link_top
        assert max(len(c.MJA) for c in chains) == mj_top
        # without a cut vertex, K + 1 holds [MJ structure 2020]
        plain = [c for c in chains if not c.fractionated]
        assert max(len(c.LA) - 1 for c in plain) <= K - 1
        assert max(len(c.MJA) for c in plain) <= K - 1


def test_cli_fractionated_table_holds_the_swivel_bucket(
    capsys: pytest.CaptureFixture[str],
) -> None:
    args = ["cells", "--kmax", "3", "--dof", "2", "--count", "--fractionated", "--sj", "--json"]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    codes = {r["code_star"]: r["chains"] for c in out["cells"] for r in c["codes"]}
    assert codes["[8001]/[1·0]"] == 1  # seed 002's example 4, F2n9-x0009
    sj = {(r["K"], tuple(r["LA"])): r["chains"] for r in out["simple_joint"]}
    assert sj[(3, (7, 1, 0, 1))] == 2
    per_k = Counter[int]()
    for c in out["cells"]:
        per_k[c["K"]] += sum(r["chains"] for r in c["codes"])
    for r in out["simple_joint"]:
        per_k[r["K"]] += r["chains"]
    assert per_k == {2: 9, 3: 219}  # the catalogs f2-n07 and f2-n09, whole
