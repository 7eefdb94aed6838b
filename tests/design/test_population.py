"""Per-frame geometry: a population evaluated in one call equals each candidate alone.

The oracle is the plug-in's ordinary path: a mechanism file per candidate, its own
model built and evaluated on its own driver values (its own plan, its own assembly
modes from its own reference configuration).
"""

from __future__ import annotations

import numpy as np
import pytest

from mjstruct.design.population import DesignSpace
from mjstruct.io import read_mechanism
from mjstruct.kinematics.evaluate import evaluate
from mjstruct.kinematics.model import KinematicModel
from mjstruct.testing import random_geometry
from project_paths import EXAMPLES


def _mechanisms():
    yield read_mechanism(EXAMPLES / "four-bar.json")
    yield read_mechanism(EXAMPLES / "slider-crank.json")
    yield read_mechanism(EXAMPLES / "kin-radial-engine-5.json")
    for name, seed in (("watt", 3), ("stephenson", 3)):
        yield random_geometry(read_mechanism(EXAMPLES / f"{name}.json"), seed)


@pytest.mark.parametrize("m", list(_mechanisms()), ids=lambda m: m.name or "?")
def test_population_equals_each_candidate_alone(m):
    model = KinematicModel.build(m)
    space = DesignSpace.build(model, boxes={}, fixed=())
    rng = np.random.default_rng(5)
    X = space.x0 + 0.03 * model.scale * rng.standard_normal((6, space.size))
    S = 7
    pop = space.population(X, samples=S)
    q = pop.cycle(span=0.6)
    ev = pop.evaluate(q, order=2)
    for p in range(len(X)):
        alone = KinematicModel.build(space.mechanism(X[p]))
        assert [s.kind for s in alone.plan.steps] == [s.kind for s in model.plan.steps]
        assert np.isclose(pop.q_ref()[p], alone.q_ref[0], atol=1e-12)
        ev1 = evaluate(alone, q[p][:, None], order=2)
        ids = [j.id for j in m.joints] + [pt.id for pt in m.points]
        for pid in ids:
            got = pop.jet(ev, pid)
            want = ev1.centre(pid) if pid in alone.geometry.centres else None
            if want is None:
                link, z = alone.geometry.points[pid]
                want = ev1.poses[link].point(z)
            for k in range(3):
                a, b = got[k][p], want[k]
                ok = np.isfinite(b)
                assert np.array_equal(np.isfinite(a), ok), (pid, k)
                assert np.allclose(a[ok], b[ok], rtol=1e-9, atol=1e-9 * model.scale), (pid, k)
        for k, (disc, det) in ev1.diag.items():
            d2, s2 = (pop.reshape(x)[p] for x in ev.diag[k])
            assert np.allclose(d2, disc, atol=1e-9, equal_nan=True)
            assert np.allclose(s2, det, atol=1e-9, equal_nan=True)
