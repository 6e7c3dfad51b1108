#!/usr/bin/python3
"""BDF2 against implicit Euler on the swimming one-flagellum cell (issue 11): accuracy and cost.

  swimming_cell_bdf2.py run    # examples/swimming_cell_one_flagellum.toml to t = 8 s, one case at
                               # a time, into out/swimming_bdf2/{euler,bdf2}_h{ms}
  swimming_cell_bdf2.py table  # -> docs/validation/swimming_cell_bdf2.csv and a printed table

Reference: Richardson's extrapolation of BDF2 at 5 and 10 ms, (4 x(5) − x(10))/3. Measured at
t = 8 s: the body's displacement along z, its Ω_z, and the flagellum's free end (distance to the
reference's, over the helix radius R = 1 cm). Cost: the CPU time of each run (user + system of
the child process, one thread: on a shared machine less noisy than wall time), steps, Newton
iterations and the steps halved (solver.max_step_halvings = 3: a step whose Newton fails is
retried as two of h/2).
"""
import json
import os
import resource
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

OUT = os.path.join(common.ROOT, "out", "swimming_bdf2")
DOCS = os.path.join(common.ROOT, "docs", "validation")
CONFIG = os.path.join(common.ROOT, "examples", "swimming_cell_one_flagellum.toml")
DURATION = 8.0
R = 0.01
CASES = [("bdf2", 0.005), ("bdf2", 0.01), ("bdf2", 0.02), ("bdf2", 0.04), ("bdf2", 0.05),
         ("bdf2", 0.1), ("euler", 0.02), ("euler", 0.01)]


def name(integrator, h):
    return f"{integrator}_h{round(h * 1000)}"


def run():
    os.makedirs(OUT, exist_ok=True)
    for integrator, h in CASES:
        out = os.path.join(OUT, name(integrator, h))
        if os.path.exists(os.path.join(out, "cpu.json")):
            continue
        args = [common.BIN, "run", CONFIG, "--output", out, "--set", f"run.integrator={integrator}",
                "--set", f"run.time_step={h}", "--set", f"run.duration={DURATION}",
                "--set", "run.frames=false", "--set", f"run.checkpoint_interval={DURATION}",
                "--set", "solver.max_step_halvings=3"]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        with open(out + ".log", "w") as log_file:
            proc = subprocess.run(args, stdout=log_file, stderr=log_file,
                                  env=dict(os.environ, OMP_NUM_THREADS="1"))
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(args)} exited with {proc.returncode}; see {out}.log")
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        with open(os.path.join(out, "cpu.json"), "w") as f:
            json.dump({"cpu_seconds": cpu}, f)
        common.log(f"{name(integrator, h)}: {cpu:.1f} s CPU")


def final(out):
    ts = common.timeseries(out)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "cpu.json")) as f:
        cpu = json.load(f)["cpu_seconds"]
    last = ts[-1]
    assert abs(last["time"] - DURATION) < 1e-9, out
    return {"dz": last["body1_z"] - ts[0]["body1_z"], "omega": last["body1_omega_z"],
            "tip": np.array([last["rod1_end_x"], last["rod1_end_y"], last["rod1_end_z"]]),
            "cpu": cpu, "steps": summary["steps"], "newton": summary["newton_iterations"],
            "halved": summary["step_reductions"]}


def table():
    runs = {(i, h): final(os.path.join(OUT, name(i, h))) for i, h in CASES}
    fine, coarse = runs[("bdf2", 0.005)], runs[("bdf2", 0.01)]
    ref = {k: (4 * fine[k] - coarse[k]) / 3 for k in ("dz", "omega", "tip")}
    rows = []
    for (integrator, h), r in runs.items():
        rows.append([integrator, h, f"{abs(r['dz'] / ref['dz'] - 1):.3e}",
                     f"{abs(r['omega'] / ref['omega'] - 1):.3e}",
                     f"{np.linalg.norm(r['tip'] - ref['tip']) / R:.3e}", r["steps"],
                     f"{r['newton'] / r['steps']:.2f}", r["halved"], f"{r['cpu']:.1f}"])
    header = ["integrator", "h", "error_dz", "error_omega_z", "error_tip_over_R", "steps",
              "newton_per_step", "steps_halved", "cpu_seconds"]
    common.write_csv(os.path.join(DOCS, "swimming_cell_bdf2.csv"), header, rows)
    print(" | ".join(header))
    for row in rows:
        print(" | ".join(str(x) for x in row))
    print(f"reference: dz = {ref['dz']:.6e} m, Omega_z = {ref['omega']:.6e} rad/s")


if __name__ == "__main__":
    {"run": run, "table": table}[sys.argv[1] if len(sys.argv) > 1 else "table"]()
