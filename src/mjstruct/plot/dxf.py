"""CAD export: the mechanism at one configuration as a DXF drawing for the workshop.

Owns :func:`write_dxf` (ezdxf, the optional ``cad`` extra): one layer per moving link
(``link-ID``) holding its outline, a binary link as a bar with rounded ends, a
ternary or higher link, or any link carrying a point off its bar, as a plate (the
hull of its joints and points grown by the bar's half-width, corners rounded: every
point of the link lies inside), a straight link as a bar between its extreme
joints or points, and a pin hole at each of its joints; the frame on layer ``frame``: a hole at
each frame pivot with a cross through it, and the guide lines of sliders on the
frame; slider blocks as rectangles on their link's layer, guides of moving links as
lines on the carrier's layer; joint ids as text on layer ``labels``; the gears' pitch
circles (the file's ``gears``) on layer ``pitch-circles``.  Lengths are the
file's length unit; sizes follow the mechanism's size as on a drawing (the pin hole's
radius is the pin's, :data:`~mjstruct.plot.style.PIN` of the size; a bar's
half-width is twice that).

Examples
--------
>>> import tempfile, os, ezdxf
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> from mjstruct.plot.scene import scene_at
>>> scene = scene_at(KinematicModel.build(read_mechanism(example_path("four-bar"))), q=1.0)
>>> out = os.path.join(tempfile.mkdtemp(), "four-bar.dxf")
>>> write_dxf(scene, out)
>>> sorted(layer.dxf.name for layer in ezdxf.readfile(out).layers)[:5]
['0', 'Defpoints', 'frame', 'labels', 'link-1']
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.plot.files import check_output, write_atomically
from mjstruct.plot.gear_artists import drawn_gears
from mjstruct.plot.scene import Scene, anchor_positions, duplicate_joint, guide_sides
from mjstruct.plot.scheme import bar_ends, is_bar, link_outline, plate_outline
from mjstruct.typing import ComplexArray

#: how ``pip`` names what writing DXF needs
CAD_EXTRA = "mjstruct[cad]"
#: a bar's half-width over the pin hole's radius
BAR = 2.0


def dxf_available() -> bool:
    """Whether ezdxf is installed."""
    import importlib.util

    return importlib.util.find_spec("ezdxf") is not None


def check_dxf(name: str = "path") -> None:
    """Refuse (``MechanismError`` naming ``name``) when ezdxf is not installed."""
    if not dxf_available():
        raise MechanismError(
            f"{name}: writing .dxf needs ezdxf, which is not installed (pip install '{CAD_EXTRA}')"
        )


#: characters DXF forbids in table names, and control characters (NUL, ESC, BEL, ...)
_FORBIDDEN = re.compile(r'[<>/\\":;?*|=`,\s\x00-\x1f\x7f-\x9f]')
#: the longest layer name DXF readers accept
MAX_NAME = 255
#: layers every drawing has (compared without case, as DXF compares table names)
_RESERVED = ("0", "defpoints", "frame", "labels", "pitch-circles")


def layer_name(link: str) -> str:
    """The DXF layer of a link: ``link-ID``, characters DXF forbids in names (and control
    characters) as ``_``, at most :data:`MAX_NAME` characters less room for a suffix
    that tells apart links whose names would coincide (:func:`layer_names`)."""
    return ("link-" + _FORBIDDEN.sub("_", link))[: MAX_NAME - 8]


def layer_names(links: Sequence[str]) -> dict[str, str]:
    """Each link's layer: :func:`layer_name`, made unique without case (``Arm`` and
    ``arm``, ``a<b`` and ``a>b`` are two links but would be one DXF layer) by a
    suffix ``~2``, ``~3``, ...

    >>> layer_names(["Arm", "arm", "a<b", "a>b"])
    {'Arm': 'link-Arm', 'arm': 'link-arm~2', 'a<b': 'link-a_b', 'a>b': 'link-a_b~2'}
    """
    taken = set(_RESERVED)
    out: dict[str, str] = {}
    for link in links:
        base = name = layer_name(link)
        k = 1
        while name.lower() in taken:
            k += 1
            name = f"{base}~{k}"
        taken.add(name.lower())
        out[link] = name
    return out


def dxf_text(text: str) -> str:
    """An id as DXF TEXT: control characters (NUL, ESC, BEL, newlines, ...) written as
    ``\\xNN`` so that a reader sees them and no reader chokes on them.

    >>> print(dxf_text("A" + chr(0) + "B" + chr(27)))
    A\\x00B\\x1b
    """
    return re.sub(r"[\x00-\x1f\x7f-\x9f]", lambda c: f"\\x{ord(c.group()):02x}", text)


def write_dxf(scene: Scene, path: str, name: str = "path") -> None:
    """Write the last shown frame of ``scene`` as DXF to ``path`` (atomically).

    Raises
    ------
    MechanismError
        ezdxf not installed (naming the ``cad`` extra), an unwritable path, or a
        configuration where the mechanism does not assemble.
    """
    check_output(path, (".dxf",), name=name)
    check_dxf(name)
    from ezdxf.enums import InsertUnits
    from ezdxf.filemanagement import new

    k = int(scene.shown[-1])
    if not scene.motion.valid[k]:
        q = ", ".join(f"{v:.9g}" for v in scene.motion.q[k])
        raise MechanismError(f"q: the mechanism does not assemble at q = {q}: nothing to export")
    doc = new("R2010", setup=True)
    doc.units = InsertUnits.Unitless  # the file's own length unit
    msp = doc.modelspace()
    model = scene.model
    m = model.mechanism
    at = anchor_positions(scene, k)
    hole = scene.pin
    half = BAR * hole
    doc.layers.add("frame", color=8)
    doc.layers.add("labels", color=7)
    layers = layer_names([x for x in m.links if x != model.frame])
    for n, (link, layer) in enumerate(layers.items()):
        doc.layers.add(layer, color=1 + n % 6)
        keys = link_outline(scene, link)
        pts = np.array([at[key] for key in keys], complex)
        if len(pts) >= 2:
            _outline(msp, pts, half, layer)
        if layer != "link-" + link:  # the id the layer's name could not keep, as TEXT
            text = msp.add_text(dxf_text(f"link {link}"), height=1.5 * hole,
                                dxfattribs={"layer": layer})  # fmt: skip
            text.set_placement((pts[0].real - 1.5 * hole, pts[0].imag - 3.0 * hole))
        for jid in m.link_joints[link]:
            j = m.joint(jid)
            if j.kind == "R":
                _circle(msp, at[jid], hole, layer)
    for j in m.joints:
        if j.kind == "R" and model.frame in j.links:
            c = at[j.id]
            _circle(msp, c, hole, "frame")
            for d in (1.0, 1j):  # a cross through the pivot
                _line(msp, c - 2 * hole * d, c + 2 * hole * d, "frame")
        if j.kind == "P":
            carrier, block = guide_sides(model, j.id)
            a, b = at[f"{j.id}/guide0"], at[f"{j.id}/guide1"]
            _line(msp, a, b, "frame" if carrier == model.frame else layers[carrier])
            _block(msp, at[f"{j.id}/block"], (b - a) / abs(b - a), hole, layers[block])
        if not (j.kind == "P" and duplicate_joint(model, j.id)):
            z = at[j.id] if j.kind == "R" else at[f"{j.id}/block"]
            label = msp.add_text(dxf_text(j.id), height=1.5 * hole, dxfattribs={"layer": "labels"})
            label.set_placement((z.real + 1.5 * hole, z.imag + 1.5 * hole))
    for pid, (link, _) in model.geometry.points.items():
        z = at[pid]
        msp.add_point((z.real, z.imag), dxfattribs={"layer": layers.get(link, "frame")})
    gears = drawn_gears(model)
    if gears:  # pitch circles, one layer for all (the gears' links keep their outlines)
        doc.layers.add("pitch-circles", color=3)
        for g in gears:
            _circle(msp, at[g.joint], g.radius, "pitch-circles")
    write_atomically(path, lambda tmp: doc.saveas(tmp), name=name)


def _xy(z: complex) -> tuple[float, float]:
    return (float(z.real), float(z.imag))


def _circle(msp: Any, c: complex, r: float, layer: str) -> None:
    msp.add_circle(_xy(c), r, dxfattribs={"layer": layer})


def _line(msp: Any, a: complex, b: complex, layer: str) -> None:
    msp.add_line(_xy(a), _xy(b), dxfattribs={"layer": layer})


def _block(msp: Any, c: complex, u: complex, hole: float, layer: str) -> None:
    """A slider block: a rectangle 2.8 × 1.7 pin radii (half sizes) along the guide."""
    n = 1j * u
    corners = [c + s * 2.8 * hole * u + t * 1.7 * hole * n
               for s, t in ((-1, -1), (1, -1), (1, 1), (-1, 1))]  # fmt: skip
    msp.add_lwpolyline([_xy(p) for p in corners], close=True, dxfattribs={"layer": layer})


def _outline(msp: Any, pts: ComplexArray, half: float, layer: str) -> None:
    """A link's outline: the convex hull of its joints and points grown by ``half``,
    the corners rounded (two of them, or all on one line: a bar with rounded ends)."""
    if len(pts) == 2 or is_bar(pts):
        a, b = bar_ends(pts)
        hull = [a, b]
    else:
        hull = list(plate_outline(pts))
    msp.add_lwpolyline(_rounded(hull, half), format="xyb", close=True,
                       dxfattribs={"layer": layer})  # fmt: skip


def _rounded(hull: list[complex], half: float) -> list[tuple[float, float, float]]:
    """(x, y, bulge) of the closed outline around a counter-clockwise convex polygon
    (two points: a segment) at distance ``half``: straight offsets of the edges joined
    by arcs around the corners (a bulge is tan of a quarter of the arc's angle)."""
    n = len(hull)
    out: list[tuple[float, float, float]] = []
    for i in range(n):
        prev, here, nxt = hull[i - 1], hull[i], hull[(i + 1) % n]
        d_in = (here - prev) / abs(here - prev)
        d_out = (nxt - here) / abs(nxt - here)
        start = here - 1j * half * d_in  # outward (right) normal of the edge coming in
        end = here - 1j * half * d_out  # and of the edge going out
        turn = math.atan2((d_out * d_in.conjugate()).imag, (d_out * d_in.conjugate()).real)
        if n == 2:
            turn = math.pi  # a bar's end: a half circle
        # counter-clockwise around the corner: a positive bulge
        out.append((start.real, start.imag, math.tan(turn / 4)))
        out.append((end.real, end.imag, 0.0))
    return out
