"""Shipped chain catalogs (JSON Lines under ``catalogs/atlas/``) and their sqlite index.

Owns writing the catalogs, the stable ids, and looking a mechanism's chain up by its
canonical code.  One file per (F, n): ``f1-n10.jsonl``, one chain per line, sorted by
(V, [MJA], [LA], canonical code); multiple-joint chains included, fractionated chains
(link–joint graph with a cut vertex) included and flagged.  Ids: ``F1n10-0042`` for
the non-fractionated chains in that order (so the simple-joint chains come first and
keep their ids), ``F2n9-x0003`` for the fractionated ones.

The sqlite index is not shipped: it is built on first use from the JSON Lines files
into ``$XDG_CACHE_HOME/mjstruct`` (else ``~/.cache/mjstruct``, else a temporary
directory), named by a hash of the catalog files, so an edited catalog gets a new index.

Examples
--------
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.io import read_mechanism
>>> hit = lookup(read_mechanism(example_path("watt")))
>>> hit.found, hit.record["name"], hit.record["code"]
(True, 'Watt six-bar', '[42]/0')
"""

from __future__ import annotations

import hashlib
import json
import os
import sqlite3
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mjstruct.mechanism import Mechanism

# (F, n) shipped: F = 1 up to 10 links, F = 2 up to 9 links
SHIPPED: tuple[tuple[int, int], ...] = ((1, 4), (1, 6), (1, 8), (1, 10), (2, 5), (2, 7), (2, 9))

_COLUMNS = (
    "canonical",
    "id",
    "name",
    "F",
    "n",
    "K",
    "V",
    "cell",
    "LA",
    "MJA",
    "code",
    "code_star",
    "planar",
    "fractionated",
    "joints",
)


def atlas_dir() -> Path:
    from mjstruct.catalog_files import catalog_root

    return catalog_root() / "atlas"


def catalog_file(F: int, n: int, root: Path | None = None) -> Path:
    return (root or atlas_dir()) / f"f{F}-n{n:02d}.jsonl"


def catalog_records(F: int, n: int, workers: int = 1) -> list[dict[str, Any]]:
    """Enumerate (F, n) with multiple and fractionated chains; one record per chain."""
    from mjstruct.structure.assortments import Assortment
    from mjstruct.structure.codes import full_code, structural_code
    from mjstruct.synthesis.atlas import atlas
    from mjstruct.synthesis.names import familiar_names

    names = familiar_names()
    chains = atlas(F, n, mj=True, fractionated=True, workers=workers).chains
    out = []
    counters = {False: 0, True: 0}
    for c in chains:
        counters[c.fractionated] += 1
        cid = f"F{F}n{n}-{'x' if c.fractionated else ''}{counters[c.fractionated]:04d}"
        a = Assortment(LA=c.LA, MJA=c.MJA)
        rec = {
            "id": cid,
            "name": names.get(c.canonical),
            "cell": f"K{c.K}V{c.V}",
            "code": structural_code(a, c.K),
            "code_star": full_code(a, c.K),
            **c.to_dict(),
        }
        out.append(rec)
    return out


def write_catalogs(root: Path | None = None, workers: int = 1) -> dict[str, int]:
    """(Re)generate every shipped catalog file; returns {file name: chain count}."""
    root = root or atlas_dir()
    root.mkdir(parents=True, exist_ok=True)
    counts = {}
    for F, n in SHIPPED:
        recs = catalog_records(F, n, workers=workers)
        path = catalog_file(F, n, root)
        with path.open("w", encoding="utf-8") as fh:
            for rec in recs:
                fh.write(json.dumps(rec, ensure_ascii=False, separators=(",", ":")) + "\n")
        counts[path.name] = len(recs)
    return counts


def read_catalog(F: int, n: int) -> list[dict[str, Any]]:
    """The records of one shipped catalog file (empty if not shipped)."""
    path = catalog_file(F, n)
    if not path.is_file():
        return []
    with path.open(encoding="utf-8") as fh:
        return [json.loads(line) for line in fh if line.strip()]


def _catalog_hash(files: list[Path]) -> str:
    h = hashlib.sha256()
    for f in files:
        h.update(f.name.encode() + b"\0" + f.read_bytes())
    return h.hexdigest()[:16]


def _cache_dirs() -> list[Path]:
    dirs = []
    if os.environ.get("XDG_CACHE_HOME"):
        dirs.append(Path(os.environ["XDG_CACHE_HOME"]) / "mjstruct")
    dirs.append(Path.home() / ".cache" / "mjstruct")
    dirs.append(
        Path(tempfile.gettempdir()) / f"mjstruct-{os.getuid() if hasattr(os, 'getuid') else 0}"
    )
    return dirs


def index_path() -> Path:
    """Path of the sqlite index, building it first if needed."""
    files = sorted(atlas_dir().glob("*.jsonl"))
    name = f"catalog-{_catalog_hash(files)}.sqlite"
    last_error: Exception | None = None
    for d in _cache_dirs():
        path = d / name
        if path.is_file():
            return path
        try:
            d.mkdir(parents=True, exist_ok=True)
            _build_index(files, path)
            return path
        except OSError as exc:  # read-only home etc.: try the next place
            last_error = exc
    raise OSError(f"cannot write the catalog index anywhere: {last_error}")


def _build_index(files: list[Path], path: Path) -> None:
    tmp = path.with_suffix(f".tmp{os.getpid()}")
    con = sqlite3.connect(tmp)
    try:
        con.execute(
            "CREATE TABLE chains (canonical TEXT PRIMARY KEY, id TEXT UNIQUE, name TEXT, "
            "F INT, n INT, K INT, V INT, cell TEXT, LA TEXT, MJA TEXT, code TEXT, "
            "code_star TEXT, planar INT, fractionated INT, joints TEXT)"
        )
        for f in files:
            with f.open(encoding="utf-8") as fh:
                rows = []
                for line in fh:
                    r = json.loads(line)
                    rows.append(
                        tuple(
                            json.dumps(r[k]) if k in ("LA", "MJA", "joints") else r[k]
                            for k in _COLUMNS
                        )
                    )
            con.executemany(f"INSERT INTO chains VALUES ({','.join('?' * len(_COLUMNS))})", rows)
        con.execute("CREATE INDEX chains_code ON chains (F, n, code_star)")
        con.commit()
    finally:
        con.close()
    os.replace(tmp, path)  # atomic: concurrent first uses do not see a half-built index


def query(sql: str, params: tuple[Any, ...] = ()) -> list[dict[str, Any]]:
    """Run a read-only query on the index; rows as dicts (LA, MJA, joints decoded)."""
    con = sqlite3.connect(f"file:{index_path()}?mode=ro", uri=True)
    con.row_factory = sqlite3.Row
    try:
        rows = [dict(r) for r in con.execute(sql, params)]
    finally:
        con.close()
    for r in rows:
        for k in ("LA", "MJA", "joints"):
            if k in r:
                r[k] = json.loads(r[k])
        for k in ("planar", "fractionated"):
            if k in r:
                r[k] = bool(r[k])
    return rows


@dataclass
class LookupResult:
    """Outcome of :func:`lookup`: the catalog record, or why there is none."""

    found: bool
    canonical: str
    F: int
    n: int
    record: dict[str, Any] = field(default_factory=dict)
    reason: str = ""


def lookup(m: Mechanism) -> LookupResult:
    """Find the chain of ``m`` in the shipped catalogs by its chain-level canonical code."""
    from mjstruct.structure.assortments import simple_joint_count
    from mjstruct.structure.isomorphism import canonical_code
    from mjstruct.structure.mobility import dof_grubler

    code = canonical_code(m, "chain")
    F = dof_grubler(m.n, simple_joint_count(m))
    rows = query("SELECT * FROM chains WHERE canonical = ?", (code,))
    if rows:
        return LookupResult(True, code, F, m.n, rows[0])
    if (F, m.n) in SHIPPED:
        from mjstruct.synthesis.admissibility import is_admissible

        why = (
            "it has a rigid sub-chain or a link with fewer than 2 joints"
            if not is_admissible(m)
            else "it should be there: please report this"
        )
        reason = f"not in catalog: the catalog of F = {F}, n = {m.n} is complete and {why}"
    else:
        from mjstruct.synthesis.admissibility import is_fractionated

        flags = f"--dof {F} --links {m.n}"
        flags += " --mj" if any(j.is_multiple for j in m.joints) else ""
        flags += " --fractionated" if is_fractionated(m) else ""
        reason = (
            f"not in catalog (shipped: F = 1 up to 10 links, F = 2 up to 9 links); "
            f"enumerate with `mjstruct atlas {flags}`"
        )
        if m.n > 12:
            reason += " (beyond about 12 links such an enumeration is very long)"
    return LookupResult(False, code, F, m.n, {}, reason)


if __name__ == "__main__":  # regenerate: python -m mjstruct.synthesis.catalog
    import sys

    for fname, count in write_catalogs(
        workers=int(sys.argv[1]) if len(sys.argv) > 1 else 1
    ).items():
        print(fname, count)
