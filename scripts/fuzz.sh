#!/usr/bin/env bash
# Builds a libFuzzer target (clang, ASan + UBSan) and runs it.
# Usage: scripts/fuzz.sh [SECONDS] [TARGET]   (default 600 s, target replay)
#   replay  fuzz/replay_reader_fuzz.cpp, the replay reader: corpus build-fuzz/corpus (seeded with
#           short replays), findings build-fuzz/findings
#   packet  fuzz/net_packet_fuzz.cpp, the session wire protocol decoder: corpus
#           build-fuzz/corpus-packet (seeded with valid datagrams), findings build-fuzz/findings-packet
#   server  fuzz/net_server_fuzz.cpp, the game server's protocol decoder and a live server sprayed
#           by a stranger (its frames must not change): corpus build-fuzz/corpus-server
#   snapshot  fuzz/net_snapshot_fuzz.cpp, the rejoin snapshot decoder (net/src/snapshot.hpp):
#           corpus build-fuzz/corpus-snapshot (seeded with valid snapshots, compressed and not)
#   state   fuzz/state_restore_fuzz.cpp, World::restore (refusals change nothing, accepted bytes are
#           canonical and step): corpus build-fuzz/corpus-state (seeded with saved scenario states)
#   api     fuzz/world_api_fuzz.cpp, the World's API over hostile definitions and call sequences
#           (refusals change nothing, accepted calls keep World::validate(), restore steps alike):
#           corpus build-fuzz/corpus-api, started empty (every input decodes to calls)
# DETSIM_FUZZ_BUILD names another build directory than build-fuzz. Exit status: 0 no finding,
# non-zero a crash, leak, timeout or OOM was found (libFuzzer prints the reproducer's path).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
target="${2:-replay}"
build="${DETSIM_FUZZ_BUILD:-build-fuzz}"
case "$target" in
  replay) fuzzer=replay_reader_fuzz seeds=make_seeds suffix="" max_len=65536 ;;
  packet) fuzzer=net_packet_fuzz seeds=make_packet_seeds suffix=-packet max_len=1300 ;;
  server) fuzzer=net_server_fuzz seeds=make_server_seeds suffix=-server max_len=4096 ;;
  snapshot) fuzzer=net_snapshot_fuzz seeds=make_snapshot_seeds suffix=-snapshot max_len=65536 ;;
  state) fuzzer=state_restore_fuzz seeds=make_state_seeds suffix=-state max_len=16384 ;;
  api) fuzzer=world_api_fuzz seeds="" suffix=-api max_len=4096 ;;
  *) echo "usage: scripts/fuzz.sh [SECONDS] [replay|packet|server|snapshot|state|api]" >&2; exit 2 ;;
esac
flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all"
cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" -DCMAKE_CXX_FLAGS="$flags" \
  -DDETSIM_BUILD_FUZZ=ON -DDETSIM_BUILD_TESTS=OFF -DDETSIM_BUILD_TOOLS=OFF >/dev/null
cmake --build "$build" --target "$fuzzer" $seeds -j "$(nproc)"
mkdir -p "$build/corpus$suffix" "$build/findings$suffix"
if [ -n "$seeds" ]; then "$build/fuzz/$seeds" "$build/corpus$suffix"; fi
cd "$build/findings$suffix"
exec "../fuzz/$fuzzer" "../corpus$suffix" -max_total_time="$seconds" -max_len="$max_len" \
  -rss_limit_mb=2048 -timeout=20 -print_final_stats=1
