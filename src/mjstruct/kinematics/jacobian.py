"""Constraint Jacobian of a planar mechanism: rank (mobility refinement) and determinant.

Owns the check beyond the counting formulas: the joint constraint equations in
link coordinates (x, y, φ of every moving link), their rectangular Jacobian J
(Nu × 3Ns), its rank (``rank J = Nu``: independent constraints and Chebyshev's count
is exact; less: redundant constraints), and the determinant of the square matrix
obtained by fixing the drivers (J with one row per driver coordinate appended, which
equals the driver-removed Jacobian's determinant up to sign).  The determinant
vanishes at singular configurations (slider-crank: L2 cos φ_rod).

References
----------
.. [1] A. N. Panasenko, "Practical implementation…" (in Russian; the available copy
   gives only this beginning of the title), Systems. Methods. Technologies,
   no. 2 (66), pp. 32–42, 2025. [Panasenko 2025] in docs/references.md.

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

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.geometry import Geometry, read_geometry
from mjstruct.kinematics.tolerances import NEAR_SINGULAR, RANK_RTOL
from mjstruct.kinematics.triangles import Pose
from mjstruct.mechanism import Mechanism, expect_mechanism

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int_]

#: the threadpoolctl controller, made once (making one scans the loaded libraries, about
#: 1 ms) and again when scipy's own BLAS has been loaded since: [scipy loaded, controller]
_BLAS: list[Any] = []


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Limit BLAS/LAPACK to one thread inside the block (threadpoolctl).

    The checks and the closure run many tiny or batched small-matrix factorisations;
    a multithreaded BLAS spends more on waking its threads than on the arithmetic, and
    under load much more (docs/decisions.md).
    """
    from threadpoolctl import ThreadpoolController

    key = "scipy.linalg" in sys.modules
    if not _BLAS or _BLAS[0] != key:
        _BLAS[:] = [key, ThreadpoolController()]
    with _BLAS[1].limit(limits=1, user_api="blas"):
        yield


@dataclass(frozen=True)
class JacobianCheck:
    """The Jacobian's rank per frame and its determinant with the drivers fixed.

    Attributes
    ----------
    J : the constraint Jacobian at the frames it was built on (``frames``), shape
        (len(frames), Nu, 3Ns); only a few frames unless it was built everywhere.  In
        units of the mechanism's size with the origin at its first joint (the rank
        and the determinant's zeros do not depend on either).
    rank : rank of J per frame (-1: not examined).
    det : determinant with the drivers fixed per frame (nan: undefined or not square).
    equations, coordinates : Nu and 3Ns.
    frames : the frames ``J`` holds.
    factor_error : when the determinant over all frames is the product of the plan's
        group determinants scaled by one constant, the largest relative disagreement
        of that product with the direct determinant on the frames built (None: the
        determinant was computed directly on every frame).
    """

    J: FloatArray
    rank: IntArray
    det: FloatArray
    equations: int
    coordinates: int
    frames: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int_))
    factor_error: float | None = None
    log_abs_det: FloatArray | None = None

    @property
    def log_det(self) -> FloatArray:
        """log |det| per frame (kept apart from ``det``, which may overflow)."""
        if self.log_abs_det is not None:
            return self.log_abs_det
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.asarray(np.log(np.abs(self.det)), dtype=np.float64)

    @property
    def shape(self) -> tuple[int, ...]:
        """(frames built, equations, coordinates)."""
        return tuple(self.J.shape)


def poses_at(poses: dict[str, Pose], idx: npt.NDArray[np.intp]) -> dict[str, Pose]:
    """The poses restricted to the frames ``idx``."""
    return {
        x: Pose(p.zA, [a[idx] for a in p.A], p.r[idx], [w[idx] for w in p.w])
        for x, p in poses.items()
    }


def reference_poses(m: Mechanism) -> dict[str, Pose]:
    """Every link at its reference pose (one frame, no rotation)."""
    z = np.zeros(1, complex)
    return {x: Pose(0j, [z], np.ones(1, complex), []) for x in m.links}


@dataclass(frozen=True)
class SparseJacobian:
    """J and the driver rows as sparse entries over frames: ``[J; D]`` without a dense matrix.

    Entry ``e`` sits at row ``rows[e]`` (the constraint rows first, then one row per
    driver), column ``cols[e]`` and has value ``values[:, e]`` on each frame; entries
    at one place add up (a prismatic joint's angle column).  Their number is linear
    in the joints, whatever the size of the dense matrix (Nu + drivers) × 3Ns.
    """

    rows: IntArray
    cols: IntArray
    values: FloatArray
    equations: int
    coordinates: int
    drivers: int

    @property
    def frames(self) -> int:
        """Frames the entries are given on."""
        return int(self.values.shape[0])

    def dense(self) -> tuple[FloatArray, FloatArray]:
        """J (frames × Nu × 3Ns) and the driver rows (frames × N × 3Ns), dense."""
        n, nc = self.equations + self.drivers, self.coordinates
        At = np.zeros((n * nc, self.frames))
        # in entry order, each place from zero: the sums of a dense fill, bit for bit
        np.add.at(At, self.rows * nc + self.cols, self.values.T)
        A = np.ascontiguousarray(At.T).reshape(self.frames, n, nc)
        return A[:, : self.equations], A[:, self.equations :]

    def matrix(self, frame: int, with_drivers: bool = True) -> Any:
        """``[J; D]`` (or J alone) on one frame as a scipy CSC matrix, zeros dropped.

        The same matrix, indices sorted, as ``csc_matrix`` of the dense one.
        """
        from scipy.sparse import csc_matrix

        n = self.equations + (self.drivers if with_drivers else 0)
        keep = self.rows < n
        A = csc_matrix(
            (self.values[frame, keep], (self.rows[keep], self.cols[keep])),
            shape=(n, self.coordinates),
        )
        A.sum_duplicates()
        A.eliminate_zeros()
        return A


def constraint_entries(
    m: Mechanism, geom: Geometry, poses: dict[str, Pose], drivers: tuple[str, ...] = ()
) -> SparseJacobian:
    """The joint constraints' Jacobian and the driver rows as sparse entries.

    Columns are (x, y, φ) of each moving link in ``m.links`` order; ``poses`` give the
    configuration (frame link at rest).  A revolute joint of links L0 … Ln gives two
    rows per pair (L0, Li): the difference of the joint's centre carried by each;
    a prismatic joint two rows (equal angles, the second link's point on the first
    link's guide); a driver one row (the relative angle or slide).
    """
    moving = [x for x in m.links if x != m.frame]
    col = {link: 3 * i for i, link in enumerate(moving)}
    F = next(iter(poses.values())).r.shape[0]
    nu = sum(2 * (len(j.links) - 1) if j.kind == "R" else 2 for j in m.joints)
    # revolute pairs, vectorised: one term per (row pair, moving link) with its sign
    t_row: list[int] = []
    t_link: list[str] = []
    t_z: list[complex] = []
    t_sign: list[float] = []
    # prismatic joints and drivers: entries one by one
    e_row: list[int] = []
    e_col: list[int] = []
    e_val: list[FloatArray] = []

    def term(i: int, link: str, z: complex, sign: float) -> None:
        if link in col:
            t_row.append(i)
            t_link.append(link)
            t_z.append(z)
            t_sign.append(sign)

    def entry(i: int, c: int, v: FloatArray | float) -> None:
        e_row.append(i)
        e_col.append(c)
        e_val.append(np.broadcast_to(np.asarray(v, float), (F,)))

    i = 0
    for j in m.joints:
        z = geom.centres[j.id]
        if j.kind == "R":
            for other in j.links[1:]:
                term(i, j.links[0], z, 1.0)
                term(i, other, z, -1.0)
                i += 2
        else:
            a, b = j.links
            if a in col:
                entry(i, col[a] + 2, 1.0)
            if b in col:
                entry(i, col[b] + 2, -1.0)
            _slide_entries(poses, col, a, b, z, 1j * geom.axes[j.id], i + 1, entry)
            i += 2
    for k, d in enumerate(drivers):
        j = m.joint(d)
        a, b = j.links[0], j.links[1]
        if j.kind == "R":
            if b in col:
                entry(nu + k, col[b] + 2, 1.0)
            if a in col:
                entry(nu + k, col[a] + 2, -1.0)
        else:
            _slide_entries(poses, col, a, b, geom.centres[d], geom.axes[d], nu + k, entry)
    T = len(t_row)
    rows = np.asarray(t_row, dtype=np.int_)
    cols = np.asarray([col[x] for x in t_link], dtype=np.int_)
    sign = np.asarray(t_sign)
    values = np.empty((F, 4 * T))
    if T:
        # each link's rotation once, gathered per term
        order = {x: k for k, x in enumerate(dict.fromkeys(t_link))}
        r = np.stack([poses[x].r for x in order], axis=1)
        arm = 1j * r[:, [order[x] for x in t_link]] * (np.asarray(t_z) - 0j)
        values[:, 0::4] = sign
        values[:, 1::4] = sign
        values[:, 2::4] = sign * arm.real
        values[:, 3::4] = sign * arm.imag
    all_rows = np.empty(4 * T, dtype=np.int_)
    all_rows[0::4], all_rows[1::4], all_rows[2::4], all_rows[3::4] = rows, rows + 1, rows, rows + 1
    all_cols = np.empty(4 * T, dtype=np.int_)
    all_cols[0::4], all_cols[1::4] = cols, cols + 1
    all_cols[2::4] = all_cols[3::4] = cols + 2
    if e_row:
        all_rows = np.concatenate([all_rows, e_row])
        all_cols = np.concatenate([all_cols, e_col])
        values = np.concatenate([values, np.stack(e_val, axis=1)], axis=1)
    return SparseJacobian(all_rows, all_cols, values, nu, 3 * len(moving), len(drivers))


def constraint_jacobian(
    m: Mechanism, geom: Geometry, poses: dict[str, Pose], drivers: tuple[str, ...] = ()
) -> tuple[FloatArray, FloatArray]:
    """J (frames × Nu × 3Ns) of the joint constraints, and the driver rows (frames × N × 3Ns).

    Dense (:func:`constraint_entries` filled in): for small mechanisms or few frames.
    Columns are (x, y, φ) of each moving link in ``m.links`` order; ``poses`` give the
    configuration (frame link at rest).
    """
    return constraint_entries(m, geom, poses, drivers).dense()


def _slide_entries(
    poses: dict[str, Pose],
    col: dict[str, int],
    a: str,
    b: str,
    z: complex,
    v: complex,
    row: int,
    entry: Any,
) -> None:
    """Gradient of Re(conj(v_a)(X_b - X_a)): v_a the direction v carried by link a."""
    va = poses[a].r * v
    xb = poses[b].point(z)[0]
    xa = poses[a].point(z)[0]
    for link, sign in ((b, 1.0), (a, -1.0)):
        if link not in col:
            continue
        c = col[link]
        entry(row, c, sign * va.real)
        entry(row, c + 1, sign * va.imag)
        d = 1j * poses[link].r * z
        entry(row, c + 2, sign * (va.conjugate() * d).real)
    if a in col:
        entry(row, col[a] + 2, ((1j * va).conjugate() * (xb - xa)).real)


def check_jacobian(
    m: Mechanism,
    geom: Geometry,
    poses: dict[str, Pose],
    drivers: tuple[str, ...],
    sample: int = 360,
    factor: tuple[FloatArray, FloatArray] | None = None,
) -> JacobianCheck:
    """Rank of J and the determinant with the drivers fixed (nan where undefined).

    Without ``factor`` the determinant is computed on every frame and the rank (an
    SVD per frame) on at most ``sample`` evenly spread frames plus every frame where
    the determinant is small or undefined, since the rank can only drop where the
    determinant does (rank is -1 on frames not examined).  The frames are taken in
    chunks, so memory stays within :data:`MEMORY_BUDGET` bytes of matrices.

    With ``factor`` = (sign, log |.|) per frame of the product of the plan's group
    determinants (see :func:`mjstruct.kinematics.checks.plan_determinant`), J is built
    on a few frames only: the determinant there fixes the constant between the two,
    the determinant on every frame is that constant times the product (its accuracy
    measured on the frames built: ``factor_error``), the rank is full wherever the
    determinant is not small, and an SVD decides the rest (at most ``sample`` frames,
    smallest |det| first, within the memory budget).  When the product does not hold
    (not a square system, or a disagreement above :data:`FACTOR_AGREES`) every frame
    is computed directly, as without ``factor``.
    """
    F = next(iter(poses.values())).r.shape[0]
    finite = np.ones(F, bool)
    for p in poses.values():
        finite &= np.isfinite(p.r) & np.isfinite(p.A[0])
    # in units of the size, relative to the first joint: J's x, y and φ columns then
    # have entries of one order whatever the unit and the origin (in the file's units
    # the φ columns are lengths and the rank test's relative tolerance failed beyond
    # sizes of about 1e8, or 1e9 sizes from the origin); log |det| is converted back
    # (the poses are moved on the frames where J is built only: moving all of them
    # copied every link's jets over every frame, 0.7 GB at 4000 links x 3600 frames)
    geom, move, shift = _in_size_units(m, geom, drivers)

    def at(idx: npt.NDArray[np.intp]) -> dict[str, Pose]:
        return move(poses_at(poses, idx))

    if factor is not None and finite.any():
        got = _factored(m, geom, at, drivers, sample, factor, finite, shift)
        if got is not None:
            return got
    return _direct(m, geom, at, drivers, sample, finite, shift)


def _in_size_units(
    m: Mechanism, geom: Geometry, drivers: tuple[str, ...]
) -> tuple[Geometry, Callable[[dict[str, Pose]], dict[str, Pose]], float]:
    """The geometry moved to the first joint and divided by the size, the same move
    for poses, and log s^k, k = (moving links) - (angle rows: prismatic joints and
    revolute drivers).

    Moving the origin adds multiples of the x, y columns to the φ columns (rank and
    determinant unchanged); dividing lengths by s divides the φ columns by s, and the
    rows whose φ entries are pure numbers (a prismatic joint's equal angles, a
    revolute driver) are multiplied by s to stay as they were: det J_file =
    det J_unit · s^k.
    """
    import dataclasses

    s = geom.scale
    o = next(iter(geom.centres.values()))
    unit = dataclasses.replace(
        geom,
        centres={j: (z - o) / s for j, z in geom.centres.items()},
        points={p: (link, (z - o) / s) for p, (link, z) in geom.points.items()},
        scale=1.0,
    )

    def move(poses: dict[str, Pose]) -> dict[str, Pose]:
        return {
            x: Pose((p.zA - o) / s, [(p.A[0] - o) / s, *(a / s for a in p.A[1:])], p.r, p.w)
            for x, p in poses.items()
        }

    angle_rows = sum(j.kind == "P" for j in m.joints)
    angle_rows += sum(m.joint(d).kind == "R" for d in drivers)
    return unit, move, (len(m.links) - 1 - angle_rows) * float(np.log(s))


#: bytes of Jacobian matrices held at once (frames are taken in chunks within it)
MEMORY_BUDGET = 64 * 2**20
#: frames on which the constant between det J and the plan's product is measured
CALIBRATION_FRAMES = 5
#: the product stands in for det J when it agrees to this (relative) on those frames
FACTOR_AGREES = 1e-6
#: at most this many near-singular frames get an SVD for the rank (the deepest dips)
RANK_FRAMES = 36


def _dips(logdet: FloatArray, weak: npt.NDArray[np.bool_], limit: int) -> npt.NDArray[np.intp]:
    """Frames of the weak runs where log |det| has a local minimum (undefined ones
    first, then the deepest), at most ``limit``, in frame order."""
    F = logdet.size
    x = np.where(np.isfinite(logdet), logdet, -np.inf)
    left = np.concatenate([[np.inf], x[:-1]])
    right = np.concatenate([x[1:], [np.inf]])
    cand = np.flatnonzero(weak & (x <= left) & (x <= right))
    if cand.size == 0:
        return np.zeros(0, dtype=np.intp)
    pick = cand[np.argsort(x[cand], kind="stable")][:limit]
    return np.sort(pick) if F else pick


def _sizes(m: Mechanism, drivers: tuple[str, ...]) -> tuple[int, int]:
    """(Nu, 3Ns): constraint equations and link coordinates."""
    nu = sum(2 * (len(j.links) - 1) if j.kind == "R" else 2 for j in m.joints)
    return nu, 3 * (len(m.links) - 1)


def _chunk(nu: int, nc: int) -> int:
    return max(1, MEMORY_BUDGET // (8 * max(1, (nu + 1) * nc)))


#: above this many rows the determinant is taken from a sparse LU factorisation
SPARSE_ROWS = 200
#: above this many matrix entries no SVD is run for the rank (n^3 time); the rank is
#: then known only where the determinant is not small
SVD_ENTRIES = 4_000_000


def _slogdet(A: Any) -> tuple[float, float]:
    """Sign and log |det| of one large square sparse matrix (CSC; sparse LU)."""
    from scipy.sparse.linalg import splu

    try:
        lu = splu(A)
    except RuntimeError:  # exactly singular
        return 0.0, float("-inf")
    d = lu.U.diagonal()
    sign = float(np.prod(np.sign(d))) * _parity(lu.perm_r) * _parity(lu.perm_c)
    with np.errstate(divide="ignore"):
        return sign, float(np.log(np.abs(d)).sum())


def _slogdets(sj: SparseJacobian) -> tuple[FloatArray, FloatArray]:
    """Sign and log |det| of ``[J; D]`` on every frame of the entries.

    Small systems (at most :data:`SPARSE_ROWS` rows): one stacked LAPACK call on the
    dense matrices; larger ones: a sparse LU per frame, built from the entries (no
    dense matrix).
    """
    if sj.equations + sj.drivers <= SPARSE_ROWS:
        J, D = sj.dense()
        sign, logdet = np.linalg.slogdet(np.concatenate([J, D], axis=1))
        return np.asarray(sign, dtype=np.float64), np.asarray(logdet, dtype=np.float64)
    got = [_slogdet(sj.matrix(i)) for i in range(sj.frames)]
    return np.array([g[0] for g in got]), np.array([g[1] for g in got])


def _parity(perm: npt.NDArray[np.int32]) -> float:
    """+1 for an even permutation, -1 for an odd one.

    n minus the number of cycles is the number of swaps; each element's cycle is
    labelled by its smallest member through pointer doubling (log2 n array steps).

    >>> _parity(np.array([1, 0, 2])), _parity(np.array([1, 2, 0]))
    (-1.0, 1.0)
    """
    n = perm.size
    label = np.arange(n)
    step = np.asarray(perm, dtype=np.intp)
    reach = 1
    while reach < n:
        label = np.minimum(label, label[step])
        step = step[step]
        reach *= 2
    cycles = int(np.count_nonzero(label == np.arange(n)))
    return -1.0 if (n - cycles) % 2 else 1.0


def _ranks(J: FloatArray, nu: int, nc: int) -> IntArray:
    if J.shape[0] == 0:
        return np.zeros(0, dtype=np.int_)
    sv = np.linalg.svd(J, compute_uv=False)
    tol = sv.max(axis=1, keepdims=True) * max(nu, nc) * RANK_RTOL
    return np.asarray((sv > tol).sum(axis=1), dtype=np.int_)


def _direct(
    m: Mechanism,
    geom: Geometry,
    at: Callable[[npt.NDArray[np.intp]], dict[str, Pose]],
    drivers: tuple[str, ...],
    sample: int,
    finite: npt.NDArray[np.bool_],
    shift: float = 0.0,
) -> JacobianCheck:
    """Determinant on every frame, rank on a sample and where the determinant is small.

    ``geom`` in units of the size, ``at(frames)`` the poses on those frames in the
    same units; ``shift`` converts log |det| back to the file's units
    (:func:`_in_size_units`).  Large systems take a sparse LU per
    frame (no dense matrix), and no SVD beyond :data:`SVD_ENTRIES` (their rank is
    then known only where the determinant is not small).
    """
    F = finite.size
    nu, nc = _sizes(m, drivers)
    square = nu + len(drivers) == nc
    step = _chunk(nu, nc)
    sign = np.full(F, np.nan)
    logdet = np.full(F, np.nan)
    idx = np.flatnonzero(finite)
    if square:
        for lo in range(0, idx.size, step):
            part = idx[lo : lo + step]
            sj = constraint_entries(m, geom, at(part), drivers)
            sign[part], logdet[part] = _slogdets(sj)
        logdet = np.where(sign == 0, -np.inf, logdet + shift)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        det = sign * np.exp(logdet)
    top = np.nanmax(logdet) if np.isfinite(logdet).any() else np.nan
    look = np.zeros(F, bool)
    look[np.linspace(0, F - 1, min(F, sample)).astype(int)] = True
    look |= ~(logdet >= top + np.log(NEAR_SINGULAR))  # small or undefined determinant
    look &= finite
    if nu * nc > SVD_ENTRIES:
        look[:] = False
    rank = np.full(F, -1)
    if square and nu * nc > SVD_ENTRIES:
        # a nonzero determinant of [J; D]: the rows of J are independent
        rank[finite & (logdet >= top + np.log(NEAR_SINGULAR))] = nu
    kept: list[FloatArray] = []
    where = np.flatnonzero(look)
    for lo in range(0, where.size, step):
        part = where[lo : lo + step]
        J, _ = constraint_jacobian(m, geom, at(part), drivers)
        rank[part] = _ranks(J, nu, nc)
        if sum(k.shape[0] for k in kept) < step:
            kept.append(J[: step - sum(k.shape[0] for k in kept)])
    J = np.concatenate(kept) if kept else np.zeros((0, nu, nc))
    return JacobianCheck(
        J, rank, det, nu, nc, where[: J.shape[0]], log_abs_det=logdet if square else None
    )


def _factored(
    m: Mechanism,
    geom: Geometry,
    at: Callable[[npt.NDArray[np.intp]], dict[str, Pose]],
    drivers: tuple[str, ...],
    sample: int,
    factor: tuple[FloatArray, FloatArray],
    finite: npt.NDArray[np.bool_],
    shift: float = 0.0,
) -> JacobianCheck | None:
    """The determinant from the plan's product, J on a few frames; None if it fails
    (``geom``, ``at`` and ``shift`` as in :func:`_direct`)."""
    sign, logf = factor
    F = logf.shape[0]
    nu, nc = _sizes(m, drivers)
    if nu + len(drivers) != nc:
        return None  # not square: redundant constraints or a wrong driver count
    ok = finite & np.isfinite(logf) & (sign != 0)
    if not ok.any():
        return None
    # calibrate on well-conditioned frames spread over the motion
    good = np.flatnonzero(ok & (logf >= logf[ok].max() - np.log(2.0)))
    n = min(good.size, CALIBRATION_FRAMES)
    # evenly spread (integer arithmetic: distinct, in order)
    cal = good[[k * (good.size - 1) // max(n - 1, 1) for k in range(n)]]
    # [J; D] on the calibration frames as sparse entries (linear in the joints): a
    # dense determinant for small systems, a sparse LU for large ones; the dense J is
    # kept for the result only where it fits the memory budget
    sj = constraint_entries(m, geom, at(cal), drivers)
    s_dir, l_dir = _slogdets(sj)
    fits = cal.size * 8 * nu * nc <= MEMORY_BUDGET
    J = sj.dense()[0] if fits else np.zeros((0, nu, nc))
    cal_kept = cal[: J.shape[0]]
    l_dir = l_dir + shift
    if not (np.isfinite(l_dir).all() and (s_dir != 0).all()):
        return None
    log_c = l_dir - logf[cal]
    sign_c = s_dir * sign[cal]
    mid = float(sorted(log_c)[log_c.size // 2])
    err = float(np.abs(np.expm1(log_c - mid)).max())
    if not (err <= FACTOR_AGREES and (sign_c == sign_c[0]).all()):
        return None
    logdet = np.where(finite, mid + logf, np.nan)
    with np.errstate(over="ignore", under="ignore"):
        det = np.where(finite, sign_c[0] * sign * np.exp(logdet), np.nan)
    top = float(np.nanmax(logdet))
    rank = np.full(F, -1)
    strong = finite & (logdet >= top + np.log(NEAR_SINGULAR))
    rank[strong] = nu  # a nonzero determinant of [J; D]: the rows of J are independent
    soft = finite & ~strong
    limit = min(sample, RANK_FRAMES, _chunk(nu, nc))
    weak = _dips(logdet, soft, limit) if soft.any() else np.zeros(0, dtype=np.intp)
    if nu * nc > SVD_ENTRIES:
        weak = weak[:0]
    if weak.size:
        Jw, _ = constraint_jacobian(m, geom, at(weak), drivers)
        rank[weak] = _ranks(Jw, nu, nc)
    else:
        Jw = np.zeros((0, nu, nc))
    keep = np.concatenate([cal_kept, weak])
    order = np.argsort(keep, kind="stable")
    return JacobianCheck(
        np.concatenate([J, Jw])[order],
        rank,
        det,
        nu,
        nc,
        keep[order],
        factor_error=err,
        log_abs_det=logdet,
    )


def jacobian_at_reference(m: Mechanism) -> JacobianCheck:
    """The Jacobian check at the file's reference configuration (all rotations zero)."""
    expect_mechanism(m)
    return check_jacobian(m, read_geometry(m), reference_poses(m), tuple(m.drivers))
