#!/usr/bin/python3
"""Paper appendix B (Fig. B.10a) and C (Fig. C.11b): l̄ against ω̄ for N ∈ {43, 65, 81}, and the
compute time per simulated second against h for RSS (N = 65) and LSBT (N = 195).

  b10_convergence.py run      the sweep examples/studies/b10_convergence.toml (resumes), then table, plot
  b10_convergence.py table    stokesrods analyze out/studies/b10 -> docs/validation/b10_{cases,critical}.csv
  b10_convergence.py timing   C.11(b): each model at h ∈ {1, 3, 10, 30} ms, ω̄ = 533, 2 s simulated,
                              implicit Euler (the paper's integrator), one thread, one case at a time;
                              CPU seconds of the child (getrusage) -> docs/validation/c11_timing.csv
  b10_convergence.py solvers  C.11(b) at h = 1 ms, the capacitance by GMRES (ours) and by a dense LU every
                              step (the paper's way), medians of 3 runs -> docs/validation/c11_solvers.csv
  b10_convergence.py plot     docs/validation/b10_c11.png from those tables alone

Buckled: rod 1's tip more than 2R off the clamp's vertical in the last 20 % of t̄ ∈ [0, 1]
(io/analysis.h); ω̄_b is the bracket (last unbuckled, first speed from which every faster one buckled].
"""
import json
import os
import resource
import subprocess
import sys

from common import BIN, ROOT, case_table, log, read_csv, sweep_study_main, write_csv

SWEEP = "examples/studies/b10_convergence.toml"
OUT = os.path.join(ROOT, "out", "studies", "b10")
DOCS = os.path.join(ROOT, "docs", "validation")
CASES = os.path.join(DOCS, "b10_cases.csv")
CRITICAL = os.path.join(DOCS, "b10_critical.csv")
TIMING = os.path.join(DOCS, "c11_timing.csv")
SOLVERS = os.path.join(DOCS, "c11_solvers.csv")
TIMING_STEPS = (3e-2, 1e-2, 3e-3, 1e-3)  # cheapest first
MODELS = (("rss", 65), ("lsbt", 195))


def table():
    rows, lines = case_table(OUT, "--line", "rods.omega_bar", "--criterion", "buckled")
    out = sorted([int(r["rods.nodes"].strip("'\"")), float(r["omega_bar"]), r["buckled"], r["final_length_bar"],
                  r["max_tip_axis_distance_over_R"], r["wall_seconds"]] for r in rows if r["status"] == "completed")
    write_csv(CASES, ["nodes", "omega_bar", "buckled", "l_bar_at_t1", "max_tip_axis_distance_over_R", "wall_seconds"],
              [[n, f"{w:g}", *rest] for n, w, *rest in out])
    write_csv(CRITICAL, ["line", "omega_b_below", "omega_b_above", "omega_b_estimate", "monotone", "points"],
              [[l["line"], l["below"], l["above"], l["estimate"], l["monotone"], l["points"]] for l in lines])


def run_cpu_seconds(out, model, nodes, h, *sets):
    """CPU seconds (children's rusage) of one run of the C.11(b) helix: ω̄ = 533, 2 s simulated,
    implicit Euler, one thread; `sets` are further --set overrides."""
    args = [BIN, "run", os.path.join(ROOT, "examples", "helix.toml"), "--output", out,
            "--set", f"fluid.model={model}", "--set", f"rods.nodes={nodes}", "--set", "rods.omega_bar=533",
            "--set", "run.duration=2.0", "--set", f"run.time_step={h}", "--set", "run.integrator=euler",
            "--set", "run.output_interval=0.5", "--set", "run.frames=false"]
    for s in sets:
        args += ["--set", s]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   env=dict(os.environ, OMP_NUM_THREADS="1"))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def timing():
    """CPU seconds per simulated second of each model and step (children's rusage, one at a time)."""
    rows = []
    for model, nodes in MODELS:
        for h in TIMING_STEPS:
            cpu = run_cpu_seconds(os.path.join(OUT, "timing", f"{model}_N{nodes}_h{h:g}"), model, nodes, h)
            rows.append([model, nodes, f"{h:g}", f"{cpu:.3f}", f"{cpu / 2.0:.4g}"])
            # after every case: an interrupted timing keeps what it measured
            write_csv(TIMING, ["model", "nodes", "time_step", "cpu_seconds", "cpu_seconds_per_simulated_second"], rows)


def solvers(repeats=3):
    """C.11(b) at h = 1 ms with the capacitance solved as we do by default (GMRES, kept preconditioner)
    and as the paper does (a dense LU every step, 𝕄 assembled every step): medians of `repeats` runs."""
    rows = []
    for model, nodes in MODELS:
        for solver, reuse in (("krylov", "1e-4"), ("krylov", "0"), ("direct", "0")):
            if model == "lsbt" and (solver, reuse) == ("krylov", "0"):
                continue  # the LSBT mobility is assembled every step anyway
            out = os.path.join(OUT, "solvers", f"{model}_{solver}_reuse{reuse}")
            cpu = sorted(run_cpu_seconds(out, model, nodes, 1e-3, f"fluid.solver={solver}",
                                         f"fluid.mobility_reuse_tolerance={reuse}") for _ in range(repeats))
            summary = json.load(open(os.path.join(out, "summary.json")))
            median = cpu[len(cpu) // 2]
            rows.append([model, nodes, solver, reuse, f"{median:.3f}", " ".join(f"{c:.2f}" for c in cpu),
                         f"{1e3 * median / summary['steps']:.3f}", f"{summary['newton_iterations'] / summary['steps']:.3f}"])
            log(f"{model} {solver} reuse {reuse}: {median:.2f} CPU s")
            write_csv(SOLVERS, ["model", "nodes", "solver", "mobility_reuse_tolerance", "cpu_seconds_median",
                                "cpu_seconds_runs", "cpu_ms_per_step", "newton_per_step"], rows)


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    cases = read_csv(CASES) if os.path.exists(CASES) else []
    for (nodes, marker) in (("43", "^"), ("65", "o"), ("81", "v")):
        pts = sorted((float(r["omega_bar"]), float(r["l_bar_at_t1"])) for r in cases if r["nodes"] == nodes)
        if pts:
            axes[0].plot(*zip(*pts), marker + "-", ms=4, mfc="none", label=f"RSS, N = {nodes}")
    axes[0].axvline(675, color="gray", lw=0.8, ls=":", label="paper ω̄_b = 675")
    axes[0].set_xlabel("ω̄")
    axes[0].set_ylabel("l̄ at t̄ = 1")
    axes[0].set_title("B.10(a): BDF2, h = 20 ms, ε = 1.02 r0", fontsize=9)
    axes[0].legend(fontsize=7)
    timing_rows = read_csv(TIMING) if os.path.exists(TIMING) else []
    for (model, nodes), marker in zip(MODELS, ("o-", "s--")):
        pts = sorted((float(r["time_step"]), float(r["cpu_seconds_per_simulated_second"]))
                     for r in timing_rows if r["model"] == model)
        if pts:
            axes[1].loglog(*zip(*pts), marker, label=f"{model.upper()}, N = {nodes}")
    axes[1].set_xlabel("h [s]")
    axes[1].set_ylabel("CPU s per simulated s")
    axes[1].set_title("C.11(b): implicit Euler, ω̄ = 533, one thread", fontsize=9)
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "b10_c11.png"), dpi=110)


def main():
    if sys.argv[1:2] == ["timing"]:
        timing()
        plot()
        return
    if sys.argv[1:2] == ["solvers"]:
        solvers()
        return
    sweep_study_main([SWEEP], table, plot)


if __name__ == "__main__":
    main()
