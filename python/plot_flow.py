#!/usr/bin/python3
"""The flow on the planes of a run (flow/flow_*.csv) with the rods' projection, as the paper's
Fig. 6(b): speed in color, in-plane direction as streamlines.

usage: plot_flow.py RUN_DIR [--output FILE]
"""
import argparse
import glob
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from stokesrods.results import nearest_frames, read_frame  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("--output", default=None)
    args = parser.parse_args()
    import json
    with open(os.path.join(args.run_dir, "summary.json")) as f:
        config = json.load(f)["config"]
    plane = config["flow_field"]
    times = sorted(plane["times"])
    files = sorted(glob.glob(os.path.join(args.run_dir, "flow", "flow_*.csv")))
    if not files:
        sys.exit(f"{args.run_dir}: no flow/flow_*.csv")
    nu, nv = plane["resolution"]
    u_edge, v_edge = np.array(plane["u"]), np.array(plane["v"])
    fig, axes = plt.subplots(1, len(files), figsize=(3.2 * len(files), 7.0), squeeze=False)
    for k, path in enumerate(files):
        d = np.genfromtxt(path, delimiter=",", names=True)
        p = np.stack([d["x"], d["y"], d["z"]], axis=1) - np.array(plane["origin"])
        w = np.stack([d["ux"], d["uy"], d["uz"]], axis=1)
        a = (p @ u_edge / u_edge.dot(u_edge) * np.linalg.norm(u_edge)).reshape(nv, nu)
        b = (p @ v_edge / v_edge.dot(v_edge) * np.linalg.norm(v_edge)).reshape(nv, nu)
        wa = (w @ u_edge / np.linalg.norm(u_edge)).reshape(nv, nu)
        wb = (w @ v_edge / np.linalg.norm(v_edge)).reshape(nv, nu)
        speed = np.linalg.norm(w, axis=1).reshape(nv, nu)
        ax = axes[0][k]
        mesh = ax.pcolormesh(100 * a, 100 * b, 1000 * speed, shading="gouraud", cmap="viridis")
        ax.streamplot(100 * a[0, :], 100 * b[:, 0], wa, wb, color="w", density=1.0,
                      linewidth=0.6, arrowsize=0.6)
        t = times[k] if k < len(times) else float("nan")
        (_, frame), = nearest_frames(args.run_dir, [t])
        rods, _ = read_frame(frame)
        for x in rods:
            q = x - np.array(plane["origin"])
            ax.plot(100 * q @ u_edge / np.linalg.norm(u_edge), 100 * q @ v_edge / np.linalg.norm(v_edge),
                    "-", color="tab:red", lw=1.5, alpha=0.8)
        ax.set_aspect("equal")
        ax.set_title(f"t = {t:g} s", fontsize=9)
        ax.set_xlabel("along u [cm]")
        if k == 0:
            ax.set_ylabel("along v [cm]")
        fig.colorbar(mesh, ax=ax, shrink=0.6, label="|u| [mm/s]")
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dir, "flow.png")
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
