#!/usr/bin/env bash
# Builds bench/sim_bench and bench/fixed_bench (Release, -O2, no -march), runs them with JSON
# output and writes docs/BENCHMARKS.md from the results (scripts/bench_report.py).
#
# Usage: scripts/bench.sh [--smoke] [--no-deps] [--sim-arg ARG]... [-- extra fixed_bench options]
#   --smoke      small scenes and a few milliseconds per benchmark: proves the pipeline works and
#                labels the report as a smoke run. The figures are not measurements.
#   --no-deps    do not install dependencies.
#   --sim-arg    pass ARG on to sim_bench (repeatable), e.g. --sim-arg=--pile_count=512.
# Environment: BUILD_DIR (default build-bench), JOBS (default 2), CXX (the compiler, read only
#              when BUILD_DIR is first configured), SIM_REPETITIONS (default 3),
#              FIXED_REPETITIONS (default 5).
# A full run takes about 5-10 minutes on 2 cores after the build (most of it the 1000-body piles).
#
# Figures are reported, never asserted: this script fails only if building or running fails.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build-bench}"
jobs="${JOBS:-2}"
sim_reps="${SIM_REPETITIONS:-3}"
fixed_reps="${FIXED_REPETITIONS:-5}"
smoke=0
deps=1
extra=()
sim_extra=()
while (($#)); do
  case "$1" in
    --smoke) smoke=1 ;;
    --no-deps) deps=0 ;;
    --sim-arg) shift; sim_extra+=("$1") ;;
    --sim-arg=*) sim_extra+=("${1#--sim-arg=}") ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "bench.sh: unknown option $1 (try --help)" >&2; exit 2 ;;
  esac
  shift
done

# ---- Dependencies: the project's script if there is one, else the Debian packages. ----
if ((deps)); then
  if [[ -f "$root/scripts/install-deps.sh" ]]; then
    bash "$root/scripts/install-deps.sh"
  elif ! dpkg -s libbenchmark-dev libfixmath-dev libbullet-dev >/dev/null 2>&1; then
    sudo=()
    if [[ "$(id -u)" != 0 ]]; then sudo=(sudo); fi
    "${sudo[@]}" apt-get install -y libbenchmark-dev libfixmath-dev libbullet-dev
  fi
fi

# ---- Build: Release at -O2 (CMake's Release default is -O3), no -march. ----
build_start=$SECONDS
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
cmake -S "$root" -B "$build_dir" "${generator[@]}" \
  -DCMAKE_BUILD_TYPE=Release \
  "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" \
  -DDETSIM_BUILD_BENCH=ON \
  -DDETSIM_BUILD_TESTS=OFF \
  -DDETSIM_BUILD_TOOLS=OFF
cmake --build "$build_dir" --target sim_bench fixed_bench -j "$jobs"
build_seconds=$((SECONDS - build_start))

# ---- Run: repetitions randomly interleaved, so a noisy moment spreads over all benchmarks (and
# detsim and Bullet share it). sim_bench first: its whole-run piles are the longest figures. ----
run_start=$SECONDS
load_before="$(uptime)"
sim_options=(--benchmark_repetitions="$sim_reps" --benchmark_enable_random_interleaving=true)
fixed_options=(--benchmark_repetitions="$fixed_reps" --benchmark_enable_random_interleaving=true)
if ((smoke)); then
  sim_options+=(--benchmark_min_time=0.01 --pile_count=125 --pile_steps=60 --pile_window=20
                --pile_state_frame=30 --pile_sleep_max_frames=600)
  fixed_options+=(--benchmark_min_time=0.01)
else
  fixed_options+=(--benchmark_min_warmup_time=0.1)
fi
sim_options+=("${sim_extra[@]}")
fixed_options+=("${extra[@]}")

sim_json="$build_dir/sim_bench.json"
"$build_dir/bench/sim_bench" "${sim_options[@]}" \
  --benchmark_out="$sim_json" --benchmark_out_format=json
fixed_json="$build_dir/fixed_bench.json"
"$build_dir/bench/fixed_bench" "${fixed_options[@]}" \
  --benchmark_out="$fixed_json" --benchmark_out_format=json
load_after="$(uptime)"
run_seconds=$((SECONDS - run_start))

# ---- Report ----
compiler="$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build_dir/CMakeCache.txt")"
report_args=(--sim-json "$sim_json" --fixed-json "$fixed_json"
             --out "$root/docs/BENCHMARKS.md" --command "bash scripts/bench.sh"
             --compiler "$compiler" --nproc "$(nproc)"
             --load-before "${load_before#"${load_before%%[![:space:]]*}"}"
             --load-after "${load_after#"${load_after%%[![:space:]]*}"}"
             --run-seconds "$run_seconds" --build-seconds "$build_seconds"
             --options "sim_bench ${sim_options[*]}; fixed_bench ${fixed_options[*]}")
if ((smoke)); then report_args+=(--smoke); fi
python3 "$root/scripts/bench_report.py" "${report_args[@]}"
echo "bench.sh: built in ${build_seconds} s, ran in ${run_seconds} s" >&2
