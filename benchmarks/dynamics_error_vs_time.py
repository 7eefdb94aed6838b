"""Accuracy against run time of the work integral's methods, and the check against frames.

The slider-crank of [Panasenko 2025] in steady motion (exact p = 10π/9; q̇(q) in closed
form) with its two-level driving force (a jump at q = π), and the same mechanism with a
smooth, asymmetric force
``-p exp(0.5 sin(q + 0.4)) (1 + 0.3 cos 2q)`` (not band-limited, so no method is exact
by symmetry; reference: scipy's adaptive ``quad_vec`` at relative tolerance 1e-12,
independent of the FFT route under test):

* the steady-motion parameter p: the trapezoid rule on 2ⁿ steps (n = 4 … 16), Gauss
  pieces split at the jump, scipy's adaptive ``quad_vec``;
* q̇(q) at 36 frames: the same, plus the Fourier fit of 2¹² samples keeping 4 … 256
  harmonics;
* the excluded-equation check against the number of frames (trapezoid and FFT on 2⁸
  samples, Gauss).

Writes ``docs/img/dyn-error-vs-time.png``, ``docs/img/dyn-check-vs-frames.png`` and
``docs/img/dyn-slider-crank.png`` (the plots of [Panasenko 2025]: Q, q̇, q̈ and joint loads
against q) and prints the table.  Run: ``python benchmarks/dynamics_error_vs_time.py``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.dynamics import dynamic_analysis
from mjstruct.io import mechanism_from_dict
from mjstruct.kinematics.model import KinematicModel
from timing import median_time

IMG = Path(__file__).resolve().parents[1] / "docs" / "img"
FRAMES = 36
QDOT0 = 10.0
#: the smooth case's force on the slider
SMOOTH_FORCE = "-p*exp(0.5*sin(q + 0.4))*(1 + 0.3*cos(2*q))"


def slider_crank(smooth: bool) -> Any:
    d = json.loads(example_path("slider-crank-seed000-dynamics").read_text())
    if smooth:
        # asymmetric and not band-limited: no method is exact by symmetry
        d["loads"][1]["force"] = [SMOOTH_FORCE, "0"]
    return mechanism_from_dict(d)


def exact_qdot(q: np.ndarray, p: float) -> np.ndarray:
    """q̇(q) of the paper's force law in closed form (energy: V q̇²/2 − V₀ q̇₀²/2 = A)."""
    phi = np.arcsin(-np.sin(q) / 2)
    xB = np.cos(q) + 2 * np.cos(phi)
    A = -10 * q + np.where(q < np.pi, 10 * p * (3 - xB), 20 * p - p * (xB - 1))
    # V from the closed-form analogs (uniform rods 1 and 2, slider 1)
    dphi = -np.cos(q) / (2 * np.cos(phi))
    dA = 1j * np.exp(1j * q)
    dc2 = dA + 1j * dphi * np.exp(1j * phi)
    dxB = (dA + 2j * dphi * np.exp(1j * phi)).real
    V = 1 * abs(dA / 2) ** 2 + 2 * abs(dc2) ** 2 + 1 * dxB**2 + 1 / 12 + 2 / 3 * dphi**2
    V0 = V[0]
    return np.sqrt((2 * A + V0 * QDOT0**2) / V)


def runs(smooth: bool) -> list[tuple[str, str, float, float, float]]:
    m = slider_crank(smooth)
    model = KinematicModel.build(m)
    if smooth:
        # the reference is independent of the fft route under test: scipy's adaptive
        # quadrature (quad_vec, relative tolerance 1e-12) between the frames
        ref = dynamic_analysis(
            m, qdot0=QDOT0, frames=FRAMES, model=model, outputs=[], method="adaptive"
        )
        p_ref, qd_ref = ref.parameters["p"], ref.qdot[:, 0]
    else:
        p_ref = 10 * math.pi / 9
        qd_ref = exact_qdot(model.sweep(FRAMES)[:, 0], p_ref)
    rows = []

    def one(label: str, family: str, **kw: Any) -> None:
        t, r = median_time(
            lambda: dynamic_analysis(m, qdot0=QDOT0, frames=FRAMES, model=model, outputs=[], **kw),
            repeat=3,
        )
        ep = abs(r.parameters["p"] - p_ref) / p_ref
        eq = float(np.abs(r.qdot[:, 0] - qd_ref).max() / np.abs(qd_ref).max())
        rows.append((family, label, t, max(ep, 1e-17), max(eq, 1e-17)))

    for n in range(4, 17, 2):
        one(f"n={n}", "trapezoid 2^n", method="trapezoid", n=n)
    for h in (4, 8, 16, 32, 64, 128, 256):
        one(f"H={h}", "FFT 2^12, H harmonics", method="fft", n=12, harmonics=h)
    one("gauss", "Gauss (split at jumps)")
    one("adaptive", "adaptive quad_vec", method="adaptive")
    return rows


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    styles = {
        "trapezoid 2^n": "o-",
        "FFT 2^12, H harmonics": "s-",
        "Gauss (split at jumps)": "*",
        "adaptive quad_vec": "D",
    }
    for smooth, colour in ((False, "C0"), (True, "C1")):
        law = "smooth force" if smooth else "two-level force (jump)"
        rows = runs(smooth)
        print(f"-- {law}")
        print(f"{'method':26s} {'':>9s} {'time ms':>9s} {'err p':>9s} {'err qdot':>9s}")
        for fam, label, t, ep, eq in rows:
            print(f"{fam:26s} {label:>9s} {t * 1e3:9.2f} {ep:9.1e} {eq:9.1e}")
        for fam, style in styles.items():
            sel = [r for r in rows if r[0] == fam]
            if fam != "FFT 2^12, H harmonics":
                axes[0].loglog(
                    [r[2] for r in sel],
                    [r[3] for r in sel],
                    style,
                    color=colour,
                    label=f"{fam}, {law}",
                    ms=7,
                )
            axes[1].loglog(
                [r[2] for r in sel],
                [r[4] for r in sel],
                style,
                color=colour,
                label=f"{fam}, {law}",
                ms=7,
            )
    axes[0].set_title("steady-motion parameter p (36 frames)")
    axes[1].set_title("speed q̇(q) at 36 frames")
    for ax in axes:
        ax.set_xlabel("run time of dynamic_analysis (s)")
        ax.set_ylabel("relative error")
        ax.grid(True, which="both", alpha=0.3)
    axes[1].legend(fontsize=6.5, loc="lower left")
    fig.tight_layout()
    fig.savefig(IMG / "dyn-error-vs-time.png", dpi=110)

    m = slider_crank(False)
    model = KinematicModel.build(m)
    frames = [9, 18, 36, 72, 144, 288, 576, 1152]
    fig, ax = plt.subplots(figsize=(6, 4))
    print("-- check against frames (two-level force)")
    for label, kw, style in (
        ("trapezoid 2^8", {"method": "trapezoid", "n": 8}, "o-"),
        ("FFT 2^8", {"method": "fft", "n": 8}, "s-"),
        ("Gauss", {}, "*-"),
    ):
        checks = [
            max(dynamic_analysis(m, qdot0=QDOT0, frames=f, model=model, **kw).check or 0, 1e-17)
            for f in frames
        ]
        print(f"{label:14s} " + " ".join(f"{c:8.1e}" for c in checks))
        ax.loglog(frames, checks, style, label=label)
    ax.set_xlabel("frames")
    ax.set_ylabel("check: relative residual of the excluded equation")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(IMG / "dyn-check-vs-frames.png", dpi=110)

    r = dynamic_analysis(m, qdot0=QDOT0, frames=360, model=model)
    q = r.q[:, 0]
    fig, axes = plt.subplots(2, 2, figsize=(10, 6.5), sharex=True)
    axes[0, 0].plot(q, r.Q)
    axes[0, 0].set_title("generalised force Q(q)")
    axes[0, 1].plot(q, r.qdot[:, 0], label="q̇")
    axes[0, 1].plot(q, r.qddot[:, 0] / 10, label="q̈ / 10")
    axes[0, 1].legend()
    axes[0, 1].set_title("speed and acceleration")
    for jid in ("O1", "A", "B"):
        link = m.joint(jid).links[1]
        axes[1, 0].plot(q, r.reactions[jid][link]["x"], label=f"{jid} on {link}")
        axes[1, 1].plot(q, r.reactions[jid][link]["y"], label=f"{jid} on {link}")
    axes[1, 1].plot(q, r.reactions["O4"]["3"]["y"], label="O4 on 3")
    axes[1, 0].set_title("joint loads, x")
    axes[1, 1].set_title("joint loads, y")
    for ax in axes[1]:
        ax.set_xlabel("q (rad)")
        ax.legend(fontsize=8)
    fig.suptitle(f"slider-crank (Panasenko 2025), steady motion p = 10π/9, q̇₀ = {QDOT0:g}")
    fig.tight_layout()
    fig.savefig(IMG / "dyn-slider-crank.png", dpi=100)


if __name__ == "__main__":
    main()
