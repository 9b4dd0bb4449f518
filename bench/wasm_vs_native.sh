#!/usr/bin/env bash
# Time per step of the pile scenes in WebAssembly (the determinism matrix's wasm32 build, run by
# node) beside the native build, measured in one run, interleaved, and checked to reach the same
# final hash: what a browser game pays for running detsim as wasm. Google Benchmark has no
# Emscripten build in Debian, so both sides are timed by `detsim run --json` (the seconds of the
# steps and of each frame's state hash, as a lockstep game takes them; scene creation excluded),
# and the median of the repetitions is reported.
#
# Usage: bench/wasm_vs_native.sh NATIVE_DETSIM WASM_DETSIM_JS [FRAMES] [REPETITIONS]
#   e.g. bench/wasm_vs_native.sh build/dev/tools/detsim build/matrix/wasm32/tools/detsim.js
#   (scripts/matrix.sh wasm32 builds the second). Prints a Markdown table (docs/BENCHMARKS.md).
set -euo pipefail

if [ $# -lt 2 ] || [ $# -gt 4 ]; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
native=$1
wasm=$2
frames=${3:-600}
reps=${4:-3}
[ -x "$native" ] || { echo "$0: no native detsim at $native" >&2; exit 2; }
[ -f "$wasm" ] || { echo "$0: no wasm detsim at $wasm" >&2; exit 2; }
command -v node >/dev/null || { echo "$0: node is not installed (apt-get install nodejs)" >&2; exit 2; }

err=$(mktemp)
trap 'rm -f "$err"' EXIT
# One run's JSON line; its progress bar and messages go to a file, shown if the run fails.
run_json() {
  if ! "$@" 2>"$err"; then
    cat "$err" >&2
    exit 1
  fi
}
field() { sed -n "s/.*\"$1\":\"\{0,1\}\([^\",}]*\).*/\1/p"; }
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

echo "| Scene | Frames | native ms/step | wasm ms/step | wasm / native | same final hash |"
echo "|---|--:|--:|--:|--:|---|"
for scene in pile_boxes pile_spheres; do
  nat=()
  was=()
  same=yes
  for ((r = 0; r < reps; r++)); do
    a=$(run_json "$native" run --scenario "$scene" --frames "$frames" --json)
    b=$(run_json node "$wasm" run --scenario "$scene" --frames "$frames" --json)
    nat+=("$(echo "$a" | field seconds)")
    was+=("$(echo "$b" | field seconds)")
    [ "$(echo "$a" | field final_hash)" = "$(echo "$b" | field final_hash)" ] || same=NO
  done
  n=$(printf '%s\n' "${nat[@]}" | median)
  w=$(printf '%s\n' "${was[@]}" | median)
  awk -v s="$scene" -v f="$frames" -v n="$n" -v w="$w" -v same="$same" \
    'BEGIN { printf "| %s | %d | %.3f | %.3f | %.2f | %s |\n", s, f, 1000*n/f, 1000*w/f, w/n, same }'
done
