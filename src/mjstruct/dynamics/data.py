"""Dynamics data of a mechanism file: inertia, gravity, parameters, loads, read and checked.

Owns the file keys ``inertia``, ``gravity``, ``parameters``, ``loads`` and
``energy_change`` (kept by the reader in :attr:`Mechanism.extra`; the ``elements``
are read by :mod:`mjstruct.dynamics.elements` and held here): their validation
(every error names its field) and the loads compiled to numpy functions of the
driver coordinate ``q``, the speed ``qdot`` and the parameters: read once per mechanism
object and kept until it is garbage-collected (:func:`read_dynamics`).

Examples
--------
>>> from mjstruct.io import mechanism_from_dict
>>> m = mechanism_from_dict({"frame": 0, "drivers": ["O1"], "joints": [
...     {"id": "O1", "links": [0, 1], "at": [0, 0]},
...     {"id": "A", "links": [1, 2], "at": [1, 0]},
...     {"id": "B", "links": [2, 3], "at": [3, 0]},
...     {"id": "P", "links": [0, 3], "type": "P", "at": [3, 0], "axis": [1, 0]}],
...     "inertia": {"1": {"mass": 1.0}, "3": {"mass": 0.5}},
...     "parameters": {"M": 10, "p": None},
...     "loads": [{"link": "1", "moment": "-M"}, {"link": "3", "force": ["p", 0]}]})
>>> d = read_dynamics(m)
>>> d.unknown, d.inertia["1"].com, d.inertia["2"].mass
('p', (0.5+0j), 0.0)
>>> float(d.loads[0].evaluate(0.0, 0.0, d.parameter_values(p=0.0))[2])
-10.0
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.elements import Element, read_elements
from mjstruct.dynamics.expressions import parse_expression, reserved_names, switch_functions
from mjstruct.errors import MechanismError
from mjstruct.kinematics.geometry import diameter
from mjstruct.kinematics.tolerances import COINCIDE
from mjstruct.mechanism import Mechanism

if TYPE_CHECKING:
    import sympy

    from mjstruct.kinematics.geometry import Geometry

FloatArray = npt.NDArray[np.float64]

#: the file keys this module reads
KEYS = ("inertia", "gravity", "parameters", "loads", "energy_change", "elements")

#: the largest characteristic load, inertia or kinetic energy a run may start from: a
#: double reaches 1.8e308, the rest is the margin for sums over the links, analogs near
#: singular positions and the conditioning of the link equations
MAGNITUDE_LIMIT = 1e250

#: farthest a centre of mass or a load's point may lie from its link's joints, in
#: mechanism sizes: the condition number of the link equations grows with the square
#: of this lever (about 4e12 at 1e6; at 1e15 no digit of the joint loads is left)
MAX_LEVER = 1e6


@dataclass(frozen=True)
class LinkInertia:
    """Mass, central moment of inertia and reference centre of mass of a moving link."""

    mass: float
    J: float
    com: complex


@dataclass(frozen=True)
class Load:
    """An active load on a link: a force ``[Fx, Fy]`` at a point, or a couple.

    Attributes
    ----------
    link : the loaded (moving) link.
    kind : ``"force"`` or ``"moment"``.
    at : the point of application in the reference configuration (forces).
    exprs : the sympy expression of each component (two for a force, one for a couple).
    where : the field that defined it (``"loads[3]"``), for messages.
    functions : the components compiled to numpy functions of ``q``, ``qdot`` and the
        ``arguments`` (the parameters the load uses, in order).
    bound : the largest magnitude a component may take (:data:`MAGNITUDE_LIMIT`, for a
        force divided by the reach of its point): beyond it the loads' work and the
        reactions would overflow a double.
    """

    link: str
    kind: str
    at: complex
    exprs: tuple[Any, ...]
    where: str
    functions: tuple[Callable[..., Any], ...]
    arguments: tuple[str, ...]
    bound: float = MAGNITUDE_LIMIT

    def evaluate(
        self, q: npt.ArrayLike, qdot: npt.ArrayLike, parameters: Mapping[str, float]
    ) -> FloatArray:
        """Components ``(Fx, Fy, M)`` over the frames (a force has M = 0, a couple F = 0)."""
        qa = np.asarray(q, float)
        qd = np.broadcast_to(np.asarray(qdot, float), qa.shape)
        args = [parameters[a] for a in self.arguments]
        vals = []
        with np.errstate(all="ignore"):
            for f in self.functions:
                try:
                    raw = np.asarray(f(qa, qd, *args))
                    if np.iscomplexobj(raw):  # a negative number to a fractional power
                        raw = np.where(raw.imag == 0, raw.real, np.nan)
                    v = np.broadcast_to(raw.astype(float), qa.shape)
                except (ArithmeticError, ValueError, TypeError):
                    # an integer too large for a double, a domain error of the math
                    # module: no value here (named below like any non-finite value)
                    v = np.full(qa.shape, np.nan)
                vals.append(v)
        zero = np.zeros(qa.shape)
        out = np.stack([vals[0], vals[1], zero] if self.kind == "force" else [zero, zero, vals[0]])
        if not np.isfinite(out).all():
            bad = np.argmax(~np.isfinite(out).all(axis=0)) if qa.ndim else 0
            qb = float(qa.reshape(-1)[bad]) if qa.size else float("nan")
            raise MechanismError(f"{self.where}: the load is not finite at q = {qb:.9g}")
        size = np.abs(out).max(axis=0) if out.size else out
        if (size > self.bound).any():
            bad = np.argmax(size > self.bound) if qa.ndim else 0
            qb = float(qa.reshape(-1)[bad])
            raise MechanismError(
                f"{self.where}: the load reaches {float(size.reshape(-1)[bad]):.3g} at q = "
                f"{qb:.9g}, more than {self.bound:.3g} (its work and the joint loads would "
                "overflow a double)"
            )
        return out

    @property
    def uses_qdot(self) -> bool:
        """Whether the load depends on the speed ``qdot``."""
        return any("qdot" in {s.name for s in e.free_symbols} for e in self.exprs)

    @cached_property
    def switches(self) -> tuple[Callable[..., Any], ...]:
        """Functions g(q) whose sign changes are the load's jumps (compiled once).

        See :func:`~mjstruct.dynamics.expressions.switch_functions`.
        """
        import sympy

        q = sympy.Symbol("q", real=True)
        return tuple(
            sympy.lambdify([q], g, modules="numpy")
            for e in self.exprs
            for g in switch_functions(e)
        )

    def is_affine_in(self, name: str) -> bool:
        """Whether every component is affine in the parameter ``name`` (decided once)."""
        if name not in self._affine:
            import sympy

            p = sympy.Symbol(name, real=True)
            self._affine[name] = all(
                sympy.diff(e, p).free_symbols.isdisjoint({p}) for e in self.exprs
            )
        return self._affine[name]

    @cached_property
    def _affine(self) -> dict[str, bool]:
        return {}

    def slope(self, name: str) -> Load:
        """The load's rate of change in the parameter ``name``, as a load (compiled once).

        What one unit of an unknown that enters affinely adds to the load, computed
        without subtracting two values of the load (whose difference would lose the
        digits of everything else in it); unbounded (it is not a load applied).
        """
        if name not in self._slopes:
            import sympy

            p = sympy.Symbol(name, real=True)
            exprs = tuple(sympy.diff(e, p) for e in self.exprs)
            used = sorted({s.name for e in exprs for s in e.free_symbols} - {"q", "qdot"})
            symbols = [sympy.Symbol(n, real=True) for n in ("q", "qdot", *used)]
            functions = tuple(
                _constant(float(e))  # a load linear in the parameter: nothing to compile
                if not e.free_symbols
                else sympy.lambdify(symbols, e, modules="numpy")
                for e in exprs
            )
            self._slopes[name] = Load(
                self.link, self.kind, self.at, exprs, self.where, functions, tuple(used), math.inf
            )
        return self._slopes[name]

    @cached_property
    def _slopes(self) -> dict[str, Load]:
        return {}

    @cached_property
    def jumps(self) -> dict[tuple[float, float, float], tuple[float, ...]]:
        """Where the load jumps along a path: (q_ref, direction, period) -> path
        parameters (filled by :meth:`~mjstruct.dynamics.equation.PathForce.switches`)."""
        return {}


def _constant(value: float) -> Callable[..., float]:
    """A load function that is the number ``value`` whatever its arguments."""

    def f(*args: Any) -> float:
        return value

    return f


@dataclass(frozen=True)
class DynamicsData:
    """The dynamics keys of a mechanism file, checked.

    Attributes
    ----------
    inertia : every moving link -> its :class:`LinkInertia` (massless when not listed).
    gravity : the acceleration of gravity as ``gx + i gy``.
    parameters : name -> value (``None`` for the unknown).
    unknown : the parameter that steady motion fixes, or ``None``.
    loads : the active loads.
    energy_change : the cycle work of all loads that steady motion must give.
    size : the mechanism's size (largest distance between two joint centres).
    inertia_scale : Σ (m R² + J) over the links, R the reach of a link's centre of
        mass (the size plus its distance from the link's farthest joint): the reduced
        inertia's order of magnitude.
    mass_reach : Σ m R (the inertia forces' order of magnitude per unit speed²).
    lever, lever_field : the largest distance of a centre of mass or a load's point
        from its link's joints, in mechanism sizes, and the field that sets it.
    elements : the force elements (springs, dampers, elastic slides, motors; see
        :mod:`mjstruct.dynamics.elements`).
    """

    inertia: dict[str, LinkInertia]
    gravity: complex
    parameters: dict[str, float | None]
    unknown: str | None
    loads: tuple[Load, ...]
    energy_change: float
    size: float = 1.0
    inertia_scale: float = 0.0
    mass_reach: float = 0.0
    lever: float = 0.0
    lever_field: str = ""
    elements: tuple[Element, ...] = ()

    def check_speed(self, name: str, speed: float | None) -> None:
        """Refuse a driver speed whose accelerations, kinetic energy or inertia forces
        would pass :data:`MAGNITUDE_LIMIT` (the message names ``name``)."""
        if speed is None or not math.isfinite(speed):
            return  # the callers refuse what is not a finite number
        w2 = speed * speed  # finite: |speed| <= 1.8e308 squares to at most inf
        for what, scale in (
            ("the accelerations (W² × size)", self.size),
            ("the kinetic energy (W² × Σ (m R² + J))", self.inertia_scale),
            ("the inertia forces (W² × Σ m R)", self.mass_reach),
        ):
            if w2 * scale > MAGNITUDE_LIMIT:
                raise MechanismError(
                    f"{name}: {speed:g} overflows {what}: {_magnitude(w2 * scale)} "
                    f"(at most {MAGNITUDE_LIMIT:.0e})"
                )

    def with_parameters(self, given: Mapping[str, float] | None) -> DynamicsData:
        """These data with parameter values ``given`` (the unknown too, then known).

        Raises
        ------
        MechanismError
            naming ``parameters``: a name that is not a parameter of the file, a value
            that is not a finite number.
        """
        if not given:
            return self
        values: dict[str, float] = {}
        for name, value in given.items():
            if name not in self.parameters:
                raise MechanismError(f"parameters: {name!r} is not a parameter of the file")
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, float, np.integer, np.floating))
                or not np.isfinite(value)
            ):
                raise MechanismError(f"parameters: {name!r} must be a finite number")
            values[name] = float(value)
        return DynamicsData(
            self.inertia,
            self.gravity,
            {**self.parameters, **values},
            None if self.unknown in values else self.unknown,
            self.loads,
            self.energy_change,
            self.size,
            self.inertia_scale,
            self.mass_reach,
            self.lever,
            self.lever_field,
            self.elements,
        )

    def parameter_values(self, **given: float) -> dict[str, float]:
        """All parameters as numbers, the unknown taken from ``given``."""
        out = {k: v for k, v in self.parameters.items() if v is not None}
        out.update(given)
        missing = [k for k in self.parameters if k not in out]
        if missing:
            raise MechanismError(f"parameters: {missing[0]!r} has no value")
        return out

    @property
    def uses_qdot(self) -> bool:
        """Whether some load depends on the speed."""
        return any(load.uses_qdot for load in self.loads)

    def is_linear_in_unknown(self) -> bool:
        """Whether every load is affine in the unknown parameter."""
        if self.unknown is None:
            return True
        return all(ld.is_affine_in(self.unknown) for ld in self.loads)


def _number(value: Any, where: str, minimum: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise MechanismError(f"{where}: must be a number")
    x = float(value)
    if not math.isfinite(x):
        raise MechanismError(f"{where}: must be finite")
    if minimum is not None and x < minimum:
        raise MechanismError(f"{where}: must be >= {minimum:g}, got {x:g}")
    return x


def _xy(value: Any, where: str) -> complex:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise MechanismError(f"{where}: must be a list [x, y]")
    return complex(_number(value[0], f"{where}[0]"), _number(value[1], f"{where}[1]"))


def _link(value: Any, m: Mechanism, where: str) -> str:
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise MechanismError(f"{where}: must be a link id")
    link = str(value)
    if link not in m.links:
        raise MechanismError(f"{where}: unknown link {link!r}")
    if link == m.frame:
        raise MechanismError(f"{where}: link {link!r} is the frame (it does not move)")
    return link


def centroid(m: Mechanism, link: str, centres: Mapping[str, complex], size: float) -> complex:
    """The centroid of a link's distinct joint centres (reference configuration).

    Centres closer than the kinematics' ``COINCIDE`` × ``size`` (the mechanism's size)
    count once, at any scale.
    """
    tol = COINCIDE * size
    pts: list[complex] = []
    for jid in m.link_joints[link]:
        z = centres[jid]
        if all(abs(z - p) > tol for p in pts):
            pts.append(z)
    return sum(pts, 0j) / len(pts)


def _joint_centres(m: Mechanism) -> dict[str, complex]:
    """Every joint centre, for a mechanism whose geometry nobody has read yet."""
    if m.frame is None:
        raise MechanismError("frame: dynamics needs a frame link")
    for k, j in enumerate(m.joints):
        if j.at is None:
            raise MechanismError(
                f"joints[{k}].at: missing for joint {j.id!r} (dynamics needs the geometry)"
            )
    return {j.id: complex(*j.at) for j in m.joints if j.at is not None}


#: read dynamics data per mechanism: id -> (a weak reference to it, its data)
_READ: dict[int, tuple[weakref.ref[Mechanism], DynamicsData]] = {}


def read_dynamics(m: Mechanism, geometry: Geometry | None = None) -> DynamicsData:
    """Read and check the dynamics keys of ``m`` (see the module docstring).

    ``geometry``: the mechanism's geometry when already read and checked (the default
    centres of mass are taken from it; without it the joint centres are checked here).

    The data are read once per mechanism object: parsing and compiling the loads
    (sympy's ``lambdify``) costs milliseconds, and a mechanism is immutable (its
    ``extra`` keys included: to change a load, build a new mechanism).  The entry is
    dropped when the mechanism is garbage-collected; data that fail their checks are
    not kept.

    Raises
    ------
    MechanismError
        naming the field: a negative mass or moment of inertia, a load on an unknown
        link or on the frame, an unparsable expression, an unknown symbol, two
        unknown parameters, a key of the wrong type.
    """
    key = id(m)
    hit = _READ.get(key)
    if hit is not None and hit[0]() is m:
        return hit[1]
    data = _read(m, geometry)

    def forget(ref: weakref.ref[Mechanism]) -> None:
        if _READ.get(key, (None,))[0] is ref:
            del _READ[key]

    _READ[key] = (weakref.ref(m, forget), data)
    return data


def _read(m: Mechanism, geometry: Geometry | None) -> DynamicsData:
    centres = _joint_centres(m) if geometry is None else geometry.centres
    extra = m.extra
    moving = [link for link in m.links if link != m.frame]
    size = geometry.scale if geometry is not None else diameter(list(centres.values()))
    if not size > 0:
        raise MechanismError("joints.at: all joint centres coincide; the mechanism has no size")

    raw_inertia = extra.get("inertia", {})
    if not isinstance(raw_inertia, Mapping):
        raise MechanismError("inertia: must be an object {link: {mass, J, com}}")
    inertia: dict[str, LinkInertia] = {}
    for key, spec in raw_inertia.items():
        link = _link(key, m, f"inertia.{key}")
        where = f"inertia.{link}"
        if not isinstance(spec, Mapping):
            raise MechanismError(f"{where}: must be an object with 'mass'")
        unknown_keys = set(spec) - {"mass", "J", "com"}
        if unknown_keys:
            raise MechanismError(f"{where}.{sorted(unknown_keys)[0]}: unknown key")
        if "mass" not in spec:
            raise MechanismError(f"{where}.mass: missing")
        mass = _number(spec["mass"], f"{where}.mass", 0.0)
        J = _number(spec.get("J", 0.0), f"{where}.J", 0.0)
        com = (
            _xy(spec["com"], f"{where}.com") if "com" in spec else centroid(m, link, centres, size)
        )
        inertia[link] = LinkInertia(mass, J, com)
    for link in moving:
        if link not in inertia:
            inertia[link] = LinkInertia(0.0, 0.0, centroid(m, link, centres, size))

    raw_g = extra.get("gravity", [0.0, 0.0])
    gravity = _xy(raw_g, "gravity")
    reach = _Reach(m, centres, size)
    inertia_scale, mass_reach = reach.check_inertia(inertia, raw_inertia, gravity)

    raw_params = extra.get("parameters", {})
    if not isinstance(raw_params, Mapping):
        raise MechanismError("parameters: must be an object {name: number or null}")
    parameters: dict[str, float | None] = {}
    reserved = reserved_names()
    for name, value in raw_params.items():
        where = f"parameters.{name}"
        if not isinstance(name, str) or not name.isidentifier() or name.startswith("_"):
            raise MechanismError(f"{where}: a parameter name must be an identifier")
        if name in reserved:
            raise MechanismError(
                f"{where}: {name!r} is reserved (a variable, constant or function)"
            )
        parameters[name] = None if value is None else _number(value, where)
    unknowns = [k for k, v in parameters.items() if v is None]
    if len(unknowns) > 1:
        raise MechanismError(
            f"parameters: two unknown parameters ({unknowns[0]!r}, {unknowns[1]!r}); "
            "at most one may be null"
        )

    energy_change = _number(extra.get("energy_change", 0.0), "energy_change")

    raw_loads = extra.get("loads", [])
    if not isinstance(raw_loads, list):
        raise MechanismError("loads: must be a list")
    loads = tuple(
        _read_load(spec, k, m, inertia, list(parameters), reach)
        for k, spec in enumerate(raw_loads)
    )
    elements = read_elements(m, centres, list(parameters), MAGNITUDE_LIMIT, MAX_LEVER)
    used = {s.name for ld in loads for e in ld.exprs for s in e.free_symbols}
    used |= {a for el in elements for a in el.arguments}
    if unknowns and unknowns[0] not in used:
        raise MechanismError(f"parameters.{unknowns[0]}: the unknown appears in no load")
    return DynamicsData(
        inertia=inertia,
        gravity=gravity,
        parameters=parameters,
        unknown=unknowns[0] if unknowns else None,
        loads=loads,
        energy_change=energy_change,
        size=size,
        inertia_scale=inertia_scale,
        mass_reach=mass_reach,
        lever=reach.lever,
        lever_field=reach.lever_field,
        elements=elements,
    )


def _magnitude(x: float) -> str:
    """``x`` for a message, an overflow said as such."""
    return f"{x:.3g}" if math.isfinite(x) else "more than 1.8e308"


class _Reach:
    """How far the points of each link lie from its joints, and the overflow checks."""

    def __init__(self, m: Mechanism, centres: Mapping[str, complex], size: float) -> None:
        self.m, self.centres, self.size = m, centres, size
        self.lever, self.lever_field = 0.0, ""

    def __call__(self, link: str, z: complex, field: str) -> float:
        """The size plus the distance of ``z`` from the link's farthest joint centre.

        Raises
        ------
        MechanismError
            naming ``field`` when that distance is more than :data:`MAX_LEVER` sizes.
        """
        arm = max(abs(z - self.centres[j]) for j in self.m.link_joints[link])
        lever = arm / self.size
        if not lever <= MAX_LEVER:
            raise MechanismError(
                f"{field}: {_magnitude(lever)} × the mechanism's size from the joints of "
                f"link {link} (at most {MAX_LEVER:.0e}: the link equations' condition "
                "grows with its square)"
            )
        if lever > self.lever:
            self.lever, self.lever_field = lever, field
        return self.size + arm

    def check_inertia(
        self,
        inertia: Mapping[str, LinkInertia],
        given: Mapping[str, Any],
        gravity: complex,
    ) -> tuple[float, float]:
        """``(Σ (m R² + J), Σ m R)``; refuse a link whose inertia or weight overflows.

        Raises
        ------
        MechanismError
            naming ``inertia.<link>.J``, ``.com``, ``.mass`` or ``gravity`` when
            ``m R² + J``, or ``m |g| R``, passes :data:`MAGNITUDE_LIMIT`.
        """
        scale = weight = 0.0
        for link, li in inertia.items():
            where = f"inertia.{link}"
            R = self(link, li.com, f"{where}.com")
            spec = given.get(link, {}) if isinstance(given, Mapping) else {}
            if li.J > MAGNITUDE_LIMIT:
                raise MechanismError(f"{where}.J: {li.J:g} is more than {MAGNITUDE_LIMIT:.0e}")
            with np.errstate(all="ignore"):
                term = li.mass * R * R + li.J
                load = li.mass * abs(gravity) * R
            if not term <= MAGNITUDE_LIMIT:
                arm = R - self.size
                if R * R <= MAGNITUDE_LIMIT:
                    field = f"{where}.mass"
                elif "com" in spec and arm > self.size:
                    field = f"{where}.com"
                else:
                    field = "joints"  # the mechanism itself is that large
                raise MechanismError(
                    f"{field}: the link's inertia m R² + J reaches {_magnitude(term)} (at most "
                    f"{MAGNITUDE_LIMIT:.0e}; R = {R:.3g}, the reach of its centre of mass)"
                )
            if not load <= MAGNITUDE_LIMIT:
                raise MechanismError(
                    f"gravity: the weight of link {link} and its moment m |g| R reach "
                    f"{_magnitude(load)} (at most {MAGNITUDE_LIMIT:.0e})"
                )
            scale += term
            weight += li.mass * R
        return scale, weight


def _read_load(
    spec: Any,
    k: int,
    m: Mechanism,
    inertia: Mapping[str, LinkInertia],
    params: list[str],
    reach: _Reach,
) -> Load:
    import sympy

    where = f"loads[{k}]"
    if not isinstance(spec, Mapping):
        raise MechanismError(f"{where}: must be an object with 'link' and 'force' or 'moment'")
    unknown_keys = set(spec) - {"link", "force", "moment", "at"}
    if unknown_keys:
        raise MechanismError(f"{where}.{sorted(unknown_keys)[0]}: unknown key")
    if "link" not in spec:
        raise MechanismError(f"{where}.link: missing")
    link = _link(spec["link"], m, f"{where}.link")
    if ("force" in spec) == ("moment" in spec):
        raise MechanismError(f"{where}: give exactly one of 'force' and 'moment'")
    exprs: list[sympy.Expr]
    if "force" in spec:
        raw = spec["force"]
        if not isinstance(raw, (list, tuple)) or len(raw) != 2:
            raise MechanismError(f"{where}.force: must be a list [Fx, Fy]")
        exprs = [parse_expression(raw[i], params, f"{where}.force[{i}]") for i in range(2)]
        at = _xy(spec["at"], f"{where}.at") if "at" in spec else inertia[link].com
        kind = "force"
        R = reach(link, at, f"{where}.at")
        if not R * R <= MAGNITUDE_LIMIT:
            raise MechanismError(
                f"{where}.at: the point is {R:.3g} from the link's joints (its moment "
                f"would overflow: at most {MAGNITUDE_LIMIT**0.5:.0e})"
            )
        bound = MAGNITUDE_LIMIT / R
    else:
        if "at" in spec:
            raise MechanismError(f"{where}.at: a couple has no point of application")
        exprs = [parse_expression(spec["moment"], params, f"{where}.moment")]
        at = inertia[link].com
        kind = "moment"
        bound = MAGNITUDE_LIMIT
    used = sorted({s.name for e in exprs for s in e.free_symbols} - {"q", "qdot"})
    symbols = [sympy.Symbol(n, real=True) for n in ("q", "qdot", *used)]
    functions = tuple(sympy.lambdify(symbols, e, modules="numpy") for e in exprs)
    return Load(link, kind, at, tuple(exprs), where, functions, tuple(used), bound)
