"""pyslvs mechanism expressions, read and written.

pyslvs describes a linkage as a list of joints (its "points"), each with a kind, an
optional slot angle and colour, a position and the links it joins::

    M[
      J[R, color[Green], P[0.0, 0.0], L[ground, link_1]],
      J[R, color[Green], P[1.0, 2.0], L[link_1, link_2, link_3]],
      J[P, A[30.0], color[Green], P[4.0, 1.0], L[ground, link_4]],
      J[R, color[Green], P[2.0, 2.5], L[link_2]],
    ]

How the two models meet:

==========================  ===================================================
pyslvs                      mjstruct
==========================  ===================================================
link ``ground``             the frame
``J[R, …, L[a, b]]``        revolute joint; three or more links: a multiple joint
``J[P, A[θ], …, L[a, b]]``  prismatic joint, ``axis`` (cos θ, sin θ), θ in degrees;
                            ``a`` carries the slot (the joint's first link)
``J[R, …, L[a]]``           a point of link ``a`` (coupler point)
``J[RP, A[θ], …]``          pin in a slot, a two-DOF higher pair: no equivalent;
                            refused, or with ``pin_slot="block"`` replaced by a
                            slider block (one more link, a P and an R joint)
==========================  ===================================================

Refused both ways (one-line :class:`~mjstruct.errors.MechanismError`): a prismatic
joint of three or more links (pyslvs's P joint has one slot link and one slider), a
joint with no position (pyslvs needs every one), a pyslvs joint that joins no link.

pyslvs has no joint ids, no drivers (its inputs live outside the expression) and no
mechanism name; the writer keeps them in a comment line that pyslvs ignores,
``# mjstruct {...}`` (JSON), so a file survives the trip with its ids, drivers,
masses and loads.  Without that line, joints are named ``P0``, ``P1``, … by their
place in the expression (pyslvs's point numbers) and the frame is ``ground``.

Examples
--------
>>> m = mechanism_from_pyslvs(
...     "M[J[R, color[Green], P[0, 0], L[ground, link_1]],"
...     " J[R, P[1, 0], L[link_1, link_2]], J[R, P[3, 1], L[link_2, link_3]],"
...     " J[R, P[3, 0], L[link_3, ground]], J[R, P[2, 2], L[link_2]]]"
... )
>>> m.frame, [j.id for j in m.joints], m.points[0].link
('ground', ['P0', 'P1', 'P2', 'P3'], 'link_2')
>>> mechanism_from_pyslvs(mechanism_to_pyslvs(m)) == m
True
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Literal, NamedTuple

from mjstruct.errors import MechanismError
from mjstruct.mechanism import Joint, Mechanism, Point

FRAME_LINK = "ground"
HEADER = "# mjstruct "
PinSlot = Literal["refuse", "block"]

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_TOKEN = re.compile(
    r"""
    (?P<space>\s+)
  | (?P<block_comment>\#\[.*?\#\][^\n]*)
  | (?P<comment>\#[^\n]*)
  | (?P<number>[+-]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][+-]?\d+)?)
  | (?P<word>[A-Za-z_][A-Za-z0-9_\-]*\[?)
  | (?P<punct>[\[\],()])
    """,
    re.VERBOSE | re.DOTALL,
)


@dataclass(frozen=True)
class PyslvsJoint:
    """One ``J[...]`` of an expression, as written (angle in degrees, or None for R)."""

    kind: str
    angle: float | None
    color: str | None
    at: tuple[float, float]
    links: tuple[str, ...]


class _Token(NamedTuple):
    kind: str
    text: str
    line: int
    column: int


_SKIPPED = frozenset({"space", "block_comment", "comment"})


def _tokens(text: str, source: str) -> list[_Token]:
    out: list[_Token] = []
    pos, line, line_start = 0, 1, 0
    # one regex scan; a gap between matches is a character no token starts with
    for match in _TOKEN.finditer(text):
        if match.start() != pos:
            break
        kind = match.lastgroup or ""
        if kind not in _SKIPPED:
            out.append(_Token(kind, match.group(), line, pos - line_start + 1))
        pos = match.end()
        if kind != "word" and kind != "punct" and kind != "number":
            newlines = match.group().count("\n")  # only spaces and comments span lines
            if newlines:
                line += newlines
                line_start = match.start() + match.group().rindex("\n") + 1
    if pos < len(text):
        raise MechanismError(
            f"{source}: line {line} column {pos - line_start + 1}: "
            f"unexpected character {text[pos]!r}"
        )
    return out


class _Reader:
    """Recursive descent over pyslvs's grammar (the order of the items is fixed)."""

    def __init__(self, text: str, source: str) -> None:
        self.tokens = _tokens(text, source)
        self.k = 0
        self.source = source

    def _fail(self, expected: str) -> MechanismError:
        if self.k >= len(self.tokens):
            return MechanismError(f"{self.source}: expected {expected}, found the end")
        t = self.tokens[self.k]
        return MechanismError(
            f"{self.source}: line {t.line} column {t.column}: expected {expected}, "
            f"found {t.text!r}"
        )

    def peek(self, text: str) -> bool:
        return self.k < len(self.tokens) and self.tokens[self.k].text == text

    def take(self, text: str, expected: str | None = None) -> None:
        if not self.peek(text):
            raise self._fail(expected or repr(text))
        self.k += 1

    def number(self, what: str) -> float:
        if self.k < len(self.tokens) and self.tokens[self.k].kind == "number":
            t = self.tokens[self.k]
            value = float(t.text)  # a long digit string reads as a float (inf if too large)
            if not math.isfinite(value):
                shown = t.text
                if len(shown) > 24:
                    shown = f"{shown[:12]}…({len(shown)} characters)"
                raise MechanismError(
                    f"{self.source}: line {t.line} column {t.column}: {what} {shown} is beyond "
                    "a double (magnitude at most 1.8e308)"
                )
            self.k += 1
            return value
        raise self._fail(what)

    def name(self, what: str) -> str:
        if self.k < len(self.tokens) and self.tokens[self.k].kind == "word":
            text = self.tokens[self.k].text
            if not text.endswith("["):
                self.k += 1
                return text
        raise self._fail(what)

    def mechanism(self) -> list[PyslvsJoint]:
        self.take("M[", "'M[' (a pyslvs expression starts with M[)")
        joints: list[PyslvsJoint] = []
        while not self.peek("]"):
            joints.append(self.joint())
            if not self.peek("]"):
                self.take(",", "',' or ']' after a joint")
        self.take("]")
        if self.k != len(self.tokens):
            raise self._fail("the end after M[...]")
        return joints

    def joint(self) -> PyslvsJoint:
        self.take("J[", "'J[' (a joint)")
        kind = self.name("a joint kind R, P or RP")
        if kind not in ("R", "P", "RP"):
            self.k -= 1
            raise self._fail("a joint kind R, P or RP")
        self.take(",")
        angle = None
        if self.peek("A["):
            self.take("A[")
            angle = self.number("the slot angle in degrees")
            self.take("]")
            self.take(",")
        if kind != "R" and angle is None:
            raise self._fail(f"'A[' (a {kind} joint needs its slot angle)")
        if kind == "R" and angle is not None:
            self.k -= 1
            raise self._fail("no A[...] in an R joint")
        color = None
        if self.peek("color["):
            self.take("color[")
            if self.peek("("):
                self.take("(")
                rgb = [self.number("a colour component")]
                for _ in range(2):
                    self.take(",")
                    rgb.append(self.number("a colour component"))
                self.take(")")
                color = "(" + ", ".join(str(int(c)) for c in rgb) + ")"
            else:
                color = self.name("a colour name")
            self.take("]")
            self.take(",")
        self.take("P[", "'P[' (the joint's position)")
        x = self.number("the x coordinate")
        self.take(",")
        y = self.number("the y coordinate")
        self.take("]")
        self.take(",")
        self.take("L[", "'L[' (the joint's links)")
        links: list[str] = []
        while not self.peek("]"):
            links.append(self.name("a link name"))
            if not self.peek("]"):
                self.take(",", "',' or ']' in L[...]")
        self.take("]")
        self.take("]", "']' closing the joint")
        return PyslvsJoint(kind, angle, color, (x, y), tuple(links))


def parse_pyslvs(text: str, source: str = "expression") -> list[PyslvsJoint]:
    """The joints of a pyslvs expression, as written (no conversion).

    Examples
    --------
    >>> [j.links for j in parse_pyslvs("M[J[P, A[90], P[0, 1], L[ground, s]],]")]
    [('ground', 's')]
    """
    if not isinstance(text, str):
        raise MechanismError(f"{source}: a pyslvs expression must be text")
    return _Reader(text, source).mechanism()


def _header(text: str, source: str) -> dict[str, Any]:
    for line in text.splitlines():
        if line.strip().startswith(HEADER):
            try:
                data = json.loads(line.strip()[len(HEADER) :])
            except json.JSONDecodeError as exc:
                raise MechanismError(f"{source}: the '{HEADER.strip()}' line: {exc.msg}") from None
            if not isinstance(data, dict):
                raise MechanismError(f"{source}: the '{HEADER.strip()}' line must hold an object")
            return data
    return {}


def _axis(degrees: float) -> tuple[float, float]:
    # exact unit vectors on the axes: cos(pi/2) would leave 6e-17
    quarter, rest = divmod(degrees, 90.0)
    if rest == 0.0:
        return ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[int(quarter) % 4]
    rad = math.radians(degrees)
    return (math.cos(rad), math.sin(rad))


def _angle(axis: tuple[float, float]) -> float:
    return math.degrees(math.atan2(axis[1], axis[0]))


def mechanism_from_pyslvs(
    text: str,
    *,
    pin_slot: PinSlot = "refuse",
    drivers: Iterable[str] | None = None,
    source: str = "expression",
) -> Mechanism:
    """A validated :class:`Mechanism` from a pyslvs expression.

    Parameters
    ----------
    text
        The expression ``M[J[...], ...]``; a ``# mjstruct {...}`` line written by
        :func:`mechanism_to_pyslvs` restores ids, name, drivers and further keys.
    pin_slot
        ``"refuse"`` (default): a pin-in-slot joint ``RP`` is bad input;
        ``"block"``: replace each by a slider block ``<slot>_block<i>`` (a P joint
        ``P<i>`` to the slot link, an R joint ``P<i>_pin`` to the pin links).
    drivers
        Driven joint ids (pyslvs keeps its inputs outside the expression); default
        those of the header line, or none.
    source
        Name used in error messages (a file name).

    Examples
    --------
    >>> expr = "M[J[R, P[0, 0], L[ground, a]], J[RP, A[0], P[2, 0], L[ground, a]]]"
    >>> mechanism_from_pyslvs(expr)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: expression: J[RP] #1 is a pin in a slot, ...
    >>> m = mechanism_from_pyslvs(expr, pin_slot="block")
    >>> [(j.id, j.kind, j.links) for j in m.joints]
    [('P0', 'R', ('ground', 'a')), ('P1', 'P', ('ground', 'ground_block1')), \
('P1_pin', 'R', ('ground_block1', 'a'))]
    """
    if pin_slot not in ("refuse", "block"):
        raise MechanismError(f"pin_slot: expected 'refuse' or 'block', got {pin_slot!r}")
    vpoints = parse_pyslvs(text, source)
    head = _header(text, source)
    ids = head.get("joints")
    if ids is not None and (not isinstance(ids, list) or len(ids) != len(vpoints)):
        raise MechanismError(
            f"{source}: the '{HEADER.strip()}' line does not match the expression's "
            f"{len(vpoints)} joints and points; delete that line"
        )
    link_pairs = head.get("links", [])
    if not isinstance(link_pairs, list) or not all(
        isinstance(p, list) and len(p) == 2 for p in link_pairs
    ):
        raise MechanismError(
            f"{source}: the '{HEADER.strip()}' line: links must be [name, id] pairs"
        )
    rename = {str(a): str(b) for a, b in link_pairs}

    def link_id(name: str) -> str:
        return rename.get(name, name)

    joints: list[Joint] = []
    points: list[Point] = []
    order: dict[str, None] = {}
    for i, vp in enumerate(vpoints):
        jid = str(ids[i]) if ids is not None else f"P{i}"
        links = tuple(link_id(x) for x in vp.links)
        where = f"{source}: J[{vp.kind}] #{i}"
        if not links:
            raise MechanismError(
                f"{where} joins no link (a free point has no place in a mechanism)"
            )
        order.update(dict.fromkeys(links))
        if vp.kind == "R":
            if len(links) == 1:
                points.append(Point(jid, links[0], vp.at))
            else:
                joints.append(Joint(jid, links, "R", vp.at))
            continue
        assert vp.angle is not None  # the reader requires A[...] for P and RP
        axis = _axis(vp.angle)
        if len(links) < 2:
            raise MechanismError(f"{where} has a slot link and no slider (L[...] needs two)")
        if vp.kind == "P":
            if len(links) > 2:
                raise MechanismError(
                    f"{where} lists {len(links)} links; a prismatic joint joins a slot link "
                    "and one slider"
                )
            joints.append(Joint(jid, links, "P", vp.at, axis))
            continue
        if pin_slot == "refuse":
            raise MechanismError(
                f"{where} is a pin in a slot, a two-DOF higher pair that R and P joints "
                "cannot represent; convert with pin_slot='block' to put "
                "a slider block in its place"
            )
        block = f"{links[0]}_block{i}"
        order[block] = None
        joints.append(Joint(jid, (links[0], block), "P", vp.at, axis))
        joints.append(Joint(f"{jid}_pin", (block, *links[1:]), "R", vp.at))

    # with the header, its frame (or none: a chain); without, pyslvs's ground link
    frame = head.get("frame") if head else (FRAME_LINK if FRAME_LINK in order else None)
    link_order = [link_id(str(a)) for a, _ in link_pairs] if link_pairs else list(order)
    if set(link_order) != set(order):
        link_order = list(order)
    extra = head.get("extra", {})
    if not isinstance(extra, dict):
        raise MechanismError(f"{source}: the '{HEADER.strip()}' line: extra must be an object")
    chosen = head.get("drivers", []) if drivers is None else list(drivers)
    if not isinstance(chosen, list):
        raise MechanismError(f"{source}: the '{HEADER.strip()}' line: drivers must be a list")
    return Mechanism(
        links=tuple(link_order),
        joints=tuple(joints),
        frame=None if frame is None else str(frame),
        drivers=tuple(str(d) for d in chosen),
        name=str(head.get("name", "")),
        points=tuple(points),
        extra=extra,
    )


def _link_names(m: Mechanism) -> dict[str, str]:
    """pyslvs names (identifiers; the frame is ``ground``) for the links of ``m``."""
    names: dict[str, str] = {}
    taken: set[str] = set()
    for link in m.links:
        if link == m.frame:
            name = FRAME_LINK
        elif _NAME.match(link) and link != FRAME_LINK:
            name = link
        else:
            name = "link_" + re.sub(r"[^A-Za-z0-9_]", "_", link)
        base, k = name, 1
        while name in taken or (name == FRAME_LINK and link != m.frame):
            name, k = f"{base}_{k}", k + 1
        names[link] = name
        taken.add(name)
    return names


def _number(v: float) -> str:
    return repr(float(v))  # shortest text that reads back to the same float


def mechanism_to_pyslvs(m: Mechanism, *, header: bool = True, color: str = "Green") -> str:
    """The pyslvs expression of ``m``, one joint a line, coordinates exact.

    Parameters
    ----------
    m
        A mechanism with every joint's position ``at`` (and ``axis`` for P joints).
    header
        Write the ``# mjstruct {...}`` comment line (ids, name, drivers, further
        keys) that pyslvs ignores and :func:`mechanism_from_pyslvs` reads.
    color
        The pyslvs colour name written in every joint.

    Raises
    ------
    MechanismError
        a joint without ``at``, a prismatic joint without ``axis`` or with more than
        two links.

    Examples
    --------
    >>> m = Mechanism.build([("O", ["0", "1"]), ("S", ["1", "0"], "P")], frame="0")
    >>> mechanism_to_pyslvs(m)
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: joints[0].at: missing for joint 'O'; a pyslvs expression \
needs every joint's position
    """
    names = _link_names(m)
    lines = []
    for k, j in enumerate(m.joints):
        if j.at is None:
            raise MechanismError(
                f"joints[{k}].at: missing for joint {j.id!r}; a pyslvs expression needs "
                "every joint's position"
            )
        links = ", ".join(names[x] for x in j.links)
        pos = f"P[{_number(j.at[0])}, {_number(j.at[1])}]"
        if j.kind == "P":
            if j.axis is None:
                raise MechanismError(
                    f"joints[{k}].axis: missing for prismatic joint {j.id!r}; pyslvs needs "
                    "the slot angle"
                )
            if len(j.links) != 2:
                raise MechanismError(
                    f"joints[{k}].links: prismatic joint {j.id!r} joins {len(j.links)} links; "
                    "a pyslvs P joint joins a slot link and one slider"
                )
            kind = f"P, A[{_number(_angle(j.axis))}]"
        else:
            kind = "R"
        lines.append(f"  J[{kind}, color[{color}], {pos}, L[{links}]],")
    for p in m.points:
        pos = f"P[{_number(p.at[0])}, {_number(p.at[1])}]"
        lines.append(f"  J[R, color[{color}], {pos}, L[{names[p.link]}]],")
    text = "M[\n" + "\n".join(lines) + "\n]\n"
    if not header:
        return text
    head: dict[str, Any] = {}
    if m.name:
        head["name"] = m.name
    if m.frame is not None:
        head["frame"] = m.frame
    head["links"] = [[names[x], x] for x in m.links]
    head["joints"] = [j.id for j in m.joints] + [p.id for p in m.points]
    if m.drivers:
        head["drivers"] = list(m.drivers)
    if m.extra:
        head["extra"] = dict(m.extra)
    return HEADER + json.dumps(head, ensure_ascii=False, allow_nan=False) + "\n" + text


def pyslvs_inputs(m: Mechanism) -> list[tuple[int, int]]:
    """pyslvs input pairs (base point, driven point) for the revolute drivers of ``m``.

    pyslvs drives the angle of the line from one point to another; for a driver joint
    that is the joint itself and another joint of its second listed link.  Indices are
    places in :func:`mechanism_to_pyslvs`'s expression.

    Examples
    --------
    >>> m = Mechanism.build([("O", [0, 1]), ("A", [1, 2]), ("B", [2, 3]), ("C", [3, 0])],
    ...                     frame=0, drivers=["O"])
    >>> pyslvs_inputs(m)
    [(0, 1)]
    """
    index = {j.id: k for k, j in enumerate(m.joints)}
    pairs = []
    for d in m.drivers:
        j = m.joint(d)
        if j.kind != "R":
            raise MechanismError(
                f"drivers: {d!r} is prismatic; a pyslvs input turns a link about a joint"
            )
        other = next((x for x in m.link_joints[j.links[1]] if x != d), None)
        if other is None:
            raise MechanismError(
                f"drivers: link {j.links[1]!r} driven by {d!r} has no other joint"
            )
        pairs.append((index[d], index[other]))
    return pairs


def _point_ids(text: str, source: str) -> list[str]:
    """The id each ``J[...]`` gets in :func:`mechanism_from_pyslvs` (header or ``P<i>``)."""
    ids = _header(text, source).get("joints")
    count = len(parse_pyslvs(text, source))
    return [str(x) for x in ids] if isinstance(ids, list) else [f"P{i}" for i in range(count)]


def mechanism_from_pyslvs_project(
    text: str, *, pin_slot: PinSlot = "refuse", source: str = "project"
) -> Mechanism:
    """A mechanism from a pyslvs project file (``.pyslvs``, YAML).

    The project's ``mechanism`` is the expression; its ``input`` pairs (base point,
    driven point) make the base points the drivers.  Reading YAML needs PyYAML
    (HDF5 projects are not read).

    Examples
    --------
    >>> m = mechanism_from_pyslvs_project(
    ...     "mechanism: M[J[R, P[0, 0], L[ground, a]], J[R, P[1, 0], L[a, b]],"
    ...     " J[R, P[2, 1], L[b, c]], J[R, P[3, 0], L[c, ground]]]\\n"
    ...     "input:\\n- [0, 1]\\n")
    >>> m.drivers, m.joint("P0").links
    (('P0',), ('ground', 'a'))
    """
    try:
        import yaml
    except ImportError:
        raise MechanismError(
            f"{source}: reading a pyslvs project needs PyYAML (pip install pyyaml)"
        ) from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        first = str(exc).splitlines()[0] if str(exc) else exc.__class__.__name__
        raise MechanismError(f"{source}: not a YAML pyslvs project ({first})") from None
    if not isinstance(data, dict) or not isinstance(data.get("mechanism"), str):
        raise MechanismError(f"{source}: mechanism: missing (a pyslvs project holds M[...] there)")
    expr = data["mechanism"]
    pairs = data.get("input") or []
    ok = isinstance(pairs, list) and all(
        isinstance(p, list | tuple) and len(p) == 2 and all(type(v) is int for v in p)
        for p in pairs
    )
    if not ok:
        raise MechanismError(f"{source}: input: expected [base, driven] point-number pairs")
    ids = _point_ids(expr, source)
    vpoints = parse_pyslvs(expr, source)
    drivers = []
    for k, (base, driven) in enumerate(pairs):
        if not (0 <= base < len(ids) and 0 <= driven < len(ids)):
            raise MechanismError(f"{source}: input[{k}]: point {base} or {driven} does not exist")
        if len(vpoints[base].links) < 2:
            raise MechanismError(f"{source}: input[{k}]: point {base} is not a joint")
        drivers.append(ids[base])
    # the mjstruct line keeps prismatic drivers too, which pyslvs inputs cannot name
    kept = _header(expr, source).get("drivers")
    if isinstance(kept, list) and set(drivers) <= {str(d) for d in kept}:
        drivers = [str(d) for d in kept]
    chosen = drivers if pairs or kept else None
    return mechanism_from_pyslvs(expr, pin_slot=pin_slot, drivers=chosen, source=source)


def mechanism_to_pyslvs_project(m: Mechanism) -> str:
    """A pyslvs project file (YAML) holding the expression and the input pairs.

    Revolute drivers become pyslvs inputs (see :func:`pyslvs_inputs`); every driver
    also stays in the expression's ``# mjstruct`` line.

    Examples
    --------
    >>> from mjstruct.io import read_mechanism
    >>> from mjstruct.catalog_files import example_path
    >>> m = read_mechanism(example_path("four-bar"))
    >>> mechanism_from_pyslvs_project(mechanism_to_pyslvs_project(m)) == m
    True
    """
    expr = mechanism_to_pyslvs(m)
    revolute = m.with_drivers(d for d in m.drivers if m.joint(d).kind == "R")
    lines = ["# a pyslvs project written by mjstruct", f"mechanism: {json.dumps(expr)}"]
    pairs = pyslvs_inputs(revolute)
    if pairs:
        lines.append("input:")
        lines.extend(f"- [{b}, {d}]" for b, d in pairs)
    return "\n".join(lines) + "\n"
