#!/usr/bin/env bash
# Builds the libFuzzer target for the replay reader (clang, ASan + UBSan) and runs it.
# Usage: scripts/fuzz.sh [SECONDS]   (default 600)
# The corpus lives in build-fuzz/corpus (seeded with short replays); findings go to
# build-fuzz/findings. Exit status: 0 no finding, non-zero a crash, leak, timeout or OOM was found
# (libFuzzer prints the reproducer's path).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
build=build-fuzz
flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all"
cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" -DCMAKE_CXX_FLAGS="$flags" \
  -DDETSIM_BUILD_FUZZ=ON -DDETSIM_BUILD_TESTS=OFF -DDETSIM_BUILD_TOOLS=OFF >/dev/null
cmake --build "$build" --target replay_reader_fuzz make_seeds -j "$(nproc)"
mkdir -p "$build/corpus" "$build/findings"
"$build/fuzz/make_seeds" "$build/corpus"
cd "$build/findings"
exec ../fuzz/replay_reader_fuzz ../corpus -max_total_time="$seconds" -max_len=65536 \
  -rss_limit_mb=2048 -timeout=20 -print_final_stats=1
