"""The per-frame error estimates bound the true errors, measured against an independent
solve in 60 digits (``high_precision.Reference``: every joint's constraints at once in
mpmath, analogs by central differences), from regular frames to 1e-8 rad from a fold.
"""

from __future__ import annotations

import cmath
import json

import numpy as np
import pytest

from high_precision import Reference
from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.mechanism import Mechanism


def non_grashof() -> Mechanism:
    """A four-bar whose crank rocks (1 + 1.2 < 0.8 + 1.5 fails Grashof): two input limits."""
    A, O2 = 1j, 1.5 + 0j
    d = abs(O2 - A)
    a = (1.2**2 - 0.8**2 + d * d) / (2 * d)
    u = (O2 - A) / d
    B = A + a * u + 1j * (1.2**2 - a * a) ** 0.5 * u
    joints = [
        {"id": "O1", "links": ["0", "1"], "at": [0, 0]},
        {"id": "A", "links": ["1", "2"], "at": [0, 1]},
        {"id": "B", "links": ["2", "3"], "at": [B.real, B.imag]},
        {"id": "O2", "links": ["3", "0"], "at": [1.5, 0]},
    ]
    return mechanism_from_dict({"frame": "0", "drivers": ["O1"], "joints": joints})


def fold_of(m: Mechanism) -> float:
    """The input limit above the reference (within 3 rad), bisected on whether the frame
    assembles when reached from the reference."""
    km = KinematicModel.build(m)
    q0 = float(km.q_ref[0])
    qs = q0 + np.linspace(0, 3.0, 301)
    ok = kinematic_analysis(km, q=qs[:, None], checks=False).valid
    k = int(np.argmin(ok))
    assert k > 0
    lo, hi = float(qs[k - 1]), float(qs[k])
    for _ in range(8):  # 65 points a level: to 1e-16 of the first bracket
        grid = np.linspace(lo, hi, 65)
        ok = kinematic_analysis(km, q=grid[:, None], checks=False).valid
        k = int(np.argmin(ok)) if not ok.all() else 64
        lo, hi = float(grid[k - 1]), float(grid[k])
    return lo


def errors(m: Mechanism, qs: list[float], h: list[float]) -> list[tuple[float, ...]]:
    """Per frame: true position, velocity and acceleration analog errors, the estimates."""
    ref = Reference(m)
    r = kinematic_analysis(m, q=np.array(qs)[:, None], checks=False)
    e = r.error
    assert e is not None and r.valid[0]
    out = []
    for i in np.flatnonzero(r.valid):
        pos, sig, kap = ref.analogs(float(r.q[i, 0]), h=h[i])

        def off(kx: str, ky: str, truth: dict[str, complex], i: int = int(i)) -> float:
            return max(
                abs(complex(r.joints[j][kx][i], r.joints[j][ky][i]) - z) for j, z in truth.items()
            )

        out.append(
            (
                off("x", "y", pos),
                off("sx", "sy", sig),
                off("kx", "ky", kap),
                float(e.position[i]),
                float(e.velocity[i]),
                float(e.acceleration[i]),
            )
        )
    return out


@pytest.mark.parametrize("name", ["four-bar", "slider-crank", "class-iv-seed003", "zhivago"])
def test_regular_frames(name: str) -> None:
    m = read_mechanism(example_path(name))
    q0 = float(KinematicModel.build(m).q_ref[0])
    for ex, es, ek, bx, bs, bk in errors(m, [q0 + 0.3, q0 + 2.0], [1e-12, 1e-12]):
        assert ex <= bx and es <= bs and ek <= bk, (ex, es, ek, bx, bs, bk)


@pytest.mark.parametrize(
    "make", [non_grashof, lambda: read_mechanism(example_path("triad-class-iii"))]
)
def test_frames_approaching_a_fold(make) -> None:  # type: ignore[no-untyped-def]
    m = make()
    qf = fold_of(m)
    eps = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
    rows = errors(m, [qf - x for x in eps], [1e-6 * min(x, 1e-6) for x in eps])
    # the class-III triad's closure stops ~1e-7 rad short of the fold (Newton's tolerance
    # against the fold's conditioning): its last frame does not close
    assert len(rows) >= 6
    for ex, es, ek, bx, bs, bk in rows:
        assert ex <= bx and es <= bs and ek <= bk, (ex, es, ek, bx, bs, bk)
    # the analogs' error grows towards the fold, and the estimate with it
    assert rows[-1][1] > 100 * rows[0][1] and rows[-1][4] > 100 * rows[0][4]


def test_error_in_the_json_is_finite_or_null() -> None:
    r = kinematic_analysis(non_grashof(), frames=72)
    d = json.loads(json.dumps(r.to_dict(), allow_nan=False))
    err = d["error"]
    assert set(err) == {"position", "velocity", "acceleration", "conditioning"}
    assert all(len(v) == 72 for v in err.values())
    for i, ok in enumerate(r.valid):
        assert (err["velocity"][i] is None) == (not ok)
    assert cmath.isfinite(max(x for x in err["position"] if x is not None))


def test_subnormal_rates_are_warned_and_carried_by_the_estimate() -> None:
    r = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=36, speed=1e-160)
    assert any("subnormal" in w and "accelerations" in w for w in r.warnings)
    assert r.error is not None
    spacing = float(np.finfo(float).smallest_subnormal)
    assert (r.error.acceleration >= spacing).all()
    quiet = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=36, speed=1.0)
    assert not any("subnormal" in w for w in quiet.warnings)
