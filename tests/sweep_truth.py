"""What a full-turn kinematics sweep should return, told by the independent oracle.

Written for the completeness tests and the population script
(``benchmarks/sweep_truth_population.py``).  The frames a one-driver mechanism reaches
from its reference are those that the independent continuation of
``full_system_continuation`` (every link a rigid body, every joint's constraints at
once, no Assur decomposition) reaches from the reference in either direction of the
driver (a revolute driver's angle taken modulo 2π: frame ``i`` of ``N`` at
``q_ref + 2π i/N`` is reached turning forwards by ``2π i/N`` or backwards by
``2π (N - i)/N``).  :func:`defects` sweeps a mechanism with ``kinematic_analysis``
(``speed`` +1 or −1) and lists what differs from that truth, by the issue's four kinds:

* ``missed``: a frame the oracle reaches that the sweep does not return as valid at the
  oracle's joint centres (1e-9 of the size) — and a "closure stops … Jacobian is
  regular" warning whose q the oracle passes;
* ``unreached``: a frame the sweep returns as valid that no motion from the reference
  reaches (the oracle stops before it both ways);
* ``json``: the JSON object is not strict JSON (a NaN or an infinity);
* ``flood``: more warnings than events can explain (one warning per interval: more
  than ``FLOOD`` warnings of one kind for one joint), or a warning about a dyad whose
  sine does not change over the sweep.

:func:`near_fold` moves a mechanism's reference to ``offset`` rad inside a fold of its
driver (found by the oracle), for sweeps that start next to one.

>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.io import read_mechanism
>>> defects(read_mechanism(example_path("four-bar")), frames=24, speed=1.0)
[]
"""

from __future__ import annotations

import cmath
import json
import re
from collections import Counter
from dataclasses import dataclass

import numpy as np

from full_system_continuation import FullSystem, Reached, reach
from mjstruct.io import mechanism_from_dict, mechanism_to_dict
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.mechanism import Mechanism
from mjstruct.testing import random_geometry, random_mechanism

#: joint centres of a returned frame must equal the oracle's to this, relative to the size
SAME = 1e-9
#: warnings of one kind for one joint above this count are a flood (one per interval)
FLOOD = 6


@dataclass(frozen=True)
class Defect:
    """One disagreement with the oracle: its kind, the frame (or -1) and what it is."""

    kind: str
    frame: int
    text: str

    def __str__(self) -> str:
        return f"{self.kind} (frame {self.frame}): {self.text}"


def population(seed: int, max_groups: int = 4) -> Mechanism:
    """Random mechanism ``seed`` of the completeness population: 1 to ``max_groups``
    Assur groups (dyads, triads, class IV) on a crank, multiple joints (``mj`` 0.3),
    sliders on 10% or 30% of the new external joints (triads with slider legs), and
    half of them with groups hanging on one link; a random reference in the unit square.
    """
    rng = np.random.default_rng(seed)
    groups = int(rng.integers(1, max_groups + 1))
    slider = float(rng.choice([0.1, 0.3]))
    hang = float(rng.choice([0.0, 0.5]))
    return random_geometry(random_mechanism(groups, seed=seed, slider=slider, hang=hang), seed)


def turn_reach(m: Mechanism, frames: int, h_max: float = 2e-3) -> dict[int, list[Reached]]:
    """Frames of the forward one-turn sweep (``q_ref + 2π i/frames``) the oracle reaches
    from the reference either way: frame -> the configurations it reaches there."""
    system = FullSystem(m)
    i = np.arange(frames)
    fwd = system.q_ref + 2 * np.pi * i / frames
    back = system.q_ref - 2 * np.pi * (frames - i[1:]) / frames
    got = reach(system, np.concatenate([fwd, back]), h_max=h_max)
    out: dict[int, list[Reached]] = {}
    for k, r in got.items():
        frame = k if k < frames else int(i[1:][k - frames])
        out.setdefault(frame, []).append(r)
    return out


def defects(
    m: Mechanism,
    frames: int,
    speed: float,
    truth: dict[int, list[Reached]] | None = None,
) -> list[Defect]:
    """What the sweep of ``m`` (``frames`` frames over a turn at ``speed``) gets wrong.

    ``truth``: :func:`turn_reach` of ``m`` at ``frames`` (computed when not given; the
    two directions share it).
    """
    if truth is None:
        truth = turn_reach(m, frames)
    with np.errstate(all="ignore"):
        r = kinematic_analysis(m, frames=frames, speed=speed)
    size = r.model.scale
    out: list[Defect] = []
    # the sweep's frame i sits at q_ref + sign·2π i/N: the forward frame i or N - i
    forward = [i if speed > 0 else (-i) % frames for i in range(frames)]
    ids = [j.id for j in m.joints]
    for i in range(frames):
        f = forward[i]
        if f in truth:
            if not r.valid[i]:
                out.append(Defect("missed", i, "reached by the oracle, not returned"))
                continue
            at = {j: complex(r.joints[j]["x"][i], r.joints[j]["y"][i]) for j in ids}
            err = min(max(abs(at[j] - z) for j, z in t.joints.items()) for t in truth[f])
            if not err <= SAME * size:
                out.append(Defect("missed", i, f"returned {err / size:.2g} of the size away"))
        elif r.valid[i]:
            out.append(Defect("unreached", i, "returned as reached; the oracle stops before"))
    try:
        json.dumps(r.to_dict(), allow_nan=False)
    except ValueError as exc:
        out.append(Defect("json", -1, str(exc)))
    out += _floods(r.warnings)
    for w in r.warnings:
        if "closure stops" in w and "regular" in w:
            stop = re.search(r"\(frame (\d+)\)", w)
            i = int(stop.group(1)) if stop else -1
            beside = (forward[(i - 1) % frames], forward[(i + 1) % frames])
            if i >= 0 and all(f in truth for f in beside):
                out.append(Defect("missed", i, f"false stop: {w[:80]}"))
    return out


def _floods(warnings: list[str]) -> list[Defect]:
    keys = Counter()
    for w in warnings:
        kind = w.split(" at q", 1)[0]
        joint = re.search(r"joint ([^)]+)\)", w)
        keys[(kind, joint.group(1) if joint else "")] += 1
    return [
        Defect("flood", -1, f"{n} warnings '{kind}' for joint {joint}")
        for (kind, joint), n in keys.items()
        if n > FLOOD
    ]


def near_fold(m: Mechanism, offset: float = 1e-4, h_max: float = 2e-3) -> Mechanism | None:
    """``m`` with its reference moved to ``offset`` rad inside the first fold the oracle
    meets turning the driver forwards (or backwards), or None when it turns fully."""
    system = FullSystem(m)
    for side in (1.0, -1.0):
        q = system.q_ref + side * np.linspace(0.0, 2 * np.pi, 2049)[:-1]
        got = reach(system, q, h_max=h_max)
        last = max(got)
        if last == q.size - 1:
            continue
        # the fold lies between the last frame reached and the next: zoom in on it
        lo, hi = float(q[last]), float(q[last + 1])
        for _ in range(3):
            grid = np.linspace(lo, hi, 65)
            got = reach(system, grid, h_max=h_max)
            k = max(got)
            lo, hi = float(grid[k]), float(grid[min(k + 1, 64)])
        target = lo - side * offset
        at = reach(system, np.array([target]), h_max=h_max)
        if not at:
            return None
        return _moved(m, at[0])
    return None


def _moved(m: Mechanism, at: Reached) -> Mechanism:
    """``m`` whose reference configuration is the oracle's configuration ``at``."""
    d = mechanism_to_dict(m)
    assert at.turns is not None
    for j in d["joints"]:
        z = at.joints[j["id"]]
        j["at"] = [z.real, z.imag]
        if j.get("type", "R") == "P":
            # the guide turns with the joint's first link
            u = complex(*j["axis"]) * cmath.exp(1j * at.turns[j["links"][0]])
            j["axis"] = [u.real, u.imag]
    return mechanism_from_dict(d)
