"""Which exchange format a file is in, and reading or writing a whole file in it.

Formats: ``json`` and ``toml`` (the mechanism file), ``pyslvs`` (a pyslvs mechanism
expression), ``pyslvs-project`` (a pyslvs project file, YAML), ``graphml`` and
``node-link`` (the link–joint graph).  By suffix: ``.json``, ``.toml``, ``.pmks`` or
``.expr``, ``.pyslvs``, ``.graphml``; node-link JSON shares
``.json`` with the mechanism file, so it is named with ``node-link`` (when reading, a
``.json`` object with ``nodes`` and no ``joints`` is taken as node-link).

Examples
--------
>>> format_for("four-bar.graphml")
'graphml'
>>> format_for("crank.txt")
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: crank.txt: unknown suffix '.txt' (give the format: json, \
toml, pyslvs, pyslvs-project, graphml, node-link)
"""

from __future__ import annotations

import json
from pathlib import Path

from mjstruct.errors import MechanismError
from mjstruct.mechanism import Mechanism

FORMATS = ("json", "toml", "pyslvs", "pyslvs-project", "graphml", "node-link")
SUFFIXES = {
    ".json": "json",
    ".toml": "toml",
    ".pmks": "pyslvs",
    ".expr": "pyslvs",
    ".pyslvs": "pyslvs-project",
    ".graphml": "graphml",
}


def format_for(path: str | Path, given: str | None = None) -> str:
    """The format named by ``given``, else the one ``path``'s suffix stands for."""
    if given is not None:
        if given not in FORMATS:
            raise MechanismError(f"format: unknown {given!r} (one of {', '.join(FORMATS)})")
        return given
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES:
        raise MechanismError(
            f"{path}: unknown suffix {suffix!r} (give the format: {', '.join(FORMATS)})"
        )
    return SUFFIXES[suffix]


def parse_as(text: str, fmt: str, source: str = "input", pin_slot: str = "refuse") -> Mechanism:
    """A mechanism from ``text`` in format ``fmt``."""
    from mjstruct.io import mechanism_from_dict, parse_mechanism

    if fmt == "toml":
        return parse_mechanism(text, toml=True, source=source)
    if fmt == "pyslvs":
        from mjstruct.exchange.pyslvs import mechanism_from_pyslvs

        if pin_slot not in ("refuse", "block"):
            raise MechanismError(f"pin_slot: expected 'refuse' or 'block', got {pin_slot!r}")
        return mechanism_from_pyslvs(
            text, pin_slot="block" if pin_slot == "block" else "refuse", source=source
        )
    if fmt == "pyslvs-project":
        from mjstruct.exchange.pyslvs import mechanism_from_pyslvs_project

        if pin_slot not in ("refuse", "block"):
            raise MechanismError(f"pin_slot: expected 'refuse' or 'block', got {pin_slot!r}")
        return mechanism_from_pyslvs_project(
            text, pin_slot="block" if pin_slot == "block" else "refuse", source=source
        )
    if fmt == "graphml":
        from mjstruct.exchange.graph_formats import mechanism_from_graphml

        return mechanism_from_graphml(text, source)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise MechanismError(
            f"{source}: not valid JSON ({exc.msg} at line {exc.lineno} column {exc.colno})"
        ) from None
    looks_node_link = isinstance(data, dict) and "nodes" in data and "joints" not in data
    if fmt == "node-link" or looks_node_link:
        from mjstruct.exchange.graph_formats import mechanism_from_node_link

        return mechanism_from_node_link(data, source)
    return mechanism_from_dict(data)


def read_as(path: str | Path, fmt: str | None = None, pin_slot: str = "refuse") -> Mechanism:
    """Read a mechanism from ``path`` in ``fmt`` (default: by suffix)."""
    p = Path(path)
    chosen = format_for(p, fmt)
    try:
        text = p.read_text(encoding="utf-8-sig")  # a byte-order mark is no text
    except FileNotFoundError:
        raise MechanismError(f"{p}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MechanismError(f"{p}: cannot read ({exc.__class__.__name__})") from None
    return parse_as(text, chosen, str(p), pin_slot)


def render(m: Mechanism, fmt: str) -> str:
    """The text of ``m`` in format ``fmt``."""
    from mjstruct.io import mechanism_to_dict, mechanism_to_toml

    if fmt == "toml":
        return mechanism_to_toml(m)
    if fmt == "pyslvs":
        from mjstruct.exchange.pyslvs import mechanism_to_pyslvs

        return mechanism_to_pyslvs(m)
    if fmt == "pyslvs-project":
        from mjstruct.exchange.pyslvs import mechanism_to_pyslvs_project

        return mechanism_to_pyslvs_project(m)
    if fmt == "graphml":
        from mjstruct.exchange.graph_formats import mechanism_to_graphml

        return mechanism_to_graphml(m)
    if fmt == "node-link":
        from mjstruct.exchange.graph_formats import mechanism_to_node_link

        return json.dumps(mechanism_to_node_link(m), indent=1, allow_nan=False) + "\n"
    if fmt == "json":
        return (
            json.dumps(mechanism_to_dict(m), indent=1, ensure_ascii=False, allow_nan=False) + "\n"
        )
    raise MechanismError(f"format: unknown {fmt!r} (one of {', '.join(FORMATS)})")


def write_as(m: Mechanism, path: str | Path, fmt: str | None = None) -> str:
    """Write ``m`` to ``path`` whole or not at all; returns the format used.

    A link is followed and a new file gets the umask's permissions
    (:mod:`mjstruct.output_files`).
    """
    from mjstruct.output_files import replacing

    p = Path(path)
    chosen = format_for(p, fmt)
    text = render(m, chosen)  # any refusal happens before the file is touched
    try:
        with replacing(p) as tmp, open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
    except OSError as exc:
        raise MechanismError(f"{p}: cannot write ({exc.__class__.__name__})") from None
    return chosen
