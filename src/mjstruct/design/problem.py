"""What a fitting task gives the searches, and the pieces every global stage shares.

Owns :class:`FitProblem` (what a task kind provides: bounds and starts of its global
variables, the assessment of a whole population in one kinematics call, the
residuals and Jacobian of its local stage, and the verdict on a design), the
records :class:`Assessment`, :class:`Outcome` and :class:`Run`, the local stage
:func:`local_solve` (scipy's ``least_squares``) and :func:`latin_hypercube`.  The
global stages (:mod:`mjstruct.design.search`, :mod:`mjstruct.design.multistart`)
build on them.

Examples
--------
>>> import numpy as np
>>> U = latin_hypercube(4, 2, np.random.default_rng(0))
>>> sorted((U * 4).astype(int)[:, 0].tolist())
[0, 1, 2, 3]
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from mjstruct.mechanism import Mechanism
from mjstruct.typing import FloatArray

#: weight of a constraint's violation among the local stage's residuals (relative
#: to the mechanism's size)
PENALTY = 10.0
#: margins down to this count as met (rounding)
MARGIN_SLACK = -1e-9
#: local-stage evaluations at most (each: one residual vector, or one Jacobian)
LOCAL_EVALUATIONS = 60
#: the local stage's tolerances (scipy's ftol, xtol, gtol): it stops at rounding
LOCAL_TOL = 1e-12
#: local searches per restart: from the global best and the next best distinct members
LOCAL_STARTS = 4

Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class Assessment:
    """A population judged in one call: ``energy`` (sum of squared target errors per
    candidate, inf where it cannot be measured) and ``margins`` (name -> per
    candidate, >= 0 where met)."""

    energy: FloatArray
    margins: Mapping[str, FloatArray]


@dataclass(frozen=True)
class Outcome:
    """A design judged by the kinematics (see :meth:`FitProblem.finish`)."""

    mechanism: Mechanism
    objective: float
    feasible: bool
    errors: tuple[float, ...]
    margins: Mapping[str, float]
    details: Mapping[str, Any]
    reason: str = ""
    local: FloatArray | None = None  # the local variables of a local solve

    @property
    def violation(self) -> float:
        """The largest constraint violation (0 when every margin is met)."""
        worst = min((v for v in self.margins.values() if math.isfinite(v)), default=0.0)
        return max(0.0, -worst)


class FitProblem:
    """What a fitting task gives the search; subclasses fill in the methods.

    ``evaluations`` counts the candidates the problem has evaluated (one per
    candidate of a population, one per residual vector, one per column set of a
    Jacobian's batch member).
    """

    kind = ""
    targets = 0
    scale = 1.0
    evaluations = 0
    #: frames one candidate takes in :meth:`assess` (sizes the batched calls)
    screen_frames = 72

    def bounds(self) -> tuple[FloatArray, FloatArray]:
        """Lower and upper bounds of the global variables."""
        raise NotImplementedError

    def start(self) -> FloatArray:
        """The global variables of the starting design."""
        raise NotImplementedError

    def starts(self) -> list[FloatArray]:
        """Designs the first population must hold: the start, and any exact solution
        the task kind knows (Freudenstein's, Burmester's)."""
        return [self.start()]

    def coarse(self) -> FitProblem:
        """The problem on fewer targets for cheap local solves (itself by default)."""
        return self

    def assess(self, X: FloatArray) -> Assessment:
        """Energy and margins of every row of ``X`` (one batched evaluation)."""
        raise NotImplementedError

    def local_start(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The local stage's variables from global ones, with their bounds."""
        raise NotImplementedError

    def residuals(self, z: FloatArray) -> FloatArray:
        """Target residuals (and constraint penalties) of local variables ``z``."""
        raise NotImplementedError

    def jacobian(self, z: FloatArray) -> FloatArray:
        """d residuals / d z."""
        raise NotImplementedError

    def finish(self, z: FloatArray, local: bool) -> Outcome:
        """The verdict on a design (``z``: local variables if ``local``, else global)."""
        raise NotImplementedError

    def energy_to_objective(self, energy: float) -> float:
        """The root mean square target error of a sum of squared errors."""
        return math.sqrt(energy / max(self.targets, 1)) if math.isfinite(energy) else math.inf


@dataclass(frozen=True)
class Run:
    """One restart: its verdicts, its record and its cost."""

    outcomes: tuple[Outcome, ...]
    history: tuple[tuple[int, float, float], ...]
    evaluations: int
    seconds: float


def local_solve(
    problem: FitProblem,
    x: FloatArray,
    evaluations: int = LOCAL_EVALUATIONS,
    z: FloatArray | None = None,
) -> Outcome | None:
    """scipy's ``least_squares`` from the global variables ``x`` (or from the local
    variables ``z`` of an earlier solve, to go on with it) on the problem's residuals
    and Jacobian, at most ``evaluations`` of them, judged by :meth:`FitProblem.finish`
    (None when the solver refuses the start).  The outcome's ``details["z"]`` holds
    the local variables reached."""
    from scipy.optimize import least_squares

    z0, zlo, zhi = problem.local_start(x)
    if z is not None:
        z0 = z
    # a box of zero width (a joint kept on a line) is a variable least squares must
    # not move: scipy wants lower < upper, so it gets a width at rounding level
    zhi = np.where(zhi > zlo, zhi, zlo + 1e-12 * (1.0 + np.abs(zlo)))
    z0 = np.clip(z0, zlo, zhi)
    try:
        with np.errstate(all="ignore"):
            ls = least_squares(
                problem.residuals,
                z0,
                jac=problem.jacobian,
                bounds=(zlo, zhi),
                method="trf",
                x_scale="jac",
                ftol=LOCAL_TOL,
                xtol=LOCAL_TOL,
                gtol=LOCAL_TOL,
                max_nfev=evaluations,
            )
    except (ValueError, np.linalg.LinAlgError):
        return None  # the global stage's verdict stands
    zx = np.asarray(ls.x, float)
    o = problem.finish(zx, local=True)
    return dataclasses.replace(o, local=zx)


def latin_hypercube(n: int, d: int, rng: np.random.Generator) -> FloatArray:
    """``n`` points in the unit cube ``d``, one in each of n strata of every axis."""
    strata = np.argsort(rng.random((d, n)), axis=1).T
    out: FloatArray = (strata + rng.random((n, d))) / n
    return out
