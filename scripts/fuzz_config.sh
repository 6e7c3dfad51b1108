#!/usr/bin/env bash
# Builds the configuration fuzzer (clang 14, libFuzzer, AddressSanitizer + UBSan; the fuzz preset)
# and runs it for a bounded time, from a seed corpus of the examples and the stored regression
# inputs (tests/data/fuzz/). Exit 1 on a crash, a sanitizer report, an exception other than
# ConfigError or a slow input; the input is left in build/fuzz/artifacts/: add it to
# tests/data/fuzz/ (the io_test FuzzRegression test replays them) and fix the bug.
#   usage: scripts/fuzz_config.sh [SECONDS=60]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
cmake --preset fuzz > /dev/null
cmake --build --preset fuzz
corpus=build/fuzz/corpus
mkdir -p "$corpus" build/fuzz/artifacts
cp examples/*.toml tests/data/fuzz/* "$corpus"/
OMP_NUM_THREADS=1 build/fuzz/fuzz/config_fuzzer "$corpus" -dict=fuzz/config.dict \
  -max_total_time="$seconds" -max_len=4096 -timeout=20 -rss_limit_mb=2048 \
  -artifact_prefix=build/fuzz/artifacts/ -print_final_stats=1 2>&1 | tail -25
exit "${PIPESTATUS[0]}"
