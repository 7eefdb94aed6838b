"""Constraint Jacobian of a planar mechanism: rank (mobility refinement) and determinant.

Owns the check beyond the counting formulas: the joint constraint equations in
link coordinates (x, y, φ of every moving link), their rectangular Jacobian J
(Nu × 3Ns), its rank (``rank J = Nu``: independent constraints and Chebyshev's count
is exact; less: redundant constraints), and the determinant of the square matrix
obtained by fixing the drivers (J with one row per driver coordinate appended, which
equals the driver-removed Jacobian's determinant up to sign).  The determinant
vanishes at singular configurations (slider-crank: L2 cos φ_rod).

Examples
--------
>>> import numpy as np
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> m = read_mechanism(example_path("slider-crank"))
>>> jr = jacobian_at_reference(m)
>>> jr.shape, int(jr.rank[0])
((1, 8, 9), 8)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.geometry import Geometry, read_geometry
from mjstruct.kinematics.tolerances import NEAR_SINGULAR, RANK_RTOL
from mjstruct.kinematics.triangles import Pose
from mjstruct.mechanism import Mechanism

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int_]


@dataclass(frozen=True)
class JacobianCheck:
    """J over the frames (F × Nu × 3Ns), its rank per frame, and the driver-fixed det."""

    J: FloatArray
    rank: IntArray
    det: FloatArray
    equations: int
    coordinates: int

    @property
    def shape(self) -> tuple[int, ...]:
        """(frames, equations, coordinates)."""
        return tuple(self.J.shape)


def reference_poses(m: Mechanism) -> dict[str, Pose]:
    """Every link at its reference pose (one frame, no rotation)."""
    z = np.zeros(1, complex)
    return {x: Pose(0j, [z], np.ones(1, complex), []) for x in m.links}


def constraint_jacobian(
    m: Mechanism, geom: Geometry, poses: dict[str, Pose], drivers: tuple[str, ...] = ()
) -> tuple[FloatArray, FloatArray]:
    """J (frames × Nu × 3Ns) of the joint constraints, and the driver rows (frames × N × 3Ns).

    Columns are (x, y, φ) of each moving link in ``m.links`` order; ``poses`` give the
    configuration (frame link at rest).
    """
    moving = [x for x in m.links if x != m.frame]
    col = {link: 3 * i for i, link in enumerate(moving)}
    F = next(iter(poses.values())).r.shape[0]
    rows: list[FloatArray] = []

    def zero() -> FloatArray:
        return np.zeros((F, 3 * len(moving)))

    def add_point(
        row_x: FloatArray, row_y: FloatArray, link: str, z: complex, sign: float
    ) -> None:
        if link not in col:
            return
        c = col[link]
        row_x[:, c] += sign
        row_y[:, c + 1] += sign
        d = 1j * poses[link].r * (z - 0j)
        row_x[:, c + 2] += sign * d.real
        row_y[:, c + 2] += sign * d.imag

    for j in m.joints:
        z = geom.centres[j.id]
        if j.kind == "R":
            for other in j.links[1:]:
                rx, ry = zero(), zero()
                add_point(rx, ry, j.links[0], z, 1.0)
                add_point(rx, ry, other, z, -1.0)
                rows += [rx, ry]
        else:
            a, b = j.links
            ra = zero()
            if a in col:
                ra[:, col[a] + 2] += 1.0
            if b in col:
                ra[:, col[b] + 2] -= 1.0
            rows.append(ra)
            rows.append(_slide_row(poses, col, a, b, z, 1j * geom.axes[j.id], zero()))
    drows = []
    for d in drivers:
        j = m.joint(d)
        a, b = j.links[0], j.links[1]
        row = zero()
        if j.kind == "R":
            if b in col:
                row[:, col[b] + 2] += 1.0
            if a in col:
                row[:, col[a] + 2] -= 1.0
        else:
            row = _slide_row(poses, col, a, b, geom.centres[d], geom.axes[d], row)
        drows.append(row)
    J = np.stack(rows, axis=1) if rows else np.zeros((F, 0, 3 * len(moving)))
    D = np.stack(drows, axis=1) if drows else np.zeros((F, 0, 3 * len(moving)))
    return J, D


def _slide_row(
    poses: dict[str, Pose],
    col: dict[str, int],
    a: str,
    b: str,
    z: complex,
    v: complex,
    row: FloatArray,
) -> FloatArray:
    """Gradient of Re(conj(v_a)(X_b - X_a)): v_a the direction v carried by link a."""
    va = poses[a].r * v
    xb = poses[b].point(z)[0]
    xa = poses[a].point(z)[0]
    for link, sign in ((b, 1.0), (a, -1.0)):
        if link not in col:
            continue
        c = col[link]
        row[:, c] += sign * va.real
        row[:, c + 1] += sign * va.imag
        d = 1j * poses[link].r * z
        row[:, c + 2] += sign * (va.conjugate() * d).real
    if a in col:
        row[:, col[a] + 2] += ((1j * va).conjugate() * (xb - xa)).real
    return row


def check_jacobian(
    m: Mechanism,
    geom: Geometry,
    poses: dict[str, Pose],
    drivers: tuple[str, ...],
    sample: int = 360,
) -> JacobianCheck:
    """Rank of J and the determinant with the drivers fixed (nan where undefined).

    The determinant is computed on every frame; the rank (an SVD per frame) on at most
    ``sample`` evenly spread frames plus every frame where the determinant is small or
    undefined, since the rank can only drop where the determinant does (rank is -1 on
    frames not examined).
    """
    J, D = constraint_jacobian(m, geom, poses, drivers)
    F, nu, nc = J.shape
    finite = np.isfinite(J).all(axis=(1, 2)) & np.isfinite(D).all(axis=(1, 2))
    rank = np.full(F, -1)
    det = np.full(F, np.nan)
    if finite.any():
        A = np.concatenate([J[finite], D[finite]], axis=1)
        if A.shape[1] == A.shape[2]:
            det[finite] = np.linalg.det(A)
        a = np.abs(det)
        top = np.nanmax(a) if np.isfinite(a).any() else np.nan
        look = np.zeros(F, bool)
        look[np.linspace(0, F - 1, min(F, sample)).astype(int)] = True
        look |= ~(a >= NEAR_SINGULAR * top)  # small or undefined determinant
        look &= finite
        sv = np.linalg.svd(J[look], compute_uv=False)
        tol = sv.max(axis=1, keepdims=True) * max(nu, nc) * RANK_RTOL
        rank[look] = (sv > tol).sum(axis=1)
    return JacobianCheck(J, rank, det, nu, nc)


def jacobian_at_reference(m: Mechanism) -> JacobianCheck:
    """The Jacobian check at the file's reference configuration (all rotations zero)."""
    return check_jacobian(m, read_geometry(m), reference_poses(m), tuple(m.drivers))
