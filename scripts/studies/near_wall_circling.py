#!/usr/bin/env python3
"""The near-wall swimming cell's circling rate from runs of examples/swimming_cell_near_wall.toml.

The cell's axis a(t) is the unit vector from the flagellum's centroid (its nodes in the ParaView
frames) to the body's centre; the wall's normal is +x, so the heading's angle about +x is
theta = atan2(-a_y, a_z) (a rotation by theta about x takes +z to (0, -sin, cos)) and the circling
rate is d(theta)/dt, positive counterclockwise seen from the fluid (right-handed about +x), by a least-squares line over [T0, end]. Also the gap's mean rate of change
(body centre's x velocity) over the same window.
The heading wobbles with the body's rotation (period T = 2 pi / |mean Omega_z|, about 16 s): the
line over a window of about one period carries part of the wobble. When the run is long enough the
rate is also given as the difference of theta's means over one period at the window's start and
end, which cancels a periodic wobble: (<theta>[t1, t1 + T] - <theta>[T0, T0 + T]) / (t1 - T0),
t1 = end - T.

    near_wall_circling.py RUN_DIR... [--from T0] [--until T1]

Prints a Markdown table (docs/validation.md, the near-wall swimming cell).
"""
import argparse
import csv
import glob
import math
import re
import sys


def frame_centroid(path):
    text = open(path).read()
    block = re.search(r'Name="points"[^>]*>(.*?)</DataArray>', text, re.S).group(1)
    values = [float(v) for v in block.split()]
    n = len(values) // 3
    return [sum(values[3 * i + c] for i in range(n)) / n for c in range(3)]


def fit_slope(t, y):
    n = len(t)
    mt, my = sum(t) / n, sum(y) / n
    return sum((a - mt) * (b - my) for a, b in zip(t, y)) / sum((a - mt) ** 2 for a in t)


def measure(run_dir, t0, t_end=math.inf):
    rows = [r for r in csv.DictReader(open(f"{run_dir}/timeseries.csv"))
            if float(r["time"]) <= t_end + 1e-9]
    frames = sorted(glob.glob(f"{run_dir}/frames/rods_*.vtp"))
    pvd = open(f"{run_dir}/rods.pvd").read()
    times = [float(t) for t in re.findall(r'timestep="([^"]+)"', pvd)]
    if len(times) != len(frames):
        sys.exit(f"{run_dir}: {len(frames)} frames, {len(times)} times in rods.pvd")
    by_time = {round(float(r["time"]), 6): r for r in rows}
    ts, phis, xs = [], [], []
    for t, f in zip(times, frames):
        row = by_time.get(round(t, 6))
        if row is None or t < t0 or t > t_end + 1e-9:
            continue
        c = [float(row[f"body1_{k}"]) for k in "xyz"]
        g = frame_centroid(f)
        a = [ci - gi for ci, gi in zip(c, g)]
        ts.append(t)
        phis.append(math.atan2(-a[1], a[2]))
        xs.append(c[0])
    for k in range(1, len(phis)):  # unwrap
        while phis[k] - phis[k - 1] > math.pi:
            phis[k] -= 2 * math.pi
        while phis[k] - phis[k - 1] < -math.pi:
            phis[k] += 2 * math.pi
    u = fit_slope([float(r["time"]) for r in rows if float(r["time"]) >= t0],
                  [float(r["body1_z"]) for r in rows if float(r["time"]) >= t0])
    window = [float(r["time"]) for r in rows if float(r["time"]) >= t0]
    omega = sum(float(r["body1_omega_z"]) for r in rows if float(r["time"]) >= t0) / len(window)
    period = 2 * math.pi / abs(omega)
    turn_rate = float("nan")
    t1 = ts[-1] - period
    if t1 > t0 + 1.0:
        def mean_over(a):
            values = [p for t, p in zip(ts, phis) if a <= t <= a + period]
            return sum(values) / len(values)
        turn_rate = (mean_over(t1) - mean_over(t0)) / (t1 - t0)
    return fit_slope(ts, phis), turn_rate, period, fit_slope(ts, xs), u, ts[-1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--from", dest="t0", type=float, default=5.0)
    parser.add_argument("--until", dest="t1", type=float, default=math.inf)
    args = parser.parse_args()
    print("| run | window [s] | circling rate, line [rad/s] | one-turn means [rad/s] | "
          "turn T [s] | gap rate dx/dt [m/s] | U_z [m/s] |")
    print("|---|---|---|---|---|---|---|")
    for run_dir in args.runs:
        rate, turn_rate, period, drift, u, end = measure(run_dir, args.t0, args.t1)
        print(f"| {run_dir.rstrip('/').split('/')[-1]} | {args.t0:g}-{end:g} | {rate:.4e} | "
              f"{turn_rate:.4e} | {period:.1f} | {drift:.3e} | {u:.4e} |")


if __name__ == "__main__":
    main()
