"""Shipped catalogs and lookup: every example file, catalog integrity, honest misses."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from mjstruct.cli.main import main
from mjstruct.io import read_mechanism
from mjstruct.structure.isomorphism import canonical_code
from mjstruct.synthesis.admissibility import is_admissible
from mjstruct.synthesis.atlas import atlas
from mjstruct.synthesis.catalog import SHIPPED, lookup, read_catalog
from mjstruct.synthesis.catalog_build import catalog_records
from project_paths import ROOT

EXAMPLES = sorted((ROOT / "catalogs" / "examples").glob("*.json"))


@pytest.fixture(autouse=True)
def _private_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_lookup_every_example(path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    m = read_mechanism(path)
    if "gears" in m.extra:  # the command looks up the equivalent lower-pair chain
        from mjstruct.gears.structure import equivalent_chain

        m = equivalent_chain(m)
    r = lookup(m)
    if r.found:
        assert r.record["canonical"] == canonical_code(m, "chain")
        assert (r.record["F"], r.record["n"]) == (r.F, m.n)
    elif (r.F, m.n) in SHIPPED:
        assert not is_admissible(m)
    else:
        # the library advises a call of atlas(), the command its flags
        assert "not in catalog" in r.reason and "atlas(F=" in r.reason
        assert "--" not in r.reason and r.atlas_args["n"] == m.n
    assert main(["lookup", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["found"] == r.found
    if r.found:
        assert {"id", "name", "K", "V", "code", "code_star"} <= set(out)
    elif r.atlas_args:
        assert f"`mjstruct atlas --dof {r.F} --links {m.n}" in out["reason"]


def test_familiar_names() -> None:
    ex = ROOT / "catalogs" / "examples"
    assert lookup(read_mechanism(ex / "watt.json")).record["name"] == "Watt six-bar"
    assert lookup(read_mechanism(ex / "stephenson.json")).record["name"] == "Stephenson six-bar"
    assert lookup(read_mechanism(ex / "four-bar.json")).record["name"] == "four-bar"


@pytest.mark.parametrize(("F", "n"), [(F, n) for F, n in SHIPPED if n <= 9])
def test_shipped_catalog_equals_fresh_enumeration(F: int, n: int) -> None:
    assert read_catalog(F, n) == catalog_records(F, n)


@pytest.mark.parametrize(("F", "n"), SHIPPED)
def test_catalog_integrity(F: int, n: int) -> None:
    recs = read_catalog(F, n)
    assert recs
    assert len({r["id"] for r in recs}) == len({r["canonical"] for r in recs}) == len(recs)
    sj = atlas(F, n).count if n <= 10 else None
    plain = [r for r in recs if not r["fractionated"] and r["V"] == 0]
    assert len(plain) == sj
    assert [r["id"] for r in plain] == [f"F{F}n{n}-{k:04d}" for k in range(1, len(plain) + 1)]
    for r in recs[:: max(1, len(recs) // 25)]:
        from mjstruct.mechanism import Mechanism

        m = Mechanism.build([(f"J{k}", js) for k, js in enumerate(r["joints"])])
        assert canonical_code(m) == r["canonical"]


def test_lookup_outside_catalog_is_honest(capsys: pytest.CaptureFixture[str]) -> None:
    path = ROOT / "catalogs" / "examples" / "radial-engine-5.json"
    assert main(["lookup", str(path)]) == 0
    out = capsys.readouterr().out
    assert "not in catalog" in out and "--links 12" in out


def test_lookup_rigid_chain_in_range(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # a triangle with a four-bar loop attached: F = 1, n = 6, but rigid sub-chain
    d = {
        "joints": [
            {"id": k, "links": ls}
            for k, ls in [
                ("a", [0, 1]),
                ("b", [1, 2]),
                ("c", [2, 0]),
                ("d", [2, 3]),
                ("e", [3, 4]),
                ("f", [4, 5]),
                ("g", [5, 0]),
            ]
        ]
    }
    p = tmp_path / "rigid.json"
    p.write_text(json.dumps(d))
    assert main(["lookup", str(p), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["found"] is False and "rigid" in out["reason"]


def test_lookup_bad_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    p = tmp_path / "bad.json"
    p.write_text("{")
    assert main(["lookup", str(p)]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_lookup_canonical_matches_analyze(capsys: pytest.CaptureFixture[str]) -> None:
    path = ROOT / "catalogs" / "examples" / "seed002-ex1-needle-drive.json"
    assert main(["analyze", str(path), "--json"]) == 0
    analyzed = json.loads(capsys.readouterr().out)
    assert main(["lookup", str(path), "--json"]) == 0
    found = json.loads(capsys.readouterr().out)
    assert found["found"] and found["canonical"] == analyzed["canonical"]
    assert found["code_star"] == analyzed["code_star"] and found["K"] == analyzed["K"]


def test_scheduler_without_dask_is_a_clean_error(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails as if absent
    assert main(["atlas", "--links", "8", "--scheduler", "tcp://127.0.0.1:1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "dask" in err


def test_index_falls_back_to_temp_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import tempfile

    from mjstruct.synthesis import catalog

    blocker = tmp_path / "not-a-dir"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    monkeypatch.setenv("HOME", str(blocker))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    path = catalog.index_path()
    assert path.is_file() and path.parent.parent == tmp_path / "tmp"
    assert catalog.query("SELECT count(*) AS c FROM chains")[0]["c"] == sum(
        len(read_catalog(F, n)) for F, n in SHIPPED
    )


# -- the index cache: hostile paths, planted files, corruption, no place to write -----


def _watt_name() -> str:
    return lookup(read_mechanism(ROOT / "catalogs" / "examples" / "watt.json")).record["name"]


def _block_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Only the temporary-directory fallback is left; returns that temp root."""
    import tempfile

    blocker = tmp_path / "not-a-dir"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    monkeypatch.setenv("HOME", str(blocker))
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    return tmp


@pytest.mark.parametrize("odd", ["a?mode=rw", "b#frag", "c%41d", "d?x=1#y"])
def test_cache_path_with_uri_characters_stays_inside(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, odd: str
) -> None:
    from mjstruct.synthesis import catalog

    cache = tmp_path / odd
    monkeypatch.setenv("XDG_CACHE_HOME", str(cache))
    assert _watt_name() == "Watt six-bar"
    path = catalog.index_path()
    assert path is not None and path.parent == cache / "mjstruct"
    # nothing was written outside the literal directory (no "a" for "a?mode=rw")
    assert sorted(p.name for p in tmp_path.iterdir()) == [odd]


def test_planted_temp_dir_of_another_user_is_not_trusted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import os
    import sqlite3

    from mjstruct.synthesis import catalog

    tmp = _block_home(tmp_path, monkeypatch)
    planted = tmp / f"mjstruct-{os.getuid()}"
    planted.mkdir(mode=0o777)
    planted.chmod(0o777)  # writable by anyone: someone else could have put an index here
    files = sorted(catalog.atlas_dir().glob("*.jsonl"))
    fake = planted / catalog._index_name(files)
    con = sqlite3.connect(fake)
    meta = {"stat_key": catalog._stat_key(files), "catalog_hash": "0"}
    catalog._fill(con, [], meta)  # an index that knows no chain
    con.close()
    assert catalog.index_path() is None  # refused; nowhere else to write
    assert _watt_name() == "Watt six-bar"  # answered from an index built in memory
    if os.getuid() == 0:  # root can plant a directory owned by someone else
        planted.chmod(0o700)
        os.chown(planted, 12345, -1)
        assert catalog.index_path() is None


@pytest.mark.parametrize("damage", ["empty", "truncated", "garbage", "old-version"])
def test_damaged_index_is_rebuilt(tmp_path: Path, damage: str) -> None:
    import sqlite3

    from mjstruct.synthesis import catalog

    path = catalog.index_path()
    assert path is not None
    data = path.read_bytes()
    if damage == "empty":
        path.write_bytes(b"")
    elif damage == "truncated":
        path.write_bytes(data[: len(data) // 3])
    elif damage == "garbage":
        path.write_bytes(b"not a database" * 100)
    else:
        con = sqlite3.connect(path)
        con.execute("UPDATE meta SET value = 1 WHERE key = 'version'")
        con.commit()
        con.close()
    assert _watt_name() == "Watt six-bar"
    assert catalog.index_path() == path and path.read_bytes() != b""
    assert not list(path.parent.glob("*.tmp"))


def test_index_that_is_a_link_is_replaced_not_followed(tmp_path: Path) -> None:
    from mjstruct.synthesis import catalog

    path = catalog.index_path()
    assert path is not None
    outside = tmp_path / "victim.txt"
    outside.write_text("keep me")
    path.unlink()
    path.symlink_to(outside)
    assert _watt_name() == "Watt six-bar"
    assert outside.read_text() == "keep me"
    assert path.is_file() and not path.is_symlink()


def test_unwritable_cache_falls_back_and_interrupted_build_leaves_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import sqlite3

    from mjstruct.synthesis import catalog

    real_fill = catalog._fill
    calls: list[int] = []

    def read_only_first(
        con: sqlite3.Connection, rows: list[tuple[object, ...]], meta: dict[str, object]
    ) -> None:
        calls.append(1)
        if len(calls) == 1:
            raise sqlite3.OperationalError("attempt to write a readonly database")
        real_fill(con, rows, meta)

    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setattr(catalog, "_fill", read_only_first)
    assert _watt_name() == "Watt six-bar"
    assert not list((tmp_path / "mjstruct").glob("*"))  # no temporary file left
    assert len(list((tmp_path / "home" / ".cache" / "mjstruct").glob("*.sqlite"))) == 1

    def interrupted(
        con: sqlite3.Connection, rows: list[tuple[object, ...]], meta: dict[str, object]
    ) -> None:
        raise KeyboardInterrupt

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "other"))
    monkeypatch.setattr(catalog, "_fill", interrupted)
    with pytest.raises(KeyboardInterrupt):
        catalog.index_path()
    assert not list((tmp_path / "other" / "mjstruct").glob("*"))


def test_names_are_printed_without_terminal_escapes(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from mjstruct.synthesis import catalog

    real = catalog.query

    def tainted(sql: str, params: tuple[object, ...] = ()) -> list[dict[str, object]]:
        rows = real(sql, params)
        for r in rows:
            r["name"] = "Watt\x1b]0;owned\x07\x1b[2J"  # ESC, BEL
        return rows

    monkeypatch.setattr(catalog, "query", tainted)
    assert main(["lookup", str(ROOT / "catalogs" / "examples" / "watt.json")]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\x07" not in out and "Watt\\x1b]0;owned" in out
    assert main(["lookup", str(ROOT / "catalogs" / "examples" / "watt.json"), "--json"]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and json.loads(out)["name"] == "Watt\x1b]0;owned\x07\x1b[2J"


def test_interrupted_catalog_writing_keeps_the_old_files(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import os

    from mjstruct.synthesis import catalog, catalog_build

    monkeypatch.setattr(catalog, "SHIPPED", ((1, 4), (2, 5)))
    old = tmp_path / "f2-n05.jsonl"
    old.write_text("old\n")
    real_replace = os.replace
    calls: list[str] = []

    def interrupt_second(src: str, dst: Path) -> None:
        calls.append(str(dst))
        if len(calls) == 2:
            raise KeyboardInterrupt
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", interrupt_second)
    with pytest.raises(KeyboardInterrupt):
        catalog_build.write_catalogs(tmp_path)
    assert old.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f1-n04.jsonl", "f2-n05.jsonl"]
    assert [json.loads(x)["id"] for x in (tmp_path / "f1-n04.jsonl").read_text().splitlines()] == [
        "F1n4-0001"
    ]


def test_page_corruption_is_rebuilt(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from mjstruct.synthesis import catalog

    path = catalog.index_path()
    assert path is not None and path.stat().st_size > 16384 + 12
    with path.open("r+b") as fh:  # damage inside a table page: the meta still reads
        fh.seek(16384)
        fh.write(b"\xff" * 12)
    assert not catalog._intact(path)
    watt = str(ROOT / "catalogs" / "examples" / "watt.json")
    for _ in range(2):  # answered at once and afterwards, from a rebuilt index
        assert main(["lookup", watt, "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["name"] == "Watt six-bar"
    assert catalog.index_path() == path and catalog._intact(path)
    assert not list(path.parent.glob("*.tmp"))


def test_wrong_query_on_a_sound_index_is_raised_not_rebuilt() -> None:
    import sqlite3

    from mjstruct.synthesis import catalog

    path = catalog.index_path()
    assert path is not None
    before = path.stat().st_ino
    with pytest.raises(sqlite3.OperationalError, match="no such column"):
        catalog.query("SELECT nonsense FROM chains")
    assert path.stat().st_ino == before


def test_warm_index_reads_no_catalog(monkeypatch: pytest.MonkeyPatch) -> None:
    from mjstruct.synthesis import catalog

    path = catalog.index_path()
    assert path is not None

    def no_reading(*args: object) -> None:
        raise AssertionError("a warm lookup read the catalogs")

    monkeypatch.setattr(catalog, "_catalog_hash", no_reading)
    monkeypatch.setattr(catalog, "_catalog_rows", no_reading)
    assert catalog.index_path() == path
    assert _watt_name() == "Watt six-bar"


def test_changed_catalog_stat_gets_a_new_index(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import shutil

    from mjstruct.synthesis import catalog

    atlas = tmp_path / "atlas"
    shutil.copytree(catalog.atlas_dir(), atlas)
    monkeypatch.setattr(catalog, "atlas_dir", lambda: atlas)
    first = catalog.index_path()
    assert first is not None
    f = atlas / "f1-n04.jsonl"
    st = f.stat()
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    second = catalog.index_path()
    assert second is not None and second != first and second.is_file()


def test_two_cold_lookups_at_once(tmp_path: Path) -> None:
    import subprocess
    import sys

    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    cmd = [
        sys.executable,
        "-m",
        "mjstruct",
        "lookup",
        str(ROOT / "catalogs" / "examples" / "watt.json"),
        "--json",
    ]
    procs = [
        subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        for _ in range(2)
    ]
    for p in procs:
        out, err = p.communicate(timeout=120)
        assert p.returncode == 0, err
        assert json.loads(out)["name"] == "Watt six-bar" and err == ""
    cache = tmp_path / "cache" / "mjstruct"
    (index,) = cache.iterdir()  # one index, no temporary file
    assert index.suffix == ".sqlite"
    from mjstruct.synthesis import catalog

    assert catalog._intact(index)
