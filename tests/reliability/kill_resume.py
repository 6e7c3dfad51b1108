#!/usr/bin/env python3
"""Interrupt a small run at random moments (SIGINT, SIGTERM, SIGKILL), resume it with --resume
until it completes, and compare every output byte for byte with the uninterrupted run.

usage: kill_resume.py STOKESRODS_BINARY WORK_DIR [--trials N] [--seed S] [--config C --set K=V ...]
Prints one line per interruption and a summary; exit 1 on any difference.
"""
import argparse
import filecmp
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time

# Two helices in RSS fluid, BDF2 with the Krylov drag (the reuse a resume has to reproduce), a
# contact-enabled model, frames and a flow plane: about 150 steps.
CASE = """
[run]
duration = 1.5
time_step = 0.01
integrator = "bdf2"
output_interval = 0.03
checkpoint_interval = 0.1
[fluid]
model = "rss"
[flow_field]
times = [0.5, 1.2]
resolution = [6, 8]
[solver]
jacobian_max_age = 5
[[rods]]
nodes = 21
axis_length = 0.1
helix_radius = 0.008
omega_bar = 900
[[rods]]
nodes = 21
axis_length = 0.1
helix_radius = 0.008
omega_bar = 900
base = [0.025, 0.0, 0.0]
"""

SIGNALS = {"INT": signal.SIGINT, "TERM": signal.SIGTERM, "KILL": signal.SIGKILL}


def run(binary, config, out, resume, extra, threads=1):
    args = [binary, "run", config, "--output", out] + (["--resume"] if resume else []) + extra
    return subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            env=dict(os.environ, OMP_NUM_THREADS=str(threads)))


def wait_for_handlers(p):
    """Until the run catches SIGINT and SIGTERM (SigCgt in /proc/PID/status) or has exited: a
    signal before main() installs its handlers ends the process by its default action, which
    says nothing about the resume (and on a loaded machine the start-up takes long enough for
    an early random moment to land there). Where /proc is missing, returns at once."""
    wanted = (1 << (signal.SIGINT - 1)) | (1 << (signal.SIGTERM - 1))
    while p.poll() is None:
        try:
            with open(f"/proc/{p.pid}/status") as f:
                caught = next(int(line.split()[1], 16) for line in f if line.startswith("SigCgt:"))
        except (OSError, StopIteration, ValueError):
            return
        if caught & wanted == wanted:
            return
        time.sleep(0.002)


def outputs(directory):
    """Every file of a run directory, relative paths."""
    files = []
    for root, _, names in os.walk(directory):
        files += [os.path.relpath(os.path.join(root, n), directory) for n in names]
    return sorted(f for f in files if not f.endswith(".tmp"))


def differences(reference, candidate):
    problems = []
    ref_files, cand_files = outputs(reference), outputs(candidate)
    if ref_files != cand_files:
        problems.append(f"file lists differ: {sorted(set(ref_files) ^ set(cand_files))}")
    for name in ref_files:
        if name not in cand_files:
            continue
        a, b = os.path.join(reference, name), os.path.join(candidate, name)
        if name == "summary.json":  # the process's own counts (wall time, 𝕄's reuse) may differ
            ja, jb = json.load(open(a)), json.load(open(b))
            for j in (ja, jb):
                j.pop("wall_seconds")
                j.pop("mobility_reuse", None)
                j.pop("krylov_products", None)
                j.pop("preconditioner_builds", None)
                j["config"]["run"].pop("output")
                j["config"]["run"].pop("checkpoint_wall_interval", None)
            if ja != jb:
                keys = sorted(k for k in set(ja) | set(jb) if ja.get(k) != jb.get(k))
                detail = "; ".join(f"{k}: {ja.get(k)} vs {jb.get(k)}" for k in keys)
                problems.append("summary.json differs beyond wall_seconds, mobility_reuse, "
                                f"krylov_products and preconditioner_builds ({detail})")
        elif not filecmp.cmp(a, b, shallow=False):
            problems.append(f"{name} differs")
    return problems


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("binary")
    parser.add_argument("work")
    parser.add_argument("--trials", type=int, default=4)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--config", help="another case instead of the built-in one")
    parser.add_argument("--set", action="append", default=[], help="KEY=VALUE for every run")
    args = parser.parse_args()
    rng = random.Random(args.seed)
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    config = os.path.abspath(args.config) if args.config else os.path.join(args.work, "case.toml")
    if not args.config:
        with open(config, "w") as f:
            f.write(CASE)
    common = [a for kv in args.set for a in ("--set", kv)]

    reference = os.path.join(args.work, "reference")
    start = time.monotonic()
    p = run(args.binary, config, reference, False, common)
    _, err = p.communicate()
    whole = time.monotonic() - start
    if p.returncode != 0:
        sys.exit(f"the uninterrupted run failed ({p.returncode}): {err.decode()}")
    print(f"uninterrupted run: {whole:.2f} s")

    failures, kills = 0, 0
    for trial in range(args.trials):
        out = os.path.join(args.work, f"trial{trial}")
        # Trial 1 checkpoints by wall time: restart points every 60 steps, written when due.
        # Trial 2 runs on two threads (the reference on one): the result must not depend on it.
        extra = common + (["--set", "run.checkpoint_wall_interval=0.3"] if trial == 1 else [])
        threads = 2 if trial == 2 else 1
        resume, attempts = False, 0
        while True:
            attempts += 1
            if attempts > 6:  # enough interruptions for one trial: let it complete
                p = run(args.binary, config, out, resume, extra, threads)
                _, err = p.communicate()
                if p.returncode != 0:
                    sys.exit(f"trial {trial}: run failed ({p.returncode}): {err.decode()}")
                break
            # The signals in turn (every kind in every few trials), at random moments.
            name = list(SIGNALS)[(trial + attempts) % len(SIGNALS)]
            delay = rng.uniform(0.05, 0.9) * whole
            p = run(args.binary, config, out, resume, extra, threads)
            wait_for_handlers(p)
            try:
                _, err = p.communicate(timeout=delay)
            except subprocess.TimeoutExpired:
                p.send_signal(SIGNALS[name])
                _, err = p.communicate()
                kills += 1
                expected = -signal.SIGKILL if name == "KILL" else 130
                ok = p.returncode in (expected, 0)  # 0: it finished before the signal landed
                print(f"trial {trial}: SIG{name} after {delay:.2f} s -> exit {p.returncode}"
                      f"{'' if ok else '  UNEXPECTED'}")
                if not ok:
                    failures += 1
                    print(err.decode())
                if p.returncode == 0:
                    break
                resume = resume or os.path.exists(os.path.join(out, "checkpoint.bin"))
                continue
            if p.returncode != 0:
                sys.exit(f"trial {trial}: run failed ({p.returncode}): {err.decode()}")
            break
        problems = differences(reference, out)
        print(f"trial {trial}: {attempts} runs, " + ("identical" if not problems else "; ".join(problems)))
        failures += len(problems)
    # The latest moment: killed after the last step's checkpoint, before summary.json. A copy of
    # the finished run without its summary resumes with no step to take.
    ended = os.path.join(args.work, "ended")
    shutil.copytree(reference, ended)
    os.remove(os.path.join(ended, "summary.json"))
    p = run(args.binary, config, ended, True, common)
    _, err = p.communicate()
    if p.returncode != 0:
        sys.exit(f"the resume after the last checkpoint failed ({p.returncode}): {err.decode()}")
    problems = differences(reference, ended)
    print("after the last checkpoint: " + ("identical" if not problems else "; ".join(problems)))
    failures += len(problems)
    print(f"{kills} interruptions over {args.trials} trials, {failures} failures")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
