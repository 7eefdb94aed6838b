"""Dyads with two prismatic pairs: PRP (slider – pin – slider) and RPP / PPR (Scotch yoke).

Closed forms (Scotch yoke, tangent mechanism, elliptical trammel driven at the pin),
an independent solution of the joint constraints with scipy at a few frames, the
constraints kept on every frame, and parallel guides (bad input at the reference,
null frames with a warning along the motion).
"""

from __future__ import annotations

import cmath
import json
import math

import numpy as np
import pytest
from scipy.optimize import fsolve

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.geometry import read_geometry
from mjstruct.kinematics.planner import plan_kinematics
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.mechanism import Mechanism


def _xy(z: complex) -> list[float]:
    return [z.real, z.imag]


def scotch_yoke(r: float, slot: float, guide: float, offset: float = 0.25) -> Mechanism:
    """Crank O–A (length r), block pinned at A sliding in the yoke's slot (direction
    ``slot``), yoke sliding on the frame along ``guide`` (angles in radians)."""
    A = complex(r, 0.0)
    return mechanism_from_dict(
        {
            "name": "yoke",
            "frame": "0",
            "drivers": ["O"],
            "joints": [
                {"id": "O", "links": ["0", "1"], "at": [0.0, 0.0]},
                {"id": "A", "links": ["1", "2"], "at": _xy(A)},
                {
                    "id": "J",
                    "links": ["2", "3"],
                    "type": "P",
                    "at": _xy(A),
                    "axis": _xy(cmath.exp(1j * slot)),
                },
                {
                    "id": "G",
                    "links": ["0", "3"],
                    "type": "P",
                    "at": _xy(A + offset),
                    "axis": _xy(cmath.exp(1j * guide)),
                },
            ],
        }
    )


def tangent(h: float, q0: float, e: float = 0.0, guide: float = 0.0) -> Mechanism:
    """PRP: slider 2 on a guide of crank 1 (along the crank, offset e), slider 3 on the
    frame's guide through (0, h) at angle ``guide``, pinned together at X."""
    u = cmath.exp(1j * q0)
    d = cmath.exp(1j * guide)
    # X: on the crank's line {e i u + s u} and the frame's line {i h + t d}
    s = ((1j * h - 1j * e * u) * d.conjugate()).imag / (u * d.conjugate()).imag
    X = 1j * e * u + s * u
    return mechanism_from_dict(
        {
            "name": "tangent",
            "frame": "0",
            "drivers": ["O"],
            "joints": [
                {"id": "O", "links": ["0", "1"], "at": [0.0, 0.0]},
                {"id": "S", "links": ["1", "2"], "type": "P", "at": _xy(X), "axis": _xy(u)},
                {"id": "X", "links": ["2", "3"], "at": _xy(X)},
                {"id": "T", "links": ["0", "3"], "type": "P", "at": _xy(X), "axis": _xy(d)},
            ],
        }
    )


def constraint_residuals(m: Mechanism, poses: dict[str, tuple[complex, float]], dq: float):
    """The joint constraints of the contract for link poses X_l(z) = T_l + e^{iφ_l} z.

    R: the link images of the centre coincide; P (a, b): equal rotations and the image
    on b of the centre on the line of a through a's image, along a's turned axis; the
    driver's relative rotation equals dq.  Written from the file, not from the plug-in.
    """
    g = read_geometry(m)

    def img(link: str, z: complex) -> complex:
        T, phi = poses[link]
        return T + cmath.exp(1j * phi) * z

    res: list[float] = []
    for j in m.joints:
        z = g.centres[j.id]
        if j.kind == "R":
            for other in j.links[1:]:
                d = img(j.links[0], z) - img(other, z)
                res += [d.real, d.imag]
        else:
            a, b = j.links
            res.append(poses[a][1] - poses[b][1])
            n = cmath.exp(1j * poses[a][1]) * 1j * g.axes[j.id]
            res.append(((img(b, z) - img(a, z)) * n.conjugate()).real)
    a, b = m.joint(m.drivers[0]).links
    res.append(poses[b][1] - poses[a][1] - dq)
    return res


def independent(m: Mechanism, dq: float, guess=None) -> dict[str, tuple[complex, float]]:
    """Solve the constraints with scipy, walking from the reference in steps <= 0.05 rad
    (or from ``guess`` in one step); returns the poses."""
    moving = [x for x in m.links if x != m.frame]

    def unpack(v):
        p = {m.frame: (0j, 0.0)}
        for i, link in enumerate(moving):
            p[link] = (complex(v[3 * i], v[3 * i + 1]), float(v[3 * i + 2]))
        return p

    v = np.zeros(3 * len(moving))
    if guess is not None:
        v = np.array([c for link in moving for c in (*_xy(guess[link][0]), guess[link][1])])
        path = [dq]
    else:
        path = list(np.linspace(0.0, dq, 1 + math.ceil(abs(dq) / 0.05))[1:])
    for d in path:
        f = fsolve(
            lambda x, d=d: constraint_residuals(m, unpack(x), d), v, xtol=1e-13, full_output=True
        )
        v = f[0]
    assert max(abs(x) for x in constraint_residuals(m, unpack(v), dq)) < 1e-13
    return unpack(v)


def analogs_against_scipy(m: Mechanism, res, i: int, joints, h: float = 1e-5) -> None:
    """σ and κ of the result against central differences of the scipy solution."""
    g = read_geometry(m)
    dq = float(res.q[i, 0] - g.driver_ref[m.drivers[0]])
    mid = result_poses(res, m, i)
    lo, hi = independent(m, dq - h, mid), independent(m, dq + h, mid)
    for jid in joints:
        link = m.joint(jid).links[-1]
        z = g.centres[jid]

        def pos(p, link=link, z=z):
            return p[link][0] + cmath.exp(1j * p[link][1]) * z

        sigma = (pos(hi) - pos(lo)) / (2 * h)
        kappa = (pos(hi) - 2 * pos(mid) + pos(lo)) / h**2
        d = res.joints[jid]
        scale = 1.0 + abs(pos(mid))
        assert abs(complex(d["sx"][i], d["sy"][i]) - sigma) < 1e-8 * scale
        assert abs(complex(d["kx"][i], d["ky"][i]) - kappa) < 1e-4 * scale


def result_poses(r, m: Mechanism, i: int) -> dict[str, tuple[complex, float]]:
    """Link poses (T, φ) at frame i from the result's joint positions and link angles."""
    g = read_geometry(m)
    out = {}
    for link in m.links:
        phi = float(r.links[link]["angle"][i]) - g.char_angle[link]
        # an anchor: a revolute centre of the link, or a P joint it is the second link of
        jid = next(
            j for j in m.link_joints[link] if m.joint(j).kind == "R" or m.joint(j).links[1] == link
        )
        P = complex(r.joints[jid]["x"][i], r.joints[jid]["y"][i])
        out[link] = (P - cmath.exp(1j * phi) * g.centres[jid], phi)
    return out


# -- (a) Scotch yoke --------------------------------------------------------------------


def test_scotch_yoke_plan_is_one_rpp_dyad():
    m = read_mechanism(example_path("scotch-yoke"))
    p = plan_kinematics(m)
    assert [s.kind for s in p.steps] == ["reference", "driver-R", "RPP"]
    assert "dyad RPP" in p.describe()[2] and "line–line" in p.describe()[2]
    # the crank's right triangle (A's distance to the frame guide) and the intersection
    assert p.complexity() == {"general": 0, "right": 2, "checks": 0, "unknowns": 0}


@pytest.mark.parametrize("W", [1.0, 2.5, -0.7])
def test_scotch_yoke_against_closed_form(W):
    m = read_mechanism(example_path("scotch-yoke"))
    g = read_geometry(m)
    r_crank = abs(g.centres["A"] - g.centres["O"])
    res = kinematic_analysis(m, frames=360, speed=W, checks="full")
    assert res.valid.all() and res.warnings == []
    q = res.q[:, 0]
    for jid in ("J", "G"):
        # the yoke translates along x: every point of it moves by r cos q - r
        x0 = g.centres[jid].real - r_crank
        d = res.joints[jid]
        np.testing.assert_allclose(d["x"], x0 + r_crank * np.cos(q), rtol=0, atol=1e-12)
        np.testing.assert_allclose(d["vx"], -r_crank * W * np.sin(q), rtol=0, atol=1e-12)
        np.testing.assert_allclose(d["ax"], -r_crank * W * W * np.cos(q), rtol=0, atol=1e-12)
        np.testing.assert_allclose(d["y"], g.centres[jid].imag, rtol=0, atol=1e-12)
        np.testing.assert_allclose(d["vy"], 0.0, rtol=0, atol=1e-12)
        np.testing.assert_allclose(d["ay"], 0.0, rtol=0, atol=1e-12)
    A = res.joints["A"]
    np.testing.assert_allclose(A["x"] + 1j * A["y"], r_crank * np.exp(1j * q), atol=1e-12)
    for link in ("2", "3"):  # block and yoke only translate
        np.testing.assert_allclose(res.links[link]["omega"], 0.0, atol=1e-12)
        np.testing.assert_allclose(res.links[link]["eps"], 0.0, atol=1e-12)
        np.testing.assert_allclose(res.links[link]["angle"], g.char_angle[link], atol=1e-12)
    assert res.checks["link_lengths"]["max_error"] < 1e-12
    assert res.checks["jacobian"]["dof"] == 1


def test_slanted_yoke_against_scipy_and_differences():
    """RPP with a slanted slot and a slanted frame guide: independent solution."""
    m = scotch_yoke(0.3, slot=1.2, guide=0.4)
    res = kinematic_analysis(m, frames=72, speed=1.0)
    assert res.valid.all()
    for i in (0, 5, 17, 40, 63):
        ref = independent(m, float(res.q[i, 0] - res.q[0, 0]))
        got = result_poses(res, m, i)
        for link in m.links:
            assert abs(got[link][0] - ref[link][0]) < 1e-12
            assert abs(got[link][1] - ref[link][1]) < 1e-12
    for i in (3, 50):
        analogs_against_scipy(m, res, i, ("J", "G"))


# -- (b) PRP ------------------------------------------------------------------------------


def test_tangent_mechanism_prp_against_closed_form():
    """Crank guide through O at angle q, frame guide y = h: X = (h cot q, h)."""
    h, q0 = 0.2, math.pi / 3
    m = tangent(h, q0)
    p = plan_kinematics(m)
    assert [s.kind for s in p.steps] == ["reference", "driver-R", "PRP"]
    assert "dyad PRP: sliders 2, 3 on the guides S, T meet at X" in p.describe()[2]
    assert p.complexity() == {"general": 0, "right": 1, "checks": 0, "unknowns": 0}
    # stay away from the parallel positions q = 0, π: q in [q0, q0 + 1.8)
    q = q0 + np.linspace(0.0, 1.8, 400)
    W = 1.3
    res = kinematic_analysis(m, q=q, speed=W)
    assert res.valid.all()
    X = res.joints["X"]
    s, c = np.sin(q), np.cos(q)
    for got, want in (
        (X["x"], h * c / s),
        (X["vx"], -h * W / s**2),
        (X["ax"], 2 * h * W * W * c / s**3),
    ):
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(X["y"], h, atol=1e-12)
    np.testing.assert_allclose(X["vy"], 0.0, atol=1e-12)
    # slider 2 turns with the crank, slider 3 only translates
    np.testing.assert_allclose(res.links["2"]["omega"], W, atol=1e-12)
    np.testing.assert_allclose(res.links["3"]["omega"], 0.0, atol=1e-12)


@pytest.mark.parametrize(("e", "guide", "q0"), [(0.05, 0.3, 1.1), (-0.1, 0.6, 2.4)])
def test_offset_prp_against_scipy(e, guide, q0):
    """PRP with an offset guide on the crank and a slanted frame guide."""
    m = tangent(0.4, q0, e=e, guide=guide)
    q = q0 + np.linspace(-0.5, 0.5, 41)
    res = kinematic_analysis(m, q=q)
    assert res.valid.all()
    for i in (0, 7, 20, 33, 40):
        ref = independent(m, float(q[i] - q0))
        got = result_poses(res, m, i)
        for link in m.links:
            assert abs(got[link][0] - ref[link][0]) < 1e-12
            assert abs(got[link][1] - ref[link][1]) < 1e-12
    for i in (4, 30):
        analogs_against_scipy(m, res, i, ("X", "S", "T"))


def test_elliptical_trammel_driven_at_the_pin_is_rpp_with_the_frame_sliding():
    """Driver at A (coupler against slider 1): the frame is the RPP dyad's sliding link."""
    L, t0 = 0.5, 0.6
    A, B = complex(L * math.cos(t0), 0), complex(0, L * math.sin(t0))
    m = mechanism_from_dict(
        {
            "frame": "0",
            "drivers": ["A"],
            "joints": [
                {"id": "P1", "links": ["0", "1"], "type": "P", "at": _xy(A), "axis": [1, 0]},
                {"id": "A", "links": ["1", "3"], "at": _xy(A)},
                {"id": "B", "links": ["3", "2"], "at": _xy(B)},
                {"id": "P2", "links": ["0", "2"], "type": "P", "at": _xy(B), "axis": [0, 1]},
            ],
        }
    )
    p = plan_kinematics(m)
    assert [s.kind for s in p.steps] == ["reference", "driver-R", "RPP"]
    res = kinematic_analysis(m, frames=360, speed=1.0)
    assert res.valid.all() and res.warnings == []
    q = res.q[:, 0]  # the coupler's angle A→B against the frame
    np.testing.assert_allclose(res.joints["A"]["x"], -L * np.cos(q), atol=1e-12)
    np.testing.assert_allclose(res.joints["A"]["vx"], L * np.sin(q), atol=1e-12)
    np.testing.assert_allclose(res.joints["A"]["ax"], L * np.cos(q), atol=1e-12)
    np.testing.assert_allclose(res.joints["B"]["y"], L * np.sin(q), atol=1e-12)
    np.testing.assert_allclose(res.joints["B"]["vy"], L * np.cos(q), atol=1e-12)
    np.testing.assert_allclose(res.joints["B"]["ay"], -L * np.sin(q), atol=1e-12)
    np.testing.assert_allclose(res.joints["A"]["y"], 0.0, atol=1e-12)
    np.testing.assert_allclose(res.joints["B"]["x"], 0.0, atol=1e-12)
    np.testing.assert_allclose(res.links["0"]["angle"], 0.0, atol=1e-12)


# -- (c) lengths and guides kept ----------------------------------------------------------


@pytest.mark.parametrize(
    "m",
    [
        scotch_yoke(0.3, slot=1.2, guide=0.4),
        scotch_yoke(1e-3, slot=-0.3, guide=2.0, offset=5.0),
        tangent(0.4, 1.1, e=0.05, guide=0.3),
        tangent(2.0, 0.7, e=-0.3, guide=-1.0),
    ],
)
def test_every_joint_constraint_holds_on_every_frame(m):
    res = kinematic_analysis(m, frames=90)
    g = read_geometry(m)
    assert res.checks["link_lengths"]["max_error"] < 1e-12 * g.scale
    # a tangent mechanism's pin runs off to infinity twice a turn: the frames past it
    # (either way) are another assembly, not reached; their positions keep the joints too
    other = res.valid if res.another_assembly is None else res.another_assembly
    ok = np.flatnonzero(res.valid | other)
    assert ok.size >= 85 and res.valid.sum() >= 40
    for i in ok:
        poses = result_poses(res, m, int(i))
        dq = float(res.q[i, 0] - res.q[0, 0])
        worst = max(abs(x) for x in constraint_residuals(m, poses, dq))
        # positions scale with 1/sin between the guides: relative to the largest one
        big = max(abs(T) for T, _ in poses.values()) + g.scale
        assert worst < 1e-12 * big


# -- (d) parallel guides --------------------------------------------------------------------


def test_parallel_guides_at_the_reference_are_bad_input(tmp_path, capsys):
    yoke = scotch_yoke(0.3, slot=0.0, guide=0.0)  # slot along the frame guide
    with pytest.raises(MechanismError, match=r"joints\[3\]\.axis: guides 'J' and 'G'"):
        kinematic_analysis(yoke)
    d = {
        "frame": "0",
        "drivers": ["O"],
        "joints": [
            {"id": "O", "links": ["0", "1"], "at": [0, 0]},
            {"id": "S", "links": ["1", "2"], "type": "P", "at": [0.2, 0], "axis": [1, 0]},
            {"id": "X", "links": ["2", "3"], "at": [0.2, 0]},
            {"id": "T", "links": ["0", "3"], "type": "P", "at": [0.2, 0], "axis": [-2, 0]},
        ],
    }
    with pytest.raises(MechanismError, match="parallel"):
        kinematic_analysis(mechanism_from_dict(d))
    f = tmp_path / "prp.json"
    f.write_text(json.dumps(d))
    assert main(["kinematics", str(f), "--json"]) == 2
    out = capsys.readouterr()
    assert out.out == ""
    lines = out.err.strip().splitlines()
    assert len(lines) == 1 and "parallel" in lines[0] and "Traceback" not in out.err


def test_guides_parallel_along_the_motion_give_null_frames_and_a_warning(tmp_path, capsys):
    """Tangent mechanism over a full turn: at q = 0, π the guides are parallel."""
    h, q0 = 0.2, math.pi / 4
    m = tangent(h, q0)
    res = kinematic_analysis(m, frames=360)  # frames 135 and 315 are q = π, 2π
    q = res.q[:, 0]
    near = np.abs(np.sin(q)) < 1e-12
    assert near.sum() == 2
    assert not res.valid[near].any()
    # the pin runs off to infinity at q = π and q = 0: the motion from q0 = π/4 reaches
    # (0, π) only; the frames of (π, 2π) assemble (the same guide lines) but lie past
    # both, another assembly, not reached
    assert res.valid[:135].all() and res.valid[316:].all() and not res.valid[136:315].any()
    assert res.another_assembly is not None
    assert np.flatnonzero(res.another_assembly).tolist() == list(range(136, 315))
    assert any("guides S and T are parallel at 2 frame(s)" in w for w in res.warnings)
    assert any("another assembly, not reached" in w for w in res.warnings)
    d = res.to_dict()
    text = json.dumps(d, allow_nan=False)  # no NaN or infinity in JSON
    assert "NaN" not in text and "Infinity" not in text
    i = int(np.flatnonzero(near)[0])
    assert d["joints"]["X"]["x"][i] is None and d["joints"]["X"]["x"][i - 1] is not None
    assert d["joints"]["X"]["x"][i + 1] is None
    assert d["another_assembly"]["frames"][0] == i + 1
    x_other = d["another_assembly"]["joints"]["X"]["x"][0]
    assert x_other == pytest.approx(float(res.joints["X"]["x"][i + 1]))
    # the valid frames still follow the closed form
    ok = ~near
    np.testing.assert_allclose(res.joints["X"]["x"][ok], h / np.tan(q[ok]), rtol=1e-12, atol=1e-12)
    # and through the CLI
    f = tmp_path / "tangent.json"
    from mjstruct.io import mechanism_to_dict

    f.write_text(json.dumps(mechanism_to_dict(m)))
    assert main(["kinematics", str(f), "--frames", "360", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["joints"]["X"]["x"][i] is None
    assert any("parallel" in w for w in out["warnings"])


def test_a_pin_run_off_to_infinity_between_two_frames_stops_the_motion():
    """No frame sits on q = π here: the guides' sign change between two frames is the wall."""
    res = kinematic_analysis(tangent(0.2, math.pi / 4), frames=361)
    q = res.q[:, 0]
    assert not np.any(np.abs(np.sin(q)) < 1e-12)
    inside = (np.mod(q, 2 * np.pi) > 0) & (np.mod(q, 2 * np.pi) < np.pi)
    assert (res.valid == inside).all()
    assert res.another_assembly is not None and (res.another_assembly == ~inside).all()
