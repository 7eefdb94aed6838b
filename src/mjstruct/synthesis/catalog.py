"""Shipped chain catalogs (JSON Lines under ``catalogs/atlas/``) and their sqlite index.

Owns the shipped files (which (F, n), where, reading one) and looking a mechanism's
chain up by its canonical code; :mod:`mjstruct.synthesis.catalog_build` writes them.
One file per (F, n): ``f1-n10.jsonl``, one chain per line, sorted by
(V, [MJA], [LA], canonical code); multiple-joint chains included, fractionated chains
(link–joint graph with a cut vertex) included and flagged.  Ids: ``F1n10-0042`` for
the non-fractionated chains in that order (so the simple-joint chains come first and
keep their ids), ``F2n9-x0003`` for the fractionated ones.

The sqlite index is not shipped: it is built on first use from the JSON Lines files
into ``$XDG_CACHE_HOME/mjstruct`` (else ``~/.cache/mjstruct``, else a private
``mjstruct-<uid>`` directory under the temporary directory; a directory that is a link,
not this user's, or writable by others is skipped), named by a hash of the catalog
files' names, sizes and modification times and the index version, so an edited
catalog gets a new index while a warm lookup reads no catalog.  The index records the
hash of the catalogs' contents it was built from.  A corrupt or truncated index (page
damage is found when a query fails and ``PRAGMA quick_check`` confirms it) is rebuilt
atomically; with nowhere to write, it is built in memory.

Examples
--------
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.io import read_mechanism
>>> hit = lookup(read_mechanism(example_path("watt")))
>>> hit.found, hit.record["name"], hit.record["code"]
(True, 'Watt six-bar', '[42]/0')
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import sqlite3
import stat
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mjstruct.mechanism import Mechanism, expect_mechanism

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


def read_catalog(F: int, n: int) -> list[dict[str, Any]]:
    """The records of one shipped catalog file (empty if not shipped)."""
    path = catalog_file(F, n)
    if not path.is_file():
        return []
    with path.open(encoding="utf-8") as fh:
        return [json.loads(line) for line in fh if line.strip()]


INDEX_VERSION = 3  # bump when the table layout changes: an older index is not reused


def _catalog_files() -> list[Path]:
    return sorted(atlas_dir().glob("*.jsonl"))


def _catalog_hash(files: list[Path]) -> str:
    """Hash of the catalogs' contents (and the index version): the index's provenance."""
    h = hashlib.sha256(f"index v{INDEX_VERSION}".encode())
    for f in files:
        h.update(f.name.encode() + b"\0" + f.read_bytes())
    return h.hexdigest()[:16]


def _stat_key(files: list[Path]) -> str:
    """Key of the catalogs' (path, name, size, mtime_ns): a few stat calls, no reading.

    A changed, added or removed catalog file changes the key and so the index name; the
    contents are hashed only when an index is built.
    """
    h = hashlib.sha256(f"index v{INDEX_VERSION}\0{atlas_dir()}".encode())
    for f in files:
        st = f.stat()
        h.update(f"\0{f.name}\0{st.st_size}\0{st.st_mtime_ns}".encode())
    return h.hexdigest()[:16]


def _index_name(files: list[Path]) -> str:
    return f"catalog-{_stat_key(files)}.sqlite"


def _cache_dirs() -> list[Path]:
    """Where the index may live, in order: the documented cache variables, then a
    private directory of this user under the system's temporary directory."""
    dirs = []
    if os.environ.get("XDG_CACHE_HOME"):
        dirs.append(Path(os.environ["XDG_CACHE_HOME"]) / "mjstruct")
    with contextlib.suppress(RuntimeError):  # no home directory can be determined
        dirs.append(Path.home() / ".cache" / "mjstruct")
    dirs.append(Path(tempfile.gettempdir()) / f"mjstruct-{_uid()}")
    return dirs


def _uid() -> int:
    return os.getuid() if hasattr(os, "getuid") else 0


def _private_dir(d: Path) -> bool:
    """Create ``d`` (mode 0700) or accept it only when it is a real directory of ours
    that nobody else can write (a planted directory or a link is refused)."""
    try:
        d.mkdir(mode=0o700, parents=True, exist_ok=True)
        st = os.lstat(d)
    except OSError:
        return False
    if not stat.S_ISDIR(st.st_mode):
        return False  # a symbolic link or a file where the directory should be
    foreign = st.st_uid != _uid() or st.st_mode & 0o022
    return not (hasattr(os, "getuid") and foreign)


def _valid_index(path: Path, key: str) -> bool:
    """A regular file (not a link) whose meta says: this index version, built from the
    catalogs of stat key ``key``, with a catalog hash.

    Cheap on purpose (no catalog is read): damage inside the table pages is found when
    a query fails, which :func:`query` answers with ``PRAGMA quick_check`` and a rebuild.
    """
    try:
        st = os.lstat(path)
    except OSError:
        return False
    if not stat.S_ISREG(st.st_mode) or st.st_size == 0:
        return False
    try:
        con = sqlite3.connect(_read_only_uri(path), uri=True)
        try:
            meta = dict(con.execute("SELECT key, value FROM meta").fetchall())
        finally:
            con.close()
    except sqlite3.Error:  # corrupt, truncated, foreign: rebuild
        return False
    return bool(
        meta.get("version") == INDEX_VERSION
        and meta.get("stat_key") == key
        and isinstance(meta.get("catalog_hash"), str)
    )


def _intact(path: Path) -> bool:
    """Whether sqlite finds the file's pages sound (``PRAGMA quick_check``)."""
    try:
        con = sqlite3.connect(_read_only_uri(path), uri=True)
        try:
            result = con.execute("PRAGMA quick_check").fetchall()
        finally:
            con.close()
    except sqlite3.Error:
        return False
    return result == [("ok",)]


def _read_only_uri(path: Path) -> str:
    # as_uri percent-encodes '?', '#' and '%': a cache path cannot inject URI parameters
    return path.resolve().as_uri() + "?mode=ro"


def _catalog_rows(files: list[Path]) -> list[tuple[Any, ...]]:
    rows = []
    for f in files:
        with f.open(encoding="utf-8") as fh:
            for line in fh:
                if not line.strip():
                    continue
                r = json.loads(line)
                rows.append(
                    tuple(
                        json.dumps(r[k]) if k in ("LA", "MJA", "joints") else r[k]
                        for k in _COLUMNS
                    )
                )
    return rows


def index_path(rebuild: Path | None = None) -> Path | None:
    """Path of the sqlite index, building it first if needed (None: no place to write).

    The index is named by the catalogs' stat key (sizes and modification times), so a
    warm call only stats the catalogs and reads the index's meta table.  A missing,
    corrupt, truncated or outdated index is rebuilt in a private temporary file of the
    same directory and moved into place atomically; a directory that cannot be
    written, or is not this user's own, is skipped for the next one.

    Parameters
    ----------
    rebuild
        An index found damaged by a query: rebuilt even though its meta looks right.
    """
    files = _catalog_files()
    key = _stat_key(files)
    name = f"catalog-{key}.sqlite"
    for d in _cache_dirs():
        if not _private_dir(d):
            continue
        path = d / name
        if path != rebuild and _valid_index(path, key):
            return path
        try:
            _build_index(files, key, path)
        except (OSError, sqlite3.Error):  # read-only directory, full disk: next place
            continue
        if _valid_index(path, key):
            return path
    return None


def _fill(con: sqlite3.Connection, rows: list[tuple[Any, ...]], meta: dict[str, Any]) -> None:
    con.execute(
        "CREATE TABLE chains (canonical TEXT PRIMARY KEY, id TEXT UNIQUE, name TEXT, "
        "F INT, n INT, K INT, V INT, cell TEXT, LA TEXT, MJA TEXT, code TEXT, "
        "code_star TEXT, planar INT, fractionated INT, joints TEXT)"
    )
    con.executemany(f"INSERT INTO chains VALUES ({','.join('?' * len(_COLUMNS))})", rows)
    con.execute("CREATE INDEX chains_code ON chains (F, n, code_star)")
    con.execute("CREATE TABLE meta (key TEXT PRIMARY KEY, value)")
    con.executemany("INSERT INTO meta VALUES (?, ?)", [("version", INDEX_VERSION), *meta.items()])
    con.commit()


def _build_index(files: list[Path], key: str, path: Path) -> None:
    """Write the index to a new private file next to ``path``, then move it into place."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".catalog-", suffix=".tmp")
    os.close(fd)  # mkstemp made it (O_EXCL, mode 0600): no link is followed
    try:
        con = sqlite3.connect(tmp)
        try:
            meta = {"stat_key": key, "catalog_hash": _catalog_hash(files)}
            _fill(con, _catalog_rows(files), meta)
        finally:
            con.close()
        os.replace(tmp, path)  # atomic: concurrent first uses never see a half-built index
    except BaseException:  # interrupted or failed: leave no temporary file behind
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _memory_index() -> sqlite3.Connection:
    files = _catalog_files()
    con = sqlite3.connect(":memory:")
    _fill(con, _catalog_rows(files), {"stat_key": "", "catalog_hash": _catalog_hash(files)})
    return con


def _run(con: sqlite3.Connection, sql: str, params: tuple[Any, ...]) -> list[dict[str, Any]]:
    con.row_factory = sqlite3.Row
    try:
        return [dict(r) for r in con.execute(sql, params)]
    finally:
        con.close()


def query(sql: str, params: tuple[Any, ...] = ()) -> list[dict[str, Any]]:
    """Run a read-only query on the index; rows as dicts (LA, MJA, joints decoded).

    With no writable cache anywhere the index is built in memory for this query.  A
    query that fails on a damaged index (``PRAGMA quick_check`` not ok) rebuilds it
    and runs again; a failure on a sound index (a wrong query) is raised.
    """
    path = index_path()
    if path is None:
        rows = _run(_memory_index(), sql, params)
    else:
        try:
            rows = _run(sqlite3.connect(_read_only_uri(path), uri=True), sql, params)
        except sqlite3.DatabaseError:
            if _intact(path):
                raise
            fresh = index_path(rebuild=path)
            con = (
                _memory_index()
                if fresh is None
                else sqlite3.connect(_read_only_uri(fresh), uri=True)
            )
            rows = _run(con, sql, params)
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
    """Outcome of :func:`lookup`: the catalog record, or why there is none.

    Attributes
    ----------
    found
        Whether the chain is in a shipped catalog.
    canonical
        Chain-level canonical code of the mechanism.
    F, n
        Degrees of freedom (Grübler) and number of links.
    record
        The catalog record when found.
    reason
        Why there is no record, and what to do, in terms of this library.
    atlas_args
        When the chain lies outside the shipped catalogs: the keyword arguments of
        :func:`mjstruct.synthesis.atlas.atlas` that enumerate its family (``F``, ``n``,
        ``mj``, ``fractionated``); empty otherwise.
    """

    found: bool
    canonical: str
    F: int
    n: int
    record: dict[str, Any] = field(default_factory=dict)
    reason: str = ""
    atlas_args: dict[str, Any] = field(default_factory=dict)


def not_shipped_reason(how: str, n: int) -> str:
    """Why a chain outside the shipped catalogs is not found, advising ``how`` to enumerate.

    One wording for the library (``how`` a call of :func:`~mjstruct.synthesis.atlas.atlas`)
    and the command line (``how`` an ``mjstruct atlas`` command).

    >>> not_shipped_reason("atlas(F=1, n=12)", 12)  # doctest: +NORMALIZE_WHITESPACE
    'not in catalog (shipped: F = 1 up to 10 links, F = 2 up to 9 links);
    enumerate with atlas(F=1, n=12)'
    """
    reason = (
        f"not in catalog (shipped: F = 1 up to 10 links, F = 2 up to 9 links); "
        f"enumerate with {how}"
    )
    if n > 12:
        reason += " (beyond about 12 links such an enumeration is very long)"
    return reason


def lookup(m: Mechanism) -> LookupResult:
    """Find the chain of ``m`` in the shipped catalogs by its chain-level canonical code.

    When the chain is outside the shipped catalogs, the result's ``atlas_args`` are the
    arguments of :func:`~mjstruct.synthesis.atlas.atlas` that enumerate it.
    """
    expect_mechanism(m)
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
        return LookupResult(False, code, F, m.n, {}, reason)
    from mjstruct.synthesis.admissibility import is_fractionated

    args: dict[str, Any] = {"F": F, "n": m.n}
    if any(j.is_multiple for j in m.joints):
        args["mj"] = True
    if is_fractionated(m):
        args["fractionated"] = True
    call = "atlas(" + ", ".join(f"{k}={v!r}" for k, v in args.items()) + ")"
    return LookupResult(False, code, F, m.n, {}, not_shipped_reason(call, m.n), args)
