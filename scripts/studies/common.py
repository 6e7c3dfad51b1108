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
