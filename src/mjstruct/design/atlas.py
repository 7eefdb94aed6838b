"""Type and dimensional synthesis together: every topology of an atlas tried on a task.

Owns :func:`atlas_candidates` and :func:`synthesize_atlas`.  The candidates are the
one-DOF chains with n links of the structural atlas (:func:`mjstruct.synthesis.atlas.
atlas`; with ``mj``, chains with multiple joints too), each with every frame link,
every driver (a revolute joint of the frame) and every moving link but the driven one
to carry the point of interest — one candidate per class of these choices that no
symmetry of the chain maps onto another (nauty's canonical code with the frame, the
drivers and the point's link coloured).  A candidate whose plan needs iteration (a
class-III group) is listed as not ranked: the population evaluation runs triangle
plans.  Each candidate gets a random starting geometry around the targets (seeded
from the task's seed and its rank in the list) and the task's own search; all run on
the process pool or a Dask cluster, in the order of the list whatever the number of
workers, and the feasible designs are ranked by their objective.

Examples
--------
>>> cands = atlas_candidates(4, mj=False)
>>> len(cands), cands[0].name, cands[0].driver
(2, 'four-bar', 'J0')
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mjstruct.design.result import DesignResult
from mjstruct.design.search import seeds
from mjstruct.errors import MechanismError, NumericalError
from mjstruct.mechanism import Mechanism
from mjstruct.structure.isomorphism import certificate_of, colour_classes, link_joint_lists

#: task keys that name the joints of the task's own mechanism (not of the atlas's)
OWN_KEYS = ("region", "fixed")


@dataclass(frozen=True)
class Candidate:
    """One topology of the atlas with its frame, driver and point link.

    Attributes
    ----------
    name : the inversion's familiar name (Watt I six-bar, ...), else the chain's, else
        a description.
    chain : the chain's canonical code.
    frame, driver, link : the frame link, the driver joint, the point's link.
    mechanism : the chain as a mechanism (links "0".."n-1", joints "J0", ...), frame
        and driver set, without geometry.
    """

    name: str
    chain: str
    frame: str
    driver: str
    link: str
    mechanism: Mechanism

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "chain": self.chain,
            "frame": self.frame,
            "driver": self.driver,
            "link": self.link,
            "joints": [[j.id, list(j.links)] for j in self.mechanism.joints],
        }


def _key(m: Mechanism, driven: str, link: str) -> str:
    """Canonical code of ``m`` with frame, drivers, the driven link and the point's
    ``link`` coloured."""
    marks = [m.links.index(driven), m.links.index(link)]
    split: list[list[int]] = []
    for c in colour_classes(m, "mechanism"):
        rest = [v for v in c if v not in marks]
        split.append(rest)
        split += [[v] for v in marks if v in c]
    sizes, cert = certificate_of(len(m.links), link_joint_lists(m), split)
    return sizes + ":" + cert.hex()


def atlas_candidates(links: int, mj: bool = True) -> list[Candidate]:
    """The atlas's one-DOF chains of ``links`` links, with every frame, revolute frame
    joint as the driver (and, at a multiple joint, every link it may turn), and every
    point link, one per symmetry class (see the module text)."""
    from mjstruct.synthesis.atlas import atlas
    from mjstruct.synthesis.names import familiar_name, inversion_name

    out: list[Candidate] = []
    seen: set[str] = set()
    for chain in atlas(1, links, mj=mj).chains:
        if not chain.planar:
            continue
        base = chain.mechanism()
        for frame in base.links:
            for j in base.joints:
                if frame not in j.links or j.kind != "R":
                    continue
                for driven in j.links:
                    if driven == frame:
                        continue
                    # the frame first and the driven link second: q is its angle
                    first = [frame, driven, *(y for y in j.links if y not in (frame, driven))]
                    joints = [(x.id, first if x is j else list(x.links)) for x in base.joints]
                    m = Mechanism.build(joints, frame=frame, drivers=[j.id])
                    for link in m.links:
                        if link in (frame, driven):
                            continue
                        key = _key(m, driven, link)
                        if key in seen:
                            continue
                        seen.add(key)
                        name = (
                            inversion_name(m)
                            or familiar_name(m)
                            or f"{links}-link chain with multiple joints {list(chain.MJA)}"
                        )
                        out.append(Candidate(name, chain.canonical, frame, j.id, link, m))
    return out


def random_start(
    c: Candidate, point: str, targets: np.ndarray, rng: np.random.Generator
) -> dict[str, Any]:
    """``c`` as a mechanism file with every joint and the point at random places in a
    box around the targets (its side twice theirs)."""
    xy = targets[:, :2]
    centre = xy.mean(axis=0)
    side = max(float(np.ptp(xy, axis=0).max()), 1e-9)
    d: dict[str, Any] = {
        "name": c.name,
        "frame": c.frame,
        "drivers": [c.driver],
        "joints": [],
        "points": [],
    }
    for j in c.mechanism.joints:
        at = centre + side * rng.uniform(-1, 1, 2)
        d["joints"].append({"id": j.id, "links": list(j.links), "at": at.tolist()})
    at = centre + side * rng.uniform(-1, 1, 2)
    d["points"].append({"id": point, "link": c.link, "at": at.tolist()})
    return d


@dataclass(frozen=True)
class Ranked:
    """One candidate's outcome: its design (None when none was found) or why not."""

    candidate: Candidate
    result: DesignResult | None
    reason: str = ""

    def to_dict(self) -> dict[str, Any]:
        d = self.candidate.to_dict()
        r = self.result
        d["objective"] = None if r is None else r.objective
        d["feasible"] = r is not None and r.feasible
        d["evaluations"] = None if r is None else r.evaluations
        d["seconds"] = None if r is None else r.seconds
        d["reason"] = self.reason
        return d


@dataclass(frozen=True)
class AtlasResult:
    """Every candidate, the feasible ones first by objective (then the others)."""

    ranked: tuple[Ranked, ...]
    seconds: float
    seed: int | None
    details: Mapping[str, Any] = field(default_factory=dict)

    @property
    def best(self) -> DesignResult | None:
        first = self.ranked[0] if self.ranked else None
        return None if first is None else first.result


def _one(job: tuple[dict[str, Any], int, Candidate, int | None]) -> Ranked:
    from mjstruct.design.api import synthesize

    task, seed, cand, max_memory = job
    try:
        return Ranked(cand, synthesize(task, seed=seed, max_memory=max_memory))
    except NumericalError as exc:
        return Ranked(cand, None, str(exc))
    except MechanismError as exc:
        return Ranked(cand, None, f"not ranked: {exc}")


def _problem(task: Any) -> Any:
    """The fitting problem of a path or motion task (for its memory estimate)."""
    if task.kind == "motion":
        from mjstruct.design.motion import motion_problem

        return motion_problem(task)
    from mjstruct.design.path import path_problem

    return path_problem(task)


def synthesize_atlas(
    task: Mapping[str, Any],
    links: int = 6,
    mj: bool = True,
    seed: int | None = None,
    workers: int = 1,
    scheduler: str | None = None,
    progress: Callable[[int, int], None] | None = None,
    max_memory: int | None = None,
) -> AtlasResult:
    """Try every candidate topology of the atlas on ``task`` (a task object) and rank them.

    The task's ``mechanism`` is not used (each candidate brings its own), nor may the
    task name joints of it (``region``, ``fixed``).

    Raises
    ------
    MechanismError
        bad task input, keys that name the task's own joints, a number of links no
        one-DOF chain has or too many chains to try (naming ``links``), a search whose
        estimated memory exceeds ``max_memory``.
    """
    from mjstruct.design.api import load_task
    from mjstruct.design.memory import check_synthesis_memory
    from mjstruct.synthesis.job_size import CHAIN_LIMIT, chain_count_estimate, check_size
    from mjstruct.synthesis.parallel import run_tasks

    if links < 4:
        raise MechanismError(
            f"links: an atlas of one-DOF chains needs at least 4 links, got {links}"
        )
    if links % 2:
        raise MechanismError(
            f"links: a one-DOF chain has an even number of links (3(n - 1) = 2j + 1 "
            f"needs n even), got {links}"
        )
    what = f"one-DOF chains of {links} links" + (" with multiple joints" if mj else "")
    estimate = chain_count_estimate(1, links, mj, False)
    check_size(estimate, what, CHAIN_LIMIT, "links", loops=(links - 2) // 2)
    for key in OWN_KEYS:
        if key in task:
            raise MechanismError(f"{key}: names joints of one mechanism; not used with an atlas")
    if task.get("task") not in ("path", "motion"):
        raise MechanismError("task: an atlas ranks path or motion synthesis")
    point = str(task.get("point", "P"))
    t0 = time.perf_counter()
    cands = atlas_candidates(links, mj)
    rng_seeds = seeds(seed, len(cands))
    jobs = []
    checked = False
    for k, c in enumerate(cands):
        data = dict(task)
        data["point"] = point
        if not checked:  # bad task input is the same for every candidate: say it once
            data["mechanism"] = random_start(c, point, np.zeros((1, 2)), np.random.default_rng(0))
            first = load_task(data)
            targets = first.targets
            check_synthesis_memory(_problem(first), first.solver, max_memory)
            checked = True
        data["mechanism"] = random_start(c, point, targets, np.random.default_rng(rng_seeds[k]))
        jobs.append((data, rng_seeds[k], c, max_memory))
    ranked = list(run_tasks(_one, jobs, workers, progress, scheduler))
    ranked.sort(key=lambda r: (r.result is None, r.result.objective if r.result else math.inf))
    return AtlasResult(tuple(ranked), time.perf_counter() - t0, seed, {"links": links, "mj": mj})
