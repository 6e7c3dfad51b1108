#!/usr/bin/python3
"""Paper appendix B (Fig. B.10b) and C (Fig. C.11a): l̄ at t̄ = 1 against ω̄ for N = 65 at the
paper's steps h = 1 ms and 0.1 ms (implicit Euler), and for LSBT with N = 195 against RSS.

  b10b_c11a.py run     the sweeps b10b_time_step, b10b_time_step_fine, c11a_lsbt (resume), table, plot
  b10b_c11a.py table   stokesrods analyze -> docs/validation/{b10b,c11a}_{cases,critical}.csv
  b10b_c11a.py plot    docs/validation/b10b_c11a.png from those tables and b10_cases.csv alone

Buckled: rod 1's tip more than 2R off the clamp's vertical in the last 20 % of t̄ ∈ [0, 1]
(io/analysis.h); ω̄_b is the bracket (last unbuckled, first speed from which every faster one buckled].
The RSS line of both panels at BDF2, h = 20 ms is B.10(a)'s N = 65 (b10_convergence.py).
"""
import os

from common import ROOT, case_table, read_csv, sweep_study_main, write_csv

SWEEPS = ["examples/studies/b10b_time_step.toml", "examples/studies/b10b_time_step_fine.toml",
          "examples/studies/c11a_lsbt.toml"]
STUDIES = os.path.join(ROOT, "out", "studies")
DOCS = os.path.join(ROOT, "docs", "validation")
# table name -> [(run folder, label of its rows)]
TABLES = {"b10b": [("b10b", "euler h=1e-3"), ("b10b_fine", "euler h=1e-4")],
          "c11a": [("c11a", "lsbt N=195")]}


def table():
    for name, sources in TABLES.items():
        cases, critical = [], []
        for folder, label in sources:
            rows, lines = case_table(os.path.join(STUDIES, folder), "--line", "rods.omega_bar",
                                     "--criterion", "buckled")
            cases += sorted([label, float(r["omega_bar"]), r["buckled"], r["final_length_bar"],
                             r["max_tip_axis_distance_over_R"], r["wall_seconds"]]
                            for r in rows if r["status"] == "completed")
            critical += [[label, l["below"], l["above"], l["estimate"], l["monotone"], l["points"]] for l in lines]
        write_csv(os.path.join(DOCS, f"{name}_cases.csv"),
                  ["run", "omega_bar", "buckled", "l_bar_at_t1", "max_tip_axis_distance_over_R", "wall_seconds"],
                  [[label, f"{w:g}", *rest] for label, w, *rest in cases])
        write_csv(os.path.join(DOCS, f"{name}_critical.csv"),
                  ["run", "omega_b_below", "omega_b_above", "omega_b_estimate", "monotone", "points"], critical)


def line(rows, key, value):
    return sorted((float(r["omega_bar"]), float(r["l_bar_at_t1"])) for r in rows if r[key] == value)


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def read(name):
        path = os.path.join(DOCS, name)
        return read_csv(path) if os.path.exists(path) else []

    bdf2 = line(read("b10_cases.csv"), "nodes", "65")
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    panels = ((axes[0], read("b10b_cases.csv"), "B.10(b): RSS, N = 65, ε = 1.02 r0", 675, "paper ω̄_b = 675"),
              (axes[1], read("c11a_cases.csv"), "C.11(a): BDF2, h = 20 ms, to t̄ = 1", 660, "paper LSBT ω̄_b = 660"))
    for ax, rows, title, paper, paper_label in panels:
        for (label, marker) in zip(sorted({r["run"] for r in rows}), ("o-", "s--", "v-.")):
            pts = line(rows, "run", label)
            ax.plot(*zip(*pts), marker, ms=4, mfc="none", label=label.replace("h=", "h = "))
        if bdf2:
            ax.plot(*zip(*bdf2), "^:", ms=4, mfc="none", color="gray", label="rss N=65, bdf2 h = 2e-2")
        ax.axvline(paper, color="gray", lw=0.8, ls=":", label=paper_label)
        ax.set_xlabel("ω̄")
        ax.set_ylabel("l̄ at t̄ = 1")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "b10b_c11a.png"), dpi=110)


if __name__ == "__main__":
    sweep_study_main(SWEEPS, table, plot)
