#!/usr/bin/env bash
# Installs the Debian packages stokesrods needs; a no-op when they are all present.
set -euo pipefail
packages=(g++ cmake make libeigen3-dev libtomlplusplus-dev libcli11-dev libfmt-dev nlohmann-json3-dev
          libopenblas-dev liblapack-dev libgtest-dev libbenchmark-dev python3 python3-numpy
          python3-matplotlib python3-dev pybind11-dev python3-pybind11 python3-pytest ffmpeg
          clang-14 libclang-rt-14-dev libopenmpi-dev openmpi-bin)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
