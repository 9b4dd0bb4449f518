#!/usr/bin/env bash
# Builds and runs every test: the README's test command, and what CI runs.
#   1. gcc, Release, warnings as errors: the whole suite, plus the installed-package consumer test.
#   2. clang with AddressSanitizer + UndefinedBehaviorSanitizer and checked invariants
#      (DETSIM_CHECKS), warnings as errors: the whole suite.
#   3. clang-format: every C++ file is formatted.
#   4. The determinism matrix (scripts/matrix.sh): every compiler, optimisation level, CPU
#      architecture that fits in what remains of the CI budget (at least the gcc -O2 build of step 1,
#      i686 and wasm32) reproduces golden/ bit for bit; DETSIM_MATRIX=full runs every leg.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh

jobs=$(nproc)
current=""
step_start=$SECONDS
finish_step() {
  if [ -n "$current" ]; then printf '== %s: passed in %d s ==\n' "$current" $((SECONDS - step_start)); fi
}
step() {
  finish_step
  current=$*
  step_start=$SECONDS
  printf '\n== %s ==\n' "$*"
}

step "gcc Release"
# Release at -O2 (the level the benchmarks report; CMake's Release default is -O3), test files at
# -O1: on 2 cores compiling is most of this script's time (tests/CMakeLists.txt says why -O1). The
# libraries build as unity batches (every test file is its own executable already), which parses
# their headers once per batch instead of once per file.
cmake -S . -B build/gcc-release -G Ninja -DCMAKE_CXX_COMPILER=g++ -DCMAKE_C_COMPILER=gcc \
  -DCMAKE_BUILD_TYPE=Release \
  "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" -DDETSIM_TEST_OPTIMIZE=-O1 -DDETSIM_WERROR=ON \
  -DCMAKE_UNITY_BUILD=ON >/dev/null
cmake --build build/gcc-release -j "$jobs"
ctest --test-dir build/gcc-release --output-on-failure -j "$jobs"

step "clang ASan+UBSan"
# -O1 with line tables only: what the sanitizers recommend (reports keep file:line stacks), and
# far cheaper to build than full debug information. DETSIM_CHECKS: every DETSIM_ASSERT and
# World::validate() after every step of every test (they only read: the golden tests still pass).
san="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake -S . -B build/clang-sanitize -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" \
  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" -DCMAKE_C_FLAGS="$san" \
  -DCMAKE_CXX_FLAGS="$san" -DCMAKE_EXE_LINKER_FLAGS="$san" -DDETSIM_WERROR=ON -DDETSIM_CHECKS=ON \
  -DCMAKE_UNITY_BUILD=ON >/dev/null
cmake --build build/clang-sanitize -j "$jobs"
# The accuracy contract is proven on 1M inputs per function, and the decimal round trips on their
# full counts, in the gcc build above; here the same tests look for undefined behaviour over every
# edge input and a tenth of the random ones (sanitized MPFR runs are ~20x slower).
DETSIM_ACCURACY_SAMPLES=100000 DETSIM_TEST_SCALE=10 \
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/clang-sanitize --output-on-failure -j "$jobs" -E '^install_consumer$'

step "clang-format"
git ls-files '*.cpp' '*.hpp' '*.h' | xargs clang-format --dry-run --Werror
echo "clang-format: all files formatted"

step "determinism matrix"
# Last, with what remains of the CI budget (DETSIM_CI_MINUTES, default 38, counted from the start
# of this script): the "ci" legs (this gcc -O2 build, i686) always run, and every further leg,
# other CPU architectures first, while the time left covers it (scripts/matrix.sh --budget). The
# summary names any leg skipped for time. DETSIM_MATRIX=full runs every leg regardless; =ci only
# the "ci" legs (docs/MATRIX.md has what each costs).
case "${DETSIM_MATRIX:-auto}" in
  full) matrix=() ;;
  ci) matrix=(--ci) ;;
  auto)
    left=$(( ${DETSIM_CI_MINUTES:-38} * 60 - SECONDS ))
    matrix=(--budget $(( left > 0 ? left : 0 )))
    ;;
  *) echo "test.sh: DETSIM_MATRIX must be auto, ci or full, got '${DETSIM_MATRIX}'" >&2; exit 2 ;;
esac
# matrix.sh counts its budget from its own start.
bash scripts/matrix.sh "${matrix[@]}" x86_64-gcc-O2=build/gcc-release
finish_step
echo "scripts/test.sh: every step passed in $SECONDS s"
