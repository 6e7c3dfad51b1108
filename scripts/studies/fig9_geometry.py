#!/usr/bin/python3
"""Paper Fig. 9: the critical crossing speed ω̄_c at Δt/R = 4 against helical pitch and helix radius.

  fig9_geometry.py run     the sweep examples/studies/fig9_pitch_radius.toml (resumes), then table, plot
  fig9_geometry.py table   stokesrods analyze out/studies/fig9 -> docs/validation/fig9_{cases,critical}.csv
  fig9_geometry.py plot    docs/validation/fig9_geometry.png from those tables alone

(a) λ/l0 ∈ [0.15, 0.45] at R/l0 = 0.05; (b) R/l0 ∈ [0.0375, 0.1125] at λ/l0 = 0.25; l0 = 0.2 m.
The shared point (λ/l0 = 0.25, R/l0 = 0.05) is the Δt/R = 4 line of Fig. 7(c3): its bracket comes
from docs/validation/fig7c3_phase.csv. Crossed: Δb ≤ 0 at t̄ = 2; ω̄_c is the bracket (last
uncrossed, first speed from which every faster one crossed], drawn at its middle with the bracket
as an error bar (at the lowest speed run, as an upper bound, where every speed crossed). Tight
bundles turn their tips around each other, so Δb at t̄ = 2 can be positive after a crossing; the
table also gives the bracket of "crossed at some t̄ ≤ 2" (a first crossing time exists), drawn grey.
"""
import os

from common import (ROOT, bracket_errorbar, case_table, crossing_marker, finish_crossing_axes, read_csv, sweep_study_main,
                    switch_bracket, write_csv)

SWEEP = "examples/studies/fig9_pitch_radius.toml"
OUT = os.path.join(ROOT, "out", "studies", "fig9")
# λ/l0 = 0.45 bisected on "crossed at some t̄ ≤ 2" (examples/studies/fig9_first_crossing.toml)
OUT_FIRST = os.path.join(ROOT, "out", "studies", "fig9_first")
DOCS = os.path.join(ROOT, "docs", "validation")
CASES = os.path.join(DOCS, "fig9_cases.csv")
CRITICAL = os.path.join(DOCS, "fig9_critical.csv")
PHASE = os.path.join(DOCS, "fig7c3_phase.csv")
PHASE_CASES = os.path.join(DOCS, "fig7c3_cases.csv")
L0, PITCH, RADIUS = 0.2, 0.05, 0.01  # the representative helix (examples/fig7_bundling.toml)


def geometry(values):
    """(λ/l0, R/l0) of a case or a line, from its "key=value" pairs (defaults: the representative helix)."""
    pitch = float(values.get("rods.pitch") or PITCH)
    radius = float(values.get("rods.helix_radius") or RADIUS)
    return f"{pitch / L0:g}", f"{radius / L0:g}"


def line_values(text):
    """"rods.pitch=0.03 rods.nodes=93" -> {"rods.pitch": "0.03", "rods.nodes": "93"} (bases skipped)."""
    return dict(p.split("=", 1) for p in text.split(" ") if "=" in p and not p.startswith("rods.2.base"))


def table():
    rows, lines = case_table(OUT, "--line", "rods.omega_bar", "--criterion", "crossed")
    rows += case_table(OUT_FIRST, "--line", "rods.omega_bar", "--criterion", "ever_crossed")[0]
    out = []
    for r in rows:
        if r["status"] != "completed":
            continue
        lam, rad = geometry(r)
        out.append([r["case"].split("__")[0], lam, rad, r.get("rods.nodes", ""), f"{float(r['omega_bar']):g}",
                    r["crossed"], r["first_crossing_t_bar"], r["final_delta_b_over_R"], r["wall_seconds"]])
    out.sort(key=lambda x: (x[0], float(x[1]), float(x[2]), float(x[4])))
    out = [c for i, c in enumerate(out) if i == 0 or c[:5] != out[i - 1][:5]]  # a case both sweeps ran
    write_csv(CASES, ["study", "lambda_over_l0", "R_over_l0", "nodes", "omega_bar", "crossed",
                      "first_crossing_t_bar", "final_delta_b_over_R", "wall_seconds"], out)
    first = {}  # (study, λ/l0, R/l0) -> [(ω̄, crossed at some t̄ ≤ 2)]
    for c in out:
        first.setdefault((c[0], c[1], c[2]), []).append((float(c[4]), c[6] != ""))
    crit = []
    for line in lines:
        values = line_values(line["line"])
        lam, rad = geometry(values)
        study = "pitch" if values.get("rods.pitch") else "radius"
        crit.append([study, lam, rad, line["below"], line["above"], line["estimate"], line["monotone"],
                     line["points"], *first_crossing(first.get((study, lam, rad), [])), "fig9"])
    shared = [(float(r["omega_bar"]), r["first_crossing_t_bar"] != "") for r in read_csv(PHASE_CASES)
              if float(r["delta_t_over_R"]) == 4]
    for line in read_csv(PHASE):  # the shared point: Fig. 7(c3) at Δt/R = 4
        if float(line["delta_t_over_R"]) == 4:
            for study in ("pitch", "radius"):
                crit.append([study, f"{PITCH / L0:g}", f"{RADIUS / L0:g}", line["omega_c_below"],
                             line["omega_c_above"], line["omega_c_estimate"], line["monotone"], line["points"],
                             *first_crossing(shared), "fig7c3"])
    crit.sort(key=lambda x: (x[0], float(x[1]), float(x[2])))
    write_csv(CRITICAL, ["study", "lambda_over_l0", "R_over_l0", "omega_c_below", "omega_c_above",
                         "omega_c_estimate", "monotone", "points", "first_crossing_below",
                         "first_crossing_above", "source"], crit)


def first_crossing(points):
    """The bracket of "crossed at some t̄ ≤ 2" along ω̄, as table text ("" where open)."""
    below, above, _ = switch_bracket(points)
    return ("" if below is None else f"{below:g}"), ("" if above is None else f"{above:g}")


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, study, column, label, where in ((axes[0], "pitch", "lambda_over_l0", "λ / l0 (R/l0 = 0.05)", "upper center"),
                                            (axes[1], "radius", "R_over_l0", "R / l0 (λ/l0 = 0.25)", "center right")):
        for r in read_csv(CASES):
            if r["study"] == study:
                crossing_marker(ax, float(r[column]), float(r["omega_bar"]), r["crossed"] == "1")
        rows = [r for r in read_csv(CRITICAL) if r["study"] == study]
        for below_key, above_key, color, width, name in (
                ("first_crossing_below", "first_crossing_above", "0.75", 4, "crossed at some t̄ ≤ 2"),
                ("omega_c_below", "omega_c_above", "k", 1.2, "ω̄_c: Δb ≤ 0 at t̄ = 2")):
            bracket_errorbar(ax, rows, column, below_key, above_key, fmt="-", color=color, lw=width, label=name)
        finish_crossing_axes(ax, label, "Δt/R = 4: ", legend_loc=where)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "fig9_geometry.png"), dpi=110)


def main():
    sweep_study_main([SWEEP], table, plot)


if __name__ == "__main__":
    main()
