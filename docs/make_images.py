"""Regenerate every image of docs/drawings.md (and the README pictures, the two
pictures of docs/singular.md and the targets charts of the shipped synthesis tasks in
docs/synthesis-design.md) from the shipped examples: ``python docs/make_images.py``
(about a minute).

Each image is made through the same functions the ``draw``, ``animate``, ``plot`` and
``atlas --draw`` commands call, so the pictures are what a user gets.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.plot.animation import write_animation
from mjstruct.plot.atlas_sheet import write_atlas_sheet
from mjstruct.plot.charts import draw_chart
from mjstruct.plot.drawing import scene_at, scene_over_cycle, write_drawing
from mjstruct.plot.files import write_atomically

IMG = Path(__file__).resolve().parent / "img"


def model(name: str, drivers: list[str] | None = None) -> KinematicModel:
    return KinematicModel.build(read_mechanism(example_path(name)), drivers)


def drawing(out: str, name: str, q: float | None = None, layers: tuple[str, ...] = (),
            speed: float = 1.0) -> None:  # fmt: skip
    write_drawing(scene_at(model(name), q, layers, speed=speed), str(IMG / out), dpi=90)


def chart(out: str, name: str, what: str, speed: float = 1.0, frames: int = 360) -> None:
    fig = draw_chart(model(name), what, frames=frames, speed=speed)
    fig.tight_layout()
    write_atomically(str(IMG / out), lambda tmp: fig.savefig(tmp, dpi=90))
    plt.close(fig)


def singular() -> None:
    """The P2-P3 diagram with MS4 and MS4's clearance zones (docs/singular.md)."""
    from mjstruct.plot.ms_diagram import ms_point, plot_ms_diagram, plot_singular_zones
    from mjstruct.singular.analysis import singular_analysis

    ms4 = read_mechanism(example_path("fourbar-ms4"))
    p1, p2, p3 = ms_point(ms4)
    zones = singular_analysis(ms4, clearance=0.02)
    for out, fig in (
        ("singular-ms-diagram.png", plot_ms_diagram(p1, point=(p2, p3), label="MS4")),
        ("singular-ms4-zones.png", plot_singular_zones(ms4, zones)),
    ):
        fig.tight_layout()
        write_atomically(str(IMG / out), lambda tmp, fig=fig: fig.savefig(tmp, dpi=90))
        plt.close(fig)


def explorer() -> None:
    """The notebook explorer's picture after O2's sliders moved it to (3.0, 1.5): the
    crank no longer turns fully (input limits on the strip)."""
    from mjstruct.plot.explorer_view import ExplorerView

    view = ExplorerView(read_mechanism(example_path("six-bar-mj-slider")), ["O2"], dpi=90)
    view.move_joint("O2", 3.0, 1.5)
    view.set_driver(100.0)
    write_atomically(
        str(IMG / "explorer-six-bar.png"), lambda tmp: Path(tmp).write_bytes(view.png())
    )


def synthesis() -> None:
    """The targets charts of the shipped tasks (README, docs/synthesis-design.md): each
    synthesised (seed 0) and drawn as ``synthesize --targets-chart`` draws it."""
    from mjstruct.design.api import load_task, synthesize
    from mjstruct.plot.design_charts import draw_targets

    tasks = Path(__file__).resolve().parent.parent / "catalogs" / "tasks"
    for name in ("path-curve18", "function-log10", "motion-five-poses"):
        result = synthesize(load_task(str(tasks / f"{name}.json")))
        fig = draw_targets(result.mechanism)
        out = IMG / f"synthesis-{name.removeprefix('path-')}.png"
        write_atomically(str(out), lambda tmp, fig=fig: fig.savefig(tmp, dpi=90))
        plt.close(fig)


def main() -> int:
    start = time.perf_counter()
    # the README picture: radial engine, Assur groups and velocity vectors
    drawing("draw-radial-engine.png", "kin-radial-engine-5", 1.2, ("assur", "velocity"))
    drawing("draw-slider-crank.png", "slider-crank", 1.0, ("velocity", "acceleration", "paths"))
    drawing("draw-scotch-yoke.png", "scotch-yoke", 0.8, ("velocity",))
    drawing("draw-zhivago.png", "zhivago", None, ("assur", "paths"))
    drawing("draw-class-iv.png", "class-iv-seed003", None, ("assur", "velocity"))
    drawing("draw-forces.png", "slider-crank-seed000-dynamics", 1.0,
            ("loads", "inertia", "reactions"), speed=10.0)  # fmt: skip
    scene = scene_over_cycle(model("kin-radial-engine-5"), 24, ("velocity",))
    write_animation(scene, str(IMG / "anim-radial-engine.gif"), fps=12)
    chart("chart-angles.png", "zhivago", "angles")
    chart("chart-omega.png", "slider-crank", "omega", speed=10.0)
    chart("chart-eps.png", "slider-crank", "eps", speed=10.0)
    chart("chart-paths.png", "zhivago", "paths")
    chart("chart-jacobian.png", "fourbar-ms2", "jacobian")
    chart("chart-transmission.png", "four-bar", "transmission")
    for what in ("V", "Q", "qdot", "reactions"):
        chart(f"chart-{what}.png", "slider-crank-seed000-dynamics", what, speed=10.0, frames=180)
    from mjstruct.synthesis.atlas import atlas

    chains = atlas(1, 8, mj=True).chains
    write_atlas_sheet(chains[12:30], str(IMG / "atlas-sheet.png"), title="F = 1, n = 8 (part)")
    singular()
    explorer()
    synthesis()
    sys.stdout.write(f"images written to {IMG} in {time.perf_counter() - start:.1f} s\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
