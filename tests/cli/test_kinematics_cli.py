"""``mjstruct kinematics``: the contract's keys, CSV, errors, Zhivago's inner driver."""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.io import read_mechanism
from mjstruct.kinematics.solver import kinematic_analysis


def _json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_contract_keys_and_speed(capsys):
    f = str(example_path("slider-crank"))
    d = _json(capsys, ["kinematics", f, "--frames", "8", "--speed", "0.5", "--json"])
    assert len(d["q"]) == 8
    assert d["q"][1] - d["q"][0] == pytest.approx(2 * math.pi / 8)
    assert set(d["joints"]) == {"O1", "A", "B", "O4"}
    assert set(d["joints"]["B"]) == {"x", "y", "vx", "vy", "ax", "ay"}
    assert set(d["links"]["2"]) == {"angle", "omega", "eps"}
    assert set(d["points"]) == {"S2"}
    assert d["warnings"] == []
    assert d["plan"]["complexity"] == {"general": 0, "right": 2, "checks": 0, "unknowns": 0}
    assert d["links"]["1"]["omega"] == pytest.approx([0.5] * 8)
    assert d["closure"] is None
    # negative speed: the coordinate decreases, the crank turns clockwise
    d2 = _json(capsys, ["kinematics", f, "--frames", "8", "--speed", "-0.5", "--json"])
    assert d2["q"][1] < d2["q"][0]
    assert d2["links"]["1"]["omega"] == pytest.approx([-0.5] * 8)


def test_csv_table(tmp_path, capsys):
    out = tmp_path / "t.csv"
    f = str(example_path("four-bar"))
    assert main(["kinematics", f, "--frames", "12", "--csv", str(out)]) == 0
    text = capsys.readouterr().out
    assert "plan" in text and "check Jacobian" in text
    # issue 38.8: it says what it wrote where, as draw, plot and animate do
    assert text.splitlines()[-1] == f"wrote {out} (the table: 12 frames, one row each)"
    with out.open() as fh:
        rows = list(csv.reader(fh))
    assert rows[0][:4] == ["q", "O1.x", "O1.y", "O1.vx"]
    assert "2.omega" in rows[0] and "M.ax" in rows[0]
    assert len(rows) == 13
    B = rows[0].index("B.x")
    r = kinematic_analysis(read_mechanism(f), frames=12)
    assert [float(x[B]) for x in rows[1:]] == pytest.approx(list(r.joints["B"]["x"]), abs=0)


def test_infeasible_frames_are_null_in_json(tmp_path, capsys):
    # a non-Grashof four-bar: the crank cannot turn fully
    data = json.loads(example_path("four-bar").read_text())
    A = 0.6 * complex(math.cos(1.0), math.sin(1.0))
    O2 = 1.0
    D = abs(O2 - A)
    al = (D * D + 0.25 - 0.49) / (2 * D)
    B = A + (al + 1j * math.sqrt(0.25 - al * al)) * (O2 - A) / D
    at = {"O1": [0, 0], "A": [A.real, A.imag], "B": [B.real, B.imag], "O2": [1, 0]}
    for j in data["joints"]:
        j["at"] = at[j["id"]]
    data.pop("points")
    p = tmp_path / "nongrashof.json"
    p.write_text(json.dumps(data))
    d = _json(capsys, ["kinematics", str(p), "--frames", "90", "--json"])
    xs = d["joints"]["B"]["x"]
    assert None in xs and xs[0] is not None
    assert any(w.startswith("no assembly") for w in d["warnings"])
    assert any(b["kind"] == "dead point" for b in d["branch_points"])


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["kinematics", "nope.json"], "no such file"),
        (["kinematics", str(example_path("watt")), "--frames", "4"], "at: missing"),
        (["kinematics", str(example_path("four-bar")), "--drivers", "Z"], "--drivers"),
        (["kinematics", str(example_path("four-bar")), "--frames", "0"], "--frames"),
        (["kinematics", str(example_path("four-bar")), "--drivers", "O1,O2"], "over-constrained"),
    ],
)
def test_bad_input_exits_2_with_one_line(argv, needle, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1


def test_structural_path_stays_light():
    # the kinematics command must not pull sympy or matplotlib in
    code = (
        "import sys; from mjstruct.cli.main import main; "
        f"main(['kinematics', {str(example_path('four-bar'))!r}, '--frames', '4']); "
        "print(any(m in sys.modules for m in ('sympy', 'matplotlib')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().endswith("False")


# -- Zhivago: q inside the loop ABDE, and the frame joint driven with iteration ----------


def test_zhivago_inner_driver_needs_triangles_only():
    m = read_mechanism(example_path("zhivago"))
    r = kinematic_analysis(m, drivers=["E"], frames=360)
    assert r.plan.unknowns == 0 and r.closure is None
    kinds = [s.kind for s in r.plan.steps]
    assert kinds == ["reference", "driver-R", "RRR", "RRR"]
    # the cluster is solved in link 1's frame, the frame link is one more dyad
    assert r.plan.reference == "1"
    # seed 000's count: 7 triangles, of which two (OAB, OBG) only re-check OG;
    # the plan needs ADE, ABD, then ODE, ODG and OGH
    c = r.plan.complexity()
    assert c["general"] == 5 and c["checks"] == 2 and c["general"] + c["checks"] == 7
    assert r.valid.all() and r.checks["link_lengths"]["max_error"] < 1e-12
    # the frame stays put: O and C fixed, frame link angle constant
    C = m.joint("C").at
    for j, (x, y) in (("O", (0, 0)), ("C", C)):
        assert np.abs(r.joints[j]["x"] - x).max() < 1e-12
        assert np.abs(r.joints[j]["y"] - y).max() < 1e-12
        assert np.abs(r.joints[j]["vx"]).max() < 1e-12
    assert np.abs(r.links["0"]["omega"]).max() < 1e-12


def test_zhivago_frame_driver_by_iteration_gives_the_same_motion():
    m = read_mechanism(example_path("zhivago"))
    rE = kinematic_analysis(m, drivers=["E"], frames=720)
    theta = rE.links["1"]["angle"]  # the physical crank angle, a computed function of q
    # with these dimensions both the crank O and the angle at E turn fully, monotonically
    assert np.all(np.diff(theta) < 0) and theta[0] - theta[-1] > np.radians(355)
    rO = kinematic_analysis(m, drivers=["O"], q=theta)
    assert rO.plan.unknowns == 1 and rO.valid.all() and rO.warnings == []
    for j in "ABCDEG":
        for k in ("x", "y"):
            assert np.abs(rO.joints[j][k] - rE.joints[j][k]).max() < 1e-9, (j, k)
    # velocities: v_O-driven = σ_O q̇_O with q̇_O = dθ/dq_E (chain rule through the inverse)
    dtheta = rE.links["1"]["sigma"]
    for j in "BDG":
        vE = rE.joints[j]["vx"] + 1j * rE.joints[j]["vy"]
        vO = (rO.joints[j]["vx"] + 1j * rO.joints[j]["vy"]) * dtheta
        assert np.abs(vO - vE).max() < 1e-8, j
    # and the full crank cycle, driven at O, needs no warning either
    assert kinematic_analysis(m, frames=360).warnings == []


def _no_nan(text: str):
    def bad(token):
        raise AssertionError(f"{token} in JSON")

    return json.loads(text, parse_constant=bad)


@pytest.mark.parametrize(
    ("name", "extra"),
    [
        ("four-bar", ["--drivers", "O2", "--frames", "90"]),  # a rocker cannot turn fully
        ("slider-crank", ["--drivers", "O4", "--stroke", "-0.3", "--frames", "30"]),
    ],
)
def test_json_is_strict_when_frames_fail(name, extra, capsys):
    argv = ["kinematics", str(example_path(name)), "--json", *extra]
    assert main(argv) == 0
    d = _no_nan(capsys.readouterr().out)
    assert d["warnings"]
    assert any(x is None for x in d["joints"]["A"]["x"])
