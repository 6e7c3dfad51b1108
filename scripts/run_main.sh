#!/usr/bin/env bash
# The main job: builds stokesrods and runs the bundling of two flagella (paper Fig. 1), then draws
# front and side views of the bundle, the flow planes and a video (out/fig1/render/). Extra
# arguments go to `stokesrods run` (e.g. --set ...).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake --preset release
cmake --build --preset release --target stokesrods
./build/release/apps/stokesrods/stokesrods run examples/fig1_bundling.toml "$@"
./build/release/apps/stokesrods/stokesrods render out/fig1 --times 0 25 50 75
