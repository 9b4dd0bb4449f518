#!/usr/bin/env bash
# Builds bench/fixed_bench (Release, -O2, no -march), runs it with JSON output and writes
# docs/BENCHMARKS.md from the result (scripts/bench_report.py).
#
# Usage: scripts/bench.sh [--smoke] [--no-deps] [-- extra fixed_bench options]
#   --smoke    a few milliseconds per benchmark: proves the pipeline works, labels the report
#              as a smoke run. The figures are not measurements.
#   --no-deps  do not install dependencies.
# Environment: BUILD_DIR (default build-bench), JOBS (default 2), CXX (the compiler, read only
#              when BUILD_DIR is first configured).
#
# Figures are reported, never asserted: this script fails only if building or running fails.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build-bench}"
jobs="${JOBS:-2}"
smoke=0
deps=1
extra=()
while (($#)); do
  case "$1" in
    --smoke) smoke=1 ;;
    --no-deps) deps=0 ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) echo "bench.sh: unknown option $1 (try --help)" >&2; exit 2 ;;
  esac
  shift
done

# ---- Dependencies: the project's script if there is one, else the two Debian packages. ----
if ((deps)); then
  if [[ -f "$root/scripts/install-deps.sh" ]]; then
    bash "$root/scripts/install-deps.sh"
  elif ! dpkg -s libbenchmark-dev libfixmath-dev >/dev/null 2>&1; then
    sudo=()
    if [[ "$(id -u)" != 0 ]]; then sudo=(sudo); fi
    "${sudo[@]}" apt-get install -y libbenchmark-dev libfixmath-dev
  fi
fi

# ---- Build: Release at -O2 (CMake's Release default is -O3), no -march. ----
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
cmake -S "$root" -B "$build_dir" "${generator[@]}" \
  -DCMAKE_BUILD_TYPE=Release \
  "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" \
  -DDETSIM_BUILD_BENCH=ON \
  -DDETSIM_BUILD_TESTS=OFF \
  -DDETSIM_BUILD_TOOLS=OFF
cmake --build "$build_dir" --target fixed_bench -j "$jobs"

# ---- Run: 5 repetitions, randomly interleaved so a noisy moment spreads over all benchmarks. ----
options=(--benchmark_repetitions=5 --benchmark_enable_random_interleaving=true)
if ((smoke)); then
  options+=(--benchmark_min_time=0.01)
else
  options+=(--benchmark_min_warmup_time=0.1)
fi
options+=("${extra[@]}")
json="$build_dir/fixed_bench.json"
"$build_dir/bench/fixed_bench" "${options[@]}" \
  --benchmark_out="$json" --benchmark_out_format=json

# ---- Report ----
compiler="$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build_dir/CMakeCache.txt")"
report_args=(--json "$json" --out "$root/docs/BENCHMARKS.md" --command "scripts/bench.sh"
             --compiler "$compiler" --options "${options[*]}")
if ((smoke)); then report_args+=(--smoke); fi
python3 "$root/scripts/bench_report.py" "${report_args[@]}"
