"""Speed of the dynamics plug-in, measured side by side in one run.

* Zhivago mechanism, free motion from q̇₀ = 20 (everything the seed computes: positions,
  analogs, V, W, Q, the steady parameter, q̇, q̈, all reactions, the check) at 36 and
  3600 frames; targets 20 ms and 0.2 s.  The kinematics alone (one ``model.motion`` of
  the same frames, order 2) is timed beside it: it bounds what the dynamics can reach.
* The seed-000 slider-crank, the same at 36 and 3600 frames.
* Reactions on stacked arrays: the plug-in's solve (with its finiteness mask) against a
  hand-written ``np.linalg.solve`` of the same frames × u × u stack; target within 3×.
  The assembly of the stack is timed separately.

Run: ``python benchmarks/bench_dynamics.py [--repeat N]``; prints medians and ratios.
"""

from __future__ import annotations

import argparse

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.dynamics import dynamic_analysis
from mjstruct.dynamics.data import read_dynamics
from mjstruct.dynamics.matrices import active_forces, link_motion
from mjstruct.dynamics.reactions import (
    inertia_loads,
    solve_stack,
    stack_loads,
    system_matrix,
    unknowns,
)
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from timing import median_time, race


def whole(name: str, frames: int, qdot0: float, repeat: int) -> None:
    m = read_mechanism(example_path(name))
    model = KinematicModel.build(m)

    def dyn() -> object:
        return dynamic_analysis(m, qdot0=qdot0, frames=frames, model=model)

    def kin() -> object:
        return model.motion(model.sweep(frames), order=2)

    t_dyn, t_kin = race([dyn, kin], repeat)
    r = dyn()
    print(
        f"{name}, {frames} frames: dynamics {t_dyn * 1e3:8.1f} ms  (kinematics alone "
        f"{t_kin * 1e3:6.1f} ms, {t_dyn / t_kin:4.1f}x)  check {r.check:.1e}"  # type: ignore[attr-defined]
    )


def stacked(name: str, frames: int, repeat: int) -> None:
    m = read_mechanism(example_path(name))
    model = KinematicModel.build(m)
    data = read_dynamics(m)
    q = model.sweep(frames)
    lm = link_motion(model, data.inertia, q, 1.0)
    params = data.parameter_values(**({data.unknown: 1.0} if data.unknown else {}))
    fa, ma = active_forces(data, lm, params, q[:, 0], np.ones(frames))
    mass = np.array([data.inertia[x].mass for x in lm.links])
    J = np.array([data.inertia[x].J for x in lm.links])
    fi, mi = inertia_loads(lm, mass, J)
    S = stack_loads(fa + fi, ma + mi)
    cols = unknowns(model)
    A = system_matrix(model, lm, cols)
    t_asm, _ = median_time(lambda: system_matrix(model, lm, cols), repeat)
    t_ours, t_hand = race(
        [lambda: solve_stack(A, S), lambda: np.linalg.solve(A, -S[..., None])[..., 0]], repeat
    )
    x = solve_stack(A, S)[0]
    ref = np.linalg.solve(A, -S[..., None])[..., 0]
    assert np.array_equal(x, ref)
    print(
        f"{name}, {frames} frames × {A.shape[1]} unknowns: stacked solve {t_ours * 1e3:7.2f} ms, "
        f"hand-written np.linalg.solve {t_hand * 1e3:7.2f} ms, ratio {t_ours / t_hand:4.2f} "
        f"(target <= 3); assembly {t_asm * 1e3:6.2f} ms"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    for frames in (36, 3600):
        whole("zhivago-dynamics", frames, 20.0, args.repeat)
        whole("slider-crank-seed000-dynamics", frames, 10.0, args.repeat)
    for frames in (36, 3600):
        stacked("zhivago-dynamics", frames, args.repeat)
        stacked("radial-engine-5-dynamics", frames, args.repeat)


if __name__ == "__main__":
    main()
