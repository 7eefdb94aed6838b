"""Small defects: overflowing strokes, numpy warnings at singular frames."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import kinematic_analysis


@pytest.mark.parametrize("stroke", ["1e308", "-1e200", "1e101"])
def test_an_overflowing_stroke_is_bad_input(capsys, stroke):
    f = str(example_path("slider-crank"))
    assert main(["kinematics", f, f"--stroke={stroke}"]) == 2
    err = capsys.readouterr().err
    assert "--stroke" in err and "Warning" not in err and len(err.strip().splitlines()) == 1
    m = read_mechanism(example_path("slider-crank"))
    with pytest.raises(MechanismError, match=r"^stroke: "):
        kinematic_analysis(m, stroke=float(stroke))


def test_points_of_a_link_at_a_singular_frame_are_nan_without_a_warning():
    model = KinematicModel.build(read_mechanism(example_path("fourbar-ms5")))
    pose = model.motion(model.q_ref[None, :]).evaluation.poses[model.frame]
    infinite = type(pose)(pose.zA, pose.A, pose.r, [np.array([np.inf]), np.array([np.inf])])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        p = infinite.point(pose.zA + 1.0)
        v = infinite.vector(1.0)
    assert not np.isfinite(p[1]).any() and not np.isfinite(v[2]).any()
