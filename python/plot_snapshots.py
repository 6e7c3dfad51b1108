#!/usr/bin/python3
"""Front (x-z) and side (y-z) views of the rods of a run at chosen times, as in the paper's Fig. 1.

usage: plot_snapshots.py RUN_DIR [--times T ...] [--output FILE]
"""
import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from stokesrods.results import nearest_frames, read_frame  # noqa: E402

COLORS = ["tab:blue", "tab:red", "tab:green", "tab:orange", "tab:purple"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("--times", type=float, nargs="+", default=[0.0])
    parser.add_argument("--output", default=None)
    args = parser.parse_args()
    frames = nearest_frames(args.run_dir, args.times)
    data = [(t, read_frame(path)[0]) for t, path in frames]
    # One horizontal range per view for all panels, so the snapshots compare at a glance.
    limits = []
    for a in (0, 1):
        lo = min(100 * x[:, a].min() for _, rods in data for x in rods)
        hi = max(100 * x[:, a].max() for _, rods in data for x in rods)
        pad = 0.1 * (hi - lo) + 0.5
        limits.append((lo - pad, hi + pad))
    fig, axes = plt.subplots(2, len(frames), figsize=(2.6 * len(frames), 7.0), squeeze=False)
    for column, (t, rods) in enumerate(data):
        for row, (a, label) in enumerate([(0, "x [cm]"), (1, "y [cm]")]):
            ax = axes[row][column]
            ax.set_xlim(*limits[a])
            ax.xaxis.set_major_locator(matplotlib.ticker.MaxNLocator(4))
            for k, x in enumerate(rods):
                ax.plot(100 * x[:, a], 100 * x[:, 2], "-", color=COLORS[k % len(COLORS)], lw=2.5,
                        solid_capstyle="round")
            ax.set_aspect("equal")
            ax.set_xlabel(label)
            if column == 0:
                ax.set_ylabel("z [cm]")
            ax.set_title(("front" if row == 0 else "side") + f", t = {t:.3g} s", fontsize=9)
            ax.grid(alpha=0.3)
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dir, "snapshots.png")
    fig.savefig(out, dpi=130)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
