#!/usr/bin/env bash
# Installs the Debian 12 packages detsim needs to build, test and benchmark, if any is missing,
# and the packages named as arguments. Non-interactive; safe to run again (it does nothing when
# everything is present).
set -euo pipefail

packages=(
  cmake ninja-build g++ clang clang-format libclang-rt-14-dev  # toolchains, sanitizer runtimes
  libgtest-dev                                                 # tests
  libxxhash-dev libcli11-dev                                   # state hashing, the CLI
  libsodium-dev pkg-config                                     # net/: session ids, challenges
  libzstd-dev                                                  # net/: rejoin snapshots
  libcpp-httplib-dev                                           # detsim serve --agones (HTTP)
  zlib1g-dev libjs-three chromium                              # detsim view; its browser test
  libmpfr-dev libgmp-dev                                       # reference for the accuracy tests
  libbenchmark-dev libfixmath-dev libbullet-dev               # benchmarks and their peers
  python3 python3-yaml                                         # docs/ tables; tests/deploy_test.py
  "$@"  # what the caller needs besides (scripts/matrix.sh: its legs' cross compilers, qemu-user)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}" >&2
sudo=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: not root and no sudo; install: ${missing[*]}" >&2; exit 2; }
  sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -q
"${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
