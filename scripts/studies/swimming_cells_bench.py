#!/usr/bin/env python3
"""Several swimming cells, dense against matrix-free mobility: CPU per step and peak memory.

Each cell is the two-flagella swimming cell of examples/swimming_cell_two_flagella.toml (a free
sphere of radius 25 mm, 400 surface points, two 65-node helices turned at omega_bar = 320), the
cells on a square grid 0.1 m apart, implicit Euler at 20 ms, one thread. The CPU per step is the
difference of two runs (S1 and S2 steps) over S2 - S1, so that start-up and the first steps from
rest cancel; the peak memory (max RSS) and the GMRES products per Newton iteration
(summary.json krylov_products / newton_iterations) are those of the longer run.

    swimming_cells_bench.py STOKESRODS [--cells 1 4 9] [--steps 3 8] [--out DIR]

Prints a Markdown table (docs/performance.md, "Cell bodies behind the matrix-free operator").
"""
import argparse
import math
import pathlib
import tempfile

from common import timed_run

CELL = """
[[bodies]]
shape = "sphere"
radius = 0.025
center = [{cx:.6f}, {cy:.6f}, 0.02]
motion = "free"
"""
ROD = """
[[rods]]
shape = "helix"
nodes = 65
axis_length = 0.2
pitch = 0.05
helix_radius = 0.01
base = [{x:.6f}, {y:.6f}, 0.0]
omega_bar = 320
body = {body}
"""


def config(cells, steps, mobility):
    text = (f'[run]\nname = "cells{cells}"\nduration = {0.02 * steps + 1e-9}\ntime_step = 0.02\n'
            f'integrator = "euler"\nframes = false\noutput_interval = 1.0\n'
            f'checkpoint_interval = 100.0\n[fluid]\nmodel = "rss"\nviscosity = 1.0\n'
            f'mobility = "{mobility}"\n')
    side = math.ceil(math.sqrt(cells))
    for k in range(cells):
        x0, y0 = 0.1 * (k % side), 0.1 * (k // side)
        text += CELL.format(cx=x0 + 0.015, cy=y0)
        for dx in (0.0, 0.03):
            text += ROD.format(x=x0 + dx, y=y0, body=k + 1)
    return text


def run(binary, cells, steps, mobility, out):
    path = pathlib.Path(out) / f"cells{cells}_{mobility}_{steps}.toml"
    path.write_text(config(cells, steps, mobility))
    run_dir = pathlib.Path(out) / f"cells{cells}_{mobility}_{steps}"
    return timed_run(binary, path, run_dir)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary")
    parser.add_argument("--cells", type=int, nargs="+", default=[1, 4, 9])
    parser.add_argument("--steps", type=int, nargs=2, default=[3, 8])
    parser.add_argument("--mobility", nargs="+", default=["dense", "matrix_free"])
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    out = args.out or tempfile.mkdtemp(prefix="swimming_cells_")
    pathlib.Path(out).mkdir(parents=True, exist_ok=True)
    s1, s2 = args.steps
    print("| cells | flagella | nodes M | body points P | unknowns 3(M+P)+6B | mobility | "
          "CPU per step [ms] | peak RSS [MB] | Newton per step | GMRES products per Newton |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for cells in args.cells:
        for mobility in args.mobility:
            cpu1, _, _ = run(args.binary, cells, s1, mobility, out)
            cpu2, rss, summary = run(args.binary, cells, s2, mobility, out)
            m, p = 130 * cells, 400 * cells
            per_step = 1e3 * (cpu2 - cpu1) / (s2 - s1)
            newton = summary["newton_iterations"] / max(summary["steps"], 1)
            products = summary.get("krylov_products", 0) / max(summary["newton_iterations"], 1)
            print(f"| {cells} | {2 * cells} | {m} | {p} | {3 * (m + p) + 6 * cells} | {mobility} "
                  f"| {per_step:.0f} | {rss:.0f} | {newton:.2f} | {products:.1f} |", flush=True)


if __name__ == "__main__":
    main()
