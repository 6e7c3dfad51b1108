#!/usr/bin/python3
"""Paper Fig. 7(c3): crossed or not over (Δt/R, ω̄), and the critical crossing speed ω̄_c.

  fig7c3_phase.py run     the sweep examples/studies/fig7c3_phase.toml (skips finished cases)
  fig7c3_phase.py plot    stokesrods analyze, then docs/validation/fig7c3_phase.{png,csv}

Crossed: Δb ≤ 0 at t̄ = 2 (the paper marks the final shape). ω̄_c on each Δt/R: the bracket
(last uncrossed, first crossed] from `stokesrods analyze`, and its middle.
"""
import os

from common import ROOT, analyze, first_number, log, sweep_study_main

SWEEP = "examples/studies/fig7c3_phase.toml"
OUT = os.path.join(ROOT, "out", "studies", "fig7c3")
DOCS = os.path.join(ROOT, "docs", "validation")
R = 0.01


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows, lines = analyze(OUT, "--line", "rods.omega_bar", "--criterion", "crossed")
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    for r in rows:
        if r["status"] != "completed":
            continue
        dt = first_number(r["rods.2.base"]) / R
        crossed = r["crossed"] == "1"
        ax.plot(dt, float(r["omega_bar"]), "o" if crossed else "^", mfc="tab:blue" if crossed else "none",
                mec="tab:blue" if crossed else "tab:red", ms=6)
    line_x, line_y = [], []
    with open(os.path.join(DOCS, "fig7c3_phase.csv"), "w") as f:
        f.write("delta_t_over_R,omega_c_below,omega_c_above,omega_c_estimate,monotone,points\n")
        for l in sorted(lines, key=lambda l: first_number(l["line"].split("=")[1])):
            dt = first_number(l["line"].split("=")[1]) / R
            f.write(f"{dt:g},{l['below']},{l['above']},{l['estimate']},{l['monotone']},{l['points']}\n")
            if l["estimate"]:
                line_x.append(dt)
                line_y.append(float(l["estimate"]))
            elif l["above"]:  # crossed at every speed: ω̄_c at or below the lowest
                line_x.append(dt)
                line_y.append(float(l["above"]))
    ax.plot(line_x, line_y, "k-", lw=1.5, label="ω̄_c: middle of the bracket (upper bound where all crossed)")
    ax.set_xlabel("Δt / R")
    ax.set_ylabel("ω̄")
    ax.set_title("crossed at t̄ = 2 (●) or not (△)", fontsize=10)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "fig7c3_phase.png"), dpi=110)
    log("wrote", os.path.join(DOCS, "fig7c3_phase.png"))


def main():
    sweep_study_main([SWEEP], plot)


if __name__ == "__main__":
    main()
