"""CAD export: `draw -o OUT.dxf` read back with ezdxf, its holes against the kinematics,
its outlines at the bar's half-width from the joints; without ezdxf one line naming the
extra."""

from __future__ import annotations

import itertools
import os

import ezdxf
import numpy as np
import pytest
from ezdxf import path as dxf_path
from ezdxf.math import bulge_to_arc

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.io import read_mechanism
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.plot import dxf as dxf_module
from mjstruct.plot.dxf import BAR, layer_name
from mjstruct.plot.style import PIN


def _segment_distance(p: np.ndarray, a: complex, b: complex) -> np.ndarray:
    d = b - a
    t = np.clip(((p - a) * np.conj(d)).real / abs(d) ** 2, 0.0, 1.0)
    return np.abs(p - (a + t * d))


def _collinear(z: list[complex]) -> bool:
    d = np.array(z) - np.mean(z)
    return bool(
        np.abs(np.imag(np.conj(d[:, None]) * d[None, :])).max() <= 1e-9 * np.abs(d).max() ** 2
    )


def _hull(z: list[complex]) -> list[complex]:
    """The joints on the convex hull (gift wrapping; a few points)."""
    pts = sorted(z, key=lambda w: (w.real, w.imag))
    hull, p = [], pts[0]
    while True:
        hull.append(p)
        q = pts[0] if pts[0] != p else pts[1]
        for r in pts:
            turn = ((q - p).conjugate() * (r - p)).imag
            if turn < 0 or (turn == 0 and abs(r - p) > abs(q - p)):
                q = r
        p = q
        if p == hull[0]:
            return hull


@pytest.mark.parametrize(
    "name", ["zhivago", "kin-radial-engine-5", "slider-crank", "four-bar", "six-bar-mj-slider"]
)
def test_holes_sit_at_the_kinematics_centres_and_outlines_around_them(tmp_path, name, capsys):
    # four-bar and six-bar-mj-slider: a coupler point off the bar (issue 38.5: it was a
    # POINT outside the link's outline) makes the link a plate through it
    m = read_mechanism(example_path(name))
    r = kinematic_analysis(m, frames=8, checks=False)  # the oracle: another entry point
    k = 3
    out = tmp_path / "m.dxf"
    q = ",".join(repr(float(v)) for v in r.q[k])
    assert main(["draw", str(example_path(name)), "--q", q, "-o", str(out)]) == 0
    assert capsys.readouterr().out.startswith(f"wrote {out} (DXF of ")
    doc = ezdxf.readfile(out)
    msp = doc.modelspace()
    scale = r.model.scale
    hole, half = PIN * scale, BAR * PIN * scale
    tol = 1e-9 * scale
    centre = {j: complex(r.joints[j]["x"][k], r.joints[j]["y"][k]) for j in r.joints}
    spot = {p: complex(r.points[p]["x"][k], r.points[p]["y"][k]) for p in r.points}
    layers = {layer.dxf.name for layer in doc.layers}
    moving = [x for x in m.links if x != m.frame]
    assert {layer_name(x) for x in moving} | {"frame", "labels"} <= layers
    circles: dict[str, list[complex]] = {}
    for c in msp.query("CIRCLE"):
        assert c.dxf.radius == pytest.approx(hole)
        circles.setdefault(c.dxf.layer, []).append(complex(c.dxf.center.x, c.dxf.center.y))
    for j in m.joints:
        if j.kind != "R":
            continue
        for link in j.links:
            layer = "frame" if link == m.frame else layer_name(link)
            # a pin hole in every link the joint joins, where the kinematics puts it
            assert min(abs(z - centre[j.id]) for z in circles[layer]) <= tol, (j.id, link)
    for link in moving:
        (outline,) = msp.query(f'LWPOLYLINE[layer=="{layer_name(link)}"]')[:1] or [None]
        joints = [centre[j] for j in m.link_joints[link] if m.joint(j).kind == "R"]
        if outline is None or len(joints) < 2:
            continue  # a slider block: its rectangle is checked by the drawing tests
        # the outline is round the link's joints and the points it carries
        joints += [spot[p.id] for p in m.points if p.link == link]
        assert outline.closed
        points = outline.get_points("xyb")
        arcs = 0
        for (x, y, bulge), (x2, y2, _) in zip(points, points[1:] + points[:1], strict=True):
            # every corner of the outline is the half-width from a joint
            assert min(abs(complex(x, y) - z) for z in joints) == pytest.approx(half)
            if bulge:
                # an arc round a joint's centre, of the half-width, turning outwards
                c, _, _, radius = bulge_to_arc((x, y), (x2, y2), bulge)
                assert radius == pytest.approx(half) and bulge > 0
                assert min(abs(complex(c.x, c.y) - z) for z in joints) <= tol
                arcs += 1
        # one arc per joint on the hull: two for a bar, as many as corners for a plate
        assert arcs == (2 if len(joints) == 2 or _collinear(joints) else len(_hull(joints)))
        flat = np.array([complex(v.x, v.y) for v in dxf_path.make_path(outline).flattening(tol)])
        corners = _hull(joints) if len(joints) > 2 and not _collinear(joints) else joints
        ring = [*corners, corners[0]] if len(corners) > 2 else corners
        d = np.min([_segment_distance(flat, a, b) for a, b in itertools.pairwise(ring)], axis=0)
        # nowhere nearer the joints than the half-width (ezdxf draws arcs as Béziers)
        assert d.min() >= half * (1 - 1e-3)
        # a part that could be cut: every joint and point of the link inside its outline
        from matplotlib.path import Path

        ring_path = Path(np.column_stack([flat.real, flat.imag]))
        inside = np.array([[z.real, z.imag] for z in joints])
        assert ring_path.contains_points(inside).all(), link
    for point in msp.query("POINT"):  # each point of interest on its link's plate
        (p,) = [x for x in m.points if layer_name(x.link) == point.dxf.layer]
        assert abs(complex(point.dxf.location.x, point.dxf.location.y) - spot[p.id]) <= tol
    assert len(msp.query('TEXT[layer=="labels"]')) >= len(m.joints) - 5


def test_without_ezdxf_one_line_naming_the_extra(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(dxf_module, "dxf_available", lambda: False)
    out = tmp_path / "m.dxf"
    assert main(["draw", str(example_path("four-bar")), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "needs ezdxf" in err and "mjstruct[cad]" in err
    assert "Traceback" not in err and os.listdir(tmp_path) == []


def test_dxf_refuses_layers(tmp_path, capsys):
    out = tmp_path / "m.dxf"
    argv = ["draw", str(example_path("four-bar")), "--show", "velocity", "-o", str(out)]
    assert main(argv) == 2
    assert "--show: a .dxf holds the links' outlines only" in capsys.readouterr().err
    assert os.listdir(tmp_path) == []
