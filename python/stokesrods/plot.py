"""Time series of a run (`stokesrods plot RUN_DIR COLUMN...`): one panel per column against time,
written to RUN_DIR/plot_<columns>.png (or --output).

usage: python3 -m stokesrods.plot RUN_DIR COLUMN... [--x time|t_bar] [--output FILE]
Exit codes as the command line's: 2 bad input (no such run or column), 4 input/output.
"""
import argparse
import os
import sys

from .results import read_timeseries


def fail(code, message):
    print(f"error: {message}", file=sys.stderr)
    sys.exit(code)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="stokesrods plot", description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("columns", nargs="+", help="timeseries.csv columns, e.g. delta_b_over_R")
    parser.add_argument("--x", default="time", help="the abscissa: time (default) or t_bar")
    parser.add_argument("--output", default=None)
    args = parser.parse_args(argv)
    path = os.path.join(args.run_dir, "timeseries.csv")
    if not os.path.exists(path):
        fail(2, f"{path}: no such file (not a run directory?)")
    series = read_timeseries(path)
    for name in [args.x] + args.columns:
        if name not in series:
            fail(2, f"{path}: no column {name!r} (columns: {', '.join(series)})")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(args.columns), 1, figsize=(6.4, 1.2 + 2.0 * len(args.columns)),
                             sharex=True, squeeze=False, layout="constrained")
    for ax, name in zip(axes[:, 0], args.columns):
        ax.plot(series[args.x], series[name], "-", lw=1.4)
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("t [s]" if args.x == "time" else r"$\bar{t}$" if args.x == "t_bar" else args.x)
    axes[0, 0].set_title(os.path.basename(os.path.normpath(args.run_dir)), fontsize=9)
    out = args.output or os.path.join(args.run_dir, "plot_" + "_".join(args.columns) + ".png")
    try:
        fig.savefig(out, dpi=130)
    except OSError as e:
        fail(4, f"{out}: {e.strerror}")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
