"""Speed of the dynamics plug-in, measured side by side in one run (CPU time, medians).

* Zhivago mechanism, free motion from q̇₀ = 20 (everything [Panasenko 2025] computes: positions,
  analogs, V, W, Q, the steady parameter, q̇, q̈, all reactions, the check) at 36 and
  3600 frames, cold: the mechanism with its loads read from its file for every call
  (planning, parsing and compiling the loads included: no per-mechanism cache can hit a
  new object); goals 20 ms and 0.2 s of CPU time, the ratio to the goal printed.  Warm:
  the same mechanism object again (its plan and compiled loads kept, as across a
  user's calls on one object; not the goal).  The kinematics alone (a fresh model's
  ``motion`` of the same frames, order 2) is timed beside it: it bounds what the
  dynamics can reach.  The same at constant speed (``--speed``: the steady parameter,
  reactions, check), cold.
* The slider-crank of [Panasenko 2025], the same at 36 and 3600 frames.
* The whole reactions step (assembly of the stacked system, active and inertia loads,
  the solve with its condition estimate, the excluded-equation check, the reaction
  dictionaries: ``joint_loads.link_loads`` and ``joint_loads.joint_loads`` on a solved
  ``LinkMotion``) against a hand-written ``np.linalg.solve`` of the same frames × u × u
  stack; target within 3×.

Run: ``python benchmarks/bench_dynamics.py [--repeat N]``; prints medians and ratios.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.dynamics import dynamic_analysis
from mjstruct.dynamics.data import read_dynamics
from mjstruct.dynamics.joint_loads import JointLoads, joint_loads, link_loads
from mjstruct.dynamics.matrices import active_forces, link_motion
from mjstruct.dynamics.reactions import (
    inertia_loads,
    is_moment,
    stack_loads,
    system_matrix,
    unknowns,
)
from mjstruct.dynamics.result import OUTPUTS
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from timing import race

#: CPU-time goals of Zhivago's free motion: frames -> seconds
GOALS = {36: 0.020, 3600: 0.2}


def whole(name: str, frames: int, qdot0: float, repeat: int) -> None:
    path = example_path(name)
    m = read_mechanism(path)

    def cold() -> object:
        # the user's first call: the mechanism and its loads read from the file, the
        # plan built, the loads parsed and compiled (no cache can hit a new object)
        return dynamic_analysis(read_mechanism(path), qdot0=qdot0, frames=frames)

    def warm() -> object:
        # a later call on the same mechanism object: its plan and compiled loads kept
        return dynamic_analysis(m, qdot0=qdot0, frames=frames)

    def speed() -> object:
        return dynamic_analysis(read_mechanism(path), speed=qdot0, frames=frames)

    def kin() -> object:
        # the kinematics of the same frames from a fresh mechanism, order 2
        fresh = KinematicModel.build(read_mechanism(path))
        return fresh.motion(fresh.sweep(frames), order=2)

    t_cold, t_warm, t_speed, t_kin = race(
        [cold, warm, speed, kin], repeat, clock=time.process_time
    )
    r = cold()
    goal = GOALS.get(frames) if name == "zhivago-dynamics" else None
    against = f"; goal {goal * 1e3:g} ms: ratio {t_cold / goal:4.2f}" if goal else ""
    print(
        f"{name}, {frames} frames: free motion, cold {t_cold * 1e3:7.1f} ms{against} "
        f"(warm, same mechanism object {t_warm * 1e3:7.1f} ms), constant speed, cold "
        f"{t_speed * 1e3:7.1f} ms (kinematics alone, cold {t_kin * 1e3:6.1f} ms; ratios "
        f"{t_cold / t_kin:4.1f}x, {t_speed / t_kin:4.1f}x)  check {r.check:.1e}"  # type: ignore[attr-defined]
    )


def reactions_step(name: str, frames: int, repeat: int) -> None:
    m = read_mechanism(example_path(name))
    model = KinematicModel.build(m)
    data = read_dynamics(m)
    q = model.sweep(frames)
    lm = link_motion(model, data.inertia, q, 1.0)
    params = data.parameter_values(**({data.unknown: 1.0} if data.unknown else {}))
    ones = np.ones(q.shape)
    wanted = set(OUTPUTS)

    def ours() -> JointLoads:
        loads = link_loads(data, lm, params, q[:, 0], ones[:, 0])
        return joint_loads(model, lm, loads, wanted)

    # the same stacked system, assembled once outside the hand-written timing
    fa, ma = active_forces(data, lm, params, q[:, 0], ones[:, 0])
    mass = np.array([data.inertia[x].mass for x in lm.links])
    J = np.array([data.inertia[x].J for x in lm.links])
    fi, mi = inertia_loads(lm, mass, J)
    S = stack_loads(fa + fi, ma + mi, model.scale)  # in units of the size, as ours
    A = system_matrix(model, lm, unknowns(model))

    def hand() -> np.ndarray:
        return np.asarray(np.linalg.solve(A, -S[..., None])[..., 0])

    t_ours, t_hand = race([ours, hand], repeat, clock=time.process_time)
    ref = hand()
    r = ours()
    d = model.drivers[0]
    cols = unknowns(model)
    col = next(c for c, u in enumerate(cols) if u.kind == "drive")
    ref = ref * np.where(is_moment(model, cols), model.scale, 1.0)  # the file's units
    assert r.driving is not None
    assert np.allclose(r.driving[d], ref[:, col], rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    print(
        f"{name}, {frames} frames × {A.shape[1]} unknowns: whole reactions step "
        f"{t_ours * 1e3:7.2f} ms, hand-written np.linalg.solve {t_hand * 1e3:7.2f} ms, "
        f"ratio {t_ours / t_hand:4.2f} (target <= 3)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    for frames in (36, 3600):
        whole("zhivago-dynamics", frames, 20.0, args.repeat)
        whole("slider-crank-seed000-dynamics", frames, 10.0, args.repeat)
    for frames in (36, 3600):
        reactions_step("zhivago-dynamics", frames, args.repeat)
        reactions_step("radial-engine-5-dynamics", frames, args.repeat)


if __name__ == "__main__":
    main()
