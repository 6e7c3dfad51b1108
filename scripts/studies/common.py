"""Shared helpers of the study scripts: run stokesrods cases (two at a time) and read results."""
import concurrent.futures
import json
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("STOKESRODS_BIN", os.path.join(ROOT, "build", "release", "apps", "stokesrods",
                                                     "stokesrods"))
JOBS = int(os.environ.get("STOKESRODS_JOBS", "2"))


def run_case(config, out, overrides, skip_done=True):
    """Runs one case into `out` (skipped when its summary says completed); returns the summary."""
    summary_path = os.path.join(out, "summary.json")
    if skip_done and os.path.exists(summary_path):
        with open(summary_path) as f:
            summary = json.load(f)
        if summary.get("status") == "completed":
            return summary
    args = [BIN, "run", os.path.join(ROOT, config), "--output", out]
    for key, value in overrides.items():
        args += ["--set", f"{key}={value}"]
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out + ".log", "w") as log_file:
        proc = subprocess.run(args, stdout=log_file, stderr=log_file)
    if proc.returncode not in (0, 3):
        raise RuntimeError(f"{' '.join(args)} exited with {proc.returncode}; see {out}.log")
    with open(summary_path) as f:
        return json.load(f)


def timed_run(binary, config_path, run_dir):
    """One run of `binary` on one thread under /usr/bin/time (the bench scripts): returns its CPU
    seconds (user + system), peak RSS [MB] and summary.json; exits naming the config on failure."""
    env = dict(os.environ, OMP_NUM_THREADS="1")
    timed = subprocess.run(["/usr/bin/time", "-f", "%U %S %M", binary, "run", str(config_path),
                            "--output", str(run_dir)], env=env, capture_output=True, text=True)
    if timed.returncode != 0:
        sys.exit(f"{config_path}: exit {timed.returncode}\n{timed.stderr[-2000:]}")
    user, system, rss_kb = timed.stderr.strip().splitlines()[-1].split()
    with open(os.path.join(run_dir, "summary.json")) as f:
        summary = json.load(f)
    return float(user) + float(system), int(rss_kb) / 1024.0, summary


def run_all(cases):
    """cases: [(config, out, overrides)]; runs them JOBS at a time; returns the summaries."""
    for _, out, _ in cases:
        os.makedirs(os.path.dirname(out), exist_ok=True)
    with concurrent.futures.ThreadPoolExecutor(max_workers=JOBS) as pool:
        return list(pool.map(lambda c: run_case(*c), cases))


def timeseries(out):
    """The run's timeseries.csv as a NumPy structured array."""
    return np.genfromtxt(os.path.join(out, "timeseries.csv"), delimiter=",", names=True)


def log(*args):
    print(*args, flush=True, file=sys.stderr)


def run_sweep(sweep_file, jobs=JOBS, extra=()):
    """Runs `stokesrods sweep` (finished cases are skipped) and returns its exit code."""
    args = [BIN, "sweep", os.path.join(ROOT, sweep_file), "--jobs", str(jobs), *extra]
    log(" ".join(args))
    return subprocess.run(args, cwd=ROOT).returncode


def analyze(sweep_dir, *extra):
    """`stokesrods analyze` on a sweep folder; returns (analysis rows, critical rows) as dicts."""
    subprocess.run([BIN, "analyze", sweep_dir, *extra], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    return read_csv(os.path.join(sweep_dir, "analysis.csv")), read_csv(os.path.join(sweep_dir, "critical.csv"))


def read_csv(path):
    """A CSV file as a list of dicts (strings)."""
    import csv
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def first_number(text):
    """The first number of a TOML value's text: "[0.04, 0.0, 0.0]" -> 0.04."""
    return float(text.strip("[] ").split(",")[0])


def case_table(sweep_dir, *analyze_args):
    """`stokesrods analyze` rows of a sweep joined with sweep.csv's wall time; ([] if never run)."""
    if not os.path.exists(os.path.join(sweep_dir, "sweep.json")):
        return [], []
    rows, lines = analyze(sweep_dir, *analyze_args)
    wall = {r["case"]: r["wall_seconds"] for r in read_csv(os.path.join(sweep_dir, "sweep.csv"))}
    for r in rows:
        r["wall_seconds"] = wall.get(r["case"], "")
    return rows, lines


def write_csv(path, header, rows):
    """rows: sequences in the order of header; writes path (a committed table) and logs it."""
    import csv
    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(header)
        w.writerows(rows)
    log("wrote", path, f"({len(rows)} rows)")


def switch_bracket(points):
    """points: [(value, yes)]. The rule of `stokesrods analyze`: (last "no" below the switch, first
    value from which every larger one is "yes"]; returns (below, above, monotone), None where open."""
    points = sorted(points)
    first_yes = len(points)
    while first_yes > 0 and points[first_yes - 1][1]:
        first_yes -= 1
    above = points[first_yes][0] if first_yes < len(points) else None
    below = points[first_yes - 1][0] if first_yes > 0 else None
    return below, above, not any(yes for _, yes in points[:first_yes])


def bracket_errorbar(ax, rows, column, below_key, above_key, **style):
    """Critical brackets (below, above] along x = row[column], drawn at their middles with the
    bracket as the error bar; at `above`, as an upper bound, where there is no `below`."""
    xs, ys, lo, hi = [], [], [], []
    for r in rows:
        if not r[above_key]:
            continue
        above = float(r[above_key])
        below = float(r[below_key]) if r[below_key] else 0.0
        xs.append(float(r[column]))
        ys.append(0.5 * (below + above) if r[below_key] else above)
        lo.append(ys[-1] - below)
        hi.append(above - ys[-1])
    ax.errorbar(xs, ys, yerr=[lo, hi], capsize=3, **style)


def crossing_marker(ax, x, y, crossed):
    """One case of a crossing diagram: ● crossed (Δb ≤ 0 at the end), △ not."""
    ax.plot(x, y, "o" if crossed else "^", ms=5, mfc="tab:blue" if crossed else "none",
            mec="tab:blue" if crossed else "tab:red")


def finish_crossing_axes(ax, xlabel, title_prefix="", legend_loc="best"):
    ax.set_xlabel(xlabel)
    ax.set_ylabel("ω̄")
    ax.set_title(f"{title_prefix}crossed at t̄ = 2 (●) or not (△)", fontsize=9)
    ax.legend(fontsize=7, loc=legend_loc)


def sweep_study_main(sweep_files, table, plot):
    """Command line of a sweep study.

    run    the sweeps (finished cases are skipped, interrupted ones resume), then table and plot
    table  `stokesrods analyze` on the run folders -> the tables in docs/validation/
    plot   the figure from the tables in docs/validation/ alone (no run folder needed)
    """
    import argparse
    p = argparse.ArgumentParser()
    p.add_argument("what", choices=["run", "table", "plot"])
    p.add_argument("--jobs", type=int, default=1)
    args = p.parse_args()
    os.makedirs(os.path.join(ROOT, "docs", "validation"), exist_ok=True)
    if args.what == "run":
        for sweep_file in sweep_files:
            run_sweep(sweep_file, args.jobs)
    if args.what in ("run", "table"):
        table()
    plot()
