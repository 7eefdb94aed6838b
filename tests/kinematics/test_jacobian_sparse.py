"""The full Jacobian check from sparse entries against the dense computation.

The check builds ``[J; D]`` as sparse entries (linear in the joints) and takes its
determinant by a sparse LU beyond :data:`~mjstruct.kinematics.jacobian.SPARSE_ROWS`
rows.  The oracle here is the dense computation the check used to make, written
out in the test: every joint's rows filled into a dense matrix per frame, numpy's
``slogdet`` and an SVD for the rank on every frame.  The check is run with the sparse
path forced on every system (``SPARSE_ROWS = 0``) and with its default, on every
shipped example with geometry and on random mechanisms.
"""

from __future__ import annotations

import glob

import numpy as np
import pytest

from mjstruct.io import read_mechanism
from mjstruct.kinematics import jacobian
from mjstruct.kinematics.checks import plan_determinant
from mjstruct.kinematics.geometry import Geometry
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import _analyse, kinematic_analysis
from mjstruct.kinematics.tolerances import CLOSURE_TOL, NEAR_SINGULAR, RANK_RTOL
from mjstruct.kinematics.triangles import Pose
from mjstruct.mechanism import Mechanism
from mjstruct.testing import random_geometry, random_mechanism, shared_crank
from project_paths import EXAMPLES


def dense_matrices(
    m: Mechanism,
    geom: Geometry,
    poses: dict[str, Pose],
    drivers: tuple[str, ...],
    origin: complex = 0j,
    size: float = 1.0,
) -> tuple[np.ndarray, int]:
    """[J; D] on every frame, dense, and Nu.

    Columns x, y and the rotation of each moving link about ``origin``, lengths in
    units of ``size``: one row pair per revolute joint pair, two rows per prismatic
    joint (equal angles; the second link's point on the first link's guide), one per
    driver.
    """
    moving = [x for x in m.links if x != m.frame]
    col = {x: 3 * i for i, x in enumerate(moving)}
    F = next(iter(poses.values())).r.shape[0]
    nu = sum(2 * (len(j.links) - 1) if j.kind == "R" else 2 for j in m.joints)
    A = np.zeros((F, nu + len(drivers), 3 * len(moving)))

    def point(i: int, link: str, z: complex, s: float) -> None:
        if link in col:
            c = col[link]
            d = 1j * poses[link].r * (z - origin) / size
            A[:, i, c] += s
            A[:, i + 1, c + 1] += s
            A[:, i, c + 2] += s * d.real
            A[:, i + 1, c + 2] += s * d.imag

    def slide(i: int, a: str, b: str, z: complex, v: complex) -> None:
        va = poses[a].r * v
        gap = (poses[b].point(z)[0] - poses[a].point(z)[0]) / size
        for link, s in ((b, 1.0), (a, -1.0)):
            if link in col:
                c = col[link]
                arm = 1j * poses[link].r * (z - origin) / size
                A[:, i, c] += s * va.real
                A[:, i, c + 1] += s * va.imag
                A[:, i, c + 2] += s * (va.conjugate() * arm).real
        if a in col:
            A[:, i, col[a] + 2] += ((1j * va).conjugate() * gap).real

    i = 0
    for j in m.joints:
        z = geom.centres[j.id]
        if j.kind == "R":
            for other in j.links[1:]:
                point(i, j.links[0], z, 1.0)
                point(i, other, z, -1.0)
                i += 2
        else:
            a, b = j.links
            for link, s in ((a, 1.0), (b, -1.0)):
                if link in col:
                    A[:, i, col[link] + 2] += s
            slide(i + 1, a, b, z, 1j * geom.axes[j.id])
            i += 2
    for k, d in enumerate(drivers):
        j = m.joint(d)
        a, b = j.links[0], j.links[1]
        if j.kind == "R":
            for link, s in ((b, 1.0), (a, -1.0)):
                if link in col:
                    A[:, nu + k, col[link] + 2] += s
        else:
            slide(nu + k, a, b, geom.centres[d], geom.axes[d])
    return A, nu


def dense_oracle(
    m: Mechanism, geom: Geometry, poses: dict[str, Pose], drivers: tuple[str, ...]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sign and log |det| of [J; D] (file units) and the rank of J (SVD, in units of
    the size about the first joint, as the check decides it) on every frame."""
    with jacobian.one_blas_thread():  # many small matrices: BLAS threads only wait
        return _oracle(m, geom, poses, drivers)


def _oracle(
    m: Mechanism, geom: Geometry, poses: dict[str, Pose], drivers: tuple[str, ...]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    A, nu = dense_matrices(m, geom, poses, drivers)
    F = A.shape[0]
    finite = np.isfinite(A).all(axis=(1, 2))
    sign = np.full(F, np.nan)
    logdet = np.full(F, np.nan)
    rank = np.full(F, -1)
    if finite.any():
        if A.shape[1] == A.shape[2]:
            sign[finite], logdet[finite] = np.linalg.slogdet(A[finite])
        o = next(iter(geom.centres.values()))
        U, _ = dense_matrices(m, geom, poses, drivers, o, geom.scale)
        J = U[finite, :nu]
        sv = np.linalg.svd(J, compute_uv=False)
        tol = sv.max(axis=1, keepdims=True) * max(J.shape[1:]) * RANK_RTOL
        rank[finite] = (sv > tol).sum(axis=1)
    return sign, logdet, rank


def _cases() -> list[tuple[str, Mechanism, int]]:
    out = []
    for f in sorted(glob.glob(str(EXAMPLES / "*.json"))):
        m = read_mechanism(f)
        if all(j.at is not None for j in m.joints):
            out.append((f.rsplit("/", 1)[-1], m, 72))
    out.append(("shared crank, 82 links", shared_crank(40), 12))
    for seed in (1, 4, 5, 8, 9, 11, 13, 17):
        m = random_geometry(random_mechanism(1 + seed % 5, seed), seed)
        out.append((f"random {seed}", m, 31))
    return out


CASES = _cases()


@pytest.mark.parametrize("name,m,frames", CASES, ids=[c[0] for c in CASES])
def test_sparse_full_check_equals_the_dense_one(
    name: str, m: Mechanism, frames: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    try:
        model = KinematicModel.build(m)
    except Exception:  # a random mechanism its drivers do not determine
        pytest.skip("not planned")
    default = kinematic_analysis(model, frames=frames, checks="full")
    monkeypatch.setattr(jacobian, "SPARSE_ROWS", 0)  # a sparse LU on every system
    sparse = kinematic_analysis(model, frames=frames, checks="full")
    # the results: the same keys and values, warnings, ranks and determinant signs
    a, b = default.checks["jacobian"], sparse.checks["jacobian"]
    for key in a:
        if key in ("min_abs_det", "max_abs_det", "det_from_plan_error"):
            continue
        assert a[key] == b[key], key
    for key in ("min_abs_det", "max_abs_det"):
        if a[key] is None:
            assert b[key] is None
        else:
            assert b[key] == pytest.approx(a[key], rel=1e-9)
    assert default.warnings == sparse.warnings
    ja, jb = default.jacobian, sparse.jacobian
    assert ja is not None and jb is not None
    assert np.array_equal(ja.rank, jb.rank)
    # against the dense oracle on every frame
    _, motion = _analyse(model, model.sweep(frames), 1.0, CLOSURE_TOL)
    sign, logdet, rank = dense_oracle(m, model.geometry, motion.evaluation.poses, model.drivers)
    for jc in (ja, jb):
        fin = np.isfinite(logdet) & np.isfinite(jc.log_det) & default.valid
        if fin.any():
            # |det| relative to its largest: equal to rounding (at a singular frame
            # both are rounding, of either sign)
            top = logdet[fin].max()
            rel = np.exp(logdet - top)
            mine = np.exp(jc.log_det - jc.log_det[fin].max())
            assert np.abs(mine[fin] - rel[fin]).max() <= 1e-9
            clear = fin & (rel > 1e-6)
            assert np.array_equal(np.sign(jc.det[clear]), sign[clear])
            flagged = np.flatnonzero(fin & (rel < NEAR_SINGULAR))
            assert np.array_equal(flagged, np.flatnonzero(fin & (mine < NEAR_SINGULAR)))
        seen = jc.rank >= 0
        assert np.array_equal(jc.rank[seen], rank[seen])


def test_entries_are_linear_in_the_joints_and_build_no_dense_matrix() -> None:
    m = shared_crank(500)  # 1002 links: a dense [J; D] would be 3003 x 3003
    model = KinematicModel.build(m)
    motion = model.motion(model.sweep(4))
    sj = jacobian.constraint_entries(m, model.geometry, motion.evaluation.poses, model.drivers)
    assert sj.values.shape[1] <= 8 * len(m.joints) + 2 * len(m.links)
    A = sj.matrix(0)
    assert A.shape == (sj.equations + sj.drivers, sj.coordinates)
    # the sparse determinant equals the plan's product up to one constant
    _, logf = plan_determinant(motion)
    dets = [jacobian._slogdet(sj.matrix(i)) for i in range(4)]
    c = [d[1] - lf for d, lf in zip(dets, logf, strict=True)]
    assert max(c) - min(c) < 1e-9


def test_permutation_parity_counts_the_swaps() -> None:
    # the sparse LU's row and column permutations: parity from the cycles
    def swaps(perm: np.ndarray) -> int:
        seen, total = set(), 0
        for i in range(perm.size):
            length = 0
            while i not in seen:
                seen.add(i)
                i = int(perm[i])
                length += 1
            total += max(0, length - 1)
        return total

    rng = np.random.default_rng(5)
    for n in (0, 1, 2, 3, 7, 64, 1001):
        for _ in range(8):
            p = rng.permutation(n)
            assert jacobian._parity(p) == (-1.0 if swaps(p) % 2 else 1.0)
