#!/usr/bin/env bash
# Builds detsim and runs the main job: the `detsim` command. With no arguments it prints the
# accuracy table of the fixed-point layer (every function measured against MPFR); any arguments are
# passed to `detsim` instead (try `scripts/run.sh --help`).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DDETSIM_BUILD_TESTS=OFF >/dev/null
cmake --build build/release --target detsim -j "$(nproc)"
if [ $# -eq 0 ]; then set -- accuracy; fi
exec build/release/tools/detsim "$@"
