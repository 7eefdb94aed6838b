"""Drawing an Assur-group decomposition on the link–joint graph (matplotlib, lazy).

This module owns the picture of :func:`mjstruct.structure.assur.assur_groups`: links
are discs coloured by the group that places them (frame grey, driven links of the
initial mechanisms dark), joints are squares, a multiple joint is one larger square
drawn once with an edge to every link it joins, so the picture shows an MJ whole.
Node positions come from the joints' ``at`` coordinates when the file has them (a
link sits at the mean of its joints), else from a Kamada–Kawai layout of the graph.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> from mjstruct.mechanism import Mechanism
>>> from mjstruct.structure.assur import assur_groups
>>> m = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
...                      ("O2", [3, 0])], frame=0, drivers=["O1"])
>>> ax = plot_decomposition(m, assur_groups(m))
>>> len(ax.get_legend().get_texts())
3
"""

from __future__ import annotations

from typing import Any

from mjstruct.mechanism import Mechanism
from mjstruct.plot.layout import equal_scale
from mjstruct.structure.assur import Decomposition, roman

Position = dict[tuple[str, str], tuple[float, float]]


def layout(m: Mechanism) -> Position:
    """Positions of ``("link", id)`` and ``("joint", id)`` nodes."""
    if all(j.at is not None for j in m.joints):
        pos: Position = {("joint", j.id): (j.at[0], j.at[1]) for j in m.joints if j.at}
        for link, jids in m.link_joints.items():
            xs = [pos[("joint", k)] for k in jids]
            pos[("link", link)] = (
                sum(x for x, _ in xs) / len(xs),
                sum(y for _, y in xs) / len(xs),
            )
        return pos
    import networkx as nx

    g = nx.Graph()
    for j in m.joints:
        g.add_edges_from((("joint", j.id), ("link", x)) for x in j.links)
    raw = nx.kamada_kawai_layout(g)
    return {k: (float(v[0]), float(v[1])) for k, v in raw.items()}


def plot_decomposition(
    m: Mechanism, d: Decomposition, ax: Any = None, pos: Position | None = None
) -> Any:
    """Draw the link–joint graph coloured by Assur group; returns the matplotlib axes."""
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 7))
    pos = layout(m) if pos is None else pos
    cmap = plt.get_cmap("tab10")
    colour: dict[str, Any] = {m.frame or "": "0.6"}
    label: dict[str, str] = {}
    for _, _, driven in d.initial:
        colour[driven] = "0.25"
    for k, g in enumerate(d.groups):
        for x in g.links:
            colour[x] = cmap(k % 10)
    # edges first, under the nodes
    for j in m.joints:
        jx, jy = pos[("joint", j.id)]
        for x in j.links:
            lx, ly = pos[("link", x)]
            ax.plot([jx, lx], [jy, ly], color="0.5", lw=1.0, zorder=1)
    for j in m.joints:
        jx, jy = pos[("joint", j.id)]
        size = 90 + 40 * (len(j.links) - 2)
        face = "white" if j.kind == "R" else "#ffe9a8"
        edge = "crimson" if j.id in d.drivers else "black"
        ax.scatter([jx], [jy], marker="s", s=size, c=face, edgecolors=edge, lw=1.5, zorder=2)
        ax.annotate(j.id, (jx, jy), xytext=(6, 6), textcoords="offset points", fontsize=8)
    for x in m.links:
        lx, ly = pos[("link", x)]
        ax.scatter([lx], [ly], s=380, c=[colour.get(x, "white")], edgecolors="black", zorder=3)
        ax.annotate(x, (lx, ly), ha="center", va="center", color="white", fontsize=9, zorder=4)
    # legend: one entry per group, plus frame and initial mechanisms
    handles = [
        Line2D([], [], marker="o", ls="", ms=10, mfc="0.6", mec="black", label="frame"),
        Line2D(
            [],
            [],
            marker="o",
            ls="",
            ms=10,
            mfc="0.25",
            mec="black",
            label="driven: " + ", ".join(f"{b} ({dr})" for dr, _, b in d.initial),
        ),
    ]
    for k, g in enumerate(d.groups):
        where = "" if g.reference == d.frame else f", in frame of {g.reference}"
        text = f"{k + 1}: class {roman(g.klass)}, links {', '.join(g.links)}{where}"
        label[str(k)] = text
        handles.append(
            Line2D([], [], marker="o", ls="", ms=10, mfc=cmap(k % 10), mec="black", label=text)
        )
    ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.9)
    equal_scale(ax)
    ax.set_axis_off()
    title = m.name or "mechanism"
    ax.set_title(
        f"{title}: Assur groups (mechanism class {roman(d.mechanism_class)})", fontsize=10
    )
    return ax


def save_figure(m: Mechanism, d: Decomposition, path: str) -> None:
    """Draw and write a PNG (Agg backend, no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 8))
    plot_decomposition(m, d, ax=ax)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
