#!/usr/bin/env bash
# Builds detsim and runs the main job: the `detsim` command. With no arguments it runs `detsim demo`:
# a 4-player arena match of bots, each with its own rollback session, over a simulated network
# (100 ms round trip, loss, duplication, reordering) in virtual time; player 0's replay recorded
# and verified; and a summary (rollbacks, bandwidth, final hash, whether the peers agreed, verify
# result, time taken). Any arguments are passed to `detsim` instead (try `scripts/run.sh --help`,
# or `scripts/run.sh accuracy` for the accuracy table of the fixed-point layer).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DDETSIM_BUILD_TESTS=OFF >/dev/null
cmake --build build/release --target detsim -j "$(nproc)"
if [ $# -eq 0 ]; then set -- demo; fi
exec build/release/tools/detsim "$@"
