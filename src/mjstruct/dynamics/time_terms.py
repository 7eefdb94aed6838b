"""The coefficients of ``V(q) q̈ + W(q) q̇² = Q(q, q̇)`` at any q, for a time integrator.

Owns :class:`ReducedEquation`: the reduced inertia ``V``, its ``W`` term, the
generalised force of gravity ``G`` and the analog of every load's point (or angle)
``σ_l``, so that ``Q(q, q̇) = G(q) + Σ_l c_l(q, q̇) · σ_l(q)`` with the load
components ``c_l`` evaluated from the file's expressions at the actual ``q`` and ``q̇``.
Also the partial derivatives the implicit solvers' Jacobian needs: ``∂c/∂q̇`` and
``∂c/∂q`` of the load expressions by sympy, ``∂(V, W, G, σ)/∂q`` from the kinematics.

The kinematic part comes from :meth:`KinematicModel.motion` in one of two ways:

``table``
    the coefficients on ``N`` equal steps of one driver turn (one tracked sweep, so
    iterated closures keep their branch), interpolated by a periodic cubic spline.  The
    interpolation error is measured at the midpoints of the grid against the exact
    kinematics and reported as :attr:`ReducedEquation.table_error`.
``exact``
    a kinematic solve at every requested q (no interpolation; each q is solved on its
    own, starting from the reference assembly).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> from mjstruct.dynamics.data import read_dynamics
>>> m = read_mechanism(example_path("slider-crank-seed000-dynamics"))
>>> model = KinematicModel.build(m)
>>> data = read_dynamics(m)
>>> params = data.parameter_values(p=1.0)
>>> tab = reduced_equation(model, data, params, table=1024)
>>> ex = reduced_equation(model, data, params, table=None)
>>> tab.kind, ex.kind, tab.table_error < 1e-9
('table', 'exact', True)
>>> q = np.array([0.3, 2.0])
>>> bool(np.allclose(tab.acceleration(q, q)[0], ex.acceleration(q, q)[0], rtol=1e-9))
True
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.data import DynamicsData
from mjstruct.dynamics.equation import coefficients
from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.model import KinematicModel, Motion

FloatArray = npt.NDArray[np.float64]

#: grid points of the default table over one driver turn
TABLE_POINTS = 2048

#: step of the central differences of the exact mode's q-derivatives, relative to
#: |q| plus q's unit (:func:`driver_unit`)
DIFF_STEP = 1e-5

#: relative mismatch of the coefficients after one turn above which they are not periodic
PERIODIC_TOL = 1e-8


def kinematic_terms(mo: Motion, data: DynamicsData, links: tuple[str, ...]) -> FloatArray:
    """Rows ``V, W, G, σx_0, σy_0, σθ_0, σx_1, ...`` over the frames of ``mo`` (order 2)."""
    V, W = coefficients(mo, data, links)
    n = mo.q.shape[0]
    G = np.zeros(n)
    g = data.gravity
    if g:
        for link in links:
            li = data.inertia[link]
            if li.mass:
                v = mo.point(link, li.com)[1]
                G += li.mass * (g.real * v.real + g.imag * v.imag)
    rows = [V, W, G]
    for load in data.loads:
        if load.kind == "force":
            v = mo.point(load.link, load.at)[1]
            rows += [v.real, v.imag, np.zeros(n)]
        else:
            rows += [np.zeros(n), np.zeros(n), np.asarray(mo.angle(load.link)[1], float)]
    return np.array(rows, dtype=float)


def driver_unit(model: KinematicModel) -> float:
    """The natural unit of the first driver's coordinate: 1 (a radian) for a revolute
    driver, the mechanism's size for a prismatic one."""
    return model.scale if model.mechanism.joint(model.drivers[0]).kind == "P" else 1.0


def _scalar(x: float) -> float:
    return float((x > 0) - (x < 0))


def _heaviside(x: float, h: float = 0.5) -> float:
    return 1.0 if x > 0 else (0.0 if x < 0 else float(h))


#: what the scalar load functions call where the math module has no such name
SCALAR_FUNCTIONS = {"sign": _scalar, "Heaviside": _heaviside}


def load_functions(
    data: DynamicsData, parameters: Mapping[str, float]
) -> list[tuple[Callable[..., Any], Callable[..., Any]]]:
    """Per load, two functions of scalars ``(q, q̇)``: its components ``(Fx, Fy, M)``,
    and their partial derivatives ``(∂/∂q of the three, ∂/∂q̇ of the three)``.

    The parameters are substituted and the expressions printed for the math module
    (a ``Piecewise`` becomes a conditional expression): a call costs microseconds,
    which is what a time integrator's many scalar evaluations need.
    """
    import sympy

    q, qd = sympy.Symbol("q", real=True), sympy.Symbol("qdot", real=True)
    out = []
    for load in data.loads:
        subs = {sympy.Symbol(a, real=True): parameters[a] for a in load.arguments}
        exprs = [e.subs(subs) for e in load.exprs]
        zero = sympy.S.Zero
        comps = [exprs[0], exprs[1], zero] if load.kind == "force" else [zero, zero, exprs[0]]
        # the jumps' delta functions are left to the step control
        parts = [
            sympy.diff(e, v).replace(sympy.DiracDelta, lambda *a: sympy.S.Zero)
            for v in (q, qd)
            for e in comps
        ]
        modules = [SCALAR_FUNCTIONS, "math"]
        out.append(
            (
                sympy.lambdify([q, qd], comps, modules=modules),
                sympy.lambdify([q, qd], parts, modules=modules),
            )
        )
    return out


@dataclass(frozen=True)
class ReducedEquation:
    """``V q̈ + W q̇² = Q(q, q̇)`` of a one-driver mechanism, evaluable at any q, q̇.

    Build it with :func:`reduced_equation`.

    Attributes
    ----------
    model : the kinematic model (one driver).
    data : the dynamics data.
    parameters : every parameter's value.
    kind : ``"table"`` or ``"exact"``.
    table_error : largest interpolation error of a coefficient at the grid's midpoints,
        relative to that coefficient's largest magnitude (None for ``exact``).
    pieces : the periodic cubic spline's coefficients, 4 × intervals × rows (``table``).
    functions : per load, its components and their partial derivatives
        (:func:`load_functions`).
    evaluations : a one-element list counting kinematic points solved.
    q_ref : the driver coordinate where the table starts (the reference).
    """

    model: KinematicModel
    data: DynamicsData
    parameters: dict[str, float]
    kind: str
    table_error: float | None
    pieces: FloatArray | None
    functions: list[tuple[Callable[..., Any], Callable[..., Any]]]
    evaluations: list[int]
    q_ref: float

    @property
    def links(self) -> tuple[str, ...]:
        return tuple(x for x in self.model.mechanism.links if x != self.model.frame)

    @property
    def unit(self) -> float:
        """The natural unit of q: a radian for a revolute driver, the mechanism's size
        for a slider (so that steps and tolerances in q do not depend on the unit of
        length)."""
        return driver_unit(self.model)

    def terms(
        self, q: npt.ArrayLike, derivative: bool = False
    ) -> tuple[FloatArray, FloatArray | None]:
        """Coefficient rows at ``q`` (rows × points) and, if asked, their q-derivative."""
        qa = np.asarray(q, float).reshape(-1)
        if self.pieces is not None:
            c = self.pieces
            N = c.shape[1]
            h = 2 * np.pi / N
            u = np.mod(qa - self.q_ref, 2 * np.pi)
            i = np.minimum((u / h).astype(int), N - 1)
            x = (u - i * h)[:, None]
            ci = c[:, i, :]
            K = (((ci[0] * x + ci[1]) * x + ci[2]) * x + ci[3]).T
            dK = ((3 * ci[0] * x + 2 * ci[1]) * x + ci[2]).T if derivative else None
            return K, dK
        if not derivative:
            return self._exact(qa), None
        h = DIFF_STEP * (self.unit + np.abs(qa))
        K3 = self._exact(np.concatenate([qa, qa - h, qa + h]))
        n = qa.size
        return K3[:, :n], (K3[:, 2 * n :] - K3[:, n : 2 * n]) / (2 * h)

    def _exact(self, q: FloatArray) -> FloatArray:
        self.evaluations[0] += q.size
        mo = self.model.motion(q[:, None], order=2)
        if not mo.valid.all():
            bad = float(q[np.argmax(~mo.valid)])
            raise NumericalError(f"the mechanism does not assemble at q = {bad:.9g}")
        return kinematic_terms(mo, self.data, self.links)

    def _call(self, which: int, q: FloatArray, qdot: FloatArray) -> FloatArray:
        """Load components (which = 0: loads × 3 × points) or partials (1: loads × 6 × points)."""
        width = 3 if which == 0 else 6
        out = np.empty((len(self.functions), width, q.size))
        for k, fns in enumerate(self.functions):
            f = fns[which]
            try:
                for j in range(q.size):
                    out[k, :, j] = f(float(q[j]), float(qdot[j]))
            except (ArithmeticError, ValueError, TypeError):  # TypeError: a complex value
                out[k] = np.nan
            if not np.isfinite(out[k]).all():
                bad = int(np.argmax(~np.isfinite(out[k]).all(axis=0)))
                where = self.data.loads[k].where
                raise MechanismError(
                    f"{where}: the load is not finite at q = {float(q[bad]):.9g}, "
                    f"qdot = {float(qdot[bad]):.9g}"
                )
        return out

    def loads(self, q: npt.ArrayLike, qdot: npt.ArrayLike) -> FloatArray:
        """Load components ``c`` (loads × 3 × points)."""
        qa = np.asarray(q, float).reshape(-1)
        return self._call(0, qa, np.broadcast_to(np.asarray(qdot, float).reshape(-1), qa.shape))

    def force(
        self, q: npt.ArrayLike, qdot: npt.ArrayLike, K: FloatArray | None = None
    ) -> FloatArray:
        """``Q(q, q̇)``, gravity included."""
        qa = np.asarray(q, float).reshape(-1)
        qd = np.broadcast_to(np.asarray(qdot, float).reshape(-1), qa.shape)
        if K is None:
            K = self.terms(qa)[0]
        sig = K[3:].reshape(-1, 3, qa.size)
        return np.asarray(K[2] + (self._call(0, qa, qd) * sig).sum(axis=(0, 1)), float)

    def rate(self, q: float, qdot: float) -> tuple[float, float]:
        """``(q̈, Q)`` at one state: the integrator's right-hand side, kept lean."""
        if not (math.isfinite(q) and math.isfinite(qdot)):
            raise NumericalError(
                f"the motion leaves the doubles (q = {q:g}, qdot = {qdot:g}): the loads are "
                "too large for the time span"
            )
        c = self.pieces
        if c is None:
            acc = self.acceleration([q], [qdot])
            return float(acc[0][0]), float(acc[1][0])
        N = c.shape[1]
        h = 2 * np.pi / N
        u = (q - self.q_ref) % (2 * np.pi)
        i = min(int(u / h), N - 1)
        x = u - i * h
        ci = c[:, i]
        K: list[float] = (((ci[0] * x + ci[1]) * x + ci[2]) * x + ci[3]).tolist()
        Q = K[2]
        for k, fns in enumerate(self.functions):
            try:
                fx, fy, m = fns[0](q, qdot)
                # float(): a negative number to a fractional power is complex in Python
                Q = float(Q + fx * K[3 + 3 * k] + fy * K[4 + 3 * k] + m * K[5 + 3 * k])
            except (ArithmeticError, ValueError, TypeError):
                Q = float("nan")
        if not np.isfinite(Q):
            self.force([q], [qdot])  # names the load that is not finite
            raise NumericalError(f"the generalised force is not finite at q = {q:.9g}")
        return (Q - K[1] * qdot * qdot) / K[0], Q

    def acceleration(
        self, q: npt.ArrayLike, qdot: npt.ArrayLike
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """``(q̈, Q, V, W)`` at the points (q, q̇), ``q̈ = (Q − W q̇²)/V``."""
        qa = np.asarray(q, float).reshape(-1)
        qd = np.broadcast_to(np.asarray(qdot, float).reshape(-1), qa.shape)
        K = self.terms(qa)[0]
        Q = self.force(qa, qd, K)
        return (Q - K[1] * qd**2) / K[0], Q, K[0], K[1]

    def partials(
        self, q: npt.ArrayLike, qdot: npt.ArrayLike
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """``(q̈, Q, [∂q̈/∂q, ∂q̈/∂q̇], [∂Q/∂q, ∂Q/∂q̇])`` at the points (q, q̇).

        ``∂V/∂q`` … come from the table's spline (or a central difference of the exact
        kinematics), ``∂c/∂q̇`` and ``∂c/∂q`` from sympy.
        """
        qa = np.asarray(q, float).reshape(-1)
        qd = np.broadcast_to(np.asarray(qdot, float).reshape(-1), qa.shape)
        K, dK = self.terms(qa, derivative=True)
        assert dK is not None
        n = qa.size
        c = self._call(0, qa, qd)
        dc = self._call(1, qa, qd)
        cq, cqd = dc[:, :3], dc[:, 3:]
        sig, dsig = K[3:].reshape(-1, 3, n), dK[3:].reshape(-1, 3, n)
        Q = K[2] + (c * sig).sum(axis=(0, 1))
        Qq = dK[2] + (cq * sig + c * dsig).sum(axis=(0, 1))
        Qqd = (cqd * sig).sum(axis=(0, 1))
        V, W = K[0], K[1]
        qdd = (Q - W * qd**2) / V
        aq = (Qq - dK[1] * qd**2 - dK[0] * qdd) / V
        aqd = (Qqd - 2 * W * qd) / V
        return qdd, Q, np.stack([aq, aqd]), np.stack([Qq, Qqd])


def reduced_equation(
    model: KinematicModel,
    data: DynamicsData,
    parameters: Mapping[str, float],
    table: int | None = TABLE_POINTS,
) -> ReducedEquation:
    """The reduced equation of ``model`` with ``table`` grid points per turn (None: exact).

    A table needs a revolute driver whose mechanism assembles over the whole turn and
    comes back to the same assembly; otherwise :class:`NumericalError` says why.
    """
    fns = load_functions(data, parameters)
    links = tuple(x for x in model.mechanism.links if x != model.frame)
    if table is None:
        return ReducedEquation(
            model, data, dict(parameters), "exact", None, None, fns, [0], float(model.q_ref[0])
        )
    from scipy.interpolate import CubicSpline

    d = model.drivers[0]
    if model.mechanism.joint(d).kind != "R":
        raise NumericalError(f"table: driver {d!r} is a slider; its motion is not periodic")
    N = int(table)
    u = 2 * np.pi * np.arange(N + 1) / N
    mid = u[: -1 : max(1, N // 64)] + np.pi / N
    mo = model.motion(model.q_ref[0] + u[:, None], order=2)
    if not mo.valid.all():
        bad = float(model.q_ref[0] + u[np.argmax(~mo.valid)])
        raise NumericalError(f"table: the mechanism does not assemble at q = {bad:.9g}")
    K = kinematic_terms(mo, data, links)
    size = np.abs(K).max(axis=1) + 1e-300
    if (np.abs(K[:, -1] - K[:, 0]) > PERIODIC_TOL * size).any():
        raise NumericalError("table: the mechanism does not return to its assembly after one turn")
    K[:, -1] = K[:, 0]
    spline = CubicSpline(u, K.T, axis=0, bc_type="periodic")
    # the midpoints, where a cubic spline errs most, against the exact kinematics
    mo_mid = model.motion(model.q_ref[0] + mid[:, None], order=2)
    if not mo_mid.valid.all():
        raise NumericalError("table: the mechanism does not assemble between grid points")
    exact = kinematic_terms(mo_mid, data, links)
    err = float((np.abs(np.asarray(spline(mid), float).T - exact) / size[:, None]).max())
    pieces = np.asarray(spline.c, float)
    return ReducedEquation(
        model,
        data,
        dict(parameters),
        "table",
        err,
        pieces,
        fns,
        [N + 1 + mid.size],
        float(model.q_ref[0]),
    )
