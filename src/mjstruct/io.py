"""Reading and writing mechanisms: the contract's JSON (and TOML), plain networkx graphs.

Every reader validates and raises :class:`~mjstruct.errors.MechanismError` with a
one-line message naming the field.

Examples
--------
>>> m = mechanism_from_dict({"joints": [{"id": "a", "links": [0, 1]},
...     {"id": "b", "links": [1, 2]}, {"id": "c", "links": [2, 3]},
...     {"id": "d", "links": [3, 0]}], "frame": 0})
>>> m.links, m.frame
(('0', '1', '2', '3'), '0')
>>> mechanism_to_dict(m)["joints"][0]
{'id': 'a', 'links': ['0', '1']}
"""

from __future__ import annotations

import json
import math
import os
import re
import stat
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mjstruct.errors import MechanismError, expect_id, expect_instance
from mjstruct.gear_pairs import read_gear_pairs
from mjstruct.mechanism import Joint, Mechanism, Point, expect_mechanism

if TYPE_CHECKING:
    import networkx as nx

_KNOWN_KEYS = {"name", "frame", "joints", "links", "drivers", "points"}


MAX_FILE_BYTES = 16 * 2**20
"""Largest mechanism file read (16 MiB, some 100 000 joints); the environment variable
``MJSTRUCT_MAX_FILE_BYTES`` or the ``max_bytes`` parameter raises it."""


def _byte_limit(max_bytes: int | None) -> int:
    if max_bytes is not None:
        return max_bytes
    raw = os.environ.get("MJSTRUCT_MAX_FILE_BYTES")
    if raw is None:
        return MAX_FILE_BYTES
    try:
        return int(raw)
    except ValueError:
        raise MechanismError(
            f"MJSTRUCT_MAX_FILE_BYTES: expected a number of bytes, got {raw!r}"
        ) from None


def read_mechanism(path: str | Path, max_bytes: int | None = None) -> Mechanism:
    """Read a mechanism file (``.json``, or ``.toml``); ``"-"`` reads standard input.

    Only regular files (and standard input) are read, and at most ``max_bytes`` bytes
    (default :data:`MAX_FILE_BYTES`): a device, a FIFO or a directory, or a larger
    file, is refused before anything is read.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise MechanismError(f"path: expected a file name, got {type(path).__name__}")
    limit = _byte_limit(max_bytes)
    if str(path) == "-":
        data = sys.stdin.buffer.read(limit + 1)
        if len(data) > limit:
            raise MechanismError(f"-: standard input exceeds {_size(limit)}; {_RAISE}")
        text = _decode(data, "-")
        if not text.strip():
            raise MechanismError("-: standard input is empty (expected JSON or TOML)")
        toml = not text.lstrip().startswith(("{", "["))
        return parse_mechanism(text, toml=toml, source="standard input")
    p = Path(path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise MechanismError(f"{p}: no such file") from None
    except OSError as exc:
        raise MechanismError(f"{p}: cannot read ({exc.__class__.__name__})") from None
    if not stat.S_ISREG(st.st_mode):
        raise MechanismError(f"{p}: not a regular file (a directory, device or FIFO)")
    if st.st_size > limit:
        raise MechanismError(f"{p}: {_size(st.st_size)} exceeds {_size(limit)}; {_RAISE}")
    try:
        with p.open("rb") as fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        raise MechanismError(f"{p}: cannot read ({exc.__class__.__name__})") from None
    if len(data) > limit:  # grew since it was measured
        raise MechanismError(f"{p}: exceeds {_size(limit)}; {_RAISE}")
    return parse_mechanism(_decode(data, str(p)), toml=p.suffix.lower() == ".toml", source=str(p))


_RAISE = "set MJSTRUCT_MAX_FILE_BYTES to read a larger file"


def _size(n: int) -> str:
    return f"{n / 2**20:.1f} MiB" if n >= 2**20 else f"{n} bytes"


def _decode(data: bytes, source: str) -> str:
    try:
        return data.decode("utf-8-sig")  # a byte-order mark, as some editors write, is no text
    except UnicodeDecodeError:
        raise MechanismError(f"{source}: cannot read (not UTF-8 text)") from None


def parse_mechanism(text: str, toml: bool = False, source: str = "input") -> Mechanism:
    """Parse mechanism text (JSON by default)."""
    if not isinstance(text, str):
        raise MechanismError(f"text: expected the file's text (a str), got {type(text).__name__}")
    if toml:
        import tomllib  # here: its import costs a JSON-only start-up a tenth

        decode_error: type[ValueError] = tomllib.TOMLDecodeError
    else:
        decode_error = json.JSONDecodeError
    try:
        data = tomllib.loads(text) if toml else json.loads(text)
    except json.JSONDecodeError as exc:
        raise MechanismError(
            f"{source}: not valid JSON ({exc.msg} at line {exc.lineno} column {exc.colno})"
        ) from None
    except decode_error as exc:
        raise MechanismError(f"{source}: not valid TOML ({exc})") from None
    except RecursionError:
        raise MechanismError(f"{source}: nested too deeply to be a mechanism") from None
    except ValueError as exc:  # an integer beyond Python's digit limit
        raise MechanismError(f"{source}: unreadable number ({exc})") from None
    if _SUSPECT_NUMBER.search(text):  # cheap gate: walk the data only when it may hold one
        _refuse_unrepresentable(data)
    return mechanism_from_dict(data)


# A number a double cannot hold has 309+ digits, a 3-digit exponent, or is inf/nan
# (JSON's Infinity/NaN, TOML's inf/nan); the gate may match more (a name "info"): the
# walk decides.
_SUSPECT_NUMBER = re.compile(r"[0-9_]{300,}|[eE][+-]?[0-9_]{3,}|inf|nan", re.IGNORECASE)
# integers are read as strings where an id is expected: any size is a valid id
_ID_KEYS = frozenset({"id", "link", "links", "frame", "drivers"})


# JSON may escape half of a UTF-16 pair alone (\ud800): no character, and no UTF-8 file
# (a report, a converted file) can hold it
_SURROGATE = re.compile("[\ud800-\udfff]")


def _refuse_surrogates(data: Any) -> None:
    """Refuse a string (or key) holding a lone surrogate, naming its field: it is no
    character, and writing it anywhere (a report, a converted file) would fail."""
    stack: list[tuple[Any, str]] = [(data, "")]
    while stack:
        value, where = stack.pop()
        if isinstance(value, Mapping):
            for k, v in value.items():
                here = f"{where}.{k}" if where else str(k)
                if _SURROGATE.search(str(k)):
                    raise MechanismError(f"{where or 'file'}: a key holds a lone surrogate")
                stack.append((v, here))
        elif isinstance(value, list):
            stack.extend((v, f"{where}[{i}]") for i, v in enumerate(value))
        elif isinstance(value, str):
            _refuse_surrogate(value, where)


def _refuse_surrogate(text: str, where: str) -> None:
    found = _SURROGATE.search(text)
    if found is not None:
        code = f"\\u{ord(found.group()):04x}"
        raise MechanismError(
            f"{where}: holds a lone UTF-16 surrogate ({code}), which is no character"
        )


def _refuse_unrepresentable(data: Any) -> None:
    """Refuse a number no double can hold, naming its field (``parameters.p``).

    Done once where files are parsed, so every reader (geometry, dynamics data) gets
    finite doubles: 10**400 or 1e400 is bad input, never an OverflowError later.
    """
    stack: list[tuple[Any, str, bool]] = [(data, "", False)]
    while stack:
        value, where, is_id = stack.pop()
        if isinstance(value, Mapping):
            for k, v in value.items():
                stack.append((v, f"{where}.{k}" if where else str(k), str(k) in _ID_KEYS))
        elif isinstance(value, list):
            stack.extend((v, f"{where}[{i}]", is_id) for i, v in enumerate(value))
        elif isinstance(value, float) and not math.isfinite(value):
            raise MechanismError(f"{where}: not a finite number (beyond a double, inf or nan)")
        elif isinstance(value, int) and not isinstance(value, bool) and not is_id:
            try:
                float(value)
            except OverflowError:
                raise MechanismError(
                    f"{where}: number too large for a double (magnitude at most 1.8e308)"
                ) from None


def _ident(value: Any, where: str) -> str:
    ident = expect_id(value, where)
    _refuse_surrogate(ident, where)
    return ident


def _xy(value: Any, where: str) -> tuple[float, float]:
    ok = isinstance(value, (list, tuple)) and len(value) == 2
    if ok and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        try:
            x, y = float(value[0]), float(value[1])
        except OverflowError:  # an integer beyond the float range
            x = y = float("inf")
        if math.isfinite(x) and math.isfinite(y):
            return (x, y)
    shown = repr(value)
    shown = shown if len(shown) <= 60 else shown[:57] + "..."
    raise MechanismError(f"{where}: expected [x, y] with two finite numbers, got {shown}")


def mechanism_from_dict(data: Any) -> Mechanism:
    """Build a validated :class:`Mechanism` from the contract's object."""
    if not isinstance(data, Mapping):
        raise MechanismError("mechanism: the top level must be an object")
    if "joints" not in data:
        raise MechanismError("joints: missing (a mechanism needs a list of joints)")
    raw_joints = data["joints"]
    if not isinstance(raw_joints, list):
        raise MechanismError("joints: must be a list")
    joints = []
    order: dict[str, None] = {}
    for k, rj in enumerate(raw_joints):
        where = f"joints[{k}]"
        if not isinstance(rj, Mapping):
            raise MechanismError(f"{where}: must be an object with 'id' and 'links'")
        if "id" not in rj:
            raise MechanismError(f"{where}.id: missing")
        if "links" not in rj:
            raise MechanismError(f"{where}.links: missing")
        if not isinstance(rj["links"], list):
            raise MechanismError(f"{where}.links: must be a list of link ids")
        links = tuple(_ident(x, f"{where}.links") for x in rj["links"])
        order.update(dict.fromkeys(links))
        kind = rj.get("type", "R")
        if not isinstance(kind, str):
            raise MechanismError(f"{where}.type: unknown joint type {kind!r} (expected R or P)")
        at = _xy(rj["at"], f"{where}.at") if "at" in rj else None
        axis = _xy(rj["axis"], f"{where}.axis") if "axis" in rj else None
        if axis is not None and axis == (0.0, 0.0):
            raise MechanismError(f"{where}.axis: the guide direction must not be zero")
        joints.append(Joint(_ident(rj["id"], f"{where}.id"), links, kind.upper(), at, axis))

    if "links" in data:
        if not isinstance(data["links"], list):
            raise MechanismError("links: must be a list of link ids")
        links = tuple(_ident(x, "links") for x in data["links"])
    else:
        links = tuple(order)

    frame = data.get("frame")
    frame_id = None if frame is None else _ident(frame, "frame")
    drivers = data.get("drivers", [])
    if not isinstance(drivers, list):
        raise MechanismError("drivers: must be a list of joint ids")
    points = []
    raw_points = data.get("points", [])
    if not isinstance(raw_points, list):
        raise MechanismError("points: must be a list")
    for k, rp in enumerate(raw_points):
        if not isinstance(rp, Mapping) or not {"id", "link", "at"} <= set(rp):
            raise MechanismError(f"points[{k}]: needs 'id', 'link' and 'at'")
        points.append(
            Point(
                _ident(rp["id"], f"points[{k}].id"),
                _ident(rp["link"], f"points[{k}].link"),
                _xy(rp["at"], f"points[{k}].at"),
            )
        )
    name = data.get("name", "")
    extra = {k: v for k, v in data.items() if k not in _KNOWN_KEYS}
    _refuse_surrogates({"name": str(name), **extra})
    m = Mechanism(
        links=links,
        joints=tuple(joints),
        frame=frame_id,
        drivers=tuple(_ident(d, "drivers") for d in drivers),
        name=str(name),
        points=tuple(points),
        extra=extra,
    )
    if "gears" in extra:  # higher pairs, kept in extra as read; checked here once
        read_gear_pairs(extra["gears"], m)
    return m


def mechanism_to_dict(m: Mechanism) -> dict[str, Any]:
    """The contract's object for ``m`` (round-trips through :func:`mechanism_from_dict`)."""
    expect_mechanism(m)
    out: dict[str, Any] = {}
    if m.name:
        out["name"] = m.name
    if m.frame is not None:
        out["frame"] = m.frame
    out["links"] = list(m.links)
    joints = []
    for j in m.joints:
        d: dict[str, Any] = {"id": j.id, "links": list(j.links)}
        if j.kind != "R":
            d["type"] = j.kind
        if j.at is not None:
            d["at"] = list(j.at)
        if j.axis is not None:
            d["axis"] = list(j.axis)
        joints.append(d)
    out["joints"] = joints
    if m.drivers:
        out["drivers"] = list(m.drivers)
    if m.points:
        out["points"] = [{"id": p.id, "link": p.link, "at": list(p.at)} for p in m.points]
    out.update(m.extra)
    # keep the doctest's short form: no links key when it adds nothing
    if list(m.links) == list(dict.fromkeys(x for j in m.joints for x in j.links)):
        del out["links"]
    return out


def _toml_string(text: str) -> str:
    """A TOML basic string: JSON's escapes, which TOML shares, and DEL (U+007F), which
    JSON leaves raw and TOML forbids raw (as it does U+0000-U+001F but the tab).

    >>> print(_toml_string("a" + chr(0x7F) + "b" + chr(0x1B)))
    "a\\u007fb\\u001b"
    """
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, Mapping):  # TOML has no null: a key whose value is null is left out
        items = [(k, x) for k, x in v.items() if x is not None]
        return (
            "{" + ", ".join(f"{_toml_string(str(k))} = {_toml_value(x)}" for k, x in items) + "}"
        )
    raise MechanismError(f"cannot write {type(v).__name__} value {v!r} as TOML")


def mechanism_to_toml(m: Mechanism) -> str:
    """The contract's object as TOML text (reads back with :func:`parse_mechanism`).

    TOML has no null: keys whose value is null are left out (read back as absent).

    >>> from mjstruct.mechanism import Mechanism
    >>> m = Mechanism.build([("a", [0, 1]), ("b", [1, 2, 0], "P")], frame=0)
    >>> parse_mechanism(mechanism_to_toml(m), toml=True) == m
    True
    """
    expect_mechanism(m)
    d = mechanism_to_dict(m)
    tables = {k: d.pop(k) for k in ("joints", "points") if k in d}
    lines = [f"{_toml_string(k)} = {_toml_value(v)}" for k, v in d.items() if v is not None]
    for key, rows in tables.items():
        for row in rows:
            lines.append(f"\n[[{key}]]")
            lines.extend(f"{_toml_string(k)} = {_toml_value(v)}" for k, v in row.items())
    return "\n".join(lines) + "\n"


def from_link_graph(
    g: nx.Graph, frame: Any = None, drivers: Any = (), name: str = ""
) -> Mechanism:
    """A simple-joint mechanism from a graph whose nodes are links and edges joints.

    Edge attribute ``type`` ("R"/"P") and ``id`` are used when present; a plain link
    graph cannot express a multiple joint, so every edge becomes a simple joint.
    """
    import networkx as nx

    expect_instance(g, "g", nx.Graph, "a networkx graph of links")
    if g.is_multigraph():
        raise MechanismError(
            "graph: parallel edges (two joints between two links) are not a chain"
        )
    joints = []
    for k, (u, v, d) in enumerate(
        sorted(g.edges(data=True), key=lambda e: (str(e[0]), str(e[1])))
    ):
        joints.append(Joint(str(d.get("id", f"J{k}")), (str(u), str(v)), str(d.get("type", "R"))))
    links = tuple(str(x) for x in g.nodes)
    return Mechanism(
        links=links,
        joints=tuple(joints),
        frame=None if frame is None else str(frame),
        drivers=tuple(str(d) for d in drivers),
        name=name,
    )


def to_networkx(m: Mechanism) -> nx.Graph:
    """The bipartite link–joint graph (see :meth:`Mechanism.graph`)."""
    expect_mechanism(m)
    return m.graph()
