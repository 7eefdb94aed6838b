"""Force elements of a mechanism file: springs, dampers, elastic slides, motors; checked.

Owns the file key ``elements`` (kept by the reader in :attr:`Mechanism.extra`): a list
of objects, each with a ``type``:

* ``spring`` (``between`` two points, ``stiffness``, optional ``free_length``) and
  ``damper`` (``between`` two points, ``rate``): a force along the line of the points;
* ``torsion_spring`` (``joint``, ``stiffness``, optional ``free_angle``) and
  ``torsion_damper`` (``joint``, ``rate``) at a revolute joint, between two of its links;
* ``elastic_slide`` (``joint``, ``stiffness``, optional ``free_length``) and
  ``slide_damper`` (``joint``, ``rate``) along a prismatic joint's guide;
* ``motor`` (``joint``, ``law``): a torque (revolute joint) or a force along the guide
  (prismatic joint), an expression of the joint's coordinate ``q``, its rate ``qdot``
  and the parameters.

A point is ``{"link": L, "at": [x, y]}`` (the point of link L whose reference position
is given) or ``{"joint": J}`` (the joint's centre, on its first listed link; a
prismatic joint's on its second).  A joint element acts between the joint's first two
listed links, or the two ``links`` given.  Every error names its field.
:mod:`mjstruct.dynamics.element_loads` evaluates the elements on a motion.

Examples
--------
>>> from mjstruct.io import mechanism_from_dict, mechanism_to_dict
>>> m = mechanism_from_dict({"frame": 0, "drivers": ["O1"], "joints": [
...     {"id": "O1", "links": [0, 1], "at": [0, 0]}],
...     "elements": [{"type": "spring", "stiffness": 10,
...                   "between": [{"link": 1, "at": [1, 0]}, {"link": 0, "at": [1, 1]}]}]})
>>> read_elements(m, {"O1": 0j}, {})[0].free
1.0
>>> bad = {"type": "damper", "between": [{"link": 1, "at": [1, 0]}, {"link": 0, "at": [1, 1]}]}
>>> m2 = mechanism_from_dict({**mechanism_to_dict(m), "elements": [bad]})
>>> read_elements(m2, {"O1": 0j}, {})
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: elements[0].rate: missing (a damper needs its rate)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from mjstruct.dynamics.expressions import parse_expression
from mjstruct.errors import MechanismError, expect_id, expect_number
from mjstruct.kinematics.geometry import diameter
from mjstruct.mechanism import Mechanism

if TYPE_CHECKING:
    import sympy

__all__ = ["ELEMENT_TYPES", "Element", "ElementPoint", "read_elements"]

#: every ``type`` an element may have, with the keys it takes
ELEMENT_TYPES: dict[str, tuple[str, ...]] = {
    "spring": ("between", "stiffness", "free_length"),
    "damper": ("between", "rate"),
    "torsion_spring": ("joint", "links", "stiffness", "free_angle"),
    "torsion_damper": ("joint", "links", "rate"),
    "elastic_slide": ("joint", "links", "stiffness", "free_length"),
    "slide_damper": ("joint", "links", "rate"),
    "motor": ("joint", "links", "law"),
}

#: elements that act along a line between two points
LINE_TYPES = ("spring", "damper")


@dataclass(frozen=True)
class ElementPoint:
    """A point of a link: ``at`` is its reference position."""

    link: str
    at: complex


@dataclass(frozen=True)
class Element:
    """One force element, checked.

    Attributes
    ----------
    kind : its ``type``.
    where : its field (``elements[2]``), for messages.
    points : a line element's two points (else empty).
    joint : a joint element's joint (else ``""``).
    links : a joint element's two links ``(a, b)``: its coordinate is b's against a's,
        and its load acts on b (a takes the opposite).
    stiffness, rate : a spring's stiffness, a damper's rate (0 when not one).
    free : the free length (line spring, elastic slide) or free angle (torsion spring;
        None: its reference value).
    slide : a joint element at a prismatic joint (a force along the guide, not a torque).
    law : a motor's law compiled to a numpy function of ``q``, ``qdot`` and
        ``arguments`` (the parameters it uses, in order).
    expr : a motor's law as a sympy expression.
    """

    kind: str
    where: str
    points: tuple[ElementPoint, ...] = ()
    joint: str = ""
    links: tuple[str, str] = ("", "")
    stiffness: float = 0.0
    rate: float = 0.0
    free: float | None = 0.0
    slide: bool = False
    law: Callable[..., Any] | None = None
    arguments: tuple[str, ...] = ()
    expr: Any = None

    @property
    def conservative(self) -> bool:
        """Whether the element stores energy (a spring) rather than doing work."""
        return self.kind in ("spring", "torsion_spring", "elastic_slide")


def _number(value: Any, where: str, minimum: float | None = None, what: str = "") -> float:
    x = expect_number(value, where)
    if minimum is not None and x < minimum:
        raise MechanismError(f"{where}: must be >= {minimum:g}{what}, got {x:g}")
    return x


def _a(kind: str) -> str:
    """``kind`` in words with its article: ``an elastic slide``."""
    words = kind.replace("_", " ")
    return ("an " if words[0] in "aeiou" else "a ") + words


def _point(
    spec: Any, where: str, m: Mechanism, centres: Mapping[str, complex]
) -> tuple[ElementPoint, frozenset[str]]:
    """The point and the links that carry it rigidly."""
    if not isinstance(spec, Mapping):
        raise MechanismError(f"{where}: must be {{'link': L, 'at': [x, y]}} or {{'joint': J}}")
    if "joint" in spec:
        if set(spec) != {"joint"}:
            raise MechanismError(f"{where}: a joint point takes only 'joint'")
        jid = expect_id(spec["joint"], f"{where}.joint")
        if jid not in centres:
            raise MechanismError(f"{where}.joint: unknown joint {jid!r}")
        j = m.joint(jid)
        if j.kind == "P":
            return ElementPoint(j.links[1], centres[jid]), frozenset({j.links[1]})
        return ElementPoint(j.links[0], centres[jid]), frozenset(j.links)
    unknown = set(spec) - {"link", "at"}
    if unknown:
        raise MechanismError(f"{where}.{sorted(unknown)[0]}: unknown key")
    for key in ("link", "at"):
        if key not in spec:
            raise MechanismError(f"{where}.{key}: missing")
    link = expect_id(spec["link"], f"{where}.link")
    if link not in m.links:
        raise MechanismError(f"{where}.link: unknown link {link!r}")
    at = spec["at"]
    if not isinstance(at, (list, tuple)) or len(at) != 2:
        raise MechanismError(f"{where}.at: must be a list [x, y]")
    z = complex(_number(at[0], f"{where}.at[0]"), _number(at[1], f"{where}.at[1]"))
    return ElementPoint(link, z), frozenset({link})


def _joint_links(spec: Mapping[str, Any], where: str, m: Mechanism) -> tuple[str, tuple[str, str]]:
    if "joint" not in spec:
        raise MechanismError(f"{where}.joint: missing")
    jid = expect_id(spec["joint"], f"{where}.joint")
    if jid not in {j.id for j in m.joints}:
        raise MechanismError(f"{where}.joint: unknown joint {jid!r}")
    j = m.joint(jid)
    if "links" in spec:
        raw = spec["links"]
        if not isinstance(raw, (list, tuple)) or len(raw) != 2:
            raise MechanismError(f"{where}.links: must be a list of two links of joint {jid}")
        pair = (expect_id(raw[0], f"{where}.links[0]"), expect_id(raw[1], f"{where}.links[1]"))
        for i, link in enumerate(pair):
            if link not in j.links:
                raise MechanismError(f"{where}.links[{i}]: link {link!r} is not in joint {jid}")
        if pair[0] == pair[1]:
            raise MechanismError(f"{where}.links: two different links of joint {jid}")
    else:
        pair = (j.links[0], j.links[1])
    return jid, pair


def read_elements(
    m: Mechanism,
    centres: Mapping[str, complex],
    parameters: Collection[str],
    limit: float = 1e250,
    max_lever: float = 1e6,
) -> tuple[Element, ...]:
    """Read and check the ``elements`` key of ``m`` (see the module docstring).

    ``centres``: the joint centres of the reference configuration; ``parameters``: the
    names a motor law may use; ``limit``: the largest energy or load a stiffness or a
    rate may give over the mechanism's reach (the dynamics data's magnitude limit);
    ``max_lever``: how many mechanism sizes a point may lie from its link's joints.

    Raises
    ------
    MechanismError
        naming the field: an unknown type or key, a negative stiffness or rate, a
        damper without a rate, a spring between two points of one link (their distance
        never changes) or between two coincident points, a torsion element at a
        prismatic joint, a slide element at a revolute one, a law that does not parse,
        a point too far from its link or a stiffness or rate beyond ``limit``.
    """
    raw = m.extra.get("elements", [])
    if not isinstance(raw, list):
        raise MechanismError("elements: must be a list")
    out = tuple(_element(spec, k, m, centres, parameters) for k, spec in enumerate(raw))
    size = diameter(list(centres.values())) or 1.0
    for el in out:
        _check_reach(el, m, centres, size, limit, max_lever)
    return out


def _check_reach(
    el: Element,
    m: Mechanism,
    centres: Mapping[str, complex],
    size: float,
    limit: float,
    max_lever: float,
) -> None:
    """Refuse an element whose point lies beyond ``max_lever`` sizes from its link's
    joints, or whose stiffness or rate times its reach squared passes ``limit`` (its
    energy, loads and the joint loads would overflow a double)."""
    reach = size
    for i, p in enumerate(el.points):
        arm = max(abs(p.at - centres[j]) for j in m.link_joints[p.link])
        if not arm <= max_lever * size:
            raise MechanismError(
                f"{el.where}.between[{i}]: {arm / size:.3g} × the mechanism's size from the "
                f"joints of link {p.link} (at most {max_lever:.0e})"
            )
        reach += arm
    if el.free is not None and el.kind != "torsion_spring":
        reach += abs(el.free)
    if el.kind.startswith("torsion"):
        reach = 2 * math.pi  # a turn of the joint
    for name, value in (("stiffness", el.stiffness), ("rate", el.rate)):
        if not value * reach * reach <= limit:
            raise MechanismError(
                f"{el.where}.{name}: {value:g} × its reach {reach:.3g} squared passes "
                f"{limit:.0e} (its energy and loads would overflow a double)"
            )


def _element(
    spec: Any,
    k: int,
    m: Mechanism,
    centres: Mapping[str, complex],
    parameters: Collection[str],
) -> Element:
    where = f"elements[{k}]"
    if not isinstance(spec, Mapping):
        raise MechanismError(f"{where}: must be an object with a 'type'")
    kind = spec.get("type")
    if kind not in ELEMENT_TYPES:
        raise MechanismError(
            f"{where}.type: must be one of {', '.join(ELEMENT_TYPES)}, got {kind!r}"
        )
    unknown = set(spec) - {"type", *ELEMENT_TYPES[kind]}
    if unknown:
        raise MechanismError(f"{where}.{sorted(unknown)[0]}: unknown key for {_a(kind)}")
    stiffness = rate = 0.0
    free: float | None = 0.0
    if "stiffness" in ELEMENT_TYPES[kind]:
        if "stiffness" not in spec:
            raise MechanismError(f"{where}.stiffness: missing ({_a(kind)} needs its stiffness)")
        stiffness = _number(spec["stiffness"], f"{where}.stiffness", 0.0, " (a stiffness)")
    if "rate" in ELEMENT_TYPES[kind]:
        if "rate" not in spec:
            raise MechanismError(f"{where}.rate: missing ({_a(kind)} needs its rate)")
        rate = _number(spec["rate"], f"{where}.rate", 0.0, " (a damping rate)")
    if kind in LINE_TYPES:
        between = spec.get("between")
        if not isinstance(between, (list, tuple)) or len(between) != 2:
            raise MechanismError(f"{where}.between: must be a list of two points")
        (p1, on1), (p2, on2) = (
            _point(between[i], f"{where}.between[{i}]", m, centres) for i in range(2)
        )
        common = on1 & on2
        if common:
            raise MechanismError(
                f"{where}.between: both points belong to link {sorted(common)[0]!r} "
                "(their distance never changes)"
            )
        length = abs(p2.at - p1.at)
        if length == 0.0:
            raise MechanismError(
                f"{where}.between: the two points coincide in the reference configuration "
                "(the line of the force is not defined)"
            )
        if kind == "spring":
            free = (
                _number(spec["free_length"], f"{where}.free_length", 0.0)
                if "free_length" in spec
                else length
            )
        return Element(kind, where, (p1, p2), stiffness=stiffness, rate=rate, free=free)
    jid, pair = _joint_links(spec, where, m)
    joint_kind = m.joint(jid).kind
    slide = kind in ("elastic_slide", "slide_damper")
    if kind.startswith("torsion") and joint_kind != "R":
        raise MechanismError(
            f"{where}.joint: {_a(kind)} needs a revolute joint, {jid} is prismatic"
        )
    if slide and joint_kind != "P":
        raise MechanismError(
            f"{where}.joint: {_a(kind)} needs a prismatic joint, {jid} is revolute"
        )
    law = None
    expr = None
    arguments: tuple[str, ...] = ()
    if kind == "torsion_spring":
        free = _number(spec["free_angle"], f"{where}.free_angle") if "free_angle" in spec else None
    elif kind == "elastic_slide":
        free = _number(spec.get("free_length", 0.0), f"{where}.free_length")
    elif kind == "motor":
        if "law" not in spec:
            raise MechanismError(f"{where}.law: missing (a motor needs its law)")
        expr, law, arguments = _compiled(spec["law"], parameters, f"{where}.law")
    return Element(
        kind,
        where,
        joint=jid,
        links=pair,
        stiffness=stiffness,
        rate=rate,
        free=free,
        slide=joint_kind == "P",
        law=law,
        arguments=arguments,
        expr=expr,
    )


def _compiled(
    text: Any, parameters: Collection[str], where: str
) -> tuple[sympy.Expr, Callable[..., Any], tuple[str, ...]]:
    import sympy

    expr = parse_expression(text, parameters, where)
    used = tuple(sorted({s.name for s in expr.free_symbols} - {"q", "qdot"}))
    symbols = [sympy.Symbol(n, real=True) for n in ("q", "qdot", *used)]
    return expr, sympy.lambdify(symbols, expr, modules="numpy"), used
