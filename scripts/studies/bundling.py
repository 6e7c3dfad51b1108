#!/usr/bin/python3
"""Paper section 4 (Fig. 1, Fig. 7): two helices rotating side by side.

  bundling.py fig7 [--h H]     Δt/R = 4 at ω̄ ∈ {43, 107, 427}; ω̄ = 427 at Δt/R ∈ {4, 6, 8}; to t̄ = 2
  bundling.py plot             the figures and the table from the runs of fig7
Outputs go to out/studies/bundling/ and docs/validation/.
"""
import argparse
import os

import numpy as np

from common import ROOT, log, run_all, timeseries

OUT = os.path.join(ROOT, "out", "studies", "bundling")
DOCS = os.path.join(ROOT, "docs", "validation")
R = 0.01
L0 = 0.2
CASES = [(4, 43), (4, 107), (4, 427), (6, 427), (8, 427)]


def case(spacing, omega_bar, h, t_end=2.0):
    name = f"dt{spacing:g}_w{omega_bar:g}_h{h:g}"
    overrides = {"rods.omega_bar": omega_bar, "rods.2.base": f"[{spacing * R:.6g}, 0.0, 0.0]",
                 "run.time_step": h, "run.t_bar_end": t_end}
    return ("examples/fig7_bundling.toml", os.path.join(OUT, name), overrides)


def plot(h):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 4, figsize=(15, 7))
    rows = []
    for k, (spacing, w) in enumerate(CASES):
        out = case(spacing, w, h)[1]
        if not os.path.exists(os.path.join(out, "timeseries.csv")):
            continue
        ts = timeseries(out)
        ax = axes[0][k] if k < 4 else axes[1][3]
        for rod, color in ((1, "tab:blue"), (2, "tab:red")):
            ax.plot(ts[f"rod{rod}_end_x"] / L0, ts[f"rod{rod}_end_y"] / L0, color=color, lw=0.8)
        ax.set_aspect("equal")
        ax.set_title(f"Δt/R = {spacing}, ω̄ = {w}", fontsize=9)
        ax.set_xlabel("x / l0")
        ax.set_ylabel("y / l0")
        target = axes[1][0] if spacing == 4 else axes[1][1]
        if spacing == 4:
            axes[1][0].plot(ts["t_bar"], ts["delta_b_over_R"], label=f"ω̄ = {w}")
        if w == 427:
            axes[1][1].plot(ts["t_bar"], ts["delta_b_over_R"], label=f"Δt/R = {spacing}")
        crossed = np.any(ts["delta_b_over_R"] < 0)
        first = ts["t_bar"][np.argmax(ts["delta_b_over_R"] < 0)] if crossed else np.nan
        rows.append((spacing, w, ts["t_bar"][-1], crossed, first, ts["delta_b_over_R"][-1],
                     np.min(ts["min_distance"]), np.max(ts["contacts"])))
    for ax, title in ((axes[1][0], "Δt/R = 4"), (axes[1][1], "ω̄ = 427")):
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xlabel("t̄")
        ax.set_ylabel("Δb / R")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=8)
    axes[1][2].axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "fig7_bundling.png"), dpi=110)
    with open(os.path.join(DOCS, f"fig7_bundling_h{h:g}.csv"), "w") as f:
        f.write("delta_t_over_R,omega_bar,t_bar_end,crossed,first_crossing_t_bar,"
                "final_delta_b_over_R,min_distance,max_contacts\n")
        for r in rows:
            f.write(",".join(str(x) for x in r) + "\n")
    log("wrote", os.path.join(DOCS, "fig7_bundling.png"))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("what", choices=["fig7", "plot"])
    p.add_argument("--h", type=float, default=1e-2)
    args = p.parse_args()
    os.makedirs(DOCS, exist_ok=True)
    if args.what == "fig7":
        run_all([case(s, w, args.h) for s, w in CASES])
    plot(args.h)


if __name__ == "__main__":
    main()
