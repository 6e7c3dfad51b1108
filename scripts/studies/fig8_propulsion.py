#!/usr/bin/python3
"""Paper Fig. 8: the propulsive force of two flagella against speed and distance.

  fig8_propulsion.py run    the sweeps fig8a_single.toml and fig8b_distance.toml (fig7c3_phase.toml
                            supplies Δt/R = 4, 6, 8 of Fig. 8a; run it with fig7c3_phase.py)
  fig8_propulsion.py plot   docs/validation/fig8_propulsion.{png,csv}

F̄p (eq. 26, both rods' clamp reactions along z over EI/l0²) is the time average over the second half
of each run (t̄ ∈ [1, 2]); `stokesrods analyze` computes it and its ratio to one flagellum at the
same ω̄. Fig. 8(a)'s lines are least-squares fits through the origin, F̄p = k ω̄; Δt = ∞ is twice
one flagellum. The reduction at Δt/R = d is 1 − k_d / k_∞.
"""
import os

import numpy as np

from common import ROOT, analyze, first_number, log, sweep_study_main

OUT = os.path.join(ROOT, "out", "studies")
DOCS = os.path.join(ROOT, "docs", "validation")
R = 0.01
PAPER_REDUCTION = {4: 40.0, 6: 31.7, 8: 20.2}


def completed(rows):
    return [r for r in rows if r["status"] == "completed"]


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    single_dir = os.path.join(OUT, "fig8_single")
    single, _ = analyze(single_dir)
    pairs, _ = analyze(os.path.join(OUT, "fig7c3"), "--single", single_dir)
    far, _ = analyze(os.path.join(OUT, "fig8b"), "--single", single_dir)
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(10, 4))
    series = {}
    for r in completed(single):
        series.setdefault(np.inf, []).append((float(r["omega_bar"]), 2 * float(r["propulsive_force_bar_mean"])))
    for r in completed(pairs):
        d = round(first_number(r["rods.2.base"]) / R, 6)
        if d in (4, 6, 8):
            series.setdefault(d, []).append((float(r["omega_bar"]), float(r["propulsive_force_bar_mean"])))
    slopes = {}
    lines = ["delta_t_over_R,points,slope_through_origin,reduction_percent,paper_reduction_percent,"
             "mean_ratio_to_two_singles"]
    for d in sorted(series):
        pts = np.array(sorted(series[d]))
        w, f = pts[:, 0], pts[:, 1]
        slopes[d] = float(w @ f / (w @ w))
        ax_a.plot(w, f, "o", ms=4, label=f"Δt/R = {d:g}")
        ax_a.plot([0, w.max()], [0, slopes[d] * w.max()], "-", lw=1, color=ax_a.lines[-1].get_color())
    single_by_w = {float(r["omega_bar"]): float(r["propulsive_force_bar_mean"]) for r in completed(single)}
    for d in sorted(series):
        pts = np.array(sorted(series[d]))
        red = 100 * (1 - slopes[d] / slopes[np.inf]) if np.inf in slopes else np.nan
        ratios = [f / (2 * single_by_w[w]) for w, f in pts if w in single_by_w]
        lines.append(f"{d:g},{len(pts)},{slopes[d]:.6g},{red:.1f},{PAPER_REDUCTION.get(d, '')},"
                     f"{np.mean(ratios) if ratios else np.nan:.4f}")
    ax_a.set_xlabel("ω̄")
    ax_a.set_ylabel("F̄p (mean over t̄ ∈ [1, 2])")
    ax_a.legend(fontsize=8)
    ax_a.set_title("(a) two flagella; ∞ = twice one flagellum", fontsize=9)
    b_rows = sorted((first_number(r["rods.2.base"]) / R, float(r["propulsive_force_ratio_to_single"]))
                    for r in completed(far) if r["propulsive_force_ratio_to_single"])
    lines.append("")
    lines.append("fig8b_delta_t_over_R,Fp_over_Fp_single")
    for d, ratio in b_rows:
        lines.append(f"{d:g},{ratio:.4f}")
    if b_rows:
        ax_b.semilogx([d for d, _ in b_rows], [x for _, x in b_rows], "o-", ms=4)
    ax_b.axhline(2, color="k", lw=0.5, ls="--")
    ax_b.set_xlabel("Δt / R")
    ax_b.set_ylabel("F̄p / F̄p single")
    ax_b.set_title("(b) ω̄ = 213", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "fig8_propulsion.png"), dpi=110)
    with open(os.path.join(DOCS, "fig8_propulsion.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    log("\n".join(lines))


def main():
    sweep_study_main(["examples/studies/fig8a_single.toml", "examples/studies/fig8b_distance.toml"], plot)


if __name__ == "__main__":
    main()
