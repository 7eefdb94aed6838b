"""The synthesis task: reading and checking a task file (JSON or TOML).

Owns :class:`Task` (what to synthesise: the task kind, the topology and its starting
geometry, the targets, their timing, and the requirements on the result) and its
readers :func:`read_task` and :func:`task_from_dict`.  Every malformed or
contradictory value is refused here, before any search runs, with one line naming
the field (``targets[3]: ...``, ``region.B: ...``): the keys are those of the
contract's "Synthesis" section plus the extensions documented in
``docs/synthesis-design.md``.

The ``fourbar-ms`` task keeps its own keys (read by :mod:`mjstruct.design.fourbar_ms`):
here only its kind is recognised.

Examples
--------
>>> t = task_from_dict({
...     "task": "path",
...     "mechanism": {"frame": 0, "drivers": ["O1"], "joints": [
...         {"id": "O1", "links": [0, 1], "at": [0, 0]},
...         {"id": "A", "links": [1, 2], "at": [0.3, 0.4]},
...         {"id": "B", "links": [2, 3], "at": [1.2, 0.9]},
...         {"id": "O2", "links": [3, 0], "at": [1, 0]}],
...         "points": [{"id": "M", "link": 2, "at": [0.6, 1.0]}]},
...     "point": "M",
...     "targets": [[0.5, 1.0], [0.7, 1.1], [0.9, 1.0]]})
>>> t.kind, t.point, t.targets.shape, t.timing is None
('path', 'M', (3, 2), True)
>>> task_from_dict({"task": "paths"})
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: task: unknown task kind 'paths' (one of fourbar-ms, ...)
"""

from __future__ import annotations

import json
import math
import os
import stat
import sys
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.io import MAX_FILE_BYTES, mechanism_from_dict, read_mechanism
from mjstruct.mechanism import Mechanism
from mjstruct.typing import FloatArray

#: the task kinds, each with the number of numbers per target
TASK_KINDS: dict[str, int] = {"path": 2, "function": 2, "motion": 3, "fourbar-ms": 0}
#: driver values (``timing``, a function's q) and target angles at most this in
#: magnitude (radians; a slide's values: mechanism sizes): a double there still keeps
#: 1e-10 of a radian, and the verdict's range of a turn or two is resolved
DRIVER_LIMIT = 1e6
#: targets and region boxes lie within this many sizes of the origin (the kinematics'
#: bound on joint centres and points, docs/contract.md section 4)
ORIGIN_LIMIT = 1e8
#: and span at most this (the kinematics' largest mechanism size)
SIZE_LIMIT = 1e50
#: four-bar motion types a task may require (``motion``)
MOTION_TYPES = ("crank-rocker", "double-crank", "double-rocker")
#: every key a path, function or motion task may hold (others are refused: a misspelt
#: key must not be silently ignored; fourbar-ms checks its own)
KNOWN_KEYS = frozenset(
    {
        "task",
        "name",
        "mechanism",
        "point",
        "link",
        "output",
        "targets",
        "timing",
        "timing_offset",
        "angle_offset",
        "region",
        "lengths",
        "fixed",
        "motion",
        "full_turn",
        "transmission_deg",
        "solver",
    }
)
#: keys of the optional ``solver`` table and their defaults
SOLVER_DEFAULTS: dict[str, int | float] = {
    "population": 8,  # members per design variable (scipy's popsize)
    "generations": 150,  # at most, per global search
    "restarts": 2,  # independent global searches (seeds derived from the task's seed)
    "samples": 72,  # path samples over a driver cycle (untimed matching, range checks)
    "tol": 1e-7,  # relative convergence of the global search
}
#: the default ``generations`` for timed targets (function tasks, and path or motion
#: tasks with ``timing``): with the driver values given the local stage has the whole
#: problem (no matching of targets to driver values to find), so the global stage only
#: supplies its starts.  Measured (benchmarks/bench_synthesis.py, timed5, seeds 0-9):
#: median sum of squared errors 3.8e-3 with 60 generations, 4.3e-3 with 150, in 0.68
#: of the time; the shipped logarithm generator reaches the same objective
TIMED_GENERATIONS = 60


@dataclass(frozen=True)
class Task:
    """A synthesis task, checked.

    Attributes
    ----------
    kind : ``"path"``, ``"function"``, ``"motion"`` or ``"fourbar-ms"``.
    data : the task file's object as read (``fourbar-ms`` reads its own keys from it).
    mechanism : the topology with its starting geometry (None for ``fourbar-ms``).
    point : path and motion: the id of the point (or joint) that traces the targets.
    link : motion: the link whose poses are the targets (the point's link); function:
        the output link.
    targets : one row per target: [x, y] (path), [q, angle] (function), [x, y, angle]
        (motion).
    timing : the driver value at each target (path, motion), or None (untimed).
    timing_offset : the timing is relative (a common offset is free); for a function
        task, the targets' driver values are.
    angle_offset : function: the targets' output angles are relative (a common offset
        is free).
    region : joint or point id -> ((xmin, ymin), (xmax, ymax)).
    lengths : (min, max) of every distance between two joints or points of one link.
    fixed : ids of joints and points that keep their starting position.
    motion : four-bars: the required motion type, or None.
    full_turn : the driver must turn fully (untimed targets always need it).
    transmission_deg : the smallest angle allowed at the solved joint of every dyad
        over the driver range (for a four-bar the transmission angle), or None.
    solver : population, generations, restarts, samples and tol of the search.
    source : where the task came from (a file name, or ``"task"``).
    """

    kind: str
    data: Mapping[str, Any]
    mechanism: Mechanism | None = None
    point: str | None = None
    link: str | None = None
    targets: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    timing: FloatArray | None = None
    timing_offset: bool = False
    angle_offset: bool = False
    region: Mapping[str, tuple[tuple[float, float], tuple[float, float]]] = field(
        default_factory=dict
    )
    lengths: tuple[float, float] | None = None
    fixed: tuple[str, ...] = ()
    motion: str | None = None
    full_turn: bool = False
    transmission_deg: float | None = None
    solver: Mapping[str, int | float] = field(default_factory=lambda: dict(SOLVER_DEFAULTS))
    source: str = "task"

    @property
    def timed(self) -> bool:
        """True when the targets carry their driver values."""
        return self.timing is not None


def read_task(path: str | Path) -> Task:
    """Read and check a task file (``.json`` or ``.toml``; ``"-"``: standard input).

    A ``mechanism`` given as a string is a path relative to the task file's folder.

    Raises
    ------
    MechanismError
        an unreadable file, or any field that is malformed or contradictory (one line
        naming the field).
    """
    data, base, source = _read_data(path)
    return task_from_dict(data, base=base, source=source)


def read_task_data(path: str | Path) -> dict[str, Any]:
    """The task file's object, read but not checked (an atlas run checks it per
    candidate); a ``mechanism`` file name is resolved against the task file's folder."""
    data, base, _ = _read_data(path)
    if not isinstance(data, dict):
        raise MechanismError("task: the top level must be an object")
    if isinstance(data.get("mechanism"), str):
        data["mechanism"] = str(Path(base) / data["mechanism"])
    return data


def _read_data(path: str | Path) -> tuple[Any, Path, str]:
    if str(path) == "-":
        raw = sys.stdin.buffer.read(MAX_FILE_BYTES + 1)
        base, source = Path.cwd(), "standard input"
    else:
        p = Path(path)
        try:
            st = os.stat(p)
        except FileNotFoundError:
            raise MechanismError(f"{p}: no such file") from None
        except OSError as exc:
            raise MechanismError(f"{p}: cannot read ({exc.__class__.__name__})") from None
        if not stat.S_ISREG(st.st_mode):
            raise MechanismError(f"{p}: not a regular file (a directory, device or FIFO)")
        try:
            with p.open("rb") as fh:
                raw = fh.read(MAX_FILE_BYTES + 1)
        except OSError as exc:
            raise MechanismError(f"{p}: cannot read ({exc.__class__.__name__})") from None
        base, source = p.resolve().parent, str(p)
    if len(raw) > MAX_FILE_BYTES:
        raise MechanismError(f"{source}: larger than {MAX_FILE_BYTES} bytes")
    try:
        text = raw.decode("utf-8-sig")  # a byte-order mark, as some editors write, is no text
    except UnicodeDecodeError:
        raise MechanismError(f"{source}: cannot read (not UTF-8 text)") from None
    suffix = Path(source).suffix.lower()
    if suffix in (".json", ".toml"):  # the name says which (a broken .json is broken JSON)
        is_toml = suffix == ".toml"
    else:
        is_toml = not text.lstrip().startswith(("{", "["))
    try:
        data = tomllib.loads(text) if is_toml else json.loads(text)
    except json.JSONDecodeError as exc:
        raise MechanismError(
            f"{source}: not valid JSON ({exc.msg} at line {exc.lineno} column {exc.colno})"
        ) from None
    except tomllib.TOMLDecodeError as exc:
        raise MechanismError(f"{source}: not valid TOML ({exc})") from None
    except (RecursionError, ValueError) as exc:
        raise MechanismError(f"{source}: unreadable ({exc.__class__.__name__})") from None
    return data, base, source


def task_from_dict(data: Any, base: str | Path | None = None, source: str = "task") -> Task:
    """Check a task object (the task file's data) and build a :class:`Task`.

    ``base``: the folder a ``mechanism`` path is relative to (default: the current one).
    """
    if not isinstance(data, Mapping):
        raise MechanismError("task: the top level must be an object")
    kind = data.get("task")
    if kind is None:
        raise MechanismError("task: missing (path, function, motion or fourbar-ms)")
    if not isinstance(kind, str) or kind not in TASK_KINDS:
        kinds = ", ".join(sorted(TASK_KINDS))
        raise MechanismError(f"task: unknown task kind {kind!r} (one of {kinds})")
    if kind == "fourbar-ms":  # its keys are read (and checked) by its own module
        return Task(kind, data, source=source)
    unknown = sorted(str(k) for k in data if k not in KNOWN_KEYS)
    if unknown:
        raise MechanismError(f"{unknown[0]}: unknown task key (see docs/synthesis-design.md)")
    if "name" in data and not isinstance(data["name"], str):
        raise MechanismError(f"name: expected a string, got {_shown(data['name'])}")
    m = _mechanism(data, base)
    if m.frame is None:
        raise MechanismError("mechanism.frame: synthesis needs a frame link")
    if len(m.drivers) != 1:
        raise MechanismError(
            f"mechanism.drivers: synthesis needs a one-DOF mechanism with one driver, "
            f"got {len(m.drivers)}"
        )
    targets = _targets(data, TASK_KINDS[kind])
    point = link = None
    if kind in ("path", "motion"):
        point, link = _point(data, m, kind)
    if kind == "function":
        link = _output_link(data, m)
    timing = _timing(data, len(targets)) if kind != "function" else None
    offset = _flag(data, "timing_offset")
    if offset and timing is None and kind != "function":
        raise MechanismError("timing_offset: needs a timing list")
    angle_offset = _flag(data, "angle_offset")
    if angle_offset and kind != "function":
        raise MechanismError("angle_offset: only for a function task")
    if kind == "function" and "timing" in data:
        raise MechanismError("timing: a function task's targets carry their driver values")
    region = _region(data, m)
    lengths = _lengths(data)
    fixed = _fixed(data, m)
    motion = _motion(data, m)
    full_turn = _flag(data, "full_turn") or (timing is None and kind != "function")
    if motion in ("crank-rocker", "double-crank"):
        full_turn = True
    if motion == "double-rocker" and timing is None and kind != "function":
        raise MechanismError(
            "motion: untimed targets are matched along a full turn of the driver, "
            "which a double-rocker's input cannot make"
        )
    transmission = _optional_number(data, "transmission_deg", 0.0, 90.0, open_high=True)
    task = Task(
        kind,
        data,
        m,
        point,
        link,
        targets,
        timing,
        offset,
        angle_offset,
        region,
        lengths,
        fixed,
        motion,
        full_turn,
        transmission,
        _solver(data, timed=kind == "function" or timing is not None),
        source,
    )
    _check_consistent(task)
    return task


# -- fields ---------------------------------------------------------------------------


def _mechanism(data: Mapping[str, Any], base: str | Path | None) -> Mechanism:
    raw = data.get("mechanism")
    if raw is None:
        raise MechanismError("mechanism: missing (a mechanism object, or a file name)")
    if isinstance(raw, str):
        path = Path(base if base is not None else ".") / raw
        try:
            return read_mechanism(path)
        except MechanismError as exc:
            raise MechanismError(f"mechanism: {exc}") from None
    if not isinstance(raw, Mapping):
        raise MechanismError("mechanism: expected a mechanism object or a file name")
    try:
        return mechanism_from_dict(raw)
    except MechanismError as exc:
        raise MechanismError(f"mechanism.{exc}") from None


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise MechanismError(f"{where}: expected a number, got {_shown(value)}")
    try:
        x = float(value)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x):
        raise MechanismError(f"{where}: not a finite number")
    return x


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _targets(data: Mapping[str, Any], width: int) -> FloatArray:
    raw = data.get("targets")
    if raw is None:
        raise MechanismError("targets: missing")
    if not isinstance(raw, list) or not raw:
        raise MechanismError("targets: expected a non-empty list of targets")
    names = {2: "[x, y]" if data["task"] == "path" else "[q, angle]", 3: "[x, y, angle]"}
    rows = []
    for i, row in enumerate(raw):
        where = f"targets[{i}]"
        ok = isinstance(row, list) and len(row) == width
        if ok:
            try:
                rows.append([_number(v, where) for v in row])
                continue
            except MechanismError:
                pass
        raise MechanismError(
            f"{where}: expected {names[width]} with {width} finite numbers, got {_shown(row)}"
        )
    return np.array(rows, dtype=float)


def _point(data: Mapping[str, Any], m: Mechanism, kind: str) -> tuple[str, str]:
    pid = data.get("point")
    if pid is None:
        raise MechanismError(f"point: missing (the id of the point that {kind} synthesis moves)")
    if isinstance(pid, bool) or not isinstance(pid, (str, int)):
        raise MechanismError(f"point: an id must be a string or an integer, got {_shown(pid)}")
    pid = str(pid)
    points = {p.id: p.link for p in m.points}
    if pid in points:
        link = points[pid]
        if link == m.frame:
            raise MechanismError(
                f"point: {pid!r} is on the frame link {link!r}, which does not move"
            )
    elif any(j.id == pid for j in m.joints):
        moving = [x for x in m.joint(pid).links if x != m.frame]
        if len(moving) < len(m.joint(pid).links):
            raise MechanismError(f"point: joint {pid!r} is on the frame link, which does not move")
        link = moving[0]
    else:
        raise MechanismError(f"point: {pid!r} is not a point or joint of the mechanism")
    if kind == "motion" and "link" in data:
        want = str(data["link"])
        if want not in m.links:
            raise MechanismError(f"link: {want!r} is not a link of the mechanism")
        if want == m.frame:
            raise MechanismError(f"link: {want!r} is the frame, which does not move")
        on = points[pid] == want if pid in points else want in m.joint(pid).links
        if not on:
            raise MechanismError(f"link: the point {pid!r} is not on link {want!r}")
        link = want
    return pid, link


def _output_link(data: Mapping[str, Any], m: Mechanism) -> str:
    if "output" in data:
        out = str(data["output"])
        if out not in m.links:
            raise MechanismError(f"output: {out!r} is not a link of the mechanism")
        if out == m.frame:
            raise MechanismError(f"output: {out!r} is the frame, which does not move")
        return out
    # the singular positions' default: the link of the last frame joint that is not
    # the driver
    frame_joints = [j for j in m.joints if m.frame in j.links and j.id not in m.drivers]
    if not frame_joints:
        raise MechanismError("output: no default (no frame joint besides the driver); name one")
    j = frame_joints[-1]
    return next(x for x in j.links if x != m.frame)


def _timing(data: Mapping[str, Any], n: int) -> FloatArray | None:
    raw = data.get("timing")
    if raw is None:
        return None
    if not isinstance(raw, list):
        raise MechanismError("timing: expected a list of driver values, one per target")
    if len(raw) != n:
        raise MechanismError(f"timing: {len(raw)} driver values for {n} targets")
    return np.array([_number(v, f"timing[{i}]") for i, v in enumerate(raw)])


def _flag(data: Mapping[str, Any], key: str) -> bool:
    value = data.get(key, False)
    if not isinstance(value, bool):
        raise MechanismError(f"{key}: expected true or false, got {_shown(value)}")
    return value


def _ids(m: Mechanism) -> set[str]:
    return {j.id for j in m.joints} | {p.id for p in m.points}


def _region(
    data: Mapping[str, Any], m: Mechanism
) -> dict[str, tuple[tuple[float, float], tuple[float, float]]]:
    raw = data.get("region", {})
    if not isinstance(raw, Mapping):
        raise MechanismError("region: expected {id: [[xmin, ymin], [xmax, ymax]]}")
    ids = _ids(m)
    out = {}
    for key, box in raw.items():
        where = f"region.{key}"
        if str(key) not in ids:
            raise MechanismError(f"{where}: {key!r} is not a joint or point of the mechanism")
        ok = isinstance(box, list) and len(box) == 2
        ok = ok and all(isinstance(c, list) and len(c) == 2 for c in box)
        if not ok:
            raise MechanismError(f"{where}: expected [[xmin, ymin], [xmax, ymax]]")
        (x0, y0), (x1, y1) = ((_number(v, where) for v in c) for c in box)
        if x0 > x1:
            raise MechanismError(f"{where}: xmin {x0:g} > xmax {x1:g}")
        if y0 > y1:
            raise MechanismError(f"{where}: ymin {y0:g} > ymax {y1:g}")
        out[str(key)] = ((x0, y0), (x1, y1))
    return out


def _lengths(data: Mapping[str, Any]) -> tuple[float, float] | None:
    raw = data.get("lengths")
    if raw is None:
        return None
    if not isinstance(raw, list) or len(raw) != 2:
        raise MechanismError("lengths: expected [min, max]")
    lo, hi = (_number(v, "lengths") for v in raw)
    if lo < 0:
        raise MechanismError(f"lengths: min {lo:g} < 0")
    if lo > hi:
        raise MechanismError(f"lengths: min {lo:g} > max {hi:g}")
    if hi <= 0:
        raise MechanismError(f"lengths: max {hi:g} leaves no length")
    return lo, hi


def _fixed(data: Mapping[str, Any], m: Mechanism) -> tuple[str, ...]:
    raw = data.get("fixed", [])
    if not isinstance(raw, list):
        raise MechanismError("fixed: expected a list of joint or point ids")
    ids = _ids(m)
    out = []
    for i, x in enumerate(raw):
        if str(x) not in ids:
            raise MechanismError(f"fixed[{i}]: {x!r} is not a joint or point of the mechanism")
        out.append(str(x))
    return tuple(out)


def is_fourbar(m: Mechanism) -> bool:
    """Four links, four revolute two-link joints, one frame: a hinged four-bar."""
    return (
        len(m.links) == 4
        and len(m.joints) == 4
        and all(j.kind == "R" and len(j.links) == 2 for j in m.joints)
    )


def _motion(data: Mapping[str, Any], m: Mechanism) -> str | None:
    raw = data.get("motion")
    if raw is None:
        return None
    if raw not in MOTION_TYPES:
        kinds = ", ".join(MOTION_TYPES)
        raise MechanismError(f"motion: unknown motion type {raw!r} (one of {kinds})")
    if not is_fourbar(m):
        raise MechanismError("motion: a motion type can only be required of a hinged four-bar")
    driver = m.joint(m.drivers[0])
    if m.frame not in driver.links:
        raise MechanismError("motion: the four-bar's driver must be a frame joint")
    return str(raw)


def _optional_number(
    data: Mapping[str, Any], key: str, lo: float, hi: float, open_high: bool = False
) -> float | None:
    if key not in data:
        return None
    x = _number(data[key], key)
    if x < lo or x > hi or (open_high and x >= hi):
        upper = f"{hi:g})" if open_high else f"{hi:g}]"
        raise MechanismError(f"{key}: {x:g} is outside [{lo:g}, {upper}")
    return x


def _solver(data: Mapping[str, Any], timed: bool = False) -> dict[str, int | float]:
    raw = data.get("solver", {})
    if not isinstance(raw, Mapping):
        raise MechanismError("solver: expected an object")
    out: dict[str, int | float] = dict(SOLVER_DEFAULTS)
    if timed:
        out["generations"] = TIMED_GENERATIONS
    for key, value in raw.items():
        where = f"solver.{key}"
        if key not in SOLVER_DEFAULTS:
            raise MechanismError(f"{where}: unknown (one of {', '.join(SOLVER_DEFAULTS)})")
        if key == "tol":
            x = _number(value, where)
            if not 0 < x < 1:
                raise MechanismError(f"{where}: must be in (0, 1), got {x:g}")
            out[key] = x
            continue
        if isinstance(value, bool) or not isinstance(value, int):
            raise MechanismError(f"{where}: expected a whole number, got {_shown(value)}")
        least = {"population": 4, "generations": 1, "restarts": 1, "samples": 8}[key]
        if not least <= value <= 100_000:
            raise MechanismError(f"{where}: must be in [{least}, 100000], got {value}")
        out[key] = value
    return out


def _size(m: Mechanism) -> float:
    """The largest distance between two joint centres (0 without geometry)."""
    at = np.array([complex(*j.at) for j in m.joints if j.at is not None])
    if len(at) < 2:
        return 0.0
    box = np.ptp(at.real) + 1j * np.ptp(at.imag)
    return float(abs(box))  # within a factor sqrt(2) of the largest distance


def _check_magnitudes(task: Task) -> None:
    """Numbers a double cannot work with as the task means them: driver values and
    angles beyond :data:`DRIVER_LIMIT`, positions farther than the kinematics' 1e8
    sizes from the origin (the size: the starting mechanism's or the targets' spread,
    whichever is larger)."""
    m = task.mechanism
    assert m is not None
    slide = m.joint(m.drivers[0]).kind == "P"
    start = _size(m)
    unit = max(start, 1e-300) if slide else 1.0
    what = "mechanism sizes" if slide else "rad"
    values: list[tuple[str, float, float]] = []  # (field, value, limit)
    if task.timing is not None:
        values += [
            (f"timing[{i}]", float(v), DRIVER_LIMIT * unit) for i, v in enumerate(task.timing)
        ]
    t = task.targets
    if task.kind == "function":
        values += [(f"targets[{i}]", float(r[0]), DRIVER_LIMIT * unit) for i, r in enumerate(t)]
        values += [(f"targets[{i}]", float(r[1]), DRIVER_LIMIT) for i, r in enumerate(t)]
    if task.kind == "motion":
        values += [(f"targets[{i}]", float(r[2]), DRIVER_LIMIT) for i, r in enumerate(t)]
    for where, v, limit in values:
        if abs(v) > limit:
            unit_word = "rad" if limit == DRIVER_LIMIT else what
            raise MechanismError(
                f"{where}: {v:.6g} is beyond {DRIVER_LIMIT:g} {unit_word} (a driver value or "
                "angle that large keeps too few digits of a turn)"
            )
    if task.kind in ("path", "motion"):
        xy = t[:, :2]
        with np.errstate(over="ignore"):
            spread = float(np.hypot(*np.ptp(xy, axis=0)))
        scale = max(start, spread)
        far = np.abs(xy).max(axis=1)
        k = int(np.argmax(far))
        if spread > SIZE_LIMIT or far[k] > ORIGIN_LIMIT * max(scale, 1e-300):
            raise MechanismError(
                f"targets[{k}]: [{xy[k, 0]:.6g}, {xy[k, 1]:.6g}] is too far out (targets lie "
                f"within {ORIGIN_LIMIT:g} sizes of the origin and {SIZE_LIMIT:g} of each other)"
            )
    for key, ((x0, y0), (x1, y1)) in task.region.items():
        corner = max(abs(x0), abs(y0), abs(x1), abs(y1))
        side = max(x1 - x0, y1 - y0)
        scale = max(start, side)
        if not math.isfinite(side) or side > SIZE_LIMIT or corner > ORIGIN_LIMIT * scale:
            raise MechanismError(
                f"region.{key}: the box is too large or too far out (within "
                f"{ORIGIN_LIMIT:g} sizes of the origin, sides up to {SIZE_LIMIT:g})"
            )


def _check_distinct_timing(task: Task) -> None:
    """Two timed targets at one driver value must be one target: a design is in one
    place at a driver value (a timing near 1e300 put two targets at one q)."""
    if task.kind == "function":
        q, field = task.targets[:, 0], "targets"
    elif task.timing is not None:
        q, field = task.timing, "timing"
    else:
        return
    first: dict[float, int] = {}
    for j, v in enumerate(q):
        i = first.setdefault(float(v), j)
        if i != j and not np.array_equal(task.targets[i], task.targets[j]):
            raise MechanismError(
                f"{field}[{j}]: the driver value of {field}[{i}] with another target "
                "(no design is in two places at one driver value)"
            )


def _check_free(task: Task) -> None:
    """Something left to design: a joint, or the point of interest, that is not fixed."""
    m = task.mechanism
    assert m is not None
    free = {j.id for j in m.joints} - set(task.fixed)
    if task.point is not None and task.point not in task.fixed:
        free.add(task.point)
    if not free:
        raise MechanismError(
            "fixed: names every joint and the point of interest: no dimension is left "
            "to synthesise"
        )


def _check_consistent(task: Task) -> None:
    """Requirements that contradict each other or the starting mechanism."""
    m = task.mechanism
    assert m is not None
    _check_magnitudes(task)
    _check_distinct_timing(task)
    _check_free(task)
    centres = {j.id: j.at for j in m.joints} | {p.id: p.at for p in m.points}
    for jid in task.fixed:
        box = task.region.get(jid)
        at = centres.get(jid)
        if box is not None and at is not None:
            (x0, y0), (x1, y1) = box
            if not (x0 <= at[0] <= x1 and y0 <= at[1] <= y1):
                raise MechanismError(
                    f"region.{jid}: the fixed position {list(at)} is outside its box"
                )
    if task.lengths is not None:
        lo, hi = task.lengths
        fixed = set(task.fixed)
        for link in m.links:
            ids = [j for j in m.link_joints[link] if j in fixed]
            ids += [p.id for p in m.points if p.link == link and p.id in fixed]
            for i, a in enumerate(ids):
                for b in ids[i + 1 :]:
                    pa, pb = centres[a], centres[b]
                    if pa is None or pb is None:
                        continue
                    d = math.dist(pa, pb)
                    if not lo <= d <= hi:
                        raise MechanismError(
                            f"lengths: the fixed {a!r} and {b!r} of link {link!r} are "
                            f"{d:.6g} apart, outside [{lo:g}, {hi:g}]"
                        )
