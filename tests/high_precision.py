"""An independent high-precision solve of a one-driver mechanism at one driver value.

Written for the kinematics' error-estimate tests and ``benchmarks/error_vs_time.py``:
the constraint equations of ``full_system_continuation.FullSystem`` (every moving link
a rigid body with its pose (x, y, φ), every joint's constraints at once, no Assur
decomposition, no plan) evaluated in mpmath at ``DIGITS`` significant digits, and
Newton's method from a double-precision configuration (its Jacobian in doubles: each
step gains about 16 − log10 of the condition number digits; the residual is driven
below 10^-(DIGITS - 10) of the size).  The velocity and acceleration analogs of every
joint centre are central differences of the centres solved at q ± h (and q), with h
a millionth of the distance to the nearest fold asked for (``scale_h``) or 1e-12:
their truncation error is h² times the next derivative, far below the doubles'
rounding at these precisions.

>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.io import read_mechanism
>>> import numpy as np
>>> m = read_mechanism(example_path("four-bar"))
>>> ref = Reference(m)
>>> pos, sig, kap = ref.analogs(ref.system.q_ref + 0.5)
>>> abs(complex(pos["B"]) - 0) > 0
True
"""

from __future__ import annotations

import mpmath as mp
import numpy as np
import numpy.typing as npt

from full_system_continuation import FullSystem, reach
from mjstruct.mechanism import Mechanism

DIGITS = 60
FloatArray = npt.NDArray[np.float64]


class Reference:
    """High-precision configurations of ``m`` along its driver (one revolute driver)."""

    def __init__(self, m: Mechanism) -> None:
        self.system = FullSystem(m)
        self.m = m

    def _residual(self, x: list[mp.mpf], dq: mp.mpf) -> list[mp.mpf]:
        s = self.system
        pose = {}
        for link, c in s.col.items():
            pose[link] = (mp.mpc(x[c], x[c + 1]), mp.expjpi(x[c + 2] / mp.pi))
        frame = s.mechanism.frame
        pose[frame] = (mp.mpc(s.origin[frame].real, s.origin[frame].imag), mp.mpc(1))
        angle = {link: x[c + 2] for link, c in s.col.items()}
        angle[frame] = mp.mpf(0)

        def point(link: str, z: complex) -> mp.mpc:
            c, r = pose[link]
            o = s.origin[link]
            return c + r * mp.mpc(z.real - o.real, z.imag - o.imag)

        out: list[mp.mpf] = []
        for joint, a, b in s.pairs:
            d = point(a, s.centres[joint]) - point(b, s.centres[joint])
            out += [d.real, d.imag]
        for joint, a, b, u in s.guides:
            z = s.centres[joint]
            D = point(b, z) - point(a, z)
            nrm = pose[a][1] * mp.mpc(u.real, u.imag)
            out += [angle[b] - angle[a], (mp.conj(nrm) * D).imag]
        a, b = s.driver
        out.append(angle[b] - angle[a] - dq)
        return out

    def solve(self, dq: mp.mpf, x0: FloatArray) -> list[mp.mpf]:
        """The configuration at q_ref + ``dq`` (mpmath), by Newton from ``x0``."""
        s = self.system
        with mp.workdps(DIGITS):
            x = [mp.mpf(float(v)) for v in x0]
            for _ in range(40):
                R = self._residual(x, dq)
                err = max(abs(r) for r in R)
                if err < mp.mpf(10) ** (-(DIGITS - 10)) * s.scale:
                    return x
                _, J = s.residual_jacobian(np.array([float(v) for v in x]), float(dq) + s.q_ref)
                # the correction from the residual (scaled, so that doubles keep it)
                big = float(err)
                step = np.linalg.lstsq(J, np.array([float(r / big) for r in R]), rcond=None)[0]
                x = [xi - mp.mpf(float(si)) * big for xi, si in zip(x, step, strict=True)]
        raise ArithmeticError("high-precision Newton did not converge")

    def centres(self, x: list[mp.mpf]) -> dict[str, mp.mpc]:
        """Every joint's centre (a slider's: the point its second link carries)."""
        s = self.system
        out = {}
        with mp.workdps(DIGITS):
            for j in self.m.joints:
                link = j.links[1] if j.kind == "P" else j.links[0]
                z = s.centres[j.id]
                if link == self.m.frame:
                    out[j.id] = mp.mpc(z.real, z.imag)
                    continue
                c = s.col[link]
                o = s.origin[link]
                r = mp.expjpi(x[c + 2] / mp.pi)
                out[j.id] = mp.mpc(x[c], x[c + 1]) + r * mp.mpc(z.real - o.real, z.imag - o.imag)
        return out

    def positions(self, q: float) -> dict[str, complex]:
        """Joint centres at driver value ``q`` (one high-precision solve), as doubles."""
        got = reach(self.system, np.array([q]))
        if 0 not in got:
            raise ArithmeticError("the frame is not reached from the reference")
        with mp.workdps(DIGITS):
            x = self.solve(mp.mpf(q) - mp.mpf(self.system.q_ref), got[0].x)
            return {j: complex(z) for j, z in self.centres(x).items()}

    def analogs(
        self, q: float, h: float = 1e-12
    ) -> tuple[dict[str, complex], dict[str, complex], dict[str, complex]]:
        """Joint centres, velocity analogs and acceleration analogs at driver value ``q``
        (a double: the kinematics' own frame), rounded to doubles."""
        s = self.system
        got = reach(s, np.array([q]))
        if 0 not in got:
            raise ArithmeticError("the frame is not reached from the reference")
        x0 = got[0].x
        with mp.workdps(DIGITS):
            dq = mp.mpf(q) - mp.mpf(s.q_ref)
            H = mp.mpf(h)
            xs = [self.solve(dq + k * H, x0) for k in (-1, 0, 1)]
            p = [self.centres(x) for x in xs]
            pos = {j: complex(p[1][j]) for j in p[1]}
            sig = {j: complex((p[2][j] - p[0][j]) / (2 * H)) for j in p[1]}
            kap = {j: complex((p[2][j] - 2 * p[1][j] + p[0][j]) / H**2) for j in p[1]}
        return pos, sig, kap
