"""Singularity charts: the P2-P3 diagram of hinged four-bars and the clearance zones.

Owns two drawings (matplotlib imported inside them): :func:`plot_ms_diagram`, the
plane of the relative coupler and output lengths at a fixed input length ``P1``, cut
by the three lines of system (4) into regions labelled by the motion, with the
reference points M1-M5 and a given mechanism's point; and
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
"""

from __future__ import annotations

import contextlib
import math
from typing import TYPE_CHECKING

import numpy as np

from mjstruct.errors import MechanismError
from mjstruct.kinematics.fourbar import MOTIONS, REFERENCE_MATRICES, fourbar_theory

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from mjstruct.kinematics.singular import SingularAnalysis
    from mjstruct.mechanism import Mechanism

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
        fig, ax = plt.subplots(figsize=(6.4, 6.0))
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
        del name
    if point is not None:
        ax.plot([point[0]], [point[1]], "r*", markersize=14, label=label)
    patches = [Patch(facecolor=COLOURS[n], edgecolor="0.5", label=n) for n in names]
    handles, _ = ax.get_legend_handles_labels()
    ax.legend(handles=handles + patches, loc="upper right", fontsize=7, framealpha=0.9)
    ax.set_xlim(0, extent)
    ax.set_ylim(0, extent)
    ax.set_xlabel("P2 = l2 / l0 (coupler)")
    ax.set_ylabel("P3 = l3 / l0 (output)")
    ax.set_title(f"Four-bar P2-P3 diagram at P1 = {P1:g}")
    ax.set_aspect("equal")
    return fig


def ms_point(mechanism: Mechanism) -> tuple[float, float, float]:
    """(P1, P2, P3) of a four-bar driven at a frame joint."""
    from mjstruct.kinematics.singular import fourbar_lengths
    from mjstruct.kinematics.singular_curve import ClosureEquations

    if len(mechanism.drivers) != 1:
        raise MechanismError("drivers: the P2-P3 diagram needs a four-bar with one driver")
    eq = ClosureEquations.build(mechanism, mechanism.drivers[0])
    lengths = fourbar_lengths(mechanism, eq)
    if lengths is None:
        raise MechanismError("mechanism: the P2-P3 diagram is for a four-bar driven at the frame")
    l0, l1, l2, l3 = lengths
    return l1 / l0, l2 / l0, l3 / l0


def plot_singular_zones(
    mechanism: Mechanism, analysis: SingularAnalysis, ax: Axes | None = None
) -> Figure:
    """The linkage drawn at each singular position, with its clearance-zone wedges.

    Each position is drawn in its own colour (joints as circles, links as bars);
    every zone is a wedge of angle ``psi`` centred on the zone link's direction at
    the pivot the link turns about.
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Wedge

    from mjstruct.kinematics.singular_curve import ClosureEquations

    if ax is None:
        fig, ax = plt.subplots(figsize=(7.0, 5.0))
    else:
        fig = ax.figure  # type: ignore[assignment]
    eq = ClosureEquations.build(mechanism, analysis.input, analysis.output)
    m = mechanism
    colours = plt.get_cmap("tab10")
    for k, p in enumerate(analysis.singular):
        x = np.array(p.configuration)
        pos = {j.id: eq.in_file_units(eq.joint_position(x, j.id)) for j in m.joints}
        c = colours(k % 10)
        for link in m.links:
            if link == m.frame:
                continue
            js = [pos[j] for j in m.link_joints[link]]
            ax.plot([z.real for z in js], [z.imag for z in js], "-", color=c, linewidth=2)
        for jid, z in pos.items():
            ax.plot([z.real], [z.imag], "o", color=c, markerfacecolor="white", markersize=5)
            if k == 0:
                ax.annotate(jid, (z.real, z.imag), textcoords="offset points", xytext=(4, -10))
        for zone in p.zone or ():
            if zone.psi is None or zone.pair is None:
                continue
            a, b = zone.pair
            # the longer link turns about its far end (the pivot of formula (3))
            shared = next(j for j in m.link_joints[a] if j in m.link_joints[b])
            far = next(j for j in m.link_joints[zone.link] if j != shared)
            centre = pos[far]
            arm = pos[shared] - centre
            direction = math.degrees(math.atan2(arm.imag, arm.real))
            radius = abs(pos[shared] - centre)
            half = math.degrees(zone.psi) / 2
            ax.add_patch(
                Wedge(
                    (centre.real, centre.imag),
                    radius,
                    direction - half,
                    direction + half,
                    color=c,
                    alpha=0.25,
                )
            )
        ax.plot([], [], "-", color=c, label=f"{p.kind} q = {math.degrees(p.q):.2f} deg")
    fz = [eq.geometry.centres[j.id] for j in m.joints if m.frame in j.links]
    ax.plot([z.real for z in fz], [z.imag for z in fz], "k^", markersize=9)
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    ax.set_title(f"singular positions and clearance zones (D = {analysis.clearance:g})")
    return fig
