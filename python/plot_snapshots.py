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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from stokesrods_frames import nearest_frames, read_frame  # noqa: E402

COLORS = ["tab:blue", "tab:red", "tab:green", "tab:orange", "tab:purple"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("--times", type=float, nargs="+", default=[0.0])
    parser.add_argument("--output", default=None)
    args = parser.parse_args()
    frames = nearest_frames(args.run_dir, args.times)
    fig, axes = plt.subplots(2, len(frames), figsize=(2.6 * len(frames), 7.0), squeeze=False)
    for column, (t, path) in enumerate(frames):
        rods, _ = read_frame(path)
        for row, (a, label) in enumerate([(0, "x [cm]"), (1, "y [cm]")]):
            ax = axes[row][column]
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
