"""The link–joint model: links, joints of any multiplicity, frame and drivers.

A joint joins two or more links on one axis, so a multiple joint (MJ) is one object
and never torn into pairs.  The structure is the bipartite link–joint graph returned
by :meth:`Mechanism.graph`; every structural function works on a :class:`Mechanism`.

Examples
--------
>>> m = Mechanism.build([("O1", ["0", "1"]), ("A", ["1", "2", "3"]),
...                      ("B", ["2", "0"]), ("C", ["3", "0"])], frame="0")
>>> m.joint("A").multiplicity
2
>>> sorted(m.graph().nodes)[:2]
[('joint', 'A'), ('joint', 'B')]
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

from mjstruct import display
from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    import networkx as nx

JOINT_KINDS = ("R", "P")

LINK = "link"
JOINT = "joint"


@dataclass(frozen=True)
class Joint:
    """A lower pair joining ``len(links) >= 2`` links on one axis.

    ``links`` keeps the file's order: the first link is the reference for the
    joint's relative coordinate and the carrier when the joint is expanded into
    simple-joint equivalents.
    """

    id: str
    links: tuple[str, ...]
    kind: str = "R"
    at: tuple[float, float] | None = None
    axis: tuple[float, float] | None = None

    @property
    def multiplicity(self) -> int:
        """j = m - 1: the number of simple joints this joint is equivalent to."""
        return len(self.links) - 1

    @property
    def is_multiple(self) -> bool:
        return len(self.links) > 2


@dataclass(frozen=True)
class Point:
    """A point of interest fixed to a link (coupler point, centre of mass)."""

    id: str
    link: str
    at: tuple[float, float]


@dataclass(frozen=True)
class Mechanism:
    """A chain (no frame) or a mechanism (frame and drivers) with multiple joints.

    Build one with :meth:`build` or :func:`mjstruct.io.mechanism_from_dict`; both
    validate.  ``extra`` keeps the file's further keys (masses, forces) untouched.
    """

    links: tuple[str, ...]
    joints: tuple[Joint, ...]
    frame: str | None = None
    drivers: tuple[str, ...] = ()
    name: str = ""
    points: tuple[Point, ...] = ()
    extra: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        validate(self)

    @classmethod
    def build(
        cls,
        joints: Iterable[tuple[str, Sequence[Any]] | tuple[str, Sequence[Any], str]],
        frame: Any = None,
        drivers: Iterable[str] = (),
        name: str = "",
    ) -> Mechanism:
        """Build from ``(id, links[, kind])`` tuples; links are listed in first-seen order."""
        if isinstance(joints, (str, bytes)) or not isinstance(joints, Iterable):
            raise MechanismError(f"joints: expected (id, links[, kind]) tuples, got {joints!r}")
        if isinstance(drivers, str):
            raise MechanismError(f"drivers: expected a list of joint ids, got {drivers!r}")
        js = []
        order: dict[str, None] = {}
        for k, spec in enumerate(joints):
            if isinstance(spec, (str, bytes)) or not isinstance(spec, Sequence) or len(spec) < 2:
                raise MechanismError(f"joints[{k}]: expected (id, links[, kind]), got {spec!r}")
            if isinstance(spec[1], (str, bytes)) or not isinstance(spec[1], Iterable):
                raise MechanismError(f"joints[{k}].links: expected a list of link ids")
            jid, links = spec[0], spec[1]
            kind = spec[2] if len(spec) > 2 else "R"
            ls = tuple(str(x) for x in links)
            order.update(dict.fromkeys(ls))
            js.append(Joint(str(jid), ls, str(kind)))
        return cls(
            links=tuple(order),
            joints=tuple(js),
            frame=None if frame is None else str(frame),
            drivers=tuple(str(d) for d in drivers),
            name=name,
        )

    # -- look-ups ---------------------------------------------------------
    @cached_property
    def _joint_index(self) -> dict[str, Joint]:
        return {j.id: j for j in self.joints}

    def joint(self, joint_id: str) -> Joint:
        """The joint with this id (``KeyError`` when there is none)."""
        return self._joint_index[joint_id]

    def other_link(self, joint_id: str, link: str) -> str:
        """The first link of the joint other than ``link`` (for a simple joint: the other).

        >>> m = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 0])])
        >>> m.other_link("A", "1"), m.other_link("A", "2")
        ('2', '1')
        """
        links = self.joint(joint_id).links
        if link not in links:
            raise MechanismError(f"link: {link!r} is not on joint {joint_id!r}")
        return next(x for x in links if x != link)

    @cached_property
    def link_joints(self) -> dict[str, tuple[str, ...]]:
        """For each link, the ids of the joints it takes part in (file order)."""
        out: dict[str, list[str]] = {link: [] for link in self.links}
        for j in self.joints:
            for link in j.links:
                out[link].append(j.id)
        return {k: tuple(v) for k, v in out.items()}

    @property
    def n(self) -> int:
        """Number of links, frame included."""
        return len(self.links)

    def graph(self) -> nx.Graph:
        """The bipartite link–joint graph (a fresh copy; nodes ``(kind, id)``).

        Link nodes carry ``frame`` (bool); joint nodes carry ``type`` and ``driver``.
        """
        return self._graph.copy()

    @cached_property
    def adjacency(self) -> dict[tuple[str, str], tuple[tuple[str, str], ...]]:
        """The bipartite graph as plain adjacency lists (no networkx needed)."""
        adj: dict[tuple[str, str], tuple[tuple[str, str], ...]] = {
            (LINK, link): tuple((JOINT, j) for j in js) for link, js in self.link_joints.items()
        }
        for j in self.joints:
            adj[(JOINT, j.id)] = tuple((LINK, link) for link in j.links)
        return adj

    @cached_property
    def _graph(self) -> nx.Graph:
        import networkx as nx  # imported here: the structural CLI path does without it

        g = nx.Graph()
        drivers = set(self.drivers)
        for link in self.links:
            g.add_node((LINK, link), bipartite=0, frame=link == self.frame)
        for j in self.joints:
            g.add_node((JOINT, j.id), bipartite=1, type=j.kind, driver=j.id in drivers)
            g.add_edges_from(((JOINT, j.id), (LINK, link)) for link in j.links)
        return g

    def _repr_svg_(self) -> str | None:
        """Notebook picture (drawn by the renderer of :mod:`mjstruct.display`)."""
        return display.svg(self)

    def with_drivers(self, drivers: Iterable[str]) -> Mechanism:
        """The same mechanism with another set of driven joints."""
        return Mechanism(
            links=self.links,
            joints=self.joints,
            frame=self.frame,
            drivers=tuple(drivers),
            name=self.name,
            points=self.points,
            extra=self.extra,
        )


def _validate_types(m: Mechanism) -> None:
    """The fields' types, before anything else reads them (``Mechanism(links=5)``)."""
    for name, kind in (("links", str), ("joints", Joint), ("drivers", str), ("points", Point)):
        value = getattr(m, name)
        if not isinstance(value, (tuple, list)) or not all(isinstance(x, kind) for x in value):
            raise MechanismError(
                f"{name}: expected a tuple of {kind.__name__} values, got {type(value).__name__}"
            )
    for k, j in enumerate(m.joints):
        if not isinstance(j.id, str) or not isinstance(j.links, (tuple, list)):
            raise MechanismError(f"joints[{k}]: expected a str id and a tuple of link ids")
        if not all(isinstance(x, str) for x in j.links):
            raise MechanismError(f"joints[{k}].links: expected link ids (str), got {j.links!r}")
    if m.frame is not None and not isinstance(m.frame, str):
        raise MechanismError(f"frame: expected a link id (str) or None, got {m.frame!r}")
    if not isinstance(m.name, str):
        raise MechanismError(f"name: expected a str, got {type(m.name).__name__}")
    if not isinstance(m.extra, Mapping):
        raise MechanismError(f"extra: expected a mapping, got {type(m.extra).__name__}")


def validate(m: Mechanism) -> None:
    """Raise :class:`MechanismError` naming the first problem found."""
    _validate_types(m)
    if not m.joints:
        raise MechanismError("joints: a chain needs at least one joint")
    if len(set(m.links)) != len(m.links):
        dup = next(x for x in m.links if m.links.count(x) > 1)
        raise MechanismError(f"links: duplicate link id {dup!r}")
    known = set(m.links)
    seen: set[str] = set()
    used: set[str] = set()
    for k, j in enumerate(m.joints):
        where = f"joints[{k}]"
        if j.id in seen:
            raise MechanismError(f"{where}.id: duplicate joint id {j.id!r}")
        seen.add(j.id)
        if len(j.links) < 2:
            raise MechanismError(
                f"{where}.links: joint {j.id!r} joins {len(j.links)} link(s); a joint needs >= 2"
            )
        if len(set(j.links)) != len(j.links):
            dup = next(x for x in j.links if j.links.count(x) > 1)
            raise MechanismError(f"{where}.links: link {dup!r} appears twice in joint {j.id!r}")
        for link in j.links:
            if link not in known:
                raise MechanismError(f"{where}.links: unknown link {link!r} in joint {j.id!r}")
        if j.kind not in JOINT_KINDS:
            raise MechanismError(
                f"{where}.type: unknown joint type {j.kind!r} (expected one of R, P)"
            )
        _expect_pair(j.at, f"{where}.at")
        _expect_pair(j.axis, f"{where}.axis")
        used.update(j.links)
    idle = [x for x in m.links if x not in used]
    if idle:
        raise MechanismError(f"links: link {idle[0]!r} takes part in no joint")
    if m.frame is not None and m.frame not in known:
        raise MechanismError(f"frame: unknown link {m.frame!r}")
    checked_driver_ids(m)  # a file may name any drivers; reports judge their balance
    point_ids: set[str] = set()
    for k, p in enumerate(m.points):
        if p.link not in known:
            raise MechanismError(f"points: point {p.id!r} is on unknown link {p.link!r}")
        if p.id in point_ids:
            raise MechanismError(f"points[{k}].id: point id {p.id!r} is used twice")
        _expect_pair(p.at, f"points[{k}].at", optional=False)
        if p.id in seen:  # outputs key joints and points by id together
            raise MechanismError(f"points[{k}].id: {p.id!r} is already a joint id")
        point_ids.add(p.id)
    parts = components(m)
    if len(parts) > 1:
        smallest = min(parts, key=len)
        raise MechanismError(
            f"joints: the chain is disconnected (links {', '.join(smallest)} form a separate part)"
        )


def _expect_pair(value: object, where: str, optional: bool = True) -> None:
    """``value`` is two finite real numbers (or None when ``optional``): every reader
    (files, pyslvs, graphs, code) gets coordinates a double holds, never inf or nan.

    >>> _expect_pair((1.0, float("inf")), "joints[0].at")
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: joints[0].at: expected [x, y] with two finite numbers, \
got (1.0, inf)
    """
    import math
    import numbers

    if value is None and optional:
        return
    ok = isinstance(value, (tuple, list)) and len(value) == 2
    if isinstance(value, (tuple, list)) and ok:
        for v in value:
            if isinstance(v, bool) or not isinstance(v, numbers.Real):
                ok = False
            else:
                try:
                    ok = ok and math.isfinite(float(v))
                except OverflowError:  # an integer beyond a double
                    ok = False
    if not ok:
        shown = repr(value)
        shown = shown if len(shown) <= 60 else shown[:57] + "..."
        raise MechanismError(f"{where}: expected [x, y] with two finite numbers, got {shown}")


def checked_driver_ids(m: Mechanism, drivers: Iterable[str] | None = None) -> tuple[str, ...]:
    """The drivers (default: ``m.drivers``) as a tuple when each is a joint id named once.

    This is the file-level check; whether the drivers suit the mobility is the
    structure's (:func:`mjstruct.structure.drivers.validate_drivers`).

    >>> m = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 0])])
    >>> checked_driver_ids(m, ["O1"])
    ('O1',)
    >>> checked_driver_ids(m, ["O1", "O1"])
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: drivers: joint 'O1' is listed twice
    """
    if isinstance(drivers, str) or not (drivers is None or isinstance(drivers, Iterable)):
        raise MechanismError(f"drivers: expected a list of joint ids, got {drivers!r}")
    out = tuple(m.drivers if drivers is None else drivers)
    known = m._joint_index
    seen: set[str] = set()
    for d in out:
        if not isinstance(d, str) or d not in known:
            raise MechanismError(f"drivers: {d!r} is not a joint id")
        if d in seen:
            raise MechanismError(f"drivers: joint {d!r} is listed twice")
        seen.add(d)
    return out


def expect_mechanism(value: object, parameter: str = "m") -> None:
    """Raise :class:`MechanismError` naming ``parameter`` unless ``value`` is a Mechanism.

    >>> expect_mechanism("four-bar.json")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: m: expected a Mechanism (read a file ...), got str
    """
    if not isinstance(value, Mechanism):
        raise MechanismError(
            f"{parameter}: expected a Mechanism (read a file with read_mechanism), "
            f"got {type(value).__name__}"
        )


def components(m: Mechanism) -> list[list[str]]:
    """Links of each connected part of the chain (a valid chain has one)."""
    seen: set[str] = set()
    parts = []
    for start in m.links:
        if start in seen:
            continue
        part, stack = [], [start]
        seen.add(start)
        while stack:
            link = stack.pop()
            part.append(link)
            for jid in m.link_joints[link]:
                for other in m.joint(jid).links:
                    if other not in seen:
                        seen.add(other)
                        stack.append(other)
        parts.append(sorted(part))
    return parts
