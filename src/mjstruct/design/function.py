"""Function synthesis: an output link's angle as a prescribed function of the driver.

Owns :func:`function_problem` (the task as a :class:`~mjstruct.design.track.
TrackProblem` whose targets are angles of the output link at the targets' driver
values; ``timing_offset`` / ``angle_offset`` make either column relative) and
:func:`freudenstein`, the exact start where it applies: for a hinged four-bar driven
at one frame pivot whose output is the link hinged at the other, Freudenstein's
equation

    K1 cos ψ − K2 cos φ + K3 = cos(φ − ψ),  K1 = d/a, K2 = d/c,
    K3 = (a² − b² + c² + d²) / (2 a c)

(φ the crank's and ψ the output's direction from the frame line, a, b, c, d the crank,
coupler, output and frame lengths) is linear in K1, K2, K3: three precision points
fix them exactly [Freudenstein 1955], more are fitted by linear least squares.  With
the frame pivots of the starting mechanism kept, each gives a four-bar assembled at
the first target (relative angles: for each offset of a grid); the best join the
global search's first population and its local starts, and the least squares over all
points on the true angle errors follows.

References
----------
.. [1] F. Freudenstein, "Approximate synthesis of four-bar linkages", Transactions of
   the ASME, 77, 1955. [Freudenstein 1955] in docs/references.md.

Examples
--------
Three precision points of a known four-bar give back its lengths:

>>> import math
>>> a, b, c, d = 0.3, 1.0, 0.8, 1.0
>>> def psi(phi):  # the output's direction, open assembly, by the law of cosines
...     A = complex(a * math.cos(phi), a * math.sin(phi))
...     e = complex(d, 0) - A
...     f = abs(e)
...     beta = math.acos((c * c + f * f - b * b) / (2 * c * f))
...     import cmath
...     return cmath.phase(-e) - beta
>>> phis = [0.3, 1.2, 2.0]
>>> K = freudenstein(phis, [psi(p) for p in phis])
>>> [round(x, 9) for x in lengths_of(K, d)]
[0.3, 1.0, 0.8]
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Sequence

import numpy as np

from mjstruct.design.population import DesignSpace
from mjstruct.design.task import Task, is_fourbar
from mjstruct.design.track import TrackProblem
from mjstruct.kinematics.model import KinematicModel
from mjstruct.typing import FloatArray


def freudenstein(
    phi: Sequence[float] | FloatArray, psi: Sequence[float] | FloatArray
) -> tuple[float, float, float]:
    """K1, K2, K3 of Freudenstein's equation through the (φ, ψ) pairs: exact for three,
    least squares for more."""
    p, s = np.asarray(phi, float), np.asarray(psi, float)
    M = np.column_stack([np.cos(s), -np.cos(p), np.ones_like(p)])
    rhs = np.cos(p - s)
    K = np.linalg.lstsq(M, rhs, rcond=None)[0]
    return float(K[0]), float(K[1]), float(K[2])


def lengths_of(K: tuple[float, float, float], d: float) -> tuple[float, float, float] | None:
    """Crank a, coupler b and output c from K1, K2, K3 and the frame d (None: no
    four-bar, a length that is not positive)."""
    K1, K2, K3 = K
    if K1 <= 0 or K2 <= 0:
        return None
    a, c = d / K1, d / K2
    b2 = a * a + c * c + d * d - 2 * a * c * K3
    if b2 <= 0:
        return None
    return a, math.sqrt(b2), c


def _fourbar_joints(task: Task) -> tuple[str, str, str, str] | None:
    """(O1, A, B, O2) when Freudenstein applies to the task's mechanism and output."""
    m = task.mechanism
    if m is None or not is_fourbar(m) or task.link is None:
        return None
    driver = m.joint(m.drivers[0])
    if m.frame not in driver.links:
        return None
    other = next(j for j in m.joints if m.frame in j.links and j.id != driver.id)
    if task.link not in other.links:
        return None
    crank = next(x for x in driver.links if x != m.frame)
    A = next(j for j in m.joints if crank in j.links and j.id != driver.id)
    B = next(j for j in m.joints if task.link in j.links and j.id != other.id)
    return driver.id, A.id, B.id, other.id


#: offsets tried per relative column (input and output) when the angles are relative
OFFSET_GRID = 24
#: Freudenstein four-bars kept as starts
FREUDENSTEIN_STARTS = 4


def freudenstein_starts(problem: TrackProblem) -> list[FloatArray]:
    """The global variables of four-bars from Freudenstein's equation: three precision
    points (first, middle, last target) exactly and all targets by linear least
    squares; the frame pivots kept, assembled at the first target.  Relative driver
    values or angles (``timing_offset``, ``angle_offset``) have their offsets tried on
    a grid of ``OFFSET_GRID`` values each; every four-bar is screened in one batched
    call and the best ``FREUDENSTEIN_STARTS`` (feasible first) are kept."""
    task = problem.task
    joints = _fourbar_joints(task)
    if joints is None or problem.angles is None or problem.timing is None:
        return []
    _, An, Bn, _ = joints
    space, model = problem.space, problem.space.model
    g = model.geometry
    start = problem.start()
    k = space.size
    O1, A0, B0, O2 = (g.centres[j] for j in joints)
    c1 = cmath.phase(A0 - O1) - float(model.q_ref[0])  # crank direction = q + c1
    c3 = g.char_angle[task.link or ""] - cmath.phase(B0 - O2)  # output angle = ψ + c3
    beta, d = cmath.phase(O2 - O1), abs(O2 - O1)
    grid = np.linspace(-math.pi, math.pi, OFFSET_GRID, endpoint=False)
    qoffs = grid if problem.offset else [0.0]
    aoffs = grid if problem.angle_offset else [0.0]
    T = len(problem.timing)
    picks = [[0, T // 2, T - 1]] if T >= 3 else []
    if T > 3:
        picks.append(list(range(T)))
    rows = []
    for qoff in qoffs:
        for aoff in aoffs:
            phi = problem.timing + qoff + c1 - beta
            psi = problem.angles + aoff - c3 - beta
            for idx in picks:
                L = lengths_of(freudenstein(phi[idx], psi[idx]), d)
                if L is None:
                    continue
                a, _, c = L
                pos = dict(space.start)
                pos[An] = O1 + a * cmath.exp(1j * (beta + phi[0]))
                pos[Bn] = O2 + c * cmath.exp(1j * (beta + psi[0]))
                x = [v for n in space.names for v in (pos[n].real, pos[n].imag)]
                extra = ([qoff] if problem.offset else []) + (
                    [aoff] if problem.angle_offset else []
                )
                rows.append(np.concatenate([x, extra if extra else start[k:]]))
    if not rows:
        return []
    X = np.clip(np.array(rows), *problem.bounds())
    if len(X) <= FREUDENSTEIN_STARTS:
        return list(X)
    judged = problem.assess(X)
    problem.evaluations += len(X)
    worst = np.min(np.stack(list(judged.margins.values())), axis=0)
    key = np.where(worst >= 0, judged.energy, np.inf)
    order = np.lexsort((-worst, key))[:FREUDENSTEIN_STARTS]
    return [X[i] for i in order]


def function_problem(task: Task) -> TrackProblem:
    """The function task ``task`` ready for :func:`~mjstruct.design.search.solve`."""
    assert task.kind == "function" and task.mechanism is not None
    model = KinematicModel.build(task.mechanism)
    space = DesignSpace.build(model, task.region, task.fixed, margin=1.0, points=())
    q, angles = task.targets[:, 0].copy(), task.targets[:, 1].copy()
    dense = range_targets(q, angles)
    fitted = task.objective == "range" and dense is not None
    if fitted:
        assert dense is not None
        q, angles = np.concatenate([q, dense[0]]), np.concatenate([angles, dense[1]])
    problem = TrackProblem(
        task, None, None, task.link, angles, 1.0, q, angle_offset=task.angle_offset, space=space
    )
    problem.range_check, problem.range_fitted = dense, fitted
    problem.extra_starts = freudenstein_starts(problem)
    return problem


#: driver values between the first and last target at which a function task's error
#: over the range is measured (and, with ``objective: "range"``, fitted)
RANGE_SAMPLES = 41


def range_targets(q: FloatArray, angles: FloatArray) -> tuple[FloatArray, FloatArray] | None:
    """The function the targets describe over the interval they span: ``RANGE_SAMPLES``
    equally spaced driver values and the angles of the cubic spline through the
    targets there (angles unwrapped along q); None with fewer than three targets.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.linspace(0.0, 1.0, 6)
    >>> qd, ad = range_targets(x, x**3)          # a cubic: the spline is exact
    >>> bool(np.allclose(ad, qd**3)), float(qd[0]), float(qd[-1])
    (True, 0.0, 1.0)
    """
    from scipy.interpolate import CubicSpline

    order = np.argsort(q)
    qs, a = q[order], np.unwrap(angles[order])
    if len(qs) < 3 or np.any(np.diff(qs) <= 0):
        return None
    grid = np.linspace(qs[0], qs[-1], RANGE_SAMPLES)
    out: FloatArray = CubicSpline(qs, a)(grid)
    return grid, out
