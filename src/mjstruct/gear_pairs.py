"""Gear pairs: the higher pairs of the mechanism file's ``gears`` list.

A gear pair joins two links by a mesh: ``external``, ``internal`` (one of the two is a
ring gear) or ``rack`` (a pinion on the first link, a rack on the second). Each gear is
fixed to its link; ``centres`` names, per gear, the joint on its axis (the rack has
none). The pitch radii come from ``radii``, or from ``teeth`` and ``module``
(``r = m Z / 2``); either may be left out for a structural analysis.

The file keeps the list under its top-level key ``gears`` (in ``Mechanism.extra``, so
every writer keeps it as read); :func:`read_gear_pairs` checks it when the file is read
and :func:`gear_pairs` gives the checked pairs of a mechanism.

Examples
--------
>>> from mjstruct.io import mechanism_from_dict
>>> m = mechanism_from_dict({
...     "frame": "0",
...     "joints": [{"id": "O", "links": ["0", "1", "3"], "at": [0, 0]},
...                {"id": "P", "links": ["3", "2"], "at": [30, 0]}],
...     "gears": [{"id": "g12", "links": ["1", "2"], "teeth": [20, 40], "module": 1,
...                "centres": ["O", "P"]},
...               {"id": "g20", "links": ["2", "0"], "type": "internal",
...                "teeth": [40, 100], "module": 1, "centres": ["P", "O"]}]})
>>> [(g.id, g.kind, g.radii) for g in gear_pairs(m)]
[('g12', 'external', (10.0, 20.0)), ('g20', 'internal', (20.0, 50.0))]
>>> mechanism_from_dict({"joints": [{"id": "O", "links": ["0", "1"]}],
...                      "gears": [{"id": "g", "links": ["1", "1"]}]})
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: gears[0].links: a gear pair joins two links, got '1' twice
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from mjstruct.errors import MechanismError, expect_id

if TYPE_CHECKING:
    from mjstruct.mechanism import Mechanism

GEAR_KINDS = ("external", "internal", "rack")
_KEYS = {"id", "links", "type", "teeth", "module", "radii", "centres", "line"}
#: relative tolerance of the meshing check (centre distance against r1 ± r2)
MESH_TOLERANCE = 1e-6


@dataclass(frozen=True)
class GearPair:
    """A mesh between the gears of two links (a higher pair: one constraint).

    For a ``rack`` pair ``teeth``, ``radii`` and ``centres`` hold the pinion's only, and
    ``line`` the rack's pitch line in the reference configuration (a point and a
    direction), when given.
    """

    id: str
    links: tuple[str, str]
    kind: str = "external"
    teeth: tuple[int, ...] | None = None
    module: float | None = None
    radii: tuple[float, ...] | None = None
    centres: tuple[str, ...] | None = None
    line: tuple[tuple[float, float], tuple[float, float]] | None = None

    @property
    def sign(self) -> int:
        """Willis' sign of the ratio seen from the carrier: -1 external, +1 internal."""
        return 1 if self.kind == "internal" else -1


def gear_pairs(m: Mechanism) -> tuple[GearPair, ...]:
    """The checked gear pairs of ``m`` (none when its file has no ``gears``)."""
    return read_gear_pairs(m.extra.get("gears", []), m)


def read_gear_pairs(raw: Any, m: Mechanism) -> tuple[GearPair, ...]:
    """The ``gears`` list checked against ``m``; bad input names the field."""
    if not isinstance(raw, list):
        raise MechanismError("gears: must be a list of gear pairs")
    seen: set[str] = set()
    out = []
    for k, entry in enumerate(raw):
        pair = _read_one(entry, f"gears[{k}]", m)
        if pair.id in seen:
            raise MechanismError(f"gears[{k}].id: duplicate gear pair id {pair.id!r}")
        seen.add(pair.id)
        out.append(pair)
    return tuple(out)


def _read_one(entry: Any, where: str, m: Mechanism) -> GearPair:
    if not isinstance(entry, Mapping):
        raise MechanismError(f"{where}: must be an object with 'id' and 'links'")
    unknown = sorted(set(entry) - _KEYS)
    if unknown:
        raise MechanismError(f"{where}.{unknown[0]}: unknown key (expected {sorted(_KEYS)})")
    for key in ("id", "links"):
        if key not in entry:
            raise MechanismError(f"{where}.{key}: missing")
    gid = expect_id(entry["id"], f"{where}.id")
    links = entry["links"]
    if not isinstance(links, list) or len(links) != 2:
        raise MechanismError(f"{where}.links: expected the two links of the mesh")
    a, b = (expect_id(x, f"{where}.links") for x in links)
    if a == b:
        raise MechanismError(f"{where}.links: a gear pair joins two links, got {a!r} twice")
    for x in (a, b):
        if x not in m.links:
            raise MechanismError(f"{where}.links: unknown link {x!r}")
    kind = entry.get("type", "external")
    if kind not in GEAR_KINDS:
        raise MechanismError(
            f"{where}.type: unknown gear pair type {kind!r} (expected {GEAR_KINDS})"
        )
    count = 1 if kind == "rack" else 2
    teeth = _teeth(entry["teeth"], f"{where}.teeth", count) if "teeth" in entry else None
    module = _positive(entry["module"], f"{where}.module") if "module" in entry else None
    radii = None
    if "radii" in entry:
        radii = tuple(
            _positive(r, f"{where}.radii") for r in _seq(entry["radii"], f"{where}.radii", count)
        )
    if teeth is not None and module is not None:
        from_teeth = tuple(module * z / 2 for z in teeth)
        if radii is not None and not all(
            math.isclose(r, q, rel_tol=MESH_TOLERANCE)
            for r, q in zip(radii, from_teeth, strict=True)
        ):
            raise MechanismError(
                f"{where}.radii: {list(radii)} differ from module × teeth / 2 = {list(from_teeth)}"
            )
        radii = from_teeth
    elif module is not None:
        raise MechanismError(f"{where}.module: needs 'teeth'")
    centres = None
    if "centres" in entry:
        centres = tuple(
            expect_id(c, f"{where}.centres")
            for c in _seq(entry["centres"], f"{where}.centres", count)
        )
        for c, link in zip(centres, (a, b), strict=False):
            if c not in {j.id for j in m.joints}:
                raise MechanismError(f"{where}.centres: unknown joint {c!r}")
            if link not in m.joint(c).links:
                raise MechanismError(
                    f"{where}.centres: joint {c!r} is not on link {link!r} (a gear turns about "
                    "a joint of its own link)"
                )
    line = None
    if "line" in entry:
        if kind != "rack":
            raise MechanismError(f"{where}.line: only a rack pair has a pitch line")
        line = _line(entry["line"], f"{where}.line")
    pair = GearPair(gid, (a, b), kind, teeth, module, radii, centres, line)
    _check_mesh(pair, where, m)
    return pair


def _check_mesh(g: GearPair, where: str, m: Mechanism) -> None:
    """Meshing gears' centres are r1 + r2 (external) or |r1 - r2| (internal) apart; a
    pinion's centre is r from the rack's pitch line."""
    if g.radii is None or g.centres is None:
        return
    at = [m.joint(c).at for c in g.centres]
    if any(p is None for p in at):
        return
    if g.kind == "rack":
        if g.line is None:
            return
        (px, py), (dx, dy) = g.line
        cx, cy = at[0]  # type: ignore[misc]
        dist = abs((cx - px) * dy - (cy - py) * dx) / math.hypot(dx, dy)
        need, rule = g.radii[0], "r"
    else:
        (x1, y1), (x2, y2) = at  # type: ignore[misc]
        dist = math.hypot(x2 - x1, y2 - y1)
        r1, r2 = g.radii
        need, rule = (r1 + r2, "r1 + r2") if g.kind == "external" else (abs(r1 - r2), "|r1 - r2|")
    if not math.isclose(dist, need, rel_tol=MESH_TOLERANCE, abs_tol=MESH_TOLERANCE * max(g.radii)):
        raise MechanismError(
            f"{where}: the gears do not mesh: centres {' and '.join(g.centres)} are {dist:.6g} "
            f"apart, a {g.kind} pair of radii {', '.join(f'{r:g}' for r in g.radii)} needs "
            f"{need:.6g} ({rule})"
        )


def _seq(value: Any, where: str, count: int) -> Sequence[Any]:
    if not isinstance(value, list) or len(value) != count:
        raise MechanismError(f"{where}: expected a list of {count}, got {value!r}")
    return value


def _teeth(value: Any, where: str, count: int) -> tuple[int, ...]:
    out = []
    for z in _seq(value, where, count):
        if isinstance(z, bool) or not isinstance(z, numbers.Integral) or z < 1:
            raise MechanismError(f"{where}: tooth numbers must be positive integers, got {z!r}")
        out.append(int(z))
    return tuple(out)


def _positive(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise MechanismError(f"{where}: expected a positive number, got {value!r}")
    x = float(value)
    if not (math.isfinite(x) and x > 0):
        raise MechanismError(f"{where}: expected a positive number, got {value!r}")
    return x


def _line(value: Any, where: str) -> tuple[tuple[float, float], tuple[float, float]]:
    if not isinstance(value, Mapping) or set(value) != {"at", "axis"}:
        raise MechanismError(f"{where}: expected {{'at': [x, y], 'axis': [dx, dy]}}")
    pts = []
    for key in ("at", "axis"):
        v = value[key]
        if not isinstance(v, list) or len(v) != 2:
            raise MechanismError(f"{where}.{key}: expected [x, y]")
        xy = (_finite(v[0], f"{where}.{key}"), _finite(v[1], f"{where}.{key}"))
        pts.append(xy)
    if pts[1] == (0.0, 0.0):
        raise MechanismError(f"{where}.axis: the direction must not be zero")
    return pts[0], pts[1]


def _finite(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
        raise MechanismError(f"{where}: expected a finite number, got {value!r}")
    return float(value)
