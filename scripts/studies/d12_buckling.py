#!/usr/bin/python3
"""Paper Fig. D.12 (Appendix D): ω̄_b of the experiment's helix against pitch and helix radius.

  d12_buckling.py run     the sweep examples/studies/d12_buckling.toml (resumes), then table, plot
  d12_buckling.py table   stokesrods analyze out/studies/d12 -> docs/validation/d12_{cases,critical}.csv
  d12_buckling.py plot    docs/validation/d12_buckling.png from those tables alone

E = 1.255 MPa, μ = 1.6 Pa·s, r0 = 1.58 mm, l0 = 20 cm (Jawed et al. 2015's scaled-up flagellum);
(a1) λ/l0 at R = 1.59 cm, (a2) R/λ at λ = 5 cm. Buckled: rod 1's tip more than 2R off the clamp's
vertical (io/analysis.h); the runs stop there (run.stop_when_buckled). ω̄_b is the bracket (last
unbuckled, first speed from which every faster one buckled], bisected to 25 by the sweep's [refine],
drawn at its middle with the bracket as an error bar.
"""
import os

from common import ROOT, bracket_errorbar, case_table, read_csv, sweep_study_main, write_csv

SWEEPS = ["examples/studies/d12_buckling.toml", "examples/studies/d12_buckling_small_radius.toml"]
OUTS = [os.path.join(ROOT, "out", "studies", "d12"), os.path.join(ROOT, "out", "studies", "d12_small_radius")]
DOCS = os.path.join(ROOT, "docs", "validation")
CASES = os.path.join(DOCS, "d12_cases.csv")
CRITICAL = os.path.join(DOCS, "d12_critical.csv")
L0, PITCH, RADIUS = 0.2, 0.05, 0.0159  # the experiment's helix


def geometry(values):
    """(study, λ/l0, R/λ) of a case or a line from its "key=value" pairs."""
    pitch = float(values.get("rods.pitch") or PITCH)
    radius = float(values.get("rods.helix_radius") or RADIUS)
    study = "radius" if abs(pitch - PITCH) < 1e-12 and abs(radius - RADIUS) > 1e-12 else "pitch"
    return study, f"{pitch / L0:.4g}", f"{radius / pitch:.4g}"


def line_values(text):
    """"rods.pitch=0.03 rods.helix_radius=0.0159" -> {"rods.pitch": "0.03", ...}."""
    return dict(p.split("=", 1) for p in text.split(" ") if "=" in p)


def table():
    rows, lines = [], []
    for out_dir in OUTS:
        r, l = case_table(out_dir, "--line", "rods.omega_bar", "--criterion", "buckled")
        rows += r
        lines += l
    out = []
    for r in rows:
        if r["status"] != "completed":
            continue
        study, lam, ratio = geometry({k: r[k].strip("'\"") for k in ("rods.pitch", "rods.helix_radius")})
        out.append([study, lam, ratio, f"{float(r['omega_bar']):g}", r["buckled"],
                    r["max_tip_axis_distance_over_R"], r["final_length_bar"], r["wall_seconds"]])
    out.sort(key=lambda x: (x[0], float(x[1]), float(x[2]), float(x[3])))
    out = [c for i, c in enumerate(out) if i == 0 or c[:4] != out[i - 1][:4]]  # a case both sweeps ran
    write_csv(CASES, ["study", "lambda_over_l0", "R_over_lambda", "omega_bar", "buckled",
                      "max_tip_axis_distance_over_R", "final_length_bar", "wall_seconds"], out)
    crit = {}  # (study, λ/l0, R/λ) -> row; a line continued in the second sweep: its bracket
    for line in lines:
        key = geometry({k: v.strip("'\"") for k, v in line_values(line["line"]).items()})
        if key in crit and not line["above"]:
            continue
        crit[key] = [*key, line["below"], line["above"], line["estimate"], line["monotone"], line["points"]]
    for key, row in list(crit.items()):
        if key[0] == "pitch" and float(key[1]) == PITCH / L0:  # the shared point is on both panels
            crit[("radius", *key[1:])] = ["radius", *row[1:]]
    crit = list(crit.values())
    crit.sort(key=lambda x: (x[0], float(x[1]), float(x[2])))
    write_csv(CRITICAL, ["study", "lambda_over_l0", "R_over_lambda", "omega_b_below", "omega_b_above",
                         "omega_b_estimate", "monotone", "points"], crit)


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    cases = read_csv(CASES)
    for ax, study, column, label in ((axes[0], "pitch", "lambda_over_l0", "λ / l0 (R = 1.59 cm)"),
                                     (axes[1], "radius", "R_over_lambda", "R / λ (λ = 5 cm)")):
        for r in cases:
            on_panel = r["study"] == study or (study == "radius" and float(r["lambda_over_l0"]) == PITCH / L0
                                               and float(r["R_over_lambda"]) == round(RADIUS / PITCH, 4))
            if on_panel:
                buckled = r["buckled"] == "1"
                ax.plot(float(r[column]), float(r["omega_bar"]), "o" if buckled else "^", ms=5,
                        mfc="tab:red" if buckled else "none", mec="tab:red" if buckled else "tab:blue")
        rows = [r for r in read_csv(CRITICAL) if r["study"] == study]
        bracket_errorbar(ax, rows, column, "omega_b_below", "omega_b_above", fmt="k-", label="ω̄_b (bracket)")
        ax.set_xlabel(label)
        ax.set_ylabel("ω̄")
        ax.set_yscale("log")
        ax.set_title("buckled (●) or not (△) at t̄ ≤ 1, DER-RSS N = 65", fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "d12_buckling.png"), dpi=110)


def main():
    sweep_study_main(SWEEPS, table, plot)


if __name__ == "__main__":
    main()
