#!/usr/bin/python3
"""Rigid helices against experiment: Rodenborn et al. (PNAS 2013, Fig. 2), ../shared/data.

  rodenborn.py    runs build/release/apps/studies/rigid_helix at the experiment's λ/R and writes
                  docs/validation/rodenborn_rigid_helices.{png,csv}

Thrust / (η ω R²) and torque / (η ω R³) of a helix rotating about its axis (held from translating),
drag / (η U R) of the helix translating along its axis, for RSS (ε = 1.02 a and ε = √e a), LSBT and
RFT (Lighthill's coefficients), at R = 6.3 mm, a = 0.397 mm, axial length 130 mm.
"""
import io
import os
import subprocess

import numpy as np

from common import ROOT, log

DATA = os.path.join(ROOT, "..", "shared", "data", "rodenborn2013_rigid_helices.csv")
if not os.path.exists(DATA):
    DATA = "/work/shared/data/rodenborn2013_rigid_helices.csv"
BIN = os.path.join(ROOT, "build", "release", "apps", "studies", "rigid_helix")
DOCS = os.path.join(ROOT, "docs", "validation")
QUANTITIES = [("thrust_over_eta_omega_R2", "thrust / (η ω R²)"),
              ("torque_over_eta_omega_R3", "torque / (η ω R³)"),
              ("drag_over_eta_U_R", "drag / (η U R)")]


def main():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    with open(DATA) as f:
        table = [line for line in f if not line.startswith("#")]
    data = np.genfromtxt(io.StringIO("".join(table)), delimiter=",", names=True)
    ratios = sorted(set(np.round(np.concatenate([data["lambda_over_R"], np.linspace(2.0, 16.0, 15)]), 3)))
    text = subprocess.run([BIN, *[f"{r:g}" for r in ratios]], check=True, capture_output=True, text=True).stdout
    with open(os.path.join(DOCS, "rodenborn_rigid_helices.csv"), "w") as f:
        f.write(text)
    sim = np.genfromtxt(io.StringIO(text), delimiter=",", names=True, dtype=None, encoding=None)
    models = list(dict.fromkeys(sim["model"]))
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    lines = ["model,quantity,mean_abs_relative_error_percent,worst_percent"]
    for ax, (col, label) in zip(axes, QUANTITIES):
        ax.plot(data["lambda_over_R"], data[col], "ks", label="experiment")
        for m in models:
            s = sim[sim["model"] == m]
            ax.plot(s["lambda_over_R"], s[col], "-", label=m)
            at = {round(float(r), 3): float(v) for r, v in zip(s["lambda_over_R"], s[col])}
            errs = [100 * (at[round(float(r), 3)] / float(v) - 1) for r, v in zip(data["lambda_over_R"], data[col])]
            lines.append(f"{m},{col},{np.mean(np.abs(errs)):.1f},{max(errs, key=abs):+.1f}")
        ax.set_xlabel("λ / R")
        ax.set_ylabel(label)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "rodenborn_rigid_helices.png"), dpi=110)
    with open(os.path.join(DOCS, "rodenborn_errors.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    log("\n".join(lines))


if __name__ == "__main__":
    main()
