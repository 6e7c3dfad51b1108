#!/usr/bin/python3
"""The swimming cell with 1, 2 and 4 flagella (issue 11; examples/swimming_cell_*.toml).

  swimming_cell.py run    # runs the three examples into out/swimming_cell_* (JOBS at a time)
  swimming_cell.py plot   # -> docs/validation/swimming_cell.{png,csv} from those runs (also from
                          #    unfinished ones: their rows so far)

Measured per run, over the second half of the simulated time reached:
  U     the body's mean velocity along z, Δz/Δt [m/s] (and |Δc|/Δt, the speed along its path);
  Omega the body's mean angular velocity about z [rad/s], and over the motor's rate ω;
  thrust the clamps' force on the rods along z, summed over the rods [N] (the fluid's force on the
        body balances it);
  the bundle: the first time the rods' closest approach falls below 3 mm, the first output row with
  a contact, and the smallest approach (2 and 4 flagella). The paper's Δb (crossing) is not used:
  it is measured in the lab frame, in which the whole cell turns.
"""
import csv
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

CASES = [(1, "one_flagellum"), (2, "two_flagella"), (4, "four_flagella")]
OUT = os.path.join(common.ROOT, "out")
DOCS = os.path.join(common.ROOT, "docs", "validation")
# The paper's helix: E = 10 MPa, r0 = 1 mm, l0 = 0.2 m, μ = 1 Pa·s; ω = ω̄ EI/(μ l0⁴).
EI = 1e7 * np.pi * 1e-3 ** 4 / 4
OMEGA = 320 * EI / (1.0 * 0.2 ** 4)


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def first_time(t, mask):
    idx = np.flatnonzero(mask)
    return float(t[idx[0]]) if idx.size else float("nan")


def measure(n, ts):
    t = ts["time"]
    half = t >= t[-1] / 2
    t0, t1 = t[half][0], t[-1]
    c0 = np.array([ts[f"body1_{a}"][half][0] for a in "xyz"])
    c1 = np.array([ts[f"body1_{a}"][-1] for a in "xyz"])
    out = {
        "flagella": n,
        "t_end": t1,
        "U_z": (c1[2] - c0[2]) / (t1 - t0),
        "speed": float(np.linalg.norm(c1 - c0)) / (t1 - t0),
        "Omega_z": float(np.mean(ts["body1_omega_z"][half])),
    }
    out["Omega_over_omega"] = out["Omega_z"] / OMEGA
    # The clamps' force on the rods, summed (the thrust the body takes), over the second half.
    out["thrust"] = float(np.mean(sum(ts[f"rod{k}_force_z"] for k in range(1, n + 1))[half]))
    if n > 1:
        out["min_distance"] = float(np.min(ts["min_distance"]))
        out["t_below_3mm"] = first_time(t, ts["min_distance"] < 3e-3)
        out["t_contact"] = first_time(t, ts["contacts"] > 0)
    return out


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    results = []
    for n, name in CASES:
        path = os.path.join(OUT, f"swimming_cell_{name}", "timeseries.csv")
        if not os.path.exists(path):
            continue
        ts = read(path)
        results.append(measure(n, ts))
        t = ts["time"]
        style = {"label": f"{n} flagell{'um' if n == 1 else 'a'}", "color": f"C{n}"}
        axes[0].plot(t, 1e3 * (ts["body1_z"] - ts["body1_z"][0]), **style)
        axes[1].plot(t, ts["body1_omega_z"] / OMEGA, **style)
        if n > 1:
            axes[2].plot(t, 1e3 * ts["min_distance"], **style)
    axes[0].set(xlabel="t [s]", ylabel="body z − z(0) [mm]", title="swimming")
    axes[1].set(xlabel="t [s]", ylabel="Ω_z / ω", title="body counter-rotation")
    axes[2].axhline(2.0, color="grey", lw=0.8, ls="--")
    axes[2].set(xlabel="t [s]", ylabel="closest approach [mm]", title="bundling (2r0 dashed)")
    for ax in axes:
        ax.legend(fontsize=8)
    fig.tight_layout()
    os.makedirs(DOCS, exist_ok=True)
    fig.savefig(os.path.join(DOCS, "swimming_cell.png"), dpi=110)
    keys = ["flagella", "t_end", "U_z", "speed", "Omega_z", "Omega_over_omega", "thrust", "min_distance",
            "t_below_3mm", "t_contact"]
    with open(os.path.join(DOCS, "swimming_cell.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in results:
            w.writerow({k: (f"{r[k]:.6g}" if k in r else "") for k in keys})
    for r in results:
        print({k: (round(v, 6) if isinstance(v, float) else v) for k, v in r.items()})


def run():
    common.run_all([(f"examples/swimming_cell_{name}.toml", os.path.join(OUT, f"swimming_cell_{name}"), {})
                    for _, name in CASES])


if __name__ == "__main__":
    {"run": run, "plot": plot}[sys.argv[1] if len(sys.argv) > 1 else "plot"]()
