#!/usr/bin/env bash
# Builds the asan preset (gcc, AddressSanitizer + UndefinedBehaviorSanitizer, -O1, asserts on; no
# benchmarks, no Python module) and runs the test suite under it: any sanitizer report fails its
# test (UBSan halts on the first, LeakSanitizer at exit). UBSan's null and alignment checks are
# left out: they took 40 % of the build's compile time; ASan reports any null dereference (its
# SEGV handler, with the stack), and Eigen's own assertion checks its objects' alignment
# (docs/reliability.md). Every test runs except `kill_resume`
# (label reliability): it times an uninterrupted run and interrupts copies at random moments,
# which under ASan takes over 10 minutes; the checkpoint and resume code it drives runs under the
# sanitizers in Cli.Resume* and Integrators/Restart.* (docs/reliability.md).
#   usage: scripts/asan_tests.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset asan > /dev/null
cmake --build --preset asan
ctest --preset asan -j2 -LE reliability
