"""An independent model for the tests: moving links in full coordinates, joints as constraints.

Each moving link has the coordinates (x, y, φ) of its centre of mass (φ its rotation
from the reference configuration); revolute joints make their links' points meet,
prismatic joints keep the two links' angles equal and the carried point on the guide.
The constraint Jacobian and its velocity terms are built by sympy from these
definitions, the forces of gravity and of the elements from their energies (springs)
or their powers (dampers, motors), and the index-1 equations

    [[M, Φ_xᵀ], [Φ_x, 0]] [a, λ] = [F, −(Φ_x v)_x v − 2 α Φ̇ − α² Φ]

(Lagrange multipliers with Baumgarte's stabilisation) are integrated by scipy.  The
file is read as plain JSON: nothing of mjstruct's dynamics is used.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

BAUMGARTE = 20.0


def _centroid(points: list[complex]) -> complex:
    distinct: list[complex] = []
    for z in points:
        if all(abs(z - p) > 1e-12 for p in distinct):
            distinct.append(z)
    return sum(distinct, 0j) / len(distinct)


class FullModel:
    """Full-coordinate model of a mechanism file (revolute and prismatic joints)."""

    def __init__(self, path: str | Path, parameters: dict[str, float] | None = None) -> None:
        d: dict[str, Any] = json.loads(Path(path).read_text())
        self.frame = str(d["frame"])
        joints = d["joints"]
        self.centre = {j["id"]: complex(*j["at"]) for j in joints}
        self.joint = {j["id"]: j for j in joints}
        links: list[str] = []
        for j in joints:
            for link in j["links"]:
                if str(link) not in links:
                    links.append(str(link))
        self.moving = [x for x in links if x != self.frame]
        inertia = d.get("inertia", {})
        self.mass, self.J, self.com = {}, {}, {}
        for link in self.moving:
            spec = inertia.get(link, {})
            self.mass[link] = float(spec.get("mass", 0.0))
            self.J[link] = float(spec.get("J", 0.0))
            pts = [self.centre[j["id"]] for j in joints if link in map(str, j["links"])]
            self.com[link] = complex(*spec["com"]) if "com" in spec else _centroid(pts)
        g = d.get("gravity", [0.0, 0.0])
        self.gravity = complex(g[0], g[1])
        self.params = {**{k: v for k, v in d.get("parameters", {}).items()}, **(parameters or {})}
        self.drivers = list(d["drivers"])
        n = 3 * len(self.moving)
        self.x = sp.symbols(f"x0:{n}", real=True)
        self.v = sp.symbols(f"v0:{n}", real=True)
        self.index = {link: 3 * i for i, link in enumerate(self.moving)}
        self._build(d.get("elements", []))

    # positions of points -------------------------------------------------------
    def angle(self, link: str) -> sp.Expr:
        return sp.Integer(0) if link == self.frame else self.x[self.index[link] + 2]

    def point(self, link: str, at: complex) -> tuple[sp.Expr, sp.Expr]:
        """World position of the point of ``link`` at ``at`` in the reference."""
        if link == self.frame:
            return sp.Float(at.real), sp.Float(at.imag)
        k = self.index[link]
        s = at - self.com[link]
        c, si = sp.cos(self.x[k + 2]), sp.sin(self.x[k + 2])
        return (self.x[k] + c * s.real - si * s.imag, self.x[k + 1] + si * s.real + c * s.imag)

    def slide(self, jid: str, pair: tuple[str, str]) -> sp.Expr:
        """Slide of link b against link a along the guide of a prismatic joint."""
        j = self.joint[jid]
        a, b = pair
        u = complex(*j["axis"])
        u /= abs(u)
        c = self.centre[jid]
        pa, pb = self.point(a, c), self.point(b, c)
        th = self.angle(a)
        ux = sp.cos(th) * u.real - sp.sin(th) * u.imag
        uy = sp.sin(th) * u.real + sp.cos(th) * u.imag
        return (pb[0] - pa[0]) * ux + (pb[1] - pa[1]) * uy

    def coordinate(self, jid: str, pair: tuple[str, str] | None = None) -> sp.Expr:
        """A joint's coordinate, measured from the reference configuration."""
        j = self.joint[jid]
        pair = pair or (str(j["links"][0]), str(j["links"][1]))
        if j.get("type", "R") == "P":
            return self.slide(jid, pair)
        return self.angle(pair[1]) - self.angle(pair[0])

    # the model ------------------------------------------------------------------
    def _build(self, elements: list[dict[str, Any]]) -> None:
        x, v = sp.Matrix(self.x), sp.Matrix(self.v)
        cons: list[sp.Expr] = []
        #: (joint, link, row): rows row, row + 1 hold the pin's multipliers on that link
        self.pins: list[tuple[str, str, int]] = []
        for jid, j in self.joint.items():
            ls = [str(link) for link in j["links"]]
            c = self.centre[jid]
            if j.get("type", "R") == "R":
                p0 = self.point(ls[0], c)
                for other in ls[1:]:
                    p = self.point(other, c)
                    self.pins.append((jid, other, len(cons)))
                    cons += [p[0] - p0[0], p[1] - p0[1]]
            else:
                a, b = ls
                u = complex(*j["axis"])
                n_ref = 1j * u / abs(u)
                th = self.angle(a)
                nx = sp.cos(th) * n_ref.real - sp.sin(th) * n_ref.imag
                ny = sp.sin(th) * n_ref.real + sp.cos(th) * n_ref.imag
                pa, pb = self.point(a, c), self.point(b, c)
                cons += [
                    self.angle(b) - self.angle(a),
                    (pb[0] - pa[0]) * nx + (pb[1] - pa[1]) * ny,
                ]
        Phi = sp.Matrix(cons)
        Jx = Phi.jacobian(x)
        gamma = -(Jx * v).jacobian(x) * v
        U = sp.Integer(0)
        extra = sp.zeros(len(self.x), 1)  # dampers and motors: a load times ∇ of its coordinate
        for link in self.moving:
            k = self.index[link]
            U -= self.mass[link] * (self.gravity.real * x[k] + self.gravity.imag * x[k + 1])

        def grad(e: sp.Expr) -> sp.Matrix:
            return sp.Matrix([e]).jacobian(x).T

        def rate(e: sp.Expr) -> sp.Expr:
            return (grad(e).T * v)[0]

        for el in elements:
            kind = el["type"]
            if kind in ("spring", "damper"):
                pts = []
                for p in el["between"]:
                    if "joint" in p:
                        j = self.joint[p["joint"]]
                        link = str(j["links"][1] if j.get("type", "R") == "P" else j["links"][0])
                        pts.append(self.point(link, self.centre[p["joint"]]))
                    else:
                        pts.append(self.point(str(p["link"]), complex(*p["at"])))
                L = sp.sqrt((pts[1][0] - pts[0][0]) ** 2 + (pts[1][1] - pts[0][1]) ** 2)
                if kind == "spring":
                    ref = [
                        self.centre[p["joint"]] if "joint" in p else complex(*p["at"])
                        for p in el["between"]
                    ]
                    L0 = el.get("free_length", abs(ref[1] - ref[0]))
                    U += sp.Rational(1, 2) * el["stiffness"] * (L - L0) ** 2
                else:
                    extra -= el["rate"] * rate(L) * grad(L)
                continue
            pair = tuple(map(str, el["links"])) if "links" in el else None
            q = self.coordinate(el["joint"], pair)
            if kind in ("torsion_spring", "elastic_slide"):
                free = el.get("free_angle" if kind == "torsion_spring" else "free_length", None)
                offset = self.reference(el["joint"], pair) if kind == "torsion_spring" else 0.0
                free = offset if free is None else free
                U += sp.Rational(1, 2) * el["stiffness"] * (q + offset - free) ** 2
            elif kind in ("torsion_damper", "slide_damper"):
                extra -= el["rate"] * rate(q) * grad(q)
            elif kind == "motor":
                qs, qds = sp.symbols("q qdot")
                law = sp.sympify(
                    el["law"], locals={k: sp.Float(v) for k, v in self.params.items()}
                )
                offset = (
                    self.reference(el["joint"], pair) if self.kind(el["joint"]) == "R" else 0.0
                )
                tau = law.subs({qs: q + offset, qds: rate(q)})
                extra += tau * grad(q)
        F = -grad(U) + extra
        args = [*self.x, *self.v]
        self.f_Phi = sp.lambdify([self.x], Phi, "numpy")
        self.f_J = sp.lambdify([self.x], Jx, "numpy")
        self.f_gamma = sp.lambdify([args], gamma, "numpy")
        self.f_F = sp.lambdify([args], F, "numpy")
        self.f_U = sp.lambdify([self.x], U, "numpy")
        self._coords = {
            d: sp.lambdify([self.x], self.coordinate(d), "numpy") for d in self.drivers
        }
        self._rates = {
            d: sp.lambdify([args], rate(self.coordinate(d)), "numpy") for d in self.drivers
        }
        self.Mdiag = np.concatenate([[self.mass[k], self.mass[k], self.J[k]] for k in self.moving])

    def kind(self, jid: str) -> str:
        return str(self.joint[jid].get("type", "R"))

    def reference(self, jid: str, pair: tuple[str, str] | None) -> float:
        """The reference relative angle of a revolute joint's links (their characteristic
        angles: first to second joint centre in file order)."""
        j = self.joint[jid]
        a, b = pair or (str(j["links"][0]), str(j["links"][1]))
        return self.char(b) - self.char(a)

    def char(self, link: str) -> float:
        if link == self.frame:
            return 0.0
        ids = [j["id"] for j in self.joint.values() if link in map(str, j["links"])]
        pts: list[complex] = []
        for jid in ids:
            if all(abs(self.centre[jid] - p) > 1e-12 for p in pts):
                pts.append(self.centre[jid])
        if len(pts) >= 2:
            return float(np.angle(pts[1] - pts[0]))
        slide = [jid for jid in ids if self.kind(jid) == "P"]
        return float(np.angle(complex(*self.joint[slide[0]]["axis"]))) if slide else 0.0

    # the motion ---------------------------------------------------------------------
    def initial(self, qdot0: np.ndarray) -> np.ndarray:
        """The reference configuration with the drivers' rates ``qdot0``."""
        n = len(self.x)
        x0 = np.zeros(n)
        for link in self.moving:
            k = self.index[link]
            x0[k], x0[k + 1] = self.com[link].real, self.com[link].imag
        J = np.asarray(self.f_J(x0), float)
        rows = []
        for d in self.drivers:
            e = self.coordinate(d)
            rows.append(
                np.array(
                    sp.lambdify([self.x], sp.Matrix([e]).jacobian(sp.Matrix(self.x)), "numpy")(x0),
                    float,
                ).reshape(-1)
            )
        A = np.vstack([J, np.array(rows)])
        b = np.concatenate([np.zeros(J.shape[0]), qdot0])
        v0 = np.linalg.solve(A, b)
        return np.concatenate([x0, v0])

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        return self.solve(y)[0]

    def solve(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The state's rate and the multipliers λ (M a + Φ_xᵀ λ = F)."""
        n = len(self.x)
        xx, vv = y[:n], y[n:]
        J = np.asarray(self.f_J(xx), float)
        m = J.shape[0]
        Phi = np.asarray(self.f_Phi(xx), float).reshape(-1)
        gamma = np.asarray(self.f_gamma(y), float).reshape(-1)
        gamma = gamma - 2 * BAUMGARTE * (J @ vv) - BAUMGARTE**2 * Phi
        F = np.asarray(self.f_F(y), float).reshape(-1)
        K = np.zeros((n + m, n + m))
        K[:n, :n] = np.diag(self.Mdiag)
        K[:n, n:] = J.T
        K[n:, :n] = J
        sol = np.linalg.solve(K, np.concatenate([F, gamma]))
        return np.concatenate([vv, sol[:n]]), sol[n:]

    def run(
        self, qdot0: np.ndarray, times: np.ndarray, rtol: float = 1e-11
    ) -> dict[str, np.ndarray]:
        """Driver coordinates (from the reference) and rates at ``times``, the energy, and
        the load of each pin on each of its links but the first (times × [x, y]): the
        constraint force −Φ_xᵀ λ of the rows p_link − p_first = 0 is −λ on that link."""
        y0 = self.initial(np.asarray(qdot0, float))
        sol = solve_ivp(
            self.rhs, (0.0, times[-1]), y0, method="DOP853", rtol=rtol, atol=rtol, t_eval=times
        )
        n = len(self.x)
        q = np.array([[self._coords[d](y[:n]) for d in self.drivers] for y in sol.y.T])
        qd = np.array([[self._rates[d](y) for d in self.drivers] for y in sol.y.T])
        T = np.array([0.5 * np.sum(self.Mdiag * y[n:] ** 2) for y in sol.y.T])
        U = np.array([float(self.f_U(y[:n])) for y in sol.y.T])
        lam = np.array([self.solve(y)[1] for y in sol.y.T])
        pins = {(jid, link): -lam[:, [r, r + 1]] for jid, link, r in self.pins}
        return {"q": q, "qdot": qd, "energy": T + U, "pins": pins}
