"""Atlas sheets: chains drawn as small figures on a grid, the form atlases are printed in.

Owns :func:`chain_layout` (where to put the joints of a chain without geometry),
:func:`draw_chain` (one panel: links as bars or as polygons of their joints, every
joint a pin, a multiple joint with one dot per link around it) and
:func:`write_atlas_sheet` (the grid, captioned with index, catalog id, [LA]/[MJA] and
a short canonical id; a PDF gets one page per grid).

A planar chain is drawn in a planar embedding with straight edges and no crossings:
the link–joint graph is embedded (networkx's planarity test) and each link becomes the
polygon of its joints in the embedding's rotation order.  Candidate placements of the
resulting joint graph are Tutte's barycentric drawing on each of its faces taken as the
outer one (faces that are a link's own polygon last: that link would cover the chain;
bars in parallel between the same two joints, which Tutte piles on one line, fanned
out), a stress layout and the Chrobak–Payne grid drawing (``networkx.planar_layout``).
Only *sound* candidates are kept (:func:`sound`: no crossings, :func:`overlaps` empty),
the best by :func:`quality` (joint spacing, joints clear of foreign bars, no two bars
in line through a multiple joint) is taken and then improved by stress-majorization
steps that keep it sound.  So the result is checked, not assumed.  A non-planar chain
gets a Kamada–Kawai layout and says so.

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
    """Place the joints of ``m``: crossing-free straight lines when the chain is planar.

    A planar chain's candidate drawings (Tutte's on each face taken as the outer one,
    and the Chrobak–Payne grid drawing) are kept only when they are *sound* (no
    crossing edges, no two link polygons sharing area, no joint or bar inside another
    link's polygon); the best by :func:`quality` is then improved by moves that keep
    it sound.
    """
    import networkx as nx

    g = m.graph()
    planar, emb = nx.check_planarity(g)
    if planar:
        outline = {
            link: tuple(j for _, j in emb.neighbors_cw_order(("link", link))) for link in m.links
        }
        jg = _joint_graph(m, outline)
        best: ChainLayout | None = None
        fallback: ChainLayout | None = None
        for pos in _candidates(jg, outline):
            lay = _normalised(ChainLayout(pos, outline, True))
            if crossings(lay):
                continue
            fallback = fallback or lay
            if not sound(lay):
                continue
            if best is None or quality(lay) > quality(best):
                best = lay
        if best is not None:
            return _relaxed(best)
        if fallback is not None:
            return fallback
        raw = nx.planar_layout(jg)
        return _normalised(ChainLayout({k: complex(*v) for k, v in raw.items()}, outline, True))
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


def _candidates(jg: Any, outline: dict[str, tuple[str, ...]]) -> list[dict[str, complex]]:
    """Tutte's barycentric drawings on every face of the joint graph as the outer one
    (a face that is one link's polygon last: that link would cover the chain), then
    a stress layout and the Chrobak–Payne grid drawing."""
    import networkx as nx

    out: list[dict[str, complex]] = []
    if jg.number_of_nodes() >= 3 and nx.is_connected(jg):
        planar, emb = nx.check_planarity(jg)
        if planar:
            polygons = {frozenset(js) for js in outline.values() if len(js) > 2}
            faces = sorted(_faces(emb), key=lambda f: (frozenset(f) in polygons, -len(f)))
            for outer in faces:
                pos = _barycentric(jg, outer)
                if pos is not None:
                    pos = _fanned(jg, pos)
                if pos is not None and not _coincide(pos):
                    out.append(pos)
    if jg.number_of_nodes() >= 2:
        grid = {k: complex(*v) for k, v in nx.planar_layout(jg).items()}
        # a stress layout spreads what Tutte piles up (joints of degree two between the
        # same two joints); kept only when it happens to be crossing-free
        if nx.is_connected(jg):
            out.append(_stress(jg, grid))
        out.append(grid)
    return out


def _fanned(jg: Any, pos: dict[str, complex]) -> dict[str, complex]:
    """Joints of degree two with the same two neighbours (bars in parallel between two
    joints, which Tutte's drawing piles on one point) spread across the line of their
    neighbours."""
    groups: dict[frozenset[str], list[str]] = {}
    for v in jg.nodes:
        if jg.degree(v) == 2:
            groups.setdefault(frozenset(jg.neighbors(v)), []).append(v)
    out = dict(pos)
    for ends, group in groups.items():
        if len(group) < 2 or len(ends) != 2:
            continue
        u, w = sorted(ends)
        mid, across = (pos[u] + pos[w]) / 2, 1j * (pos[w] - pos[u])
        for t, v in zip(np.linspace(-0.3, 0.3, len(group)), sorted(group), strict=True):
            out[v] = mid + t * across
    return out


def _stress_weights(jg: Any, keys: list[str]) -> tuple[Any, Any]:
    """Graph distances between joints and the stress weights 1/d²."""
    import networkx as nx

    index = {k: i for i, k in enumerate(keys)}
    n = len(keys)
    d = np.full((n, n), float(n))
    for v, row in nx.all_pairs_shortest_path_length(jg):
        for u, k in row.items():
            d[index[v], index[u]] = k
    np.fill_diagonal(d, 1.0)
    w = d**-2.0
    np.fill_diagonal(w, 0.0)
    np.fill_diagonal(d, 0.0)
    return d, w


def _stress_step(z: Any, d: Any, w: Any) -> Any:
    """One localized stress-majorization update of every joint (Gansner et al.)."""
    diff = z[:, None] - z[None, :]
    dist = np.maximum(np.abs(diff), 1e-9)
    pull = (w * d / dist * diff).sum(axis=1) + (w * z[None, :]).sum(axis=1)
    return pull / np.maximum(w.sum(axis=1), 1e-300)


def _stress(jg: Any, start: dict[str, complex], rounds: int = 60) -> dict[str, complex]:
    """Stress majorization: distances in the drawing follow graph distances."""
    keys = list(start)
    d, w = _stress_weights(jg, keys)
    z = np.array([start[k] for k in keys], complex)
    z = z / max(float(np.abs(z - z.mean()).max()), 1e-12)
    for _ in range(rounds):
        z = _stress_step(z, d, w)
    return {k: complex(v) for k, v in zip(keys, z, strict=True)}


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


def _cross(a: complex, b: complex) -> float:
    return float((a.conjugate() * b).imag)


def crossings(lay: ChainLayout) -> int:
    """Pairs of drawn segments that cross (segments sharing a joint do not count)."""
    p, q, shared = _segments(lay)
    if p.size < 2:
        return 0

    def orient(a: Any, b: Any, c: Any) -> Any:
        return ((b - a).conj() * (c - a)).imag

    p1, p2, p3, p4 = p[:, None], q[:, None], p[None, :], q[None, :]
    d1, d2 = orient(p3, p4, p1), orient(p3, p4, p2)
    d3, d4 = orient(p1, p2, p3), orient(p1, p2, p4)
    hit = (d1 * d2 < 0) & (d3 * d4 < 0) & ~shared
    return int(np.triu(hit, 1).sum())


def _segments(lay: ChainLayout) -> tuple[Any, Any, Any]:
    """Segment ends (complex arrays) and which pairs of segments share a joint."""
    edges = lay.edges()
    p = np.array([lay.pos[a] for a, _ in edges], complex)
    q = np.array([lay.pos[b] for _, b in edges], complex)
    ends = [{a, b} for a, b in edges]
    shared = np.array([[bool(e & f) for f in ends] for e in ends], bool).reshape(len(ends), -1)
    return p, q, shared


def _inside(z: complex, poly: list[complex]) -> bool:
    """``z`` strictly inside the simple polygon ``poly`` (even–odd rule)."""
    hit = False
    for a, b in zip(poly, poly[1:] + poly[:1], strict=True):
        if (a.imag > z.imag) != (b.imag > z.imag):
            x = a.real + (z.imag - a.imag) * (b.real - a.real) / (b.imag - a.imag)
            if x > z.real:
                hit = not hit
    return hit


def _area2(poly: list[complex]) -> float:
    """Twice the signed area (positive counter-clockwise)."""
    return sum(_cross(a, b) for a, b in zip(poly, poly[1:] + poly[:1], strict=True))


def overlaps(lay: ChainLayout) -> list[tuple[str, str]]:
    """Pairs (polygon link, other link) drawn over each other: a joint of the other
    strictly inside the polygon, or the other leaving a shared joint into the polygon's
    corner (two polygons sharing area, a bar across a polygon, a polygon of no area)."""
    pos = lay.pos
    out: list[tuple[str, str]] = []
    polys = {k: js for k, js in lay.outline.items() if len(js) > 2}
    for link, js in polys.items():
        poly = [pos[j] for j in js]
        area = _area2(poly)
        if abs(area) < 1e-3:
            out.append((link, link))
            continue
        if area < 0:
            js, poly = js[::-1], poly[::-1]
        corner = {}
        for i, j in enumerate(js):
            v, nxt, prv = poly[i], poly[(i + 1) % len(js)], poly[i - 1]
            corner[j] = (v, np.angle(nxt - v), _turn(nxt - v, prv - v))
        for other, ojs in lay.outline.items():
            if other == link:
                continue
            if any(j not in js and _inside(pos[j], poly) for j in ojs):
                out.append((link, other))
                continue
            for j in set(ojs) & set(js):
                v, start, width = corner[j]
                k = ojs.index(j)
                nbrs = [ojs[(k + 1) % len(ojs)], ojs[k - 1]] if len(ojs) > 2 else [ojs[1 - k]]
                if any(0.02 < _turn(np.exp(1j * start), pos[w] - v) < width - 0.02 for w in nbrs):
                    out.append((link, other))
                    break
    return out


def _turn(a: complex, b: complex) -> float:
    """Counter-clockwise angle from direction ``a`` to direction ``b``, in [0, 2π)."""
    return float(np.angle(b / a) % (2 * np.pi)) if a and b else 0.0


def sound(lay: ChainLayout) -> bool:
    """No crossing edges and no link drawn over another (see :func:`overlaps`)."""
    return not crossings(lay) and not overlaps(lay)


def quality(lay: ChainLayout) -> float:
    """How well the drawing reads, 0 (degenerate), 1 or more (well).

    The worst of: the smallest joint distance, the smallest distance from a joint to a
    segment not at it (a joint that seems to lie on another link), and at a multiple
    joint the smallest angle between segments of different links (0°: overlapping,
    180°: two bars through the pin that read as one bar), each over a value that reads
    well."""
    keys = list(lay.pos)
    z = np.array([lay.pos[k] for k in keys], complex)
    n = z.size
    if n < 2:
        return 1.0
    d = np.abs(z[:, None] - z[None, :]) + np.eye(n) * 9.0
    near = float(d.min()) / (1.2 / np.sqrt(n))
    edges = lay.edges()
    index = {k: i for i, k in enumerate(keys)}
    a = np.array([index[x] for x, _ in edges], int)
    b = np.array([index[y] for _, y in edges], int)
    p, q = z[a], z[b]
    w = z[:, None] - p[None, :]
    u = (q - p)[None, :]
    t = np.clip((w * u.conj()).real / np.maximum(np.abs(u) ** 2, 1e-300), 0.0, 1.0)
    dist = np.abs(w - t * u)
    dist[a, np.arange(a.size)] = 9.0
    dist[b, np.arange(b.size)] = 9.0
    gap = float(dist.min(initial=9.0)) / 0.15
    multiple = {j for j in keys if sum(j in js for js in lay.outline.values()) > 2}
    at: dict[str, list[tuple[str, complex]]] = {}
    for link, js in lay.outline.items():
        for k, j in enumerate(js):
            if j in multiple:
                nbrs = [js[1 - k]] if len(js) == 2 else [js[(k + 1) % len(js)], js[k - 1]]
                at.setdefault(j, []).extend((link, lay.pos[x] - lay.pos[j]) for x in nbrs)
    bend = 9.0
    for arms in at.values():
        for i, (la, da) in enumerate(arms):
            for lb, db in arms[i + 1 :]:
                if la != lb:
                    theta = abs(float(np.angle(db / da)))
                    bend = min(bend, theta, np.pi - theta)
    return float(min(near, gap, bend / 0.3))


def _relaxed(lay: ChainLayout, rounds: int = 30, moves: int = 120) -> ChainLayout:
    """Improve a sound drawing without ever making it unsound: stress-majorization
    steps (shortened until the drawing stays sound), then single-joint moves that raise
    :func:`quality`; deterministic."""
    import networkx as nx

    keys = list(lay.pos)
    jg = nx.Graph()
    jg.add_nodes_from(keys)
    jg.add_edges_from(lay.edges())

    def layout(z: Any) -> ChainLayout:
        pos = {k: complex(v) for k, v in zip(keys, z, strict=True)}
        return _normalised(ChainLayout(pos, lay.outline, lay.planar))

    best, score = lay, quality(lay)
    if nx.is_connected(jg) and len(keys) > 2:
        d, w = _stress_weights(jg, keys)
        z = np.array([lay.pos[k] for k in keys], complex)
        current = lay
        for _ in range(rounds):
            target = _stress_step(z, d, w)
            alpha = 1.0
            while alpha > 0.05:
                trial = layout(z + alpha * (target - z))
                if sound(trial):
                    break
                alpha /= 2
            else:
                break
            current = trial
            z = np.array([current.pos[k] for k in keys], complex)
        if quality(current) > score:
            best, score = current, quality(current)
    rng = np.random.default_rng(len(keys))
    step = 0.2
    for r in range(moves if score < 1.0 else 0):
        v = keys[r % len(keys)]
        pos = dict(best.pos)
        pos[v] += step * complex(*rng.normal(size=2))
        trial = _normalised(ChainLayout(pos, lay.outline, lay.planar))
        q = quality(trial)
        if q > score and sound(trial):
            best, score = trial, q
            if score >= 1.0:
                break
        elif r % len(keys) == len(keys) - 1:
            step = max(0.03, step * 0.8)
    return best


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
            fig.suptitle(title, fontsize=9, y=0.995, va="top")
        # keep a band for the title, else the captions of the top row run into it
        height = fig.get_figheight()
        fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - (0.3 / height if title else 0.0)))
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
