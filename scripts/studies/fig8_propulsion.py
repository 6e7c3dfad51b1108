#!/usr/bin/python3
"""Paper Fig. 8: the propulsive force of two flagella against speed and distance.

  fig8_propulsion.py run     the sweeps fig8a_single.toml and fig8b_distance.toml (resume), then table, plot
                             (fig7c3_phase.toml supplies Δt/R = 4, 6, 8 of Fig. 8a: run fig7c3_phase.py first)
  fig8_propulsion.py table   docs/validation/fig8_single_cases.csv, fig8b_cases.csv (stokesrods analyze)
                             and the summary fig8_propulsion.csv (fits of those and of fig7c3_cases.csv)
  fig8_propulsion.py plot    docs/validation/fig8_propulsion.png from those tables alone
  fig8_propulsion.py table also writes, when their run folders exist, the checks of Fig. 8(b)'s rise
                             from Δt/R = 3 to 50: fig8b_windows.csv (over which times F̄p is averaged,
                             from out/studies/fig8b) and fig8b_sensitivity.csv (fig8b_sensitivity.toml)

F̄p (eq. 26, both rods' clamp reactions along z over EI/l0²) is the time average over the second half
of each run (t̄ ∈ [1, 2]); `stokesrods analyze` computes it and its ratio to one flagellum at the
same ω̄. Fig. 8(a)'s lines are least-squares fits through the origin, F̄p = k ω̄; Δt = ∞ is twice
one flagellum. The reduction at Δt/R = d is 1 − k_d / k_∞ (also given with the final values of F̄p
instead of the averages, as a check of how much the choice matters).
"""
import os

import numpy as np

from common import ROOT, case_table, first_number, log, read_csv, sweep_study_main, write_csv

OUT = os.path.join(ROOT, "out", "studies")
DOCS = os.path.join(ROOT, "docs", "validation")
SINGLE = os.path.join(DOCS, "fig8_single_cases.csv")
PAIRS = os.path.join(DOCS, "fig7c3_cases.csv")
FAR = os.path.join(DOCS, "fig8b_cases.csv")
SUMMARY = os.path.join(DOCS, "fig8_propulsion.csv")
WINDOWS = os.path.join(DOCS, "fig8b_windows.csv")
SENSITIVITY = os.path.join(DOCS, "fig8b_sensitivity.csv")
RISE_ENDS = ("0.03", "0.5")  # rods.2.base x of Δt/R = 3 and 50
R = 0.01
PAPER_REDUCTION = {4: 40.0, 6: 31.7, 8: 20.2}
FORCE = ["propulsive_force_bar_mean", "propulsive_force_bar_final"]


def table():
    single_dir = os.path.join(OUT, "fig8_single")
    single, _ = case_table(single_dir)
    rows = sorted((float(r["omega_bar"]), r) for r in single if r["status"] == "completed")
    write_csv(SINGLE, ["omega_bar"] + FORCE + ["wall_seconds"],
              [[f"{w:g}"] + [r[c] for c in FORCE + ["wall_seconds"]] for w, r in rows])
    far, _ = case_table(os.path.join(OUT, "fig8b"), "--single", single_dir)
    rows = sorted((first_number(r["rods.2.base"]) / R, r) for r in far if r["status"] == "completed")
    write_csv(FAR, ["delta_t_over_R"] + FORCE + ["propulsive_force_ratio_to_single", "wall_seconds"],
              [[f"{d:g}"] + [r[c] for c in FORCE + ["propulsive_force_ratio_to_single", "wall_seconds"]]
               for d, r in rows])
    write_csv(SUMMARY, ["delta_t_over_R", "points", "speeds", "slope_of_mean", "reduction_percent",
                        "paper_reduction_percent", "slope_of_final", "reduction_of_final_percent"],
              summary_rows(series()))
    rise_tables()


def rise_tables():
    """Fig. 8(b)'s rise F̄p(50)/F̄p(3) − 1: by averaging window (and the value at single times), and
    with one modelling choice changed at a time (fig8b_sensitivity.toml's cases, means over t̄ ∈ [1, 2])."""
    from common import timeseries
    ends = [os.path.join(OUT, "fig8b", f"rod2.base=_{x}_0.0_0.0_") for x in RISE_ENDS]
    if all(os.path.exists(os.path.join(e, "timeseries.csv")) for e in ends):
        series3, series50 = [timeseries(e) for e in ends]
        rows = []
        for a, b in ((0.0, 2.0), (0.25, 2.0), (0.5, 2.0), (1.0, 2.0), (0.02, 0.02), (0.1, 0.1), (0.25, 0.25),
                     (2.0, 2.0)):
            f3, f50 = window_mean(series3, a, b), window_mean(series50, a, b)
            rows.append([f"{a:g}", f"{b:g}", f"{f3:.5g}", f"{f50:.5g}", f"{100 * (f50 / f3 - 1):.1f}"])
        write_csv(WINDOWS, ["t_bar_from", "t_bar_to", "F_p_bar_at_3", "F_p_bar_at_50", "rise_percent"], rows)
    runs, _ = case_table(os.path.join(OUT, "fig8b_sensitivity"))
    far, _ = case_table(os.path.join(OUT, "fig8b"))
    by_variant = {}
    for r in [dict(r, case="base__" + r["case"]) for r in far] + runs:
        x = r["rods.2.base"].strip("[] ").split(",")[0].strip()
        if r["status"] == "completed" and x in RISE_ENDS:
            by_variant.setdefault(r["case"].split("__")[0], {})[x] = float(r["propulsive_force_bar_mean"])
    rows = [[v, f"{f[RISE_ENDS[0]]:.5g}", f"{f[RISE_ENDS[1]]:.5g}", f"{100 * (f[RISE_ENDS[1]] / f[RISE_ENDS[0]] - 1):.1f}"]
            for v, f in by_variant.items() if len(f) == 2]
    if runs:
        write_csv(SENSITIVITY, ["variant", "F_p_bar_at_3", "F_p_bar_at_50", "rise_percent"], rows)


def window_mean(series, a, b):
    """F̄p averaged (trapezoids) over t̄ ∈ [a, b], or its value at the row nearest a when a = b."""
    t, f = series["t_bar"], series["propulsive_force_bar"]
    if a == b:
        return float(f[np.argmin(abs(t - a))])
    inside = (t >= max(a, t[1]) - 1e-9) & (t <= b + 1e-9)  # the row at t = 0 has no force yet
    return float(np.trapz(f[inside], t[inside]) / (t[inside][-1] - t[inside][0]))


def series():
    """{Δt/R: [(ω̄, F̄p mean, F̄p final)]} from the committed case tables; ∞ = twice one flagellum."""
    out = {np.inf: [(float(r["omega_bar"]), 2 * float(r[FORCE[0]]), 2 * float(r[FORCE[1]]))
                    for r in read_csv(SINGLE)]}
    for r in read_csv(PAIRS):
        d = float(r["delta_t_over_R"])
        if d in PAPER_REDUCTION:
            out.setdefault(d, []).append((float(r["omega_bar"]), float(r[FORCE[0]]), float(r[FORCE[1]])))
    return {d: np.array(sorted(v)) for d, v in out.items() if v}


def slope(points, column):
    """Least-squares slope through the origin of F̄p (column 1 mean, 2 final) against ω̄."""
    w = points[:, 0]
    return float(w @ points[:, column] / (w @ w))


def summary_rows(lines):
    rows = []
    for d in sorted(lines):
        pts = lines[d]
        k_mean, k_final = slope(pts, 1), slope(pts, 2)
        red = 100 * (1 - k_mean / slope(lines[np.inf], 1))
        red_final = 100 * (1 - k_final / slope(lines[np.inf], 2))
        rows.append([f"{d:g}", len(pts), " ".join(f"{w:g}" for w in pts[:, 0]), f"{k_mean:.6g}",
                     f"{red:.1f}", PAPER_REDUCTION.get(d, ""), f"{k_final:.6g}", f"{red_final:.1f}"])
    return rows


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(10, 4))
    lines = series()
    for d in sorted(lines):
        pts = lines[d]
        k = slope(pts, 1)
        ax_a.plot(pts[:, 0], pts[:, 1], "o", ms=4, label=f"Δt/R = {d:g}")
        ax_a.plot([0, pts[:, 0].max()], [0, k * pts[:, 0].max()], "-", lw=1, color=ax_a.lines[-1].get_color())
    ax_a.set_xlabel("ω̄")
    ax_a.set_ylabel("F̄p (mean over t̄ ∈ [1, 2])")
    ax_a.legend(fontsize=8)
    ax_a.set_title("(a) two flagella; ∞ = twice one flagellum", fontsize=9)
    far = [(float(r["delta_t_over_R"]), float(r["propulsive_force_ratio_to_single"])) for r in read_csv(FAR)]
    if far:
        ax_b.semilogx([d for d, _ in far], [x for _, x in far], "o-", ms=4)
    ax_b.axhline(2, color="k", lw=0.5, ls="--")
    ax_b.set_xlabel("Δt / R")
    ax_b.set_ylabel("F̄p / F̄p single (means over t̄ ∈ [1, 2])")
    ax_b.set_title("(b) ω̄ = 213", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "fig8_propulsion.png"), dpi=110)
    log(open(SUMMARY).read())


def main():
    sweep_study_main(["examples/studies/fig8a_single.toml", "examples/studies/fig8b_distance.toml"], table, plot)


if __name__ == "__main__":
    main()
