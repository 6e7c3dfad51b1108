"""Fig. 1 over its 75 s with implicit Euler and BDF2 at several steps, against the h = 1 ms
implicit Euler run of docs/validation/fig1_time_step.csv (the accuracy target of the performance
issue: Δb/R within 0.03 of it at all times, minimum distance within 0.1 mm).

    /usr/bin/python3 time_integrator.py            # runs what is missing (one thread each), then
                                                   # writes docs/validation/fig1_integrators.{csv,png}
Compute time is the run's wall time (summary.json), one thread (OMP_NUM_THREADS=1).
"""
import csv
import json
import os

import numpy as np

import common

CASES = [("euler", 0.01), ("euler", 0.005), ("bdf2", 0.04), ("bdf2", 0.02), ("bdf2", 0.01)]
OUT = os.path.join(common.ROOT, "out", "studies", "integrators")
DOCS = os.path.join(common.ROOT, "docs", "validation")


def out_dir(integrator, h):
    return os.path.join(OUT, f"{integrator}_h{h:g}")


def main():
    os.environ["OMP_NUM_THREADS"] = "1"
    cases = [("examples/fig1_bundling.toml", out_dir(i, h),
              {"run.integrator": i, "run.time_step": h, "run.output_interval": 1.0,
               "run.frames": "false"}) for i, h in CASES]
    common.run_all(cases)
    ref = np.genfromtxt(os.path.join(DOCS, "fig1_time_step.csv"), delimiter=",", names=True)
    rows = []
    for integrator, h in CASES:
        ts = common.timeseries(out_dir(integrator, h))
        with open(os.path.join(out_dir(integrator, h), "summary.json")) as f:
            summary = json.load(f)
        db = np.interp(ref["time"], ts["time"], ts["delta_b_over_R"])
        md = np.interp(ref["time"], ts["time"], ts["min_distance"])
        rows.append({"integrator": integrator, "h": h,
                     "max_delta_b_over_R_error": float(np.max(np.abs(db - ref["delta_b_over_R_h1e3"]))),
                     "max_min_distance_error_mm": 1e3 * float(np.max(np.abs(md - ref["min_distance_h1e3"]))),
                     "steps": summary["steps"], "newton_iterations": summary["newton_iterations"],
                     "wall_seconds": summary["wall_seconds"]})
        common.log(rows[-1])
    with open(os.path.join(DOCS, "fig1_integrators.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    ax[0].plot(ref["time"], ref["delta_b_over_R_h1e3"], "k-", lw=2, label="Euler, h = 1 ms (reference)")
    for integrator, h in CASES:
        ts = common.timeseries(out_dir(integrator, h))
        ax[0].plot(ts["time"], ts["delta_b_over_R"], "--" if integrator == "euler" else "-",
                   label=f"{integrator}, h = {1e3 * h:g} ms")
        db = np.interp(ref["time"], ts["time"], ts["delta_b_over_R"])
        ax[1].semilogy(ref["time"], np.abs(db - ref["delta_b_over_R_h1e3"]) + 1e-6,
                       "--" if integrator == "euler" else "-", label=f"{integrator}, {1e3 * h:g} ms")
    ax[1].axhline(0.03, color="k", lw=0.8)
    ax[0].set(xlabel="t [s]", ylabel="Δb/R", title="Fig. 1: Δb/R")
    ax[1].set(xlabel="t [s]", ylabel="|Δb/R − reference|", title="difference to h = 1 ms (target 0.03)")
    ax[0].legend(fontsize=7)
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "fig1_integrators.png"), dpi=120)


if __name__ == "__main__":
    main()
