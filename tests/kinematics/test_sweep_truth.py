"""Full-turn sweeps of random mechanisms against the independent oracle, both ways.

The truth is ``sweep_truth`` (the continuation of every link's constraints at once of
``full_system_continuation``, from the reference either way round): every frame it
reaches is returned at its joint centres whichever way the driver turns, no frame it
does not reach is returned as reached, the JSON is strict and the warnings come one
per event.  The population (``sweep_truth.population``) has class II–IV groups, triads
with slider legs, multiple joints and groups hanging on one link; the seeds below are
the first of each defect kind found in it, kept as regression cases, plus
sweeps whose reference sits 1e-4 rad from a fold.  A larger population runs in
``benchmarks/sweep_truth_population.py``.
"""

from __future__ import annotations

import pytest

from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from mjstruct.structure.assur import assur_groups
from sweep_truth import defects, near_fold, population, turn_reach

FRAMES = 72


def _planned(m: Mechanism) -> bool:
    try:
        assur_groups(m)
        KinematicModel.build(m)
    except (MechanismError, NumericalError):
        return False
    return True


def _both_ways(m: Mechanism, frames: int = FRAMES) -> list[str]:
    truth = turn_reach(m, frames)
    return [f"speed {w:+g}: {d}" for w in (1.0, -1.0) for d in defects(m, frames, w, truth)]


@pytest.mark.parametrize(
    ("seed", "kind"),
    [
        (55, "frames lost one way (the reseed kept to half a turn; a false closure stop)"),
        (68, "frames lost the other way (the same)"),
        (2, "frames between two gaps returned as reached"),
        (19, "frames past a gap returned as reached"),
        (4, "a mode flip in frames that do not assemble: NaN sine in the JSON"),
        (109, "NaN sine in the JSON; a false closure stop"),
        (7, "a rigid RRP dyad: a near branch point at every frame"),
        (9, "a rigid dyad: 35 warnings"),
    ],
)
def test_regression_seeds(seed: int, kind: str) -> None:
    m = population(seed)
    assert _planned(m)
    assert _both_ways(m) == [], kind


@pytest.mark.parametrize("seed", [200, 201, 202, 203, 204, 205])
def test_fresh_random_mechanisms(seed: int) -> None:
    m = population(seed)
    if not _planned(m):
        pytest.skip("not planned: outside the kinematics' scope, not a defect")
    assert _both_ways(m, 36) == []


@pytest.mark.parametrize("seed", [3, 12, 13])
def test_sweeps_starting_next_to_a_fold(seed: int) -> None:
    m = near_fold(population(seed), 1e-4)
    assert m is not None and _planned(m)
    assert _both_ways(m, 36) == []


def test_cli_json_of_a_mechanism_that_had_a_nan_sine(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    import json

    from mjstruct.cli.main import main
    from mjstruct.io import mechanism_to_dict

    f = tmp_path / "m.json"
    f.write_text(json.dumps(mechanism_to_dict(population(4))))
    assert main(["kinematics", str(f), "--frames", "72", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert all(b["sine"] is not None for b in d["branch_points"] if b["kind"] == "mode flip")
    assert set(d["error"]) == {"position", "velocity", "acceleration", "conditioning"}


def test_a_rigid_dyad_is_said_once() -> None:
    from mjstruct.kinematics.solver import kinematic_analysis

    r = kinematic_analysis(population(7), frames=72)
    rigid = [w for w in r.warnings if "rigid relative to the links it hangs on" in w]
    assert len(rigid) == 1 and not any("near branch point" in w for w in r.warnings)
