"""Singular positions of a one-DOF linkage: input limits, output extremes, change points.

Owns the analysis behind ``mjstruct singular``: along every branch of the
configuration curve through the reference (continued through change points, traced
by :mod:`mjstruct.singular.curve`) it finds

* **input limits**: the Jacobian minor without the input column vanishes (the input
  stops and reverses; four-bar: coupler in line with the output),
* **output extremes**: the minor without the output column vanishes (the output
  reverses; four-bar: input in line with the coupler),
* **change points**: the whole Jacobian loses rank (branches cross; four-bar: all
  four centres in line),

each located by root refinement (Brent's method on the tangent's input or output
component; a Gauss-Newton system for change points), with the joints in line there,
the clearance zone of each collinear pair, the input's range and, for a four-bar,
the closed-form theory of :mod:`mjstruct.singular.fourbar`.  A branch along which
a minor vanishes identically (a joint sitting on another over a range: MS2's dwell,
MS5's locked input) is a fold arc, named in the warnings.

References
----------
.. [1] Singular positions and synthesis of hinged multi-joint mechanisms with
   clearances in their revolute pairs (in Russian; eLibrary document code EDN PBGDPR;
   authors, exact title, journal and year not given in the available copy).
   [Four-bar clearances] in docs/references.md.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> r = singular_analysis(read_mechanism(example_path("fourbar-ms4")))
>>> [(p.kind, round(float(np.degrees(p.q)), 6)) for p in r.singular]
[('output_extreme', 70.528779), ('output_extreme', 289.471221), ('change_point', 360.0)]
>>> r.fourbar.motion, round(float(np.degrees(r.fourbar.swing)), 2)
('crank-rocker', 141.06)
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.jacobian import one_blas_thread
from mjstruct.kinematics.tolerances import (
    AT_CHANGE_POINT,
    COINCIDE_ALONG,
    COLLINEAR_TOL,
    DISPLAY_ZERO,
    FOLD_TOL,
    FULL_TURN_SLACK,
    MAX_CLEARANCE,
    NEAR_CHANGE_POINT,
    Q_TOUCH,
    ROOT_ABS,
    ROOT_AT_STATION,
    SAME_POINT,
    TURNS,
)
from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.output_numbers import json_number
from mjstruct.singular.classification import (
    SingularClass,
    classify_fold_arc,
    classify_position,
    fold_arc_theta,
    singular_group_class,
    theta_of_zones,
    theta_without_pair,
)
from mjstruct.singular.clearance import exact_zone, formula3, leading_order_zone
from mjstruct.singular.curve import (
    MAX_STEP,
    Bifurcation,
    Branch,
    ClosureEquations,
    correct_many,
    point_on_step,
    tangents,
    trace_component,
    wrap_delta,
)
from mjstruct.singular.fourbar import TIE, FourBar, fourbar_theory
from mjstruct.structure.mobility import dof_grubler
from mjstruct.typing import FloatArray

if TYPE_CHECKING:
    from mjstruct.kinematics.result import KinematicsResult

KINDS = ("input_limit", "output_extreme", "change_point")


@dataclass(frozen=True)
class Zone:
    """Clearance zone of one collinear pair at a singular position.

    Attributes
    ----------
    pair : the two moving links in line.
    link : the longer link of the pair, whose turn about its pivot is ``psi``.
    psi : zone angle (rad): formula (3) for a four-bar, else the leading order.
    method : ``"formula-3"`` or ``"leading-order"``.
    psi_exact : the feasibility search's angle (only when asked for; ``None`` when
        the search found no placement, the warnings say why).
    lam, delta : formula (3)'s ``lambda = r / l`` (shorter over longer link of the
        pair) and ``delta = D / l`` (total clearance over the longer link); ``None``
        for a leading-order zone, which does not use them.
    exact_sought : the feasibility search was asked for (the JSON then has
        ``psi_exact``, null when it was not found).
    """

    pair: tuple[str, str]
    link: str
    psi: float | None
    method: str
    psi_exact: float | None = None
    lam: float | None = None
    delta: float | None = None
    exact_sought: bool = False

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "pair": list(self.pair),
            "link": self.link,
            "psi": json_number(self.psi),
            "method": self.method,
            "lambda": json_number(self.lam),
            "delta": json_number(self.delta),
        }
        if self.exact_sought or self.psi_exact is not None:
            d["psi_exact"] = json_number(self.psi_exact)  # null: not found (warnings say why)
        return d


@dataclass(frozen=True)
class SingularPosition:
    """One singular position on the configuration curve.

    Attributes
    ----------
    kind : ``input_limit``, ``output_extreme`` or ``change_point``.
    q : driver coordinate (revolute: in [q_ref, q_ref + 2 pi)).
    output_angle : the output link's angle (rad, in (-pi, pi]).
    collinear : ids of the joints in line (file order).
    pairs : pairs of moving links in line with their shared joint.
    zone : clearance zones, one per collinear pair of moving links (empty when no
        two are in line, e.g. a class-III group's input limit; ``None`` without a
        clearance).
    configuration : the link coordinates there (``x, y, phi`` of each moving link,
        lengths over the mechanism's size), as
        :class:`~mjstruct.singular.curve.ClosureEquations` numbers them.
    classification : its type and trap of [Four-bar clearances]
        (:mod:`mjstruct.singular.classification`).
    """

    kind: str
    q: float
    output_angle: float
    collinear: tuple[str, ...]
    pairs: tuple[tuple[str, str], ...]
    zone: tuple[Zone, ...] | None = None
    configuration: tuple[float, ...] = field(default=(), repr=False, compare=False)
    classification: SingularClass | None = field(default=None, compare=False)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "kind": self.kind,
            "q": json_number(self.q),
            "output_angle": json_number(self.output_angle),
            "collinear": list(self.collinear),
        }
        if self.zone is not None:
            d["zone"] = [z.to_dict() for z in self.zone]
        d["classification"] = (
            None if self.classification is None else self.classification.to_dict()
        )
        return d


@dataclass(frozen=True)
class FoldArc:
    """A stretch of a branch along which a minor vanishes identically (a fold arc).

    Attributes
    ----------
    kind : ``output_extreme`` (the output dwells while the input moves: MS2) or
        ``input_limit`` (the input is locked while the rest moves: MS5).
    q_from, q_to : the input's range over the arc (equal for a locked input), cut at
        the change points on the branch, where the linkage can enter or leave it;
        ``q_from`` in [q_ref, q_ref + 2 pi) for a revolute driver, ``q_to >= q_from``.
    joints : ids of the joints that sit on another along the arc (file order).
    output_angle : the dwell angle of the output (``None`` for a locked input).
    classification : its type and trap of [Four-bar clearances] (III/C or IV/D).
    """

    kind: str
    q_from: float
    q_to: float
    joints: tuple[str, ...]
    output_angle: float | None
    classification: SingularClass | None = field(default=None, compare=False)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "kind": self.kind,
            "q_from": json_number(self.q_from),
            "q_to": json_number(self.q_to),
            "joints": list(self.joints),
            "output_angle": json_number(self.output_angle),
        }
        d["classification"] = (
            None if self.classification is None else self.classification.to_dict()
        )
        return d


@dataclass(frozen=True)
class InputRange:
    """Where the input can be: a full turn, or increasing ``[q_from, q_to]`` intervals."""

    full_turn: bool
    intervals: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class SingularAnalysis:
    """Result of :func:`singular_analysis` (the ``mjstruct singular`` JSON object)."""

    input: str
    output: str
    singular: tuple[SingularPosition, ...]
    input_range: InputRange
    fourbar: FourBar | None
    warnings: tuple[str, ...]
    clearance: float | None
    branches: int
    revolute: bool = True
    fourbar_output: str | None = None
    fold_arcs: tuple[FoldArc, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The contract's JSON object (no NaN: missing numbers are null)."""
        fb: dict[str, Any] | None = None
        if self.fourbar is not None:
            f = self.fourbar
            fb = {
                "MS": [json_number(p) for p in f.MS],
                "grashof": f.grashof,
                "motion": f.motion,
                "system4": list(f.system4),
                "swing": json_number(f.swing),
                "time_ratio": json_number(f.time_ratio),
                "output_link": self.fourbar_output,
            }
        return {
            "input": self.input,
            "output": self.output,
            "singular": [p.to_dict() for p in self.singular],
            "input_range": {
                "full_turn": self.input_range.full_turn,
                "intervals": [
                    [json_number(a), json_number(b)] for a, b in self.input_range.intervals
                ],
            },
            "fourbar": fb,
            "fold_arcs": [a.to_dict() for a in self.fold_arcs],
            "clearance": json_number(self.clearance),
            "warnings": list(self.warnings),
        }


def dof(m: Mechanism) -> int:
    """Grübler's count 3(n - 1) - 2 sum(multiplicity) (R and P joints alike)."""
    return dof_grubler(len(m.links), sum(j.multiplicity for j in m.joints))


def _is_fourbar(m: Mechanism) -> bool:
    return (
        len(m.links) == 4
        and len(m.joints) == 4
        and all(j.kind == "R" and len(j.links) == 2 for j in m.joints)
    )


def fourbar_links(m: Mechanism, eq: ClosureEquations) -> tuple[str, str, str] | None:
    """(input, coupler, output) link ids of a four-bar driven at a frame joint, else
    ``None``; the output here is the link hinged to the frame at the other frame joint
    (the one the closed-form theory's ``P3``, swing and time ratio describe)."""
    if not _is_fourbar(m) or m.frame not in m.joint(eq.driver).links:
        return None
    d = m.joint(eq.driver)
    inp = next(x for x in d.links if x != m.frame)
    other = next(j for j in m.joints if j.id != d.id and m.frame in j.links)
    out = next(x for x in other.links if x != m.frame)
    coupler = next(x for x in m.links if x not in (m.frame, inp, out))
    return inp, coupler, out


def fourbar_lengths(
    m: Mechanism, eq: ClosureEquations
) -> tuple[float, float, float, float] | None:
    """(l0, l1, l2, l3) of a four-bar driven at a frame joint, else ``None``."""
    links = fourbar_links(m, eq)
    if links is None:
        return None
    inp, coupler, out = links
    d = m.joint(eq.driver)
    other = next(j for j in m.joints if j.id != d.id and m.frame in j.links)
    A = next(j.id for j in m.joints if set(j.links) == {inp, coupler})
    B = next(j.id for j in m.joints if set(j.links) == {coupler, out})
    c = eq.geometry.centres
    return (
        abs(c[other.id] - c[d.id]),
        abs(c[A] - c[d.id]),
        abs(c[B] - c[A]),
        abs(c[other.id] - c[B]),
    )


def _collinear(
    eq: ClosureEquations, x: FloatArray
) -> tuple[tuple[str, ...], list[tuple[str, str, str, str, str]]]:
    """Joints in line at ``x``, and (link a, link b, joint, joint on a, joint on b) triples."""
    m = eq.mechanism
    pos = {j.id: eq.joint_position(x, j.id) for j in m.joints}
    found: set[str] = set()
    triples: list[tuple[str, str, str, str, str]] = []
    for j in m.joints:
        if j.kind != "R":
            continue
        for i, a in enumerate(j.links):
            for b in j.links[i + 1 :]:
                for ja in m.link_joints[a]:
                    for jb in m.link_joints[b]:
                        if j.id in (ja, jb) or ja == jb:
                            continue
                        if m.joint(ja).kind != "R" or m.joint(jb).kind != "R":
                            continue
                        u, v = pos[ja] - pos[j.id], pos[jb] - pos[j.id]
                        den = abs(u) * abs(v)
                        if den == 0 or abs((u.conjugate() * v).imag) <= COLLINEAR_TOL * den:
                            found |= {j.id, ja, jb}
                            triples.append((a, b, j.id, ja, jb))
    return tuple(jj.id for jj in m.joints if jj.id in found), triples


def singular_analysis(
    mechanism: Mechanism,
    output: str | None = None,
    clearance: float | None = None,
    exact: bool = False,
) -> SingularAnalysis:
    """Singular positions of a one-DOF linkage on the curve through its reference.

    Parameters
    ----------
    mechanism : one driver, F = 1, every joint with ``at`` (and ``axis`` for sliders).
    output : the output link (default: the link of the last frame joint that is not
        the driver).
    clearance : total radial clearance of the pins (length unit of the file); adds
        a zone to every singular position.
    exact : also run the feasibility search for every zone (slower).

    Raises
    ------
    MechanismError
        F != 1, not one driver, an unknown output link, a negative clearance, a
        linkage that cannot move from its reference configuration.
    NumericalError
        the curve could not be traced.
    """
    expect_mechanism(mechanism, "mechanism")
    m = mechanism
    if m.extra.get("gears"):
        raise MechanismError("gears: singular positions of geared mechanisms are not analysed yet")
    F = dof(m)
    if F != 1:
        raise MechanismError(f"mechanism: singular positions need F = 1, this one has F = {F}")
    if len(m.drivers) != 1:
        raise MechanismError(
            f"drivers: singular positions need exactly one driver, got {len(m.drivers)}"
        )
    if output is not None:
        output = str(output)
        if output not in m.links:
            raise MechanismError(f"output: {output!r} is not a link of the mechanism")
        if output == m.frame:
            raise MechanismError(f"output: {output!r} is the frame")
    if clearance is not None and not (math.isfinite(clearance) and clearance >= 0):
        raise MechanismError(f"clearance: must be a finite number >= 0, got {clearance}")
    if clearance is not None and clearance > MAX_CLEARANCE:
        raise MechanismError(f"clearance: {clearance:g} is too large (at most {MAX_CLEARANCE:g})")
    # many tiny and batched small factorisations: a threaded BLAS only adds wake-ups
    # (under load, 4-20 times the time of the analysis itself)
    with one_blas_thread():
        return _analyse(m, output, clearance, exact)


def _analyse(
    m: Mechanism, output: str | None, clearance: float | None, exact: bool
) -> SingularAnalysis:
    """The analysis behind :func:`singular_analysis` (arguments checked there)."""
    driver = m.drivers[0]
    eq = ClosureEquations.build(m, driver, output)
    lengths = fourbar_lengths(m, eq)
    fb = None
    if lengths is not None:
        l0, l1, l2, l3 = lengths
        longest = max(lengths)
        if longest >= sum(lengths) - longest - TIE * longest:
            raise MechanismError(
                "joints.at: the four-bar cannot move from its reference configuration (its "
                "longest link equals the other three together)"
            )
        fb = fourbar_theory(l1 / l0, l2 / l0, l3 / l0)
    branches, bifs = trace_component(eq, eq.reference())
    warnings: list[str] = [] if fb is None else list(fb.notes)
    fb_links = fourbar_links(m, eq) if fb is not None else None
    fb_out = None if fb_links is None else fb_links[2]
    if fb_out is not None and fb_out != eq.output_link:
        warnings.append(
            f"fourbar: swing and time_ratio are those of link {fb_out} (the output hinged "
            f"to the frame), not of the chosen output link {eq.output_link}"
        )
    rows = eq.jacobian(eq.reference()).shape[0]
    if rows != eq.n - 1:
        warnings.append(
            f"redundant constraints ({rows} equations for {eq.n - 1}): change points are "
            "not searched (the bordered determinant needs a square system)"
        )
    q_ref = float(eq.geometry.driver_ref[driver])
    revolute = m.joint(driver).kind == "R"

    def qwrap(q: float) -> float:
        if not revolute:
            return q
        r = (q - q_ref) % (2 * math.pi)
        return q_ref + (0.0 if r > 2 * math.pi - Q_TOUCH else r)

    found: list[tuple[str, FloatArray]] = [("change_point", b.x) for b in bifs]
    fold_arcs: list[FoldArc] = []
    unclassified: set[int] = set()
    q_spans: list[tuple[float, float, bool]] = []
    for br in branches:
        qs, gq = eq.inputs(br.x)
        dq = np.einsum("kn,kn->k", gq, br.t)
        do = np.einsum("kn,kn->k", eq.outputs(br.x)[1], br.t)
        limits: list[float] = []
        fold_in = bool(np.all(np.abs(dq) < FOLD_TOL))
        fold_out = bool(np.all(np.abs(do) < FOLD_TOL))
        if fold_in or fold_out:
            same = _coinciding(eq, br)
            warnings.append(_fold_warning(eq, br, fold_in, qwrap(float(qs[0])), same))
            arcs = _fold_arcs(eq, br, fold_in, qs, bifs, same, q_ref, revolute)
            if fold_in and fold_out:  # neither moves: no type of the classification
                unclassified.update(id(a) for a in arcs)
            fold_arcs += arcs
        for kind, comp, fold, grad in (
            ("input_limit", dq, fold_in, eq.inputs),
            ("output_extreme", do, fold_out, eq.outputs),
        ):
            if fold:
                continue
            for i, at_station in _sign_changes(comp):
                xr = br.x[i] if at_station else _refine_root(eq, br, i, grad)
                if xr is None:
                    near = [b for b in bifs if _near(eq, br.x[i], b.x, NEAR_CHANGE_POINT)]
                    if not near:
                        warnings.append(
                            f"{kind}: a sign change near q = {qwrap(float(qs[i])):.9g} could "
                            "not be located (a tangency); it is not listed"
                        )
                    continue
                if any(_near(eq, xr, b.x, AT_CHANGE_POINT) for b in bifs):
                    continue
                found.append((kind, xr))
                if kind == "input_limit":  # the exact ends of this branch's q span
                    limits.append(eq.input(xr)[0])
        winds = revolute and abs(qs[-1] - qs[0]) > math.pi
        q_spans.append((min([float(qs.min()), *limits]), max([float(qs.max()), *limits]), winds))
    unique: list[tuple[str, FloatArray]] = []
    for kind, x in found:
        if not any(_near(eq, x, y, SAME_POINT) for _, y in unique):
            unique.append((kind, x))
    positions = []
    groups = _group_classes(m) if any(k == "input_limit" for k, _ in unique) else None
    for kind, x in unique:
        coll, triples = _collinear(eq, x)
        pairs = tuple(dict.fromkeys((a, b) for a, b, *_ in triples if m.frame not in (a, b)))
        zone = None
        theta = None
        if clearance is not None:
            zone, notes = _zones(eq, x, kind, triples, clearance, fb is not None, exact)
            where = f"{kind} q = {qwrap(eq.input(x)[0]):.9g}"
            warnings += [f"exact zone at the {where}: {n}" for n in notes]
            theta = theta_of_zones([z.psi for z in zone])
            if not pairs:  # no pair in line (an Assur point): the link turning most
                held = "output" if kind == "output_extreme" else "input"
                theta = theta_without_pair(eq, x, held, clearance)
        q = float(qwrap(eq.input(x)[0]))
        klass = None
        if kind == "input_limit" and groups is not None:
            klass = singular_group_class(eq, x, groups)
        positions.append(
            SingularPosition(
                kind,
                q,
                _half_turn(eq.output_angle(x)),
                coll,
                pairs,
                zone,
                tuple(float(v) for v in x),
                classify_position(kind, q, pairs, theta, klass),
            )
        )
    # positions equal to rounding sort alike whichever branch met them first
    positions.sort(
        key=lambda p: (
            round(p.q, 9),
            KINDS.index(p.kind),
            round(p.output_angle, 9),
            p.collinear,
            tuple(round(v, 9) for v in p.configuration),
        )
    )
    rng = _input_range(q_spans, q_ref, revolute)
    fold_arcs = [
        a
        if id(a) in unclassified
        else dataclasses.replace(
            a,
            classification=classify_fold_arc(
                a.kind,
                a.q_from,
                a.q_to,
                fold_arc_theta(a.joints, m.link_joints, eq.geometry.centres, clearance),
            ),
        )
        for a in fold_arcs
    ]
    return SingularAnalysis(
        driver,
        eq.output_link,
        tuple(positions),
        rng,
        fb,
        tuple(warnings),
        clearance,
        len(branches),
        revolute,
        fb_out,
        tuple(sorted(fold_arcs, key=lambda a: (round(a.q_from, 9), round(a.q_to, 9), a.kind))),
    )


def _group_classes(m: Mechanism) -> list[tuple[tuple[str, ...], int]] | None:
    """Each Assur group's links and class in solving order (None: no decomposition)."""
    from mjstruct.structure.assur import assur_groups

    try:
        return [(g.links, g.klass) for g in assur_groups(m).groups]
    except MechanismError:
        return None


def _sign_changes(comp: FloatArray) -> list[tuple[int, bool]]:
    """Where a tangent component changes sign along a closed branch.

    ``comp[-1]`` belongs to the closing station, a copy of the first, so the stations
    are taken cyclically.  Returns ``(i, False)`` for a sign change between stations
    ``i`` and ``i + 1`` (to be refined) and ``(i, True)`` for a run of vanishing values
    between opposite signs, ``i`` its middle station (the root itself: the reference,
    or any start station, can lie exactly on a singular position, where the product
    test of neighbours sees ``0`` and no sign change).
    """
    c = np.asarray(comp[:-1], dtype=np.float64)
    n = c.size
    scale = float(np.abs(c).max()) if n else 0.0
    sign = np.where(np.abs(c) <= ROOT_AT_STATION * scale, 0.0, np.sign(c))
    if n == 0 or not sign.any():
        return []
    out: list[tuple[int, bool]] = []
    for i in range(n):
        if sign[i] * sign[(i + 1) % n] < 0:
            out.append((i, False))
        elif sign[i] == 0 and sign[i - 1] != 0:  # a run of zeros starts at i
            k = i
            while sign[k % n] == 0:
                k += 1
            if sign[i - 1] * sign[k % n] < 0:
                out.append((((i + k - 1) // 2) % n, True))
    return out


def _refine_root(
    eq: ClosureEquations, br: Branch, i: int, grads: Callable[[FloatArray], Any]
) -> FloatArray | None:
    """The point between samples i and i+1 where the tangent's component vanishes.

    ``grads``: the batched coordinate (``eq.inputs`` or ``eq.outputs``).  Nine points
    of the step are corrected together; the secant in their bracket and two points
    1e-6 of the step to its sides narrow it (together again), and Brent's method
    finishes in the narrow bracket.
    """
    from scipy.optimize import brentq

    x0, t0 = br.x[i], br.t[i]

    def comp(s: float) -> float:
        x = point_on_step(eq, x0, t0, s)
        return float(grads(x[None, :])[1][0] @ tangents(eq, x[None, :], t0)[0][0])

    def comps(ss: FloatArray) -> tuple[FloatArray, FloatArray]:
        Y, ok = correct_many(eq, x0 + ss[:, None] * t0, t0)
        Y[ss == 0.0] = x0
        if not ok[ss != 0.0].all():
            raise NumericalError("configuration curve: Newton failed inside a located step")
        V, _ = tangents(eq, Y, t0)
        return Y, np.einsum("kn,kn->k", grads(Y)[1], V)

    s1 = float(t0 @ (br.x[i + 1] - x0))
    grid = np.linspace(0.0, s1, 9)
    Y, vals = comps(grid)
    for k in range(9):
        if abs(vals[k]) < ROOT_ABS:
            return np.asarray(Y[k], dtype=np.float64)
    for k in range(8):
        if vals[k] * vals[k + 1] < 0:
            lo, hi = float(grid[k]), float(grid[k + 1])
            # the secant through the bracket, then a bracket 1e-6 of the step around
            # it, corrected together: Brent's method starts within a few ulps' reach
            est = lo - vals[k] * (hi - lo) / (vals[k + 1] - vals[k])
            d = 1e-6 * abs(s1)
            near = np.array([max(lo, est - d), est, min(hi, est + d)])
            _, nv = comps(near)
            pts = [(lo, vals[k]), *zip(near, nv, strict=True), (hi, vals[k + 1])]
            for (a, fa), (b, fb) in itertools.pairwise(sorted(pts)):
                if fa == 0.0:
                    return point_on_step(eq, x0, t0, float(a))
                if fa * fb < 0:
                    s = brentq(comp, a, b, xtol=1e-15, rtol=1e-15, maxiter=200)
                    return point_on_step(eq, x0, t0, float(s))
    return None


def _near(eq: ClosureEquations, a: FloatArray, b: FloatArray, tol: float) -> bool:
    return float(np.abs(wrap_delta(eq, a - b)).max()) < tol


def _tidy(v: float) -> float:
    """Round-off below DISPLAY_ZERO shown as zero (no "-0")."""
    return 0.0 if abs(v) < DISPLAY_ZERO else v


def _coinciding(eq: ClosureEquations, br: Branch) -> list[tuple[str, str]]:
    """Pairs of joints (file order) that coincide all along a branch."""
    ids = [j.id for j in eq.mechanism.joints]
    P = eq.joint_positions(br.x[::5])
    same = []
    for i, a in enumerate(ids):
        for k in range(i + 1, len(ids)):
            if float(np.abs(P[:, i] - P[:, k]).max()) < COINCIDE_ALONG:
                same.append((a, ids[k]))
    return same


def _fold_arcs(
    eq: ClosureEquations,
    br: Branch,
    fold_in: bool,
    qs: FloatArray,
    bifs: Sequence[Bifurcation],
    same: list[tuple[str, str]],
    q_ref: float,
    revolute: bool,
) -> list[FoldArc]:
    """The fold arcs of a fold branch, cut at the change points on it."""
    ids = {j for pair in same for j in pair}
    joints = tuple(j.id for j in eq.mechanism.joints if j.id in ids)
    two_pi = 2 * math.pi
    if fold_in:
        q = float(qs[0])
        if revolute:
            q = q_ref + _wrap_rel(q - q_ref)
        return [FoldArc("input_limit", q, q, joints, None)]
    dwell = _half_turn(eq.output_angle(br.x[0]))
    lo, hi = float(qs.min()), float(qs.max())
    # change points on this branch: within a continuation step of one of its stations
    cuts = sorted(
        float(eq.input(b.x)[0])
        for b in bifs
        if float(np.linalg.norm(wrap_delta(eq, br.x - b.x), axis=1).min()) < MAX_STEP
    )
    if not revolute:
        inner = [c for c in cuts if lo < c < hi]
        ends = [lo, *inner, hi]
        return [
            FoldArc("output_extreme", a, b, joints, dwell) for a, b in itertools.pairwise(ends)
        ]
    rel: list[float] = []
    for c in sorted(_wrap_rel(c - q_ref) for c in cuts):
        if not rel or c - rel[-1] > FULL_TURN_SLACK:  # a change point met by several branches
            rel.append(c)
    # a branch that winds once: arcs between its change points
    if hi - lo >= two_pi - FULL_TURN_SLACK:
        if not rel:
            return [FoldArc("output_extreme", q_ref, q_ref + two_pi, joints, dwell)]
        ends = [*rel, rel[0] + two_pi]
    else:
        base = _wrap_rel(lo - q_ref)
        inner = sorted(c if c >= base else c + two_pi for c in rel)
        ends = [base, *(c for c in inner if base < c < base + hi - lo), base + hi - lo]
    return [
        FoldArc("output_extreme", q_ref + a, q_ref + b, joints, dwell)
        for a, b in itertools.pairwise(ends)
        if b - a > Q_TOUCH
    ]


def _half_turn(a: float) -> float:
    """An angle in (-pi, pi]: -pi up to round-off is pi (one position, one number)."""
    r = math.remainder(a, 2 * math.pi)
    return math.pi if r <= -math.pi + Q_TOUCH else r


def _wrap_rel(d: float) -> float:
    """``d`` modulo 2 pi in [0, 2 pi), round-off just below 2 pi taken as 0."""
    r = d % (2 * math.pi)
    return 0.0 if r > 2 * math.pi - Q_TOUCH else r


def _fold_warning(
    eq: ClosureEquations, br: Branch, fold_in: bool, q0: float, pairs: list[tuple[str, str]]
) -> str:
    same = [f"{b} sits on {a}" for a, b in pairs]
    what = " and ".join(same) if same else "no two joints coincide"
    if fold_in:
        return (
            f"fold arc: the input stays at q = {_tidy(q0):.9g} along a whole branch while "
            f"the rest moves ({what}); its positions are not listed"
        )
    return (
        f"fold arc: the output dwells at {_tidy(eq.output_angle(br.x[0])):.9g} rad along a whole "
        f"branch while the input moves ({what}); its positions are not listed"
    )


def _zones(
    eq: ClosureEquations,
    x: FloatArray,
    kind: str,
    triples: list[tuple[str, str, str, str, str]],
    clearance: float,
    fourbar: bool,
    exact: bool,
) -> tuple[tuple[Zone, ...], list[str]]:
    """The zone of each collinear pair, and why an exact zone could not be found."""
    m = eq.mechanism
    notes: list[str] = []
    c = eq.geometry.centres
    load = [j.id for j in m.joints]
    per_pin = {jid: clearance / len(load) for jid in load}
    fixed = "output" if kind == "output_extreme" else "input"
    out: list[Zone] = []
    seen: set[tuple[str, str]] = set()
    for a, b, jid, ja, jb in triples:
        if m.frame in (a, b) or (a, b) in seen:
            continue
        seen.add((a, b))
        la, lb = abs(c[ja] - c[jid]), abs(c[jb] - c[jid])
        longer = a if la >= lb else b
        if fourbar:
            u = eq.joint_position(x, ja) - eq.joint_position(x, jid)
            v = eq.joint_position(x, jb) - eq.joint_position(x, jid)
            stretched = (u.conjugate() * v).real < 0
            psi: float | None = formula3(max(la, lb), min(la, lb), clearance, stretched)
            method = "formula-3"
            lam: float | None = min(la, lb) / max(la, lb)
            delta: float | None = clearance / max(la, lb)
            # formula (3)'s triangle: the pair's outer pivots held, i.e. the link not
            # in the pair (input and coupler: the output; coupler and output: the
            # input); at a change point each pair has its own (both are in line)
            f = "output" if _input_link(eq) in (a, b) else "input"
        else:
            f = fixed if _turns(eq, x, fixed, longer) else _other(fixed)
            psi = leading_order_zone(eq, x, f, longer, per_pin)
            method = "leading-order"
            lam = delta = None
        pe = None
        if exact:
            try:
                pe = exact_zone(eq, x, f, longer, per_pin, guess=psi)
            except NumericalError as e:
                reason = str(e).removeprefix("exact zone: ")
                notes.append(f"pair {a}-{b}: {reason}; psi_exact is null, psi ({method}) stands")
        out.append(Zone((a, b), longer, psi, method, pe, lam, delta, exact))
    # no pair in line (e.g. a class-III group's input limit): no entry, as the
    # contract has one entry per collinear pair
    return tuple(out), notes


def _input_link(eq: ClosureEquations) -> str:
    """The moving link of the driver joint (the input of a four-bar)."""
    m = eq.mechanism
    return next(x for x in m.joint(eq.driver).links if x != m.frame)


def _other(fixed: str) -> str:
    return "input" if fixed == "output" else "output"


def _direction(eq: ClosureEquations, x: FloatArray, fixed: str) -> tuple[FloatArray, FloatArray]:
    from mjstruct.singular.clearance import singular_direction

    return singular_direction(eq, x, fixed)


def _turns(eq: ClosureEquations, x: FloatArray, fixed: str, link: str) -> bool:
    v, _ = _direction(eq, x, fixed)
    return bool(abs(v[3 * eq.moving.index(link) + 2]) > TURNS)


def _input_range(
    spans: Sequence[tuple[float, float, bool]],
    q_ref: float,
    revolute: bool,
) -> InputRange:
    """Union of the branches' input spans (on the circle for a revolute driver)."""
    two_pi = 2 * math.pi
    if revolute and any(w for _, _, w in spans):
        return InputRange(True, ((float(q_ref), float(q_ref + two_pi)),))
    arcs = sorted((lo, hi) for lo, hi, _ in spans)
    if not revolute:
        merged: list[list[float]] = []
        for lo, hi in arcs:
            if merged and lo <= merged[-1][1] + Q_TOUCH:
                merged[-1][1] = max(merged[-1][1], hi)
            else:
                merged.append([lo, hi])
        return InputRange(False, tuple((float(a), float(b)) for a, b in merged))
    rel = sorted(((lo - q_ref) % two_pi, (lo - q_ref) % two_pi + (hi - lo)) for lo, hi in arcs)
    merged = []
    for lo, hi in rel:
        if merged and lo <= merged[-1][1] + Q_TOUCH:
            merged[-1][1] = max(merged[-1][1], hi)
        else:
            merged.append([lo, hi])
    if len(merged) > 1 and merged[-1][1] - two_pi >= merged[0][0] - Q_TOUCH:
        first = merged.pop(0)
        merged[-1][1] = max(merged[-1][1], first[1] + two_pi)
    if any(b - a >= two_pi - FULL_TURN_SLACK for a, b in merged):
        return InputRange(True, ((float(q_ref), float(q_ref + two_pi)),))
    return InputRange(False, tuple((float(q_ref + a), float(q_ref + b)) for a, b in merged))


def classify_singular_frames(
    analysis: SingularAnalysis, q: Sequence[float] | npt.ArrayLike, tol: float
) -> list[str | None]:
    """Name the singular position nearest each driver value, within ``tol``.

    For the kinematics report: for every frame's ``q`` (compared modulo 2 pi for a
    revolute driver) the ``kind`` of the closest singular position within ``tol``
    (a change point wins a tie), else ``None``.

    >>> from mjstruct.io import read_mechanism
    >>> from mjstruct.catalog_files import example_path
    >>> a = singular_analysis(read_mechanism(example_path("fourbar-ms1")))
    >>> classify_singular_frames(a, [0.0, 1.0, np.pi], 1e-6)
    ['change_point', None, 'change_point']
    """
    out: list[str | None] = []
    for v in np.asarray(q, float).reshape(-1):
        best: tuple[float, int] | None = None
        for p in analysis.singular:
            d = abs(v - p.q)
            if analysis.revolute:
                d = abs(math.remainder(v - p.q, 2 * math.pi))
            if d <= tol:
                key = (d, -KINDS.index(p.kind))
                if best is None or key < best:
                    best = key
        out.append(None if best is None else KINDS[-best[1]])
    return out


#: the kinematics' flagged frames are named for mechanisms up to this many links (the
#: analysis traces the curve with dense SVDs: 0.1-0.4 s up to 16 links, 6.4 s at 62)
KINDS_MAX_LINKS = 16


def name_flagged_frames(r: KinematicsResult, frames: npt.NDArray[np.intp]) -> list[str | None]:
    """Kind of the singular position at each flagged frame of a kinematics result.

    What the kinematics' near-singular check calls (installed by the package through
    :func:`mjstruct.kinematics.checks.set_singular_namer`): from
    :func:`singular_analysis` (one driver, F = 1; its positions are located to 1e-9
    in q) within one frame step of each frame; only up to :data:`KINDS_MAX_LINKS`
    links, None where not identified.
    """
    none: list[str | None] = [None] * len(frames)
    drivers = r.plan.drivers
    if len(drivers) != 1 or len(r.mechanism.links) > KINDS_MAX_LINKS:
        return none
    m = r.mechanism
    if tuple(m.drivers) != drivers:
        m = dataclasses.replace(m, drivers=drivers)
    try:
        a = singular_analysis(m)
    except (MechanismError, NumericalError):
        return none
    q = r.q[:, 0]
    step = float(np.abs(np.diff(q)).max()) if q.size > 1 else 2 * np.pi
    return classify_singular_frames(a, q[frames], tol=step)
