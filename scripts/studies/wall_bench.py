#!/usr/bin/env python3
"""Flagella above a no-slip wall, dense against matrix-free mobility: CPU per step and peak memory.

N copies of the paper's helix (65 nodes, R = 1 cm, lambda = 5 cm, l0 = 0.2 m, omega_bar = 320) on a
ring with neighbouring bases 3R apart, hanging down toward the wall z = -0.215 m (1.5 cm below
their free ends), implicit Euler (h = 10 ms), GMRES, one thread. The CPU per step is the difference
of two runs (S1 and S2 steps) over S2 - S1, so that start-up and the first steps cancel; the peak
memory (max RSS) is that of the longer run.

    wall_bench.py STOKESRODS [--flagella 4 10] [--steps 3 8] [--out DIR]

Prints a Markdown table (docs/performance.md, "The wall behind the matrix-free operator").
"""
import argparse
import math
import pathlib
import tempfile

from common import timed_run

ROD = """
[[rods]]
shape = "helix"
nodes = 65
axis_length = 0.2
pitch = 0.05
helix_radius = 0.01
base = [{x:.6f}, {y:.6f}, 0.0]
omega_bar = 320
"""


def config(flagella, steps, mobility):
    text = (f'[run]\nname = "wall{flagella}"\nduration = {0.01 * steps + 1e-9}\n'
            f'time_step = 0.01\nframes = false\noutput_interval = 1.0\n'
            f'checkpoint_interval = 100.0\n[fluid]\nmodel = "rss"\nviscosity = 1.0\n'
            f'mobility = "{mobility}"\n[wall]\npoint = [0.0, 0.0, -0.215]\n'
            f'normal = [0.0, 0.0, 1.0]\n')
    ring = 0.03 / (2.0 * math.sin(math.pi / flagella)) if flagella > 1 else 0.0
    for k in range(flagella):
        a = 2.0 * math.pi * k / flagella
        text += ROD.format(x=ring * math.cos(a), y=ring * math.sin(a))
    return text


def run(binary, flagella, steps, mobility, out):
    name = f"wall{flagella}_{mobility}_{steps}"
    path = pathlib.Path(out) / f"{name}.toml"
    path.write_text(config(flagella, steps, mobility))
    run_dir = pathlib.Path(out) / name
    return timed_run(binary, path, run_dir)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary")
    parser.add_argument("--flagella", type=int, nargs="+", default=[4, 10])
    parser.add_argument("--steps", type=int, nargs=2, default=[3, 8])
    parser.add_argument("--mobility", nargs="+", default=["dense", "matrix_free"])
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    out = args.out or tempfile.mkdtemp(prefix="wall_bench_")
    pathlib.Path(out).mkdir(parents=True, exist_ok=True)
    s1, s2 = args.steps
    print("| flagella | nodes M | mobility | CPU per step [ms] | peak RSS [MB] | "
          "Newton per step |")
    print("|---|---|---|---|---|---|")
    for flagella in args.flagella:
        for mobility in args.mobility:
            cpu1, _, _ = run(args.binary, flagella, s1, mobility, out)
            cpu2, rss, summary = run(args.binary, flagella, s2, mobility, out)
            per_step = 1e3 * (cpu2 - cpu1) / (s2 - s1)
            steps = max(summary["steps"], 1)
            newton = summary["newton_iterations"] / steps
            print(f"| {flagella} | {65 * flagella} | {mobility} | {per_step:.0f} | {rss:.0f} "
                  f"| {newton:.2f} |", flush=True)


if __name__ == "__main__":
    main()
