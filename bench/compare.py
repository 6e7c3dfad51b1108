#!/usr/bin/python3
"""Two builds (or two settings) of bench_cases alternated in one sitting: medians and their ratio.

On a shared, noisy machine the same binary can run 30 % slower from one minute to the next, so a
change is measured against its baseline run for run: each round runs every case with the
baseline and the candidate one right after the other, in alternating order (baseline first in
odd rounds, candidate first in even ones), and the table gives per case the median over the
rounds of each, their ranges, the ratio of the medians (candidate / baseline), the range and
the median of the rounds' own ratios (each round's pair ran seconds apart) and the ratio of the
two sides' minima (the host's noise only adds time, so each side's fastest run is the one it
disturbed least), with the work counted per step (Newton iterations, GMRES products), which does
not depend on the host. Baseline and candidate differ by their binary (a build of
the commit before the change, e.g. in a git worktree), by settings (--set-candidate), or both.
See bench/README.md.

    git worktree add /tmp/base HEAD~1 && (cd /tmp/base && cmake --preset release &&
        cmake --build --preset release --target bench_cases)
    /usr/bin/python3 bench/compare.py --baseline /tmp/base/build/release/bench/bench_cases \\
        --cases fig1_h1ms,ring10 --rounds 5
    /usr/bin/python3 bench/compare.py --cases fig1_h1ms \\
        --set-candidate solver.jacobian_max_age=3
"""

import argparse
import copy
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run_table  # noqa: E402  (the runner and formatting of the table: one process per run)


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--baseline", default="build/release/bench/bench_cases",
                   help="the baseline's bench_cases (default: this tree's)")
    p.add_argument("--candidate", default="build/release/bench/bench_cases",
                   help="the candidate's bench_cases (default: this tree's)")
    p.add_argument("--cases", default="fig1_h1ms,ring10,lattice10",
                   help="comma-separated case names (default: fig1_h1ms,ring10,lattice10), or "
                   "'all': " + ",".join(run_table.ALL_CASES))
    p.add_argument("--threads", default="1", help="comma-separated OMP_NUM_THREADS values")
    p.add_argument("--rounds", type=int, default=3, help="rounds of alternated runs (default 3)")
    p.add_argument("--steps", type=int, help="timed steps of every case (run_table's default)")
    p.add_argument("--warmup", type=int, help="untimed steps first (run_table's default)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="configuration override for both (repeatable)")
    p.add_argument("--set-candidate", action="append", default=[], metavar="KEY=VALUE",
                   help="configuration override for the candidate only (repeatable)")
    p.add_argument("--timeout", type=float, default=600.0, help="wall seconds per run")
    p.add_argument("--mem-limit-gb", type=float, default=8.0,
                   help="address-space limit of each run (RLIMIT_AS), capped at the memory "
                   "available minus 2 GB")
    p.add_argument("--json", metavar="OUT", help="write the raw results here")
    args = p.parse_args()
    if args.rounds < 1:
        p.error("--rounds takes an integer ≥ 1")
    args.cases, args.threads = run_table.parse_cases_and_threads(p, args.cases, args.threads)
    for name in ("baseline", "candidate"):
        if not os.access(getattr(args, name), os.X_OK):
            p.error(f"--{name} {getattr(args, name)} is not an executable")
    if args.baseline == args.candidate and not args.set_candidate:
        p.error("baseline and candidate are the same binary with the same settings: give "
                "--baseline, --candidate or --set-candidate")
    return args


def side(args, binary, extra):
    """The arguments run_table.run_case reads, for one side."""
    s = copy.copy(args)
    s.binary = binary
    s.set = list(args.set) + list(extra)
    return s


def summary(runs):
    ms = [r["ms_per_step_median"] for r in runs]
    return {"median": statistics.median(ms), "low": min(ms), "high": max(ms),
            "newton": statistics.median(r.get("newton_per_step", 0.0) for r in runs),
            "products": statistics.median(r.get("krylov_per_step", 0.0) for r in runs)}


def main():
    args = parse_args()
    mem_limit = int(run_table.address_space_gb(args.mem_limit_gb) * 2**30)
    sides = {"baseline": side(args, args.baseline, []),
             "candidate": side(args, args.candidate, args.set_candidate)}
    print(run_table.describe_machine(run_table.machine()))
    print(f"Load average at start: {run_table.load_text(os.getloadavg())}")
    print(f"baseline:  {args.baseline} {' '.join(args.set)}")
    print(f"candidate: {args.candidate} {' '.join(args.set + args.set_candidate)}")
    runs = {(c, t, s): [] for c in args.cases for t in args.threads for s in sides}
    for k in range(args.rounds):
        order = ["baseline", "candidate"] if k % 2 == 0 else ["candidate", "baseline"]
        for case in args.cases:
            for threads in args.threads:
                for name in order:
                    row = run_table.run_case(sides[name], case, threads, mem_limit)
                    row.update(round=k + 1, side=name)
                    runs[(case, threads, name)].append(row)
                    ms = run_table.fmt_num(row.get("ms_per_step_median")) if row["ok"] else \
                        "failed: " + row.get("message", "")
                    print(f"  round {k + 1}/{args.rounds} {case} threads={threads} {name}: {ms}",
                          file=sys.stderr, flush=True)
    print(f"Load average at end: {run_table.load_text(os.getloadavg())}")
    head = ["case", "threads", "baseline ms/step (median, range)",
            "candidate ms/step (median, range)", "candidate / baseline", "rounds' ratios",
            "median of the rounds' ratios", "ratio of the minima", "Newton it./step",
            "GMRES products/step"]
    print("| " + " | ".join(head) + " |")
    print("|" + " --- |" * len(head))
    fmt = run_table.fmt_num
    for case in args.cases:
        for threads in args.threads:
            a, b = runs[(case, threads, "baseline")], runs[(case, threads, "candidate")]
            failed = [r for r in a + b if not r["ok"]]
            if failed:
                print(f"| {case} | {threads} | **{failed[0].get('side')}: "
                      f"{failed[0].get('message', 'failed')}** |" + " |" * (len(head) - 3))
                continue
            sa, sb = summary(a), summary(b)
            ratios = sorted(y["ms_per_step_median"] / x["ms_per_step_median"]
                            for x, y in zip(a, b))
            cells = [case, str(threads),
                     f"{fmt(sa['median'])} ({fmt(sa['low'])}–{fmt(sa['high'])})",
                     f"{fmt(sb['median'])} ({fmt(sb['low'])}–{fmt(sb['high'])})",
                     fmt(sb["median"] / sa["median"]),
                     f"{fmt(ratios[0])}–{fmt(ratios[-1])}",
                     fmt(statistics.median(ratios)), fmt(sb["low"] / sa["low"]),
                     f"{fmt(sa['newton'], 2)} → {fmt(sb['newton'], 2)}",
                     f"{fmt(sa['products'], 2)} → {fmt(sb['products'], 2)}"]
            print("| " + " | ".join(cells) + " |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": run_table.machine(), "baseline": args.baseline,
                       "candidate": args.candidate, "set": args.set,
                       "set_candidate": args.set_candidate, "rounds": args.rounds,
                       "results": [r for rs in runs.values() for r in rs]}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
