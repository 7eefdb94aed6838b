"""An independent oracle of the frames a one-driver mechanism reaches from its reference.

Written for the kinematics' completeness tests, from the mechanism file alone: no Assur
decomposition, no plan, no triangle step.  Every moving link is a rigid body with the
pose (x, y, φ) that carries its reference points z to ``c + e^{iφ} (z - r)`` (``r`` its
first joint's centre; at the reference c = r, φ = 0; the frame stays put).  The
constraints are every link's joints at once: at a revolute joint of links l0, l1, …
the centre carried by l0 equals the one carried by each other link (so every distance
between the centres of one link is kept: it is rigid); at a prismatic joint the two
links keep their relative rotation and the second one's point stays on the first one's
guide line; the revolute driver's relative rotation is q − q_ref.  With one driver the
system is square (3 unknowns per moving link).

:func:`reach` continues the configuration from the reference in the driver, each
direction on its own, in small adaptive steps (tangent predictor dx/dq = −J_x⁻¹ J_q,
Newton corrector on the full system, the step halved where Newton fails, where the
corrector lands far from the prediction or where det J_x changes sign, doubled after
easy steps); it stops at a fold (the step below ``h_min``) or where det J_x changes
sign, and gives every frame it reached: the joint centres and the smallest singular
value of J_x there.

>>> import numpy as np
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.io import read_mechanism
>>> m = read_mechanism(example_path("four-bar"))
>>> system = FullSystem(m)
>>> got = reach(system, system.q_ref + np.array([-0.1, 0.0, 0.1]))
>>> sorted(got) == [0, 1, 2]
True
"""

from __future__ import annotations

import cmath
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from threadpoolctl import threadpool_limits

from mjstruct.mechanism import Mechanism

FloatArray = npt.NDArray[np.float64]


class FullSystem:
    """The constraint equations of every link of a one-revolute-driver mechanism."""

    def __init__(self, m: Mechanism) -> None:
        if len(m.drivers) != 1 or m.joint(m.drivers[0]).kind != "R":
            raise ValueError("the oracle takes one revolute driver")
        self.mechanism = m
        self.centres = {j.id: complex(*j.at) for j in m.joints}
        self.moving = [x for x in m.links if x != m.frame]
        self.col = {x: 3 * i for i, x in enumerate(self.moving)}
        self.origin = {x: self.centres[m.link_joints[x][0]] for x in m.links}
        self.scale = max(abs(a - b) for a in self.centres.values() for b in self.centres.values())
        # (joint, link a, link b) revolute pairs, (joint, a, b, axis) prismatic guides
        self.pairs: list[tuple[str, str, str]] = []
        self.guides: list[tuple[str, str, str, complex]] = []
        for j in m.joints:
            if j.kind == "R":
                self.pairs += [(j.id, j.links[0], x) for x in j.links[1:]]
            else:
                a, b = j.links
                u = complex(*j.axis)
                self.guides.append((j.id, a, b, u / abs(u)))
        d = m.joint(m.drivers[0])
        self.driver = (d.links[0], d.links[1])
        # the driver's coordinate at the reference: the second link's characteristic
        # angle relative to the first one's, as the kinematics reads it
        self.q_ref = self._char(d.links[1]) - self._char(d.links[0])
        self.size = 3 * len(self.moving)
        self.equations = 2 * len(self.pairs) + 2 * len(self.guides) + 1

    def _char(self, link: str) -> float:
        if link == self.mechanism.frame:
            return 0.0
        # the contract's characteristic vector: from the link's first revolute centre
        # to its second (file order), else its slider's axis
        m = self.mechanism
        js = [j for j in m.link_joints[link] if m.joint(j).kind == "R"]
        if len(js) > 1:
            return cmath.phase(self.centres[js[1]] - self.centres[js[0]])
        slides = [j for j in m.link_joints[link] if m.joint(j).kind == "P"]
        return cmath.phase(complex(*m.joint(slides[0]).axis)) if slides else 0.0

    def reference(self) -> FloatArray:
        """The unknowns at the reference configuration."""
        x = np.zeros(self.size)
        for link, c in self.col.items():
            x[c], x[c + 1] = self.origin[link].real, self.origin[link].imag
        return x

    def _pose(self, x: FloatArray, link: str) -> tuple[complex, complex]:
        if link == self.mechanism.frame:
            return self.origin[link], 1 + 0j
        c = self.col[link]
        return complex(x[c], x[c + 1]), cmath.exp(1j * x[c + 2])

    def point(self, x: FloatArray, link: str, z: complex) -> complex:
        """Where ``link`` carries its reference point ``z``."""
        c, r = self._pose(x, link)
        return c + r * (z - self.origin[link])

    def angle(self, x: FloatArray, link: str) -> float:
        """The rotation of ``link`` from the reference."""
        return 0.0 if link == self.mechanism.frame else float(x[self.col[link] + 2])

    def _index(self) -> None:
        # the revolute pairs as arrays: each side's link (N: the frame) and arm at rest
        n = len(self.moving)
        ids = {x: i for i, x in enumerate(self.moving)}
        ids[self.mechanism.frame] = n
        self._ia = np.array([ids[a] for _, a, _ in self.pairs], dtype=int)
        self._ib = np.array([ids[b] for _, _, b in self.pairs], dtype=int)
        self._za = np.array([self.centres[j] - self.origin[a] for j, a, _ in self.pairs])
        self._zb = np.array([self.centres[j] - self.origin[b] for j, _, b in self.pairs])
        self._c0 = np.array([self.origin[x] for x in [*self.moving, self.mechanism.frame]])

    def residual_jacobian(self, x: FloatArray, q: float) -> tuple[FloatArray, FloatArray]:
        """R(x, q) and dR/dx; dR/dq is −1 on the last (driver) row."""
        if not hasattr(self, "_ia"):
            self._index()
        n = len(self.moving)
        R = np.zeros(self.equations)
        J = np.zeros((self.equations, self.size))
        c = self._c0.copy()
        rot = np.ones(n + 1, dtype=complex)
        c[:n] = x[0::3] + 1j * x[1::3]
        rot[:n] = np.exp(1j * x[2::3])
        ia, ib = self._ia, self._ib
        arm_a, arm_b = rot[ia] * self._za, rot[ib] * self._zb
        d = c[ia] + arm_a - c[ib] - arm_b
        m = 2 * len(self.pairs)
        R[0:m:2], R[1:m:2] = d.real, d.imag
        rows = np.arange(0, m, 2)
        for idx, arm, sign in ((ia, arm_a, 1.0), (ib, arm_b, -1.0)):
            moving = idx < n
            r0, k = rows[moving], 3 * idx[moving]
            turn = 1j * arm[moving]
            J[r0, k] += sign
            J[r0 + 1, k + 1] += sign
            J[r0, k + 2] += sign * turn.real
            J[r0 + 1, k + 2] += sign * turn.imag
        row = m
        for joint, a, b, u in self.guides:
            z = self.centres[joint]
            ca, ra = self._pose(x, a)
            cb, rb = self._pose(x, b)
            arm_a1, arm_b1 = ra * (z - self.origin[a]), rb * (z - self.origin[b])
            D = (cb + arm_b1) - (ca + arm_a1)
            nrm = ra * u
            R[row] = self.angle(x, b) - self.angle(x, a)
            R[row + 1] = (nrm.conjugate() * D).imag
            for link, sign, arm1 in ((b, 1.0, arm_b1), (a, -1.0, arm_a1)):
                if link == self.mechanism.frame:
                    continue
                k = self.col[link]
                J[row, k + 2] += sign
                J[row + 1, k] += sign * nrm.conjugate().imag
                J[row + 1, k + 1] += sign * (nrm.conjugate() * 1j).imag
                J[row + 1, k + 2] += sign * (nrm.conjugate() * 1j * arm1).imag
            if a != self.mechanism.frame:
                J[row + 1, self.col[a] + 2] += ((1j * nrm).conjugate() * D).imag
            row += 2
        a, b = self.driver
        R[row] = self.angle(x, b) - self.angle(x, a) - (q - self.q_ref)
        for link, sign in ((b, 1.0), (a, -1.0)):
            if link != self.mechanism.frame:
                J[row, self.col[link] + 2] += sign
        return R, J

    def joints(self, x: FloatArray) -> dict[str, complex]:
        """Every joint's centre (a slider's: the point its second link carries)."""
        out = {}
        for j in self.mechanism.joints:
            link = j.links[1] if j.kind == "P" else j.links[0]
            out[j.id] = self.point(x, link, self.centres[j.id])
        return out


@dataclass(frozen=True)
class Reached:
    """One frame the continuation reached: the joint centres, J_x's smallest singular
    value there (relative to the largest) and every link's rotation from the reference."""

    joints: dict[str, complex]
    smallest: float
    turns: dict[str, float] | None = None
    #: the poses (x, y, φ per moving link) there
    x: FloatArray | None = None


def _newton(
    system: FullSystem, x: FloatArray, q: float, tol: float, iterations: int = 8
) -> tuple[FloatArray, FloatArray] | None:
    """Newton on the full system at ``q`` from ``x``: (x, J_x) or None."""
    for _ in range(iterations):
        R, J = system.residual_jacobian(x, q)
        if np.abs(R).max() <= tol:
            return x, J
        try:
            x = x - _solve(J, R)
        except np.linalg.LinAlgError:
            return None
        if not np.isfinite(x).all():
            return None
    R, J = system.residual_jacobian(x, q)
    return (x, J) if np.abs(R).max() <= tol else None


def _solve(J: FloatArray, b: FloatArray) -> FloatArray:
    if J.shape[0] == J.shape[1]:
        return np.asarray(np.linalg.solve(J, b), dtype=float)
    return np.asarray(np.linalg.lstsq(J, b, rcond=None)[0], dtype=float)


def _sign(J: FloatArray) -> float:
    if J.shape[0] != J.shape[1]:
        return 1.0
    return float(np.linalg.slogdet(J)[0])


def _tangent(J: FloatArray) -> FloatArray:
    # dR/dq is -1 on the driver row: J_x dx/dq = e_last
    e = np.zeros(J.shape[0])
    e[-1] = 1.0
    return _solve(J, e)


def reach(
    system: FullSystem,
    q: npt.ArrayLike,
    h_max: float = 2e-3,
    h_min: float = 1e-10,
) -> dict[int, Reached]:
    """The frames of driver values ``q`` reached from the reference, by frame index.

    Frames on either side of ``q_ref`` are reached by continuation from the reference
    in that direction (in order of their distance); the continuation of a side stops
    at a fold or a sign change of det J_x (the frames beyond are not in the result).
    """
    # many small dense solves: BLAS threads only wait for each other
    with threadpool_limits(limits=1):
        return _reach(system, np.asarray(q, dtype=float), h_max, h_min)


def _reach(system: FullSystem, qa: FloatArray, h_max: float, h_min: float) -> dict[int, Reached]:
    tol = 1e-13 * system.scale
    x0 = system.reference()
    R0, J0 = system.residual_jacobian(x0, system.q_ref)
    if np.abs(R0).max() > 1e-9 * system.scale:
        raise ValueError("the reference configuration does not satisfy the constraints")
    out: dict[int, Reached] = {}
    for side in (1.0, -1.0):
        idx = [
            i for i in np.argsort(np.abs(qa - system.q_ref)) if (qa[i] - system.q_ref) * side >= 0
        ]
        x, J, qc = x0.copy(), J0, system.q_ref
        sign = _sign(J0)
        h = h_max / 8
        for i in idx:
            target = float(qa[i])
            while qc != target:
                step = min(h, abs(target - qc))
                qn = target if step == abs(target - qc) else qc + side * step
                pred = x + _tangent(J) * (qn - qc)
                got = _newton(system, pred, qn, tol)
                ok = got is not None and _sign(got[1]) == sign
                if ok:
                    assert got is not None
                    moved = np.abs(got[0] - pred).max()
                    ok = moved <= 0.1 * np.abs(pred - x).max() + 1e-9 * system.scale
                if ok:
                    assert got is not None
                    x, J = got
                    qc = qn
                    h = min(2 * h, h_max)
                else:
                    h = 0.5 * step
                    if h < h_min:
                        break
            if qc != target:
                break
            s = np.linalg.svd(J, compute_uv=False)
            turns = {link: system.angle(x, link) for link in system.mechanism.links}
            out[int(i)] = Reached(system.joints(x), float(s[-1] / s[0]), turns, x.copy())
    return out
