#!/usr/bin/env bash
# The cross-architecture determinism matrix (part of the README's test command; docs/MATRIX.md).
#
# Each leg builds the detsim command (and the example game's pushball-tool) for one CPU, compiler
# and optimisation level, then runs
#   detsim golden check --dir golden          (every golden scenario's hashes, and the golden replays)
#   detsim verify golden/replays/*.dsr        (each golden replay, frame by frame)
#   pushball-tool verify golden/games/*.dsr   (a game's own input bytes and state section)
# natively or under qemu-user. Every leg must reproduce the same golden/ data, bit for bit.
#
# Usage: scripts/matrix.sh [--list] [--ci] [--budget SECONDS] [LEG ...] [LEG=BUILD_DIR ...]
#   LEG         run only the legs named (default: every leg, in the order of the table below)
#   --ci        run only the legs marked "ci" below (docs/MATRIX.md has the measured cost of each)
#   --budget S  the "ci" legs always run; every other leg starts only while the time left of S
#               seconds covers 1.25 times the longest leg so far, and is reported as skipped
#               otherwise (not a failure). scripts/test.sh gives the matrix what remains of the
#               CI budget, so a fast machine runs every leg and a slow one at least the "ci" legs.
#   LEG=DIR     for that leg, use the detsim already built in DIR instead of building it
#               (scripts/test.sh passes its gcc -O2 build this way)
#   --list      print the legs and exit
# Exit status: 0 every leg matched; 1 some leg differed (the leg, scenario and frame are named);
# 2 bad usage, or a leg that could not be built or run.
#
# Lean by design (the whole test command must fit its CI budget on two cores): a leg builds only the
# detsim target, each library as one unity translation unit, with the CLI11 argument parser at -O0
# (it computes nothing the golden data checks); the golden runs are short.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

# name | compiler | optimisation and code-generation flags | emulator ("" = run natively) | ci
# The "ci" legs give the most independent evidence per minute: the gcc -O2 build of the test suite
# (free), 32-bit without __int128 (i686, run on the real CPU) and WebAssembly (wasm32: Debian's
# emscripten, the CLI run by node, the way a browser game runs detsim). Every other leg, big-endian ones
# included, costs 6-15 minutes on two cores (docs/MATRIX.md): DETSIM_MATRIX=full in scripts/test.sh.
# In order of evidence per minute, so that a time budget cuts the least informative legs: the
# other CPU architectures first (big-endian 64-bit, ARM, 32-bit big-endian, ...), then the other
# x86-64 compilers and optimisation levels.
legs=(
  "x86_64-gcc-O2|g++|-O2||ci"
  "i686|i686-linux-gnu-g++-12|-O2|qemu-i386|ci"
  "wasm32|em++|-O2|node|ci"
  "aarch64|aarch64-linux-gnu-g++-12|-O2|qemu-aarch64|"
  "s390x|s390x-linux-gnu-g++-12|-O2|qemu-s390x|"
  "armhf|arm-linux-gnueabihf-g++-12|-O2|qemu-arm|"
  "mips|mips-linux-gnu-g++-12|-O2|qemu-mips|"
  "ppc64le|powerpc64le-linux-gnu-g++-12|-O2|qemu-ppc64le|"
  "riscv64|riscv64-linux-gnu-g++-12|-O2|qemu-riscv64|"
  "x86_64-clang-O2|clang++|-O2||"
  "x86_64-gcc-O3|g++|-O3||"
  "x86_64-clang-O3|clang++|-O3||"
  "x86_64-gcc-O3-fast-math-native|g++|-O3 -ffast-math -march=native||"
  "x86_64-gcc-O0|g++|-O0||"
  "x86_64-clang-O0|clang++|-O0||"
)

usage() {
  sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}

declare -A prebuilt=()
selected=()
budget=""
expect_budget=0
for arg in "$@"; do
  if [ $expect_budget -eq 1 ]; then
    [[ "$arg" =~ ^[0-9]+$ ]] || { echo "matrix: --budget needs whole seconds, got '$arg'" >&2; exit 2; }
    budget=$arg; expect_budget=0; continue
  fi
  case "$arg" in
    --budget) expect_budget=1 ;;
    --budget=*)
      budget=${arg#--budget=}
      [[ "$budget" =~ ^[0-9]+$ ]] || { echo "matrix: --budget needs whole seconds, got '$budget'" >&2; exit 2; }
      ;;
    --list)
      for leg in "${legs[@]}"; do
        IFS='|' read -r name cxx flags emu ci <<<"$leg"
        printf '%-32s %-30s %-30s %-14s %s\n' "$name" "$cxx" "$flags" "${emu:-native}" "$ci"
      done
      exit 0
      ;;
    --ci)
      for leg in "${legs[@]}"; do
        [ "${leg##*|}" = ci ] && selected+=("${leg%%|*}")
      done
      ;;
    -h | --help) usage ;;
    -*) echo "matrix: unknown option '$arg'" >&2; usage ;;
    *=*) prebuilt[${arg%%=*}]=${arg#*=} ;;
    *) selected+=("$arg") ;;
  esac
done

find_leg() {
  local leg
  for leg in "${legs[@]}"; do
    [ "${leg%%|*}" = "$1" ] && { echo "$leg"; return 0; }
  done
  return 1
}

[ $expect_budget -eq 0 ] || { echo "matrix: --budget needs a number of seconds" >&2; exit 2; }
if [ ${#selected[@]} -eq 0 ]; then
  for leg in "${legs[@]}"; do selected+=("${leg%%|*}"); done
fi
for name in "${selected[@]}" "${!prebuilt[@]}"; do
  find_leg "$name" >/dev/null || { echo "matrix: unknown leg '$name' (--list shows them)" >&2; exit 2; }
done
for name in "${!prebuilt[@]}"; do
  [ -x "${prebuilt[$name]}/tools/detsim" ] || [ -f "${prebuilt[$name]}/tools/detsim.js" ] ||
    { echo "matrix: leg $name: no detsim in ${prebuilt[$name]}/tools" >&2; exit 2; }
  [ -x "${prebuilt[$name]}/examples/pushball/pushball-tool" ] ||
    [ -f "${prebuilt[$name]}/examples/pushball/pushball-tool.js" ] ||
    { echo "matrix: leg $name: no pushball-tool in ${prebuilt[$name]}/examples/pushball" >&2; exit 2; }
done

# The selected legs' cross compilers (Debian's g++-12-<triplet>) and qemu-user, if missing.
packages=()
for name in "${selected[@]}"; do
  [ -n "${prebuilt[$name]:-}" ] && continue
  IFS='|' read -r _ cxx _ emu _ <<<"$(find_leg "$name")"
  if [ "$cxx" = em++ ]; then
    packages+=(emscripten)
  elif [ -n "$emu" ]; then
    packages+=("g++-12-${cxx%-g++-12}" qemu-user)
  fi
done
bash scripts/install-deps.sh "${packages[@]}"

jobs=$(nproc)
mkdir -p build/matrix
results=()
failed=0
broken=0

# build_leg NAME CXX FLAGS EMULATOR DIR: configures and builds the detsim target; returns nonzero
# with the log in DIR.log on failure.
build_leg() {
  local name=$1 cxx=$2 flags=$3 emu=$4 dir=$5
  local cross=()
  if [ "$cxx" = em++ ]; then
    build_wasm_leg "$flags" "$dir"
    return
  fi
  if [ -n "$emu" ]; then
    # Statically linked, so qemu-user needs no target C library; xxHash and CLI11 come from the
    # host's headers (a cross build has no target libraries of them).
    cross=(-DCMAKE_SYSTEM_NAME=Linux "-DCMAKE_SYSTEM_PROCESSOR=${name}"
           -DCMAKE_EXE_LINKER_FLAGS=-static "-DCMAKE_CROSSCOMPILING_EMULATOR=${emu}")
  fi
  # -march=native on an AVX-512 CPU makes gcc 12 warn inside its own avx512fintrin.h (a
  # -W(maybe-)uninitialized false positive, GCC bug 105593) where xxHash's inline AVX-512 path uses it:
  # the compiler's header, not detsim's code, so those two warnings stay warnings on such legs.
  local build_flags=$flags
  case " $flags " in *" -march=native "*) build_flags="$flags -Wno-error=uninitialized -Wno-error=maybe-uninitialized" ;; esac
  cmake -S "$root" -B "$dir" -G Ninja "-DCMAKE_CXX_COMPILER=$cxx" -DCMAKE_BUILD_TYPE=Release \
    "-DCMAKE_CXX_FLAGS_RELEASE=$build_flags" "${cross[@]}" \
    -DDETSIM_BUILD_TESTS=OFF -DDETSIM_BUILD_EXAMPLES=ON -DDETSIM_INSTALL=OFF \
    -DDETSIM_WITH_MPFR=OFF -DDETSIM_WERROR=ON \
    -DDETSIM_HEADER_ONLY_DEPS=ON -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=0 \
    -DDETSIM_CLI_PARSER_OPTIONS=-O0 >"$dir.log" 2>&1 &&
    cmake --build "$dir" -j "$jobs" --target detsim pushball-tool >>"$dir.log" 2>&1
}

# build_wasm_leg FLAGS DIR: the WebAssembly leg, with Debian's emscripten (emcmake sets its CMake
# toolchain). The project's defaults under Emscripten do the rest: no sockets (DETSIM_WITH_UDP
# off), no tests or MPFR, xxHash and CLI11 from the host's headers as in the cross legs, and each
# tool linked into one .js file with its .wasm inside, for node (tools/CMakeLists.txt). Emscripten's
# JavaScript optimiser needs the acorn module from Debian's node-acorn, which a node not from
# Debian does not look for. The C API's library is built too (a browser game's engine binds to it),
# though no check runs it.
build_wasm_leg() {
  local flags=$1 dir=$2
  emcmake cmake -S "$root" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    "-DCMAKE_CXX_FLAGS_RELEASE=$flags" \
    -DDETSIM_BUILD_TESTS=OFF -DDETSIM_BUILD_EXAMPLES=ON -DDETSIM_INSTALL=OFF \
    -DDETSIM_WITH_MPFR=OFF -DDETSIM_WERROR=ON \
    -DDETSIM_HEADER_ONLY_DEPS=ON -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=0 \
    -DDETSIM_CLI_PARSER_OPTIONS=-O0 >"$dir.log" 2>&1 &&
    NODE_PATH="/usr/share/nodejs${NODE_PATH:+:$NODE_PATH}" \
      cmake --build "$dir" -j "$jobs" --target detsim pushball-tool detsim_c >>"$dir.log" 2>&1
}

# check_leg EMULATOR BUILD_DIR: the golden check and the golden replays' verification, and the
# example games' golden replays through their own tools (a game's own input bytes and game state
# section). A cross binary that this machine runs itself (i686 on an x86-64 kernel with 32-bit
# support) runs natively, on a real CPU of its architecture and far faster than emulated; any
# other goes to its emulator.
check_leg() {
  local emu=$1 dir=$2 bin=$2/tools/detsim game=$2/examples/pushball/pushball-tool
  local run=("$bin") run_game=("$game")
  if [ -f "$bin.js" ]; then  # WebAssembly: the program is JavaScript, run by $emu (node)
    run=("$emu" "$bin.js")
    run_game=("$emu" "$game.js")
  elif [ -n "$emu" ] && ! "$bin" --version >/dev/null 2>&1; then
    run=("$emu" "$bin")
    run_game=("$emu" "$game")
  fi
  echo "running: ${run[*]}"
  "${run[@]}" golden check --dir "$root/golden" || return
  local replay
  for replay in "$root"/golden/replays/*.dsr; do
    "${run[@]}" verify "$replay" || return
  done
  for replay in "$root"/golden/games/pushball*.dsr; do
    "${run_game[@]}" verify "$replay" || return
  done
}

longest=0
skipped=0
for name in "${selected[@]}"; do
  IFS='|' read -r _ cxx flags emu ci <<<"$(find_leg "$name")"
  if [ -n "$budget" ] && [ "$ci" != ci ] && ((SECONDS + longest * 5 / 4 > budget)); then
    printf '\n-- matrix leg %s: skipped, %d s of the %d s budget left (the longest leg took %d s)\n' \
      "$name" $((budget > SECONDS ? budget - SECONDS : 0)) "$budget" "$longest"
    results+=("$name|skipped: time budget|-|-"); skipped=$((skipped + 1)); continue
  fi
  printf '\n-- matrix leg %s (%s %s%s)\n' "$name" "$cxx" "$flags" "${emu:+, run by $emu}"
  start=$SECONDS
  dir=${prebuilt[$name]:-build/matrix/$name}
  if [ -z "${prebuilt[$name]:-}" ]; then
    if ! command -v "$cxx" >/dev/null || { [ -n "$emu" ] && ! command -v "$emu" >/dev/null; }; then
      echo "matrix: leg $name: $cxx${emu:+ or $emu} is not installed" >&2
      results+=("$name|not run: toolchain missing|-|-"); broken=1; continue
    fi
    if ! build_leg "$name" "$cxx" "$flags" "$emu" "$dir"; then
      tail -n 30 "$dir.log" >&2
      echo "matrix: leg $name: the build failed (log: $dir.log)" >&2
      results+=("$name|BUILD FAILED|$((SECONDS - start))|-"); broken=1; continue
    fi
  fi
  built=$SECONDS
  if output=$(check_leg "$emu" "$dir" 2>&1); then
    echo "$output"
    results+=("$name|ok|$((built - start))|$((SECONDS - built))")
    ((SECONDS - start > longest)) && longest=$((SECONDS - start))
  else
    echo "$output"
    echo "matrix: leg $name DIFFERS from golden/: see the mismatches above (scenario, frame," \
         "expected and actual hash)" >&2
    results+=("$name|DIFFERS|$((built - start))|$((SECONDS - built))"); failed=1
  fi
done

printf '\n%-32s %-28s %8s %8s\n' "leg" "result" "build s" "check s"
for r in "${results[@]}"; do
  IFS='|' read -r name result build check <<<"$r"
  printf '%-32s %-28s %8s %8s\n' "$name" "$result" "$build" "$check"
done
if [ $failed -ne 0 ]; then
  echo "matrix: FAILED: some leg does not reproduce golden/" >&2
  exit 1
fi
if [ $broken -ne 0 ]; then
  echo "matrix: some leg could not be built or run" >&2
  exit 2
fi
if [ $skipped -ne 0 ]; then
  echo "matrix: every leg that ran reproduces golden/ bit for bit; $skipped skipped for time"
else
  echo "matrix: every leg reproduces golden/ bit for bit"
fi
