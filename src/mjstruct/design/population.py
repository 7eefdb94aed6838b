"""Design variables and the evaluation of a whole population in one kinematics call.

Owns :class:`DesignSpace`: the design variables of a topology (the x and y of every
joint centre and point of the reference configuration that is free to move; link
lengths follow from them), their bounds, and the mechanism a vector of them
describes; and :func:`population_model`, the kinematic model whose geometry differs
per frame, so that ``P`` candidates × ``S`` driver values are one call of
:func:`~mjstruct.kinematics.evaluate.evaluate` with ``P·S`` frames.

Per-frame geometry: every joint centre and point of the model's
:class:`~mjstruct.kinematics.geometry.Geometry` is an array over the frames instead
of a number (each frame its own reference configuration); the plan (which steps, in
which order) is the starting mechanism's, and each frame's assembly modes are those
of its own reference configuration.  The evaluation's arithmetic is the same
elementwise, so a frame gives what a model of that candidate alone gives (test:
``tests/design/test_population.py``).

Examples
--------
>>> import numpy as np
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("four-bar")))
>>> space = DesignSpace.build(model, boxes={}, fixed=(), margin=1.0)
>>> space.names
('O1', 'A', 'B', 'O2', 'M')
>>> X = np.stack([space.x0, space.x0 * 1.1])          # two candidates
>>> pop = space.population(X, samples=3)
>>> q = pop.cycle()                                   # 3 values per candidate
>>> ev = pop.evaluate(q, order=0)
>>> z = pop.reshape(ev.poses["2"].point(pop.points["M"])[0])
>>> z.shape, bool(abs(z[0, 0] - complex(*model.mechanism.points[0].at)) < 1e-12)
((2, 3), True)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from mjstruct.io import mechanism_from_dict, mechanism_to_dict
from mjstruct.kinematics.evaluate import Evaluation, evaluate
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from mjstruct.typing import ComplexArray, FloatArray

Box = tuple[tuple[float, float], tuple[float, float]]


@dataclass(frozen=True)
class DesignSpace:
    """The design variables of one topology and their bounds.

    Attributes
    ----------
    model : the starting mechanism's kinematic model (its plan serves every candidate).
    names : ids of the free joints and points, in order; variable 2k is the x of
        ``names[k]``, 2k + 1 its y.
    lower, upper : bounds of the variables.
    start : every joint centre and point of the starting geometry (complex).
    """

    model: KinematicModel
    names: tuple[str, ...]
    lower: FloatArray
    upper: FloatArray
    start: Mapping[str, complex]

    @classmethod
    def build(
        cls,
        model: KinematicModel,
        boxes: Mapping[str, Box],
        fixed: Sequence[str],
        margin: float = 1.0,
        around: Sequence[complex] = (),
        points: Sequence[str] | None = None,
    ) -> DesignSpace:
        """Variables for every joint not in ``fixed``, and every point in ``points``
        (default: every point) not in ``fixed``; the other points keep their place on
        their links (they do not change the motion).

        A position with a box in ``boxes`` stays in it; the others stay in the default
        box: the bounding box of the starting geometry and the points ``around`` (the
        targets), grown by ``margin`` times its larger side on every side.
        """
        g = model.geometry
        start: dict[str, complex] = dict(g.centres)
        start.update({pid: z for pid, (_, z) in g.points.items()})
        allz = list(start.values()) + list(around)
        xs = [z.real for z in allz]
        ys = [z.imag for z in allz]
        side = max(max(xs) - min(xs), max(ys) - min(ys), g.scale)
        default: Box = (
            (min(xs) - margin * side, min(ys) - margin * side),
            (max(xs) + margin * side, max(ys) + margin * side),
        )
        frozen = set(fixed)
        if points is not None:
            frozen |= set(g.points) - set(points)
        names = tuple(k for k in start if k not in frozen)
        lo, hi = [], []
        for k in names:
            (x0, y0), (x1, y1) = boxes.get(k, default)
            lo += [x0, y0]
            hi += [x1, y1]
        return cls(model, names, np.array(lo), np.array(hi), start)

    @property
    def size(self) -> int:
        """Number of design variables."""
        return 2 * len(self.names)

    @property
    def x0(self) -> FloatArray:
        """The starting geometry's variables (clipped into the bounds)."""
        x = np.array([c for k in self.names for c in (self.start[k].real, self.start[k].imag)])
        out: FloatArray = np.clip(x, self.lower, self.upper)
        return out

    def on_bound(self, x: FloatArray, rel: float = 1e-6) -> list[str]:
        """The variables of ``x`` left on a bound of their box (within ``rel`` of its
        width), named ``"id.x (lower)"``, ``"id.y (upper)"``, ...: a box the search
        pressed against, which may hold a better design outside it."""
        out = []
        width = np.maximum(self.upper - self.lower, 1e-300)
        for i, v in enumerate(np.asarray(x, float)[: self.size]):
            if self.upper[i] <= self.lower[i]:
                continue  # a box of zero width: the position is given, not pressed
            where = f"{self.names[i // 2]}.{'xy'[i % 2]}"
            if v <= self.lower[i] + rel * width[i]:
                out.append(f"{where} (lower)")
            elif v >= self.upper[i] - rel * width[i]:
                out.append(f"{where} (upper)")
        return out

    def positions(self, X: FloatArray) -> dict[str, ComplexArray]:
        """Every joint centre and point per candidate (rows of ``X``): id -> (P,) array."""
        X = np.atleast_2d(X)
        P = X.shape[0]
        out = {k: np.full(P, z, dtype=complex) for k, z in self.start.items()}
        for i, k in enumerate(self.names):
            out[k] = X[:, 2 * i] + 1j * X[:, 2 * i + 1]
        return out

    def population(self, X: FloatArray, samples: int) -> Population:
        """The candidates ``X`` (P × variables), each repeated over ``samples`` frames."""
        X = np.atleast_2d(np.asarray(X, float))
        positions = self.positions(X)
        model = population_model(self.model, positions, samples)
        return Population(self, X, samples, model, positions)

    def mechanism(self, x: FloatArray) -> Mechanism:
        """The starting mechanism with the geometry of the variables ``x``."""
        pos = {k: complex(v[0]) for k, v in self.positions(np.atleast_2d(x)).items()}
        d = mechanism_to_dict(self.model.mechanism)
        for j in d["joints"]:
            z = pos[str(j["id"])]
            j["at"] = [float(z.real), float(z.imag)]
        for p in d.get("points", []):
            z = pos[str(p["id"])]
            p["at"] = [float(z.real), float(z.imag)]
        return mechanism_from_dict(d)


def population_model(
    model: KinematicModel, positions: Mapping[str, ComplexArray], samples: int
) -> KinematicModel:
    """``model`` with per-frame geometry: candidate p's positions on frames p·S … p·S + S − 1.

    ``positions`` maps every joint and point id to its (P,) positions.  Link angles
    of the reference configuration (and so each driver's reference value) follow from
    the positions, from the same pair of joints the file's geometry uses.
    """
    g = model.geometry

    def frames(z: ComplexArray) -> ComplexArray:
        return np.repeat(z, samples)

    centres = {j: frames(positions[j]) for j in g.centres}
    points = {pid: (link, frames(positions[pid])) for pid, (link, _) in g.points.items()}
    char_angle: dict[str, Any] = {}
    for link, pair in g.char_joints.items():
        if pair:
            char_angle[link] = np.angle(centres[pair[1]] - centres[pair[0]])
        else:
            char_angle[link] = g.char_angle[link]
    driver_ref: dict[str, Any] = {}
    m = model.mechanism
    for d in g.driver_ref:
        j = m.joint(d)
        driver_ref[d] = 0.0 if j.kind == "P" else char_angle[j.links[1]] - char_angle[j.links[0]]
    # the Geometry's fields are typed for one configuration; arrays over the frames
    # flow through the same arithmetic (see the module's docstring)
    geometry = dataclasses.replace(
        g,
        centres=cast(dict[str, complex], centres),
        points=cast(dict[str, tuple[str, complex]], points),
        char_angle=cast(dict[str, float], char_angle),
        driver_ref=cast(dict[str, float], driver_ref),
    )
    return dataclasses.replace(model, geometry=geometry)


@dataclass(frozen=True)
class Population:
    """Candidates of one design space, each over ``samples`` frames of one model.

    Attributes
    ----------
    space : the design space.
    X : the candidates' variables (P × variables).
    samples : frames per candidate.
    model : the per-frame model (P·samples frames).
    positions : every joint centre and point per candidate (id -> (P,)).
    """

    space: DesignSpace
    X: FloatArray
    samples: int
    model: KinematicModel
    positions: dict[str, ComplexArray]

    @property
    def size(self) -> int:
        """Number of candidates P."""
        return int(self.X.shape[0])

    @property
    def points(self) -> dict[str, ComplexArray]:
        """Reference position of every point per frame (for ``Pose.point``)."""
        points = cast(dict[str, tuple[str, ComplexArray]], self.model.geometry.points)
        return {pid: z for pid, (_, z) in points.items()}

    @property
    def centres(self) -> dict[str, ComplexArray]:
        """Reference centre of every joint per frame."""
        return cast(dict[str, ComplexArray], self.model.geometry.centres)

    def q_ref(self) -> FloatArray:
        """Each candidate's driver value at its reference configuration, (P,)."""
        d = self.model.drivers[0]
        ref = np.asarray(self.model.geometry.driver_ref[d], float)
        return np.broadcast_to(ref, (self.size * self.samples,))[:: self.samples].copy()

    def cycle(self, start: FloatArray | None = None, span: float = 2 * np.pi) -> FloatArray:
        """Driver values (P × S): ``samples`` equal steps over ``span`` from each
        candidate's reference (or from ``start``), the end point excluded."""
        s = self.q_ref() if start is None else np.asarray(start, float)
        return s[:, None] + span * np.arange(self.samples)[None, :] / self.samples

    def evaluate(self, q: FloatArray, order: int = 0) -> Evaluation:
        """The plan on driver values ``q`` (P × S: candidate p's own values)."""
        qf = np.asarray(q, float).reshape(-1, 1)
        return evaluate(self.model, qf, order=order)

    def reshape(self, a: Any) -> Any:
        """An array over the frames as P × S."""
        return np.asarray(a).reshape(self.size, self.samples)

    def where(self, ev: Evaluation, pid: str) -> ComplexArray:
        """Positions of a point or joint centre, P × S."""
        g = self.model.geometry
        if pid in g.points:
            link, z = g.points[pid]
            return cast(ComplexArray, self.reshape(ev.poses[link].point(z)[0]))
        return cast(ComplexArray, self.reshape(ev.centre(pid)[0]))

    def jet(self, ev: Evaluation, pid: str) -> list[ComplexArray]:
        """The jet of a point or joint centre, each P × S."""
        g = self.model.geometry
        if pid in g.points:
            link, z = g.points[pid]
            jet = ev.poses[link].point(z)
        else:
            jet = ev.centre(pid)
        return [cast(ComplexArray, self.reshape(a)) for a in jet]
