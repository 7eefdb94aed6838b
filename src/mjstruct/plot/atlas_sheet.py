"""Atlas sheets: chains drawn as small figures on a grid, the form atlases are printed in.

Owns :func:`chain_layout` (where to put the joints of a chain without geometry),
:func:`draw_chain` (one panel: links as bars or as polygons of their joints, every
joint a pin, a multiple joint with one dot per link around it) and
:func:`write_atlas_sheet` (the grid, captioned with index, catalog id, [LA]/[MJA] and
a short canonical id; a PDF gets one page per grid).

A planar chain is drawn in a planar embedding with straight edges and no crossings:
the link–joint graph is embedded (networkx's planarity test), each link becomes the
polygon of its joints in the embedding's rotation order, and the resulting joint graph
is placed by Tutte's barycentric method on one of its longest faces (the crossing-free
drawing whose joints lie farthest apart), falling back to the
Chrobak–Payne grid drawing (``networkx.planar_layout``) when Tutte's drawing is not
crossing-free.  :func:`crossings` counts crossing edges, so the result is checked,
not assumed.  A non-planar chain gets a Kamada–Kawai layout and says so.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> m = Mechanism.build([("A", [0, 1]), ("B", [1, 2]), ("C", [2, 3, 4]), ("D", [3, 5]),
...                      ("E", [5, 0]), ("F", [4, 5]), ("G", [0, 4])])
>>> lay = chain_layout(m)
>>> lay.planar, crossings(lay)
(True, 0)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from mjstruct.mechanism import Mechanism

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from mjstruct.synthesis.atlas import Chain

#: panels per page of a PDF atlas sheet
PER_PAGE = 30


@dataclass(frozen=True)
class ChainLayout:
    """Joint positions of a chain and each link's outline.

    Attributes
    ----------
    pos : joint id -> position (complex).
    outline : link id -> its joints in drawing order (a polygon when 3 or more).
    planar : whether the chain is planar (and so drawn without crossings).
    """

    pos: dict[str, complex]
    outline: dict[str, tuple[str, ...]]
    planar: bool

    def edges(self) -> list[tuple[str, str]]:
        """The drawn segments: each link's sides (a binary link is one segment)."""
        out: list[tuple[str, str]] = []
        for js in self.outline.values():
            if len(js) == 2:
                out.append((js[0], js[1]))
            elif len(js) > 2:
                out += [(js[i], js[(i + 1) % len(js)]) for i in range(len(js))]
        return out


def chain_layout(m: Mechanism) -> ChainLayout:
    """Place the joints of ``m``: crossing-free straight lines when the chain is planar."""
    import networkx as nx

    g = m.graph()
    planar, emb = nx.check_planarity(g)
    if planar:
        outline = {
            link: tuple(j for _, j in emb.neighbors_cw_order(("link", link))) for link in m.links
        }
        jg = _joint_graph(m, outline)
        pos = _tutte(jg, outline)
        lay = ChainLayout(pos, outline, True) if pos is not None else None
        if lay is None:
            raw = nx.planar_layout(jg)
            lay = ChainLayout({k: complex(*v) for k, v in raw.items()}, outline, True)
        return _normalised(lay)
    raw = nx.kamada_kawai_layout(g)
    pos = {j.id: complex(*raw[("joint", j.id)]) for j in m.joints}
    outline = {}
    for link, js in m.link_joints.items():
        c = sum(pos[j] for j in js) / len(js)
        outline[link] = tuple(sorted(js, key=lambda j: float(np.angle(pos[j] - c))))
    return _normalised(ChainLayout(pos, outline, False))


def _joint_graph(m: Mechanism, outline: dict[str, tuple[str, ...]]) -> Any:
    import networkx as nx

    jg = nx.Graph()
    jg.add_nodes_from(j.id for j in m.joints)
    for js in outline.values():
        if len(js) == 2:
            jg.add_edge(js[0], js[1])
        elif len(js) > 2:
            jg.add_edges_from((js[i], js[(i + 1) % len(js)]) for i in range(len(js)))
    return jg


def _faces(emb: Any) -> list[list[Any]]:
    seen: set[tuple[Any, Any]] = set()
    faces = []
    for v, w in emb.edges():
        if (v, w) in seen:
            continue
        face = emb.traverse_face(v, w, mark_half_edges=seen)
        faces.append(face)
    return faces


def _tutte(jg: Any, outline: dict[str, tuple[str, ...]]) -> dict[str, complex] | None:
    """Tutte's barycentric drawing, the best of the longest faces taken as the outer one
    (crossing-free, joints farthest apart); None when none applies."""
    import networkx as nx

    if jg.number_of_nodes() < 3 or not nx.is_connected(jg):
        return None
    planar, emb = nx.check_planarity(jg)
    if not planar:
        return None
    faces = sorted(_faces(emb), key=len, reverse=True)[:8]
    best: tuple[float, dict[str, complex]] | None = None
    for outer in faces:
        pos = _barycentric(jg, outer)
        if pos is None or _coincide(pos):
            continue
        if crossings(ChainLayout(pos, outline, True)):
            continue
        score = _spacing(pos)
        if best is None or score > best[0]:
            best = (score, pos)
    return None if best is None else best[1]


def _spacing(pos: dict[str, complex]) -> float:
    """Smallest distance between two joints over the drawing's size."""
    z = np.array(list(pos.values()))
    d = np.abs(z[:, None] - z[None, :]) + np.eye(z.size) * 1e9
    return float(d.min() / max(float(np.abs(z - z.mean()).max()), 1e-12))


def _barycentric(jg: Any, outer: list[Any]) -> dict[str, complex] | None:
    if len(outer) < 3 or len(set(outer)) != len(outer):
        return None
    pos: dict[str, complex] = {
        v: complex(np.exp(2j * np.pi * k / len(outer))) for k, v in enumerate(outer)
    }
    inner = [v for v in jg.nodes if v not in pos]
    if inner:
        index = {v: i for i, v in enumerate(inner)}
        a = np.zeros((len(inner), len(inner)))
        b = np.zeros(len(inner), complex)
        for v in inner:
            i = index[v]
            a[i, i] = jg.degree(v)
            for w in jg.neighbors(v):
                if w in index:
                    a[i, index[w]] -= 1.0
                else:
                    b[i] += pos[w]
        try:
            x = np.linalg.solve(a, b)
        except np.linalg.LinAlgError:
            return None
        pos.update({v: complex(x[index[v]]) for v in inner})
    return pos


def _coincide(pos: dict[str, complex]) -> bool:
    z = np.array(list(pos.values()))
    if z.size < 2:
        return False
    d = np.abs(z[:, None] - z[None, :]) + np.eye(z.size)
    return bool(d.min() < 1e-6 * max(1.0, float(np.abs(z).max())))


def _normalised(lay: ChainLayout) -> ChainLayout:
    z = np.array(list(lay.pos.values()))
    c = (z.real.min() + z.real.max()) / 2 + 1j * (z.imag.min() + z.imag.max()) / 2
    r = max(float(np.abs(z - c).max()), 1e-12)
    return ChainLayout({k: (v - c) / r for k, v in lay.pos.items()}, lay.outline, lay.planar)


def crossings(lay: ChainLayout) -> int:
    """Pairs of drawn segments that cross (segments sharing a joint do not count)."""
    segs = [(lay.pos[a], lay.pos[b], {a, b}) for a, b in lay.edges()]

    def orient(p: complex, q: complex, r: complex) -> float:
        return float(((q - p).conjugate() * (r - p)).imag)

    count = 0
    for i, (p1, p2, e1) in enumerate(segs):
        for p3, p4, e2 in segs[i + 1 :]:
            if e1 & e2:
                continue
            d1, d2 = orient(p3, p4, p1), orient(p3, p4, p2)
            d3, d4 = orient(p1, p2, p3), orient(p1, p2, p4)
            if d1 * d2 < 0 and d3 * d4 < 0:
                count += 1
    return count


def draw_chain(
    ax: Axes, m: Mechanism, layout: ChainLayout | None = None, caption: str | None = None
) -> ChainLayout:
    """Draw one chain on ``ax`` (links as bars or polygons, pins, MJ dots); returns its layout."""
    from matplotlib.patches import Circle, Polygon

    lay = chain_layout(m) if layout is None else layout
    pin = min(0.07, 0.3 * _spacing(lay.pos)) if len(lay.pos) > 1 else 0.07
    colour = "#34495e"
    for link, js in lay.outline.items():
        z = [lay.pos[j] for j in js]
        face = "0.55" if link == m.frame else colour
        if len(z) == 2:
            ax.plot(
                [z[0].real, z[1].real],
                [z[0].imag, z[1].imag],
                lw=2.5,
                color=face,
                solid_capstyle="round",
                zorder=2,
                gid=f"link:{link}",
            )
        else:
            ax.add_patch(
                Polygon(
                    [(p.real, p.imag) for p in z],
                    closed=True,
                    facecolor=face,
                    alpha=0.4,
                    edgecolor=face,
                    lw=2.0,
                    zorder=1,
                    gid=f"link:{link}",
                )
            )
    for j in m.joints:
        zj = lay.pos[j.id]
        r = pin * (1.3 if j.is_multiple else 1.0)
        ax.add_patch(
            Circle(
                (zj.real, zj.imag),
                r,
                facecolor="white",
                edgecolor="black",
                lw=1.0,
                zorder=3,
                gid=f"joint:{j.id}",
            )
        )
        if j.is_multiple:
            n = len(j.links)
            ring = zj + 1.9 * pin * np.exp(1j * (np.pi / 2 + 2 * np.pi * np.arange(n) / n))
            ax.scatter(ring.real, ring.imag, s=4, c="black", zorder=4, gid=f"mj:{j.id}")
    ax.set_xlim(-1.3, 1.3)
    ax.set_ylim(-1.3, 1.3)
    ax.set_aspect("equal")
    ax.set_axis_off()
    if caption:
        ax.set_title(caption, fontsize=6, pad=2)
    return lay


def chain_caption(index: int, chain: Chain, catalog_id: str | None = None) -> str:
    """``index  id`` / ``[LA] … [MJA] …`` / short canonical id (non-planar said so)."""
    la = ",".join(str(x) for x in chain.LA)
    mja = ",".join(str(x) for x in chain.MJA) or "-"
    head = f"{index}" + (f"  {catalog_id}" if catalog_id else "")
    tag = chain.canonical.split("-")
    short = f"{tag[0]}-{tag[1][:8]}" if len(tag) > 1 else chain.canonical[:12]
    flag = "  non-planar" if not chain.planar else ""
    return f"{head}\n[LA] {la}  [MJA] {mja}\n{short}{flag}"


def atlas_figures(
    chains: Sequence[Chain],
    catalog_ids: dict[str, str] | None = None,
    title: str = "",
    per_page: int | None = PER_PAGE,
) -> list[Any]:
    """One figure per page of ``per_page`` panels (None: all on one page), captioned."""
    import matplotlib.pyplot as plt

    ids = catalog_ids or {}
    per = max(1, len(chains)) if per_page is None else max(1, per_page)
    pages = [list(range(i, min(i + per, len(chains)))) for i in range(0, len(chains), per)]
    figs = []
    for page in pages or [[]]:
        cols = min(6, max(1, len(page)))
        rows = max(1, -(-len(page) // cols))
        fig = plt.figure(figsize=(1.6 * cols + 0.4, 1.75 * rows + 0.6))
        figs.append(fig)
        for slot, k in enumerate(page):
            c = chains[k]
            ax = fig.add_subplot(rows, cols, slot + 1)
            caption = chain_caption(k + 1, c, ids.get(c.canonical))
            draw_chain(ax, c.mechanism(), caption=caption)
        if not page:
            fig.text(0.5, 0.5, "no chains", ha="center")
        if title:
            fig.suptitle(title, fontsize=9)
        fig.tight_layout()
    return figs


def write_atlas_sheet(
    chains: Sequence[Chain],
    path: str,
    catalog_ids: dict[str, str] | None = None,
    title: str = "",
    per_page: int = PER_PAGE,
    name: str = "path",
) -> int:
    """Draw ``chains`` on a grid and write ``path`` (.pdf: pages of ``per_page``; .svg/.png:
    one page); returns the number of pages."""
    import matplotlib.pyplot as plt

    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output, write_atomically

    suffix = check_output(path, FIGURE_SUFFIXES, name=name)
    figs = atlas_figures(chains, catalog_ids, title, per_page if suffix == ".pdf" else None)
    try:

        def write(tmp: str) -> None:
            if suffix == ".pdf":
                from matplotlib.backends.backend_pdf import PdfPages

                with PdfPages(tmp) as pdf:
                    for fig in figs:
                        pdf.savefig(fig)
            else:
                figs[0].savefig(tmp, dpi=110)

        write_atomically(path, write, name=name)
    finally:
        for fig in figs:
            plt.close(fig)
    return len(figs)
