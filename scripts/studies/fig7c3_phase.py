#!/usr/bin/python3
"""Paper Fig. 7(c3): crossed or not over (Δt/R, ω̄), and the critical crossing speed ω̄_c.

  fig7c3_phase.py run     the sweep examples/studies/fig7c3_phase.toml (resumes), then table, plot
  fig7c3_phase.py table   stokesrods analyze out/studies/fig7c3 -> docs/validation/fig7c3_{cases,phase}.csv
  fig7c3_phase.py plot    docs/validation/fig7c3_phase.png from those two tables alone

Crossed: Δb ≤ 0 at t̄ = 2 (the paper marks the final shape). ω̄_c on each Δt/R: the bracket
(last uncrossed, first speed from which every faster one crossed] from `stokesrods analyze`, and its
middle. fig7c3_cases.csv also carries F̄p of every case (Fig. 8a's lines at Δt/R = 4, 6, 8).
"""
import os

from common import (ROOT, case_table, crossing_marker, finish_crossing_axes, first_number, read_csv,
                    sweep_study_main, write_csv)

SWEEP = "examples/studies/fig7c3_phase.toml"
OUT = os.path.join(ROOT, "out", "studies", "fig7c3")
DOCS = os.path.join(ROOT, "docs", "validation")
CASES = os.path.join(DOCS, "fig7c3_cases.csv")
PHASE = os.path.join(DOCS, "fig7c3_phase.csv")
R = 0.01
CASE_COLUMNS = ["first_crossing_t_bar", "crossed", "final_delta_b_over_R", "min_distance",
                "propulsive_force_bar_mean", "propulsive_force_bar_final", "wall_seconds"]


def table():
    rows, lines = case_table(OUT, "--line", "rods.omega_bar", "--criterion", "crossed")
    done = sorted((first_number(r["rods.2.base"]) / R, float(r["omega_bar"]), r)
                  for r in rows if r["status"] == "completed")
    write_csv(CASES, ["delta_t_over_R", "omega_bar"] + CASE_COLUMNS,
              [[f"{d:g}", f"{w:g}"] + [r[c] for c in CASE_COLUMNS] for d, w, r in done])
    out = []
    for line in sorted(lines, key=lambda l: first_number(l["line"].split("=")[1])):
        d = first_number(line["line"].split("=")[1]) / R
        out.append([f"{d:g}", line["below"], line["above"], line["estimate"], line["monotone"], line["points"]])
    write_csv(PHASE, ["delta_t_over_R", "omega_c_below", "omega_c_above", "omega_c_estimate", "monotone",
                      "points"], out)


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    for r in read_csv(CASES):
        crossing_marker(ax, float(r["delta_t_over_R"]), float(r["omega_bar"]), r["crossed"] == "1")
    line_x, line_y = [], []
    for line in read_csv(PHASE):
        value = line["omega_c_estimate"] or line["omega_c_above"]  # all crossed: at most the lowest
        if value:
            line_x.append(float(line["delta_t_over_R"]))
            line_y.append(float(value))
    ax.plot(line_x, line_y, "k-", lw=1.5, label="ω̄_c: middle of the bracket (upper bound where all crossed)")
    finish_crossing_axes(ax, "Δt / R", legend_loc="lower right")
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "fig7c3_phase.png"), dpi=110)


def main():
    sweep_study_main([SWEEP], table, plot)


if __name__ == "__main__":
    main()
