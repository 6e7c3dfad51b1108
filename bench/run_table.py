#!/usr/bin/python3
"""The benchmark table of whole simulations: runs bench_cases once per case and thread count.

Each case runs in its own process (so its peak memory is its own), with OMP_NUM_THREADS set, a
wall-clock timeout and an address-space limit, so that a case too slow or too big becomes a row
saying so. Prints the machine, a markdown table and, when at least three of lattice10/20/50/100
ran, the scaling exponent of the time per step against the number of rods. See bench/README.md.

    /usr/bin/python3 bench/run_table.py --cases fig1_h1ms,lattice10 --threads 1,2 --steps 20
"""

import argparse
import json
import math
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time

ALL_CASES = ["fig1_h1ms", "fig1_h10ms", "fig1_explicit", "fig1_lsbt_N195", "ring10",
             "lattice2", "lattice4", "lattice10", "lattice20", "lattice50", "lattice100"]
# Beyond the hundred (from session 38): named with --cases or 'large', not in 'all' (a
# round of both on one and two threads takes ~3 minutes, most of it lattice400's rebuilds).
LARGE_CASES = ["lattice200", "lattice400"]
ROD_COUNT = {"fig1_h1ms": 2, "fig1_h10ms": 2, "fig1_explicit": 2, "fig1_lsbt_N195": 2,
             "ring10": 10, "lattice2": 2, "lattice4": 4, "lattice10": 10, "lattice20": 20,
             "lattice50": 50, "lattice100": 100, "lattice200": 200, "lattice400": 400}
# (warm-up, timed steps) per case when not given on the command line: fewer for the big ones.
# The warm-up passes the start from rest: the clamps start turning at full speed at t = 0, and
# for the first 20-60 steps (more with more rods) Newton needs 2 iterations (and GMRES up to 1.5x the products) where
# the rest of a run needs 1; a run has 1e4-1e5 steps, so the table times the steps after it.
# Timed steps 40/20/10/10 since 2026-11-25 (were 20/10/5/3: the one-thread exponent of three
# successive tables then spread 1.39-1.54); 40 for all four since 2026-11-28: the kept
# preconditioner is rebuilt at most every 40 steps (sim/hydro_coupling.cc), so a window of 40
# holds about one rebuild (lattice100: steps 41, 81, ...; ~400 ms on one thread), which the
# median leaves out and the mean, and so the seconds per simulated second, now carries.
# From 2026-12-08 (session 39) the coarse level's E is rebuilt at every k-th rebuild only (k = 2 at
# 200 helices, 4 at 400: sim/hydro_coupling.h CoarseRebuildPeriod), so the mean of those two
# cases needs k x 40 timed steps to hold one whole cycle: 80 and 160 (a round of `large` then
# takes about 5 minutes on 1 and 2 threads).
DEFAULT_STEPS = {"lattice10": (60, 40), "lattice20": (60, 40), "lattice50": (60, 40),
                 "lattice100": (60, 40), "lattice200": (60, 80), "lattice400": (60, 160)}
DEFAULT_WARMUP, DEFAULT_TIMED = 100, 50
SCALING_CASES = ["lattice10", "lattice20", "lattice50", "lattice100"]
# The growth at scale, when lattice200 or lattice400 ran: the fit from fifty on.
LARGE_SCALING_CASES = ["lattice50", "lattice100", "lattice200", "lattice400"]


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cases", default="all",
                   help="comma-separated case names, or 'all' (default): " + ",".join(ALL_CASES)
                   + "; 'large' or by name: " + ",".join(LARGE_CASES))
    p.add_argument("--threads", default="1,2", help="comma-separated OMP_NUM_THREADS values")
    p.add_argument("--steps", type=int, help="timed steps of every case (default: 50, fewer "
                   "for lattice10 and up)")
    p.add_argument("--warmup", type=int, help="untimed steps first (default: 100, fewer for "
                   "lattice10 and up: 60)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="configuration override passed to every case (repeatable)")
    p.add_argument("--binary", default="build/release/bench/bench_cases")
    p.add_argument("--timeout", type=float, default=600.0, help="wall seconds per case run")
    p.add_argument("--mem-limit-gb", type=float, default=8.0,
                   help="address-space limit of each case (RLIMIT_AS), capped at the memory "
                   "available minus 2 GB")
    p.add_argument("--repeat", type=int, default=1,
                   help="rounds of all the runs, one after the other (default 1): each row then "
                   "gives the median run and the range, the exponent the fit of the medians and "
                   "the range of the rounds' fits")
    p.add_argument("--json", metavar="OUT", help="write the raw results here")
    args = p.parse_args()
    if args.repeat < 1:
        p.error("--repeat takes an integer ≥ 1")
    args.cases, args.threads = parse_cases_and_threads(p, args.cases, args.threads)
    if not os.access(args.binary, os.X_OK):
        p.error(f"{args.binary} is not an executable: build it with "
                "cmake --build --preset release --target bench_cases")
    return args


def parse_cases_and_threads(p, cases, threads):
    """--cases (comma-separated, or 'all') and --threads (comma-separated integers ≥ 1) as
    lists; p.error on anything else."""
    names = [c for c in cases.split(",") if c]
    cases = []
    for c in names:
        cases += ALL_CASES if c == "all" else LARGE_CASES if c == "large" else [c]
    unknown = [c for c in cases if c not in ALL_CASES + LARGE_CASES]
    if unknown:
        p.error(f"unknown case(s) {', '.join(unknown)}; known: {', '.join(ALL_CASES + LARGE_CASES)}")
    try:
        threads = [int(t) for t in threads.split(",") if t]
    except ValueError:
        p.error("--threads takes integers, e.g. 1,2")
    if not threads or min(threads) < 1:
        p.error("--threads takes integers ≥ 1")
    return cases, threads


def read_first(path, key):
    try:
        with open(path) as f:
            for line in f:
                if line.startswith(key):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def mem_available_gb():
    kb = read_first("/proc/meminfo", "MemAvailable")
    return float(kb.split()[0]) / 2**20 if kb else None


def git_version():
    try:
        out = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True,
                             text=True, timeout=10, cwd=os.path.dirname(os.path.abspath(__file__)))
        return out.stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        return None


def machine():
    return {
        "nproc": len(os.sched_getaffinity(0)),
        "cpu": read_first("/proc/cpuinfo", "model name") or "unknown",
        "mem_total_gb": round(float(read_first("/proc/meminfo", "MemTotal").split()[0]) / 2**20, 1),
        "mem_available_gb": round(mem_available_gb() or 0.0, 1),
        "git": git_version(),
        "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
    }


def describe_machine(info):
    """The machine() line the scripts print first."""
    return (f"Machine: {info['nproc']} CPUs ({info['cpu']}), {info['mem_total_gb']} GB "
            f"({info['mem_available_gb']} GB available); {info['date']}; git {info['git']}")


def load_text(load):
    return " ".join(f"{l:.2f}" for l in load)


def address_space_gb(requested_gb):
    """The address-space limit of each run: as asked, at most the memory available minus 2 GB."""
    avail = mem_available_gb() or requested_gb + 2.0
    return max(0.1, min(requested_gb, avail - 2.0))


def run_case(args, case, threads, mem_limit_bytes):
    """One process: its JSON line plus what the parent saw (wall time, exit, peak memory)."""
    warmup, timed = DEFAULT_STEPS.get(case, (DEFAULT_WARMUP, DEFAULT_TIMED))
    warmup = args.warmup if args.warmup is not None else warmup
    timed = args.steps if args.steps is not None else timed
    cmd = [args.binary, case, "--steps", str(timed), "--warmup", str(warmup)]
    for s in args.set:
        cmd += ["--set", s]
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (mem_limit_bytes, mem_limit_bytes))

    row = {"case": case, "threads": threads, "command": " ".join(cmd)}
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        start = time.monotonic()
        proc = subprocess.Popen(cmd, stdout=out, stderr=err, env=env, preexec_fn=limit)
        status, usage, timed_out = None, None, False
        while status is None:
            pid, st, ru = os.wait4(proc.pid, os.WNOHANG)
            if pid == proc.pid:
                status, usage = st, ru
            elif time.monotonic() - start > args.timeout:
                proc.kill()  # this child only, by its id
                _, status, usage = os.wait4(proc.pid, 0)
                timed_out = True
            else:
                time.sleep(0.05)
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped by wait4, tell Popen
        row["wall_seconds"] = round(time.monotonic() - start, 2)
        row["child_peak_rss_mb"] = round(usage.ru_maxrss / 1024.0, 1)
        row["exit_code"] = proc.returncode
        out.seek(0)
        err.seek(0)
        stdout = out.read().decode(errors="replace")
        stderr = err.read().decode(errors="replace")
    lines = [l for l in stdout.splitlines() if l.strip().startswith("{")]
    if lines:
        try:
            result = json.loads(lines[-1])
            result["omp_max_threads"] = result.pop("threads", None)  # what the child saw
            row.update(result)
        except json.JSONDecodeError:
            pass
    model, progress = parse_progress(stderr)
    for key, value in model.items():
        row.setdefault(key, value)
    if timed_out and row.get("ok") is False and "message" in row:
        row["message"] += f" (then hung, killed after {args.timeout:g} s)"
    elif timed_out:
        row["ok"] = False
        row["message"] = f"timed out after {args.timeout:g} s" + progress
    elif "ok" not in row:
        row["ok"] = False
        code = proc.returncode
        why = f"killed by {signal.Signals(-code).name}" if code < 0 else f"exit code {code}"
        tail = stderr.strip().splitlines()[-1:] if stderr.strip() else []
        row["message"] = "; ".join([why + progress] + tail)
    row.setdefault("peak_rss_mb", row["child_peak_rss_mb"])
    return row


def parse_progress(stderr):
    """The model line and how far the steps got, from bench_cases' '# ...' lines on stderr."""
    model, last = {}, None
    for line in stderr.splitlines():
        words = line.split()
        if len(words) >= 2 and words[0] == "#" and words[1] == "model":
            for w in words[2:]:
                key, _, value = w.partition("=")
                try:
                    model[key] = float(value) if key == "h" else int(value)
                except ValueError:
                    pass
        elif len(words) >= 4 and words[0] == "#" and words[1] in ("warmup", "step"):
            last = words[1:]
    if not model:
        return model, " (before the model was built)"
    if last is None:
        return model, " (model built, during the first warm-up step)"
    phase, count, ms = last[0], last[1], " ".join(last[2:])
    done, of = count.split("/")
    return model, f" ({phase} {done} of {of} done, the last took {ms})"


def fmt_num(x, digits=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    decimals = max(0, digits - 1 - mag)
    return f"{x:.{decimals}f}"


def table(rows):
    base = {}
    for r in rows:
        if r["ok"] and r["threads"] == 1:
            base[r["case"]] = r["ms_per_step_median"]
    head = ["case", "rods", "h [ms]", "threads", "ms/step (median)", "CPU ms/step", "Newton it./step",
            "s per simulated s", "peak memory [MB]", "speedup over 1 thread", "note"]
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for r in rows:
        h = r.get("h")
        speedup = ""
        if r["ok"] and r["threads"] != 1 and r["case"] in base and r["ms_per_step_median"]:
            speedup = fmt_num(base[r["case"]] / r["ms_per_step_median"]) + "×"
        note = "" if r["ok"] else "**" + r.get("message", "failed").replace("|", "/") + "**"
        if r["ok"] and r.get("steps") is not None:
            note = f"{r['steps']} steps"
        if r["ok"] and r.get("runs", 1) > 1:
            lo, hi = r["ms_range"]
            note += f"; median of {r['runs']} runs ({fmt_num(lo)}–{fmt_num(hi)})"
        cells = [r["case"], str(r.get("rods", ROD_COUNT[r["case"]])),
                 fmt_num(h * 1e3) if h else "–", str(r["threads"]),
                 fmt_num(r.get("ms_per_step_median")) if r["ok"] else "–",
                 fmt_num(r.get("cpu_ms_per_step")) if r["ok"] else "–",
                 fmt_num(r.get("newton_per_step"), 2) if r["ok"] else "–",
                 fmt_num(r.get("wall_s_per_sim_s")) if r["ok"] else "–",
                 fmt_num(r.get("peak_rss_mb"), 3), speedup, note]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def median_rows(rounds):
    """Per case and thread count, the run of median time (its other fields with it) over the
    rounds, with the range and the number of runs; a case that failed in any round is the first
    such failure."""
    out = []
    for i, first in enumerate(rounds[0]):
        runs = [r[i] for r in rounds]
        failed = [r for r in runs if not r["ok"]]
        if failed:
            out.append(failed[0])
            continue
        runs.sort(key=lambda r: r["ms_per_step_median"])
        row = dict(runs[(len(runs) - 1) // 2])  # the lower median for an even count
        row["runs"] = len(runs)
        row["ms_range"] = (runs[0]["ms_per_step_median"], runs[-1]["ms_per_step_median"])
        out.append(row)
    return out


def fit_exponent(points):
    """Least-squares slope and intercept of log(ms) against log(rods)."""
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(t) for _, t in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    return slope, math.exp(my - slope * mx)


def scaling(rows, threads_list, rounds=None):
    out = []
    for t in threads_list:
        if rounds and len(rounds) > 1:  # each round's own fit, for the spread
            fits = []
            for rr in rounds:
                ran = {r["case"]: r for r in rr if r["threads"] == t and r["ok"]}
                pts = [(ROD_COUNT[c], ran[c]["ms_per_step_median"]) for c in SCALING_CASES
                       if c in ran]
                if len(pts) >= 3:
                    fits.append(fit_exponent(pts)[0])
            if fits:
                out.append(f"Scaling, {t} thread(s), each round's fit: "
                           + ", ".join(f"{f:.2f}" for f in fits))
        ran = {r["case"]: r for r in rows if r["threads"] == t and r["ok"]}
        pts = [(ROD_COUNT[c], ran[c]["ms_per_step_median"]) for c in SCALING_CASES if c in ran]
        if len(pts) >= 3:
            slope, pref = fit_exponent(pts)
            names = ", ".join(c for c in SCALING_CASES if c in ran)
            out.append(f"Scaling, {t} thread(s), over {names}: ms/step ≈ {pref:.3g} · rods^"
                       f"{slope:.2f}")
        else:
            lattice = [c for c in ALL_CASES if c.startswith("lattice") and c in ran]
            pts = [(ROD_COUNT[c], ran[c]["ms_per_step_median"]) for c in lattice]
            have = [c for c in SCALING_CASES if c in ran]
            msg = (f"Scaling, {t} thread(s): {len(have)} of {'/'.join(SCALING_CASES)} ran "
                   f"({', '.join(have) or 'none'}), no fit (needs 3)")
            if len(pts) >= 3:
                slope, pref = fit_exponent(pts)
                msg += (f"; over all lattices that ran ({', '.join(lattice)}, small counts, "
                        f"not the asymptotic exponent): ms/step ≈ {pref:.3g} · rods^{slope:.2f}")
            out.append(msg)
        if any(c in ran for c in LARGE_CASES):
            pts = [(ROD_COUNT[c], ran[c]["ms_per_step_median"]) for c in LARGE_SCALING_CASES
                   if c in ran]
            if len(pts) >= 2:
                slope, pref = fit_exponent(pts)
                names = ", ".join(c for c in LARGE_SCALING_CASES if c in ran)
                out.append(f"Scaling at scale, {t} thread(s), over {names}: ms/step ≈ {pref:.3g} · "
                           f"rods^{slope:.2f}")
    return out


def main():
    args = parse_args()
    info = machine()
    mem_limit_gb = address_space_gb(args.mem_limit_gb)
    load_start = os.getloadavg()
    print(describe_machine(info))
    print(f"Load average at start: {load_text(load_start)}")
    print(f"Per case: timeout {args.timeout:g} s, address space {mem_limit_gb:.1f} GB; "
          f"binary {args.binary}" + (f"; --set {' '.join(args.set)}" if args.set else ""))
    sys.stdout.flush()

    rounds = []
    for k in range(args.repeat):
        rows = []
        for case in args.cases:
            for t in args.threads:
                row = run_case(args, case, t, int(mem_limit_gb * 2**30))
                row["round"] = k + 1
                rows.append(row)
                status = (f"{fmt_num(row.get('ms_per_step_median'))} ms/step" if row["ok"]
                          else row.get("message", "failed"))
                tag = f" round {k + 1}/{args.repeat}" if args.repeat > 1 else ""
                print(f"  {case} threads={t}{tag}: {status} ({row['wall_seconds']} s)",
                      file=sys.stderr, flush=True)
        rounds.append(rows)
    rows = median_rows(rounds) if args.repeat > 1 else rounds[0]
    load_end = os.getloadavg()

    print(f"Load average at end: {load_text(load_end)}")
    cores = sorted({r["blas_core"] for r in rows if r.get("blas_core")})
    if cores:
        print(f"OpenBLAS kernels: {', '.join(cores)}")
    print()
    print(table(rows))
    print()
    for line in scaling(rows, args.threads, rounds):
        print(line)

    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": info, "load_start": load_start, "load_end": load_end,
                       "timeout": args.timeout, "mem_limit_gb": mem_limit_gb, "set": args.set,
                       "repeat": args.repeat,
                       "results": [r for rr in rounds for r in rr]}, f, indent=2)
            f.write("\n")
    return 0  # failed and timed-out cases are rows of the table, not an error of the script


if __name__ == "__main__":
    sys.exit(main())
