#!/usr/bin/python3
"""Issue 8, "What the helix's l0 measures": ω̄_b with the lead-in within l0 or above it, ε = 1.02 r0 or √e r0.

  lead_in.py run     the sweep examples/studies/lead_in_buckling.toml (resumes), then table
  lead_in.py table   stokesrods analyze out/studies/lead_in -> docs/validation/lead_in_{cases,critical}.csv
  lead_in.py plot    prints the brackets from docs/validation/lead_in_critical.csv (no figure)

Buckled: rod 1's tip more than 2R off the clamp's vertical in the last 20 % of t̄ ∈ [0, 1]
(io/analysis.h); ω̄_b is the bracket (last unbuckled, first speed from which every faster one
buckled], bisected to 12.5 by the sweep's [refine].
"""
import os

from common import ROOT, case_table, log, read_csv, sweep_study_main, write_csv

SWEEP = "examples/studies/lead_in_buckling.toml"
OUT = os.path.join(ROOT, "out", "studies", "lead_in")
DOCS = os.path.join(ROOT, "docs", "validation")
CASES = os.path.join(DOCS, "lead_in_cases.csv")
CRITICAL = os.path.join(DOCS, "lead_in_critical.csv")


def table():
    rows, lines = case_table(OUT, "--line", "rods.omega_bar", "--criterion", "buckled")
    done = sorted(((r["rods.lead_in"].strip("'\""), float(r["fluid.regularization"]), float(r["omega_bar"])), r)
                  for r in rows if r["status"] == "completed")
    write_csv(CASES, ["lead_in", "regularization_over_r0", "omega_bar", "buckled", "max_tip_axis_distance_over_R",
                      "wall_seconds"],
              [[k[0], f"{k[1]:g}", f"{k[2]:g}", r["buckled"], r["max_tip_axis_distance_over_R"], r["wall_seconds"]]
               for k, r in done])
    write_csv(CRITICAL, ["line", "below", "above", "estimate", "monotone", "points"],
              [[l["line"], l["below"], l["above"], l["estimate"], l["monotone"], l["points"]] for l in lines])


def plot():
    for line in read_csv(CRITICAL):
        log(f"{line['line']}: ω̄_b in ({line['below']}, {line['above']}]")


def main():
    sweep_study_main([SWEEP], table, plot)


if __name__ == "__main__":
    main()
