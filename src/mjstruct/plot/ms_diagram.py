"""Singularity charts: the P2-P3 diagram of hinged four-bars and the clearance zones.

Owns two drawings (matplotlib imported inside them): :func:`plot_ms_diagram`, the
plane of the relative coupler and output lengths at a fixed input length ``P1``, cut
by the three lines of system (4) into regions labelled by the motion, with the
reference points M1-M5 and a given mechanism's point, each with the classes of its
singular positions (types I-V and traps A-E, :mod:`mjstruct.singular.classification`); and
:func:`plot_singular_zones`, a four-bar drawn at each of its singular positions with
the wedge of its clearance zone at the pivot of the zone's link.

References
----------
.. [1] Singular positions and synthesis of hinged multi-joint mechanisms with
   clearances in their revolute pairs (in Russian; eLibrary document code EDN PBGDPR;
   authors, exact title, journal and year not given in the available copy).
   [Four-bar clearances] in docs/references.md.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> fig = plot_ms_diagram(0.5, point=(1.0, 1.5))
>>> [t.get_text() for t in fig.axes[0].texts if t.get_text().startswith("M")]
['M1', 'M2', 'M3', 'M4']
>>> fig.axes[0].get_legend().get_texts()[3].get_text()
'mechanism: II/B//П, II/B//В'
"""

from __future__ import annotations

import contextlib
import math
from typing import TYPE_CHECKING

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.singular.classification import fourbar_classes
from mjstruct.singular.fourbar import MOTIONS, REFERENCE_MATRICES, fourbar_theory

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from mjstruct.mechanism import Mechanism
    from mjstruct.singular.analysis import SingularAnalysis

COLOURS = {
    "crank-rocker": "#9ecae1",
    "double-crank": "#a1d99b",
    "double-rocker": "#fdd0a2",
    "triple-rocker": "#dadaeb",
    "rocker-crank": "#fcbba1",
    "no loop": "#ffffff",
}


def plot_ms_diagram(
    P1: float,
    point: tuple[float, float] | None = None,
    label: str = "mechanism",
    extent: float = 2.5,
    resolution: int = 400,
    ax: Axes | None = None,
) -> Figure:
    """The P2-P3 diagram at fixed ``P1``: regions of motion, lines (4.1)-(4.3), M1-M5.

    Parameters
    ----------
    P1 : relative input length (input over frame), > 0.
    point : a mechanism's (P2, P3) to mark.
    label : its label.
    extent : the plot spans 0..extent on both axes.
    resolution : grid points per axis for the regions.
    ax : draw into these axes (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not (math.isfinite(P1) and P1 > 0):
        raise MechanismError(f"P1: must be a positive number, got {P1}")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    if ax is None:
        fig, ax = plt.subplots(figsize=(8.4, 6.0))
    else:
        fig = ax.figure  # type: ignore[assignment]
    names = [*MOTIONS, "no loop"]
    g = np.linspace(extent / resolution / 2, extent, resolution)
    code = np.full((resolution, resolution), len(MOTIONS))
    for i, p3 in enumerate(g):
        for j, p2 in enumerate(g):
            with contextlib.suppress(MechanismError):  # no loop: left white
                code[i, j] = MOTIONS.index(fourbar_theory(P1, p2, p3).motion)
    cmap = ListedColormap([COLOURS[n] for n in names])
    ax.imshow(
        code,
        origin="lower",
        extent=(0, extent, 0, extent),
        cmap=cmap,
        vmin=-0.5,
        vmax=len(names) - 0.5,
        interpolation="nearest",
    )
    x = np.array([0.0, extent])
    lines = {
        "(4.1) 1 + P1 = P2 + P3": (x, 1 + P1 - x),
        "(4.2) 1 + P2 = P1 + P3": (x, 1 + x - P1),
        "(4.3) 1 + P3 = P1 + P2": (x, P1 + x - 1),
    }
    for (text, (xs, ys)), style in zip(lines.items(), ("-", "--", "-."), strict=True):
        ax.plot(xs, ys, "k", linestyle=style, linewidth=1.2, label=text)
    for k, (name, (p1, p2, p3)) in enumerate(REFERENCE_MATRICES.items(), 1):
        if abs(p1 - P1) < 1e-12:
            ax.plot([p2], [p3], "ko", markersize=6)
            ax.annotate(f"M{k}", (p2, p3), textcoords="offset points", xytext=(6, 6))
            # its singular positions' classes of [Four-bar clearances], in closed form
            ax.annotate(
                ", ".join(fourbar_classes(p1, p2, p3)), (p2, p3), textcoords="offset points",
                xytext=(6, -8), fontsize=6, gid=f"classes:M{k}",
            )  # fmt: skip
        del name
    if point is not None:
        with contextlib.suppress(MechanismError):  # no loop: no classes
            label = f"{label}: {', '.join(fourbar_classes(P1, *point))}"
        ax.plot([point[0]], [point[1]], "r*", markersize=14, label=label)
    patches = [Patch(facecolor=COLOURS[n], edgecolor="0.5", label=n) for n in names]
    handles, _ = ax.get_legend_handles_labels()
    # beside the diagram: its regions and lines are what it shows
    ax.legend(
        handles=handles + patches, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7,
        frameon=False,
    )  # fmt: skip
    ax.set_xlim(0, extent)
    ax.set_ylim(0, extent)
    ax.set_xlabel("P2 = l2 / l0 (coupler)")
    ax.set_ylabel("P3 = l3 / l0 (output)")
    ax.set_title(f"Four-bar P2-P3 diagram at P1 = {P1:g}")
    ax.set_aspect("equal")
    return fig


def ms_point(mechanism: Mechanism) -> tuple[float, float, float]:
    """(P1, P2, P3) of a four-bar driven at a frame joint."""
    from mjstruct.singular.analysis import fourbar_lengths
    from mjstruct.singular.curve import ClosureEquations

    if len(mechanism.drivers) != 1:
        raise MechanismError("drivers: the P2-P3 diagram needs a four-bar with one driver")
    eq = ClosureEquations.build(mechanism, mechanism.drivers[0])
    lengths = fourbar_lengths(mechanism, eq)
    if lengths is None:
        raise MechanismError("mechanism: the P2-P3 diagram is for a four-bar driven at the frame")
    l0, l1, l2, l3 = lengths
    return l1 / l0, l2 / l0, l3 / l0


#: colours of the singular positions (outside the link and group colours)
POSITION_COLOURS = ("#e6008a", "#00897b", "#ef6c00", "#5e35b1", "#6d4c41")


def plot_singular_zones(
    mechanism: Mechanism, analysis: SingularAnalysis, ax: Axes | None = None
) -> Figure:
    """The linkage's scheme at its singular positions, with the clearance-zone wedges.

    The first position is drawn as ``mjstruct draw`` draws the mechanism
    (:func:`~mjstruct.plot.drawing.draw_scene`: frame, links, pins, labels), the others
    as dashed outlines over it, each position in its own colour; every zone is a wedge
    of angle ``psi`` centred on the zone link's direction at the pivot the link turns
    about, marked ψ1, ψ2, ... and listed with its value right of the drawing.
    """
    import dataclasses

    import matplotlib.pyplot as plt

    from mjstruct.kinematics.model import KinematicModel
    from mjstruct.plot.drawing import anchor_positions, draw_scene, scene_at

    if ax is None:
        fig, ax = plt.subplots(figsize=(9.0, 5.6))
    else:
        fig = ax.figure  # type: ignore[assignment]
    model = KinematicModel.build(mechanism, [analysis.input])
    m = mechanism
    scenes = [scene_at(model, q=[p.q]) for p in analysis.singular]
    placed = [
        anchor_positions(s, int(s.shown[-1])) if s.motion.valid[int(s.shown[-1])] else None
        for s in scenes
    ]
    if scenes:
        # one picture frame for every position: the first scene's, grown to cover them
        # all (its footer, with the scale bar, stays below everything)
        base = scenes[0]
        cloud = np.array([z for pos in placed if pos for z in pos.values()], complex)
        x0, x1, y0, y1 = base.limits
        if cloud.size:
            pad = 0.12 * model.scale
            x0, x1 = min(x0, cloud.real.min() - pad), max(x1, cloud.real.max() + pad)
            y0 = min(y0, cloud.imag.min() - pad - base.footer)
            y1 = max(y1, cloud.imag.max() + pad)
        draw_scene(dataclasses.replace(base, limits=(x0, x1, y0, y1)), ax=ax, title=False)
    notes = 0
    for k, (p, pos) in enumerate(zip(analysis.singular, placed, strict=True)):
        colour = POSITION_COLOURS[k % len(POSITION_COLOURS)]
        if pos is None:
            continue
        if k > 0:
            for link in m.links:
                if link != m.frame:
                    z = [pos[j] for j in m.link_joints[link]]
                    ax.plot([w.real for w in z], [w.imag for w in z], "--", color=colour,
                            lw=1.6, zorder=4, gid=f"position:{k}:{link}")  # fmt: skip
        degrees = round(math.degrees(p.q) % 360.0, 2) % 360.0
        label = f"{p.kind.replace('_', ' ')}, q = {degrees:.2f}°"
        ax.plot([], [], "-" if k == 0 else "--", color=colour, lw=2, label=label)
        for zone in p.zone or ():
            if zone.psi is None or zone.pair is None:
                continue
            a, b = zone.pair
            # the longer link turns about its far end (the pivot of formula (3))
            shared = next(j for j in m.link_joints[a] if j in m.link_joints[b])
            far = next(j for j in m.link_joints[zone.link] if j != shared)
            _zone(ax, pos[far], pos[shared], zone.psi, colour, notes, zone.link, (a, b))
            notes += 1
    # beside the axes, the positions and below them the zones' callouts: the scheme
    # fills the axes
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    clearance = "" if analysis.clearance is None else f" (D = {analysis.clearance:g})"
    ax.set_title(f"{m.name or 'mechanism'}: singular positions and clearance zones{clearance}",
                 fontsize=10)  # fmt: skip
    return fig


def _zone(
    ax: Axes,
    centre: complex,
    tip: complex,
    psi: float,
    colour: str,
    n: int,
    link: str,
    pair: tuple[str, str],
) -> None:
    """A wedge of angle ``psi`` about ``centre`` towards ``tip``, with ψ written beside it."""
    from matplotlib.patches import Wedge

    direction = math.degrees(math.atan2((tip - centre).imag, (tip - centre).real))
    half = math.degrees(psi) / 2
    ax.add_patch(
        Wedge(
            (centre.real, centre.imag),
            abs(tip - centre),
            direction - half,
            direction + half,
            facecolor=colour,
            edgecolor=colour,
            alpha=0.3,
            lw=1.0,
            zorder=8,
            gid=f"zone:{link}:{n}",
        )
    )
    # the wedge is marked ψ1, ψ2, ... at a corner; its value is listed in a column
    # right of the drawing, below the legend (no text on the drawing itself)
    # at the corner of the wedge, off the link's line
    u = np.exp(1j * math.radians(direction + half))
    corner = centre + abs(tip - centre) * u
    ax.annotate(
        f"ψ{n + 1}",
        (corner.real, corner.imag),
        xytext=(9 * u.real, 9 * u.imag),
        textcoords="offset points",
        ha="center",
        va="center",
        fontsize=8,
        color=colour,
        zorder=9,
        gid=f"psi:{link}:{n}:mark",
    )
    ax.annotate(
        f"ψ{n + 1} = {math.degrees(psi):.3g}° (link {link}, pair {pair[0]}-{pair[1]})",
        (1.02, 0.72 - 0.06 * n),
        xycoords="axes fraction",
        ha="left",
        va="center",
        fontsize=8,
        color=colour,
        zorder=9,
        gid=f"psi:{link}:{n}",
    )
