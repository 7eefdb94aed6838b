"""Burmester's theory: the dyads that guide a moving plane through four or five poses.

Owns :func:`burmester_dyads`: the centre points C (fixed pivots) and circle points m
(moving pivots, in the moving plane's coordinates) with |T_j(m) − C| the same in
every pose j, where T_j(m) = P_j + e^{iθ_j} m places the plane's point m in pose j
[Burmester 1888; Sandor & Erdman 1984].  Subtracting the first pose's equation from
the others leaves, per pose j ≥ 2, one equation bilinear in C and m:

    C · w_j(m) = e_j(m) / 2,  w_j = P_j − P_1 + (R_j − R_1) m,
    e_j = |P_j|² − |P_1|² + 2 Re((P̄_j R_j − P̄_1 R_1) m),  R_j = e^{iθ_j}.

Five poses give four equations in the four unknowns: a finite set of Burmester
point pairs (at most four real ones), found here by Newton's method from a grid of
starts, vectorised over the starts, with the duplicates merged.  Four poses give a
one-parameter family (the centre- and circle-point curves), sampled here by fixing
the circle point's x at a grid of values.  Two dyads make a four-bar.

References
----------
.. [1] L. Burmester, Lehrbuch der Kinematik, 1888. [Burmester 1888] in
   docs/references.md.
.. [2] G. N. Sandor, A. G. Erdman, Advanced Mechanism Design, vol. 2, 1984.
   [Sandor & Erdman 1984] in docs/references.md.

Examples
--------
The two dyads of a known four-bar (pivots 0 and 2, crank 0.5, coupler 1.8, rocker
1.2) are found back from five poses of its coupler (origin at A, x axis along AB):

>>> import cmath
>>> def pose(phi):
...     A = 0.5 * cmath.exp(1j * phi)
...     e = 2 - A
...     B = A + 1.8 * cmath.exp(1j * (cmath.phase(e) + cmath.acos(
...         (1.8**2 + abs(e) ** 2 - 1.2**2) / (2 * 1.8 * abs(e))).real))
...     return A, cmath.phase(B - A)
>>> dyads = burmester_dyads([pose(p) for p in (0.2, 0.9, 1.6, 2.3, 3.0)], size=2.0)
>>> [any(abs(C - C0) + abs(m - m0) < 1e-7 for C, m in dyads) for C0, m0 in ((0, 0), (2, 1.8))]
[True, True]
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from mjstruct.typing import ComplexArray, FloatArray

#: Newton iterations per start
ITERATIONS = 40
#: a root: the equations' residual, relative to the size squared
ROOT = 1e-10


def _system(P: ComplexArray, R: ComplexArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Residuals (starts × equations) and Jacobians (starts × equations × 4) at the
    unknowns v = (cx, cy, mx, my) per start."""
    c = v[:, 0] + 1j * v[:, 1]
    m = v[:, 2] + 1j * v[:, 3]
    dP = P[1:] - P[0]
    dR = R[1:] - R[0]
    g = np.conj(P[1:]) * R[1:] - np.conj(P[0]) * R[0]
    e = np.abs(P[1:]) ** 2 - abs(P[0]) ** 2
    w = dP[None, :] + dR[None, :] * m[:, None]
    F = (np.conj(c)[:, None] * w).real - 0.5 * e[None, :] - (g[None, :] * m[:, None]).real
    h = np.conj(c)[:, None] * dR[None, :]
    J = np.empty((*F.shape, 4))
    J[..., 0] = w.real
    J[..., 1] = w.imag
    J[..., 2] = h.real - g.real[None, :]
    J[..., 3] = -h.imag + g.imag[None, :]
    return F, J


def burmester_dyads(
    poses: Sequence[tuple[complex, float]], size: float, grid: int = 9, samples: int = 24
) -> list[tuple[complex, complex]]:
    """Dyads (C, m) guiding the plane through ``poses`` (position of the plane's
    origin, its angle): the Burmester pairs for five poses, samples of the curves
    for four; searched within ``size`` (a length) of the poses."""
    if len(poses) not in (4, 5):
        raise ValueError("Burmester's theory needs four or five poses")
    P = np.array([p for p, _ in poses], complex)
    R = np.exp(1j * np.array([t for _, t in poses], float))
    centre = P.mean()
    span = np.linspace(-size, size, grid)
    if len(poses) == 5:
        gx, gy, hx, hy = np.meshgrid(span, span, span, span, indexing="ij")
        v = np.column_stack(
            [centre.real + gx.ravel(), centre.imag + gy.ravel(), hx.ravel(), hy.ravel()]
        )
        free = np.ones(4, bool)
    else:
        # the circle point's x fixed at ``samples`` values; Newton on (cx, cy, my)
        mx = np.linspace(-size, size, samples)
        gx, gy, hy, fx = np.meshgrid(span[::2], span[::2], span[::2], mx, indexing="ij")
        v = np.column_stack(
            [centre.real + gx.ravel(), centre.imag + gy.ravel(), fx.ravel(), hy.ravel()]
        )
        free = np.array([True, True, False, True])
    scale2 = max(size * size, 1e-300)
    for _ in range(ITERATIONS):
        F, J = _system(P, R, v)
        Jf = J[..., free]
        with np.errstate(all="ignore"):
            step = np.linalg.lstsq(Jf[0], F[0], rcond=None)[0] if len(v) == 1 else None
            if step is None:
                try:
                    step = np.linalg.solve(Jf, F[..., None])[..., 0]
                except np.linalg.LinAlgError:
                    step = np.stack(
                        [np.linalg.lstsq(a, b, rcond=None)[0] for a, b in zip(Jf, F, strict=True)]
                    )
        v[:, free] -= np.where(np.isfinite(step), step, 0.0)
    F, _ = _system(P, R, v)
    ok = np.isfinite(F).all(axis=1) & (np.abs(F).max(axis=1) < ROOT * scale2)
    ok &= np.abs(v[:, :2] - [centre.real, centre.imag]).max(axis=1) < 10 * size
    ok &= np.abs(v[:, 2:]).max(axis=1) < 10 * size
    out: list[tuple[complex, complex]] = []
    for row in v[ok]:
        C, m = complex(row[0], row[1]), complex(row[2], row[3])
        if all(abs(C - C2) + abs(m - m2) > 1e-6 * size for C2, m2 in out):
            out.append((C, m))
    out.sort(key=lambda d: (round(d[1].real, 9), round(d[1].imag, 9)))
    return out
