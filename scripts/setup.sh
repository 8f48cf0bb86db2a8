#!/usr/bin/env bash
# Installs the Debian packages clothcd needs; does nothing when they are all present.
# Usage: scripts/setup.sh [demo|test|full]
#   demo: the library and the command-line tool; test (default): also the test suite's needs;
#   full: also the Python module and its tests, the benchmarks and the clang sanitizer and fuzzing
#   tree (test.sh --full).
set -euo pipefail

profile=${1:-test}
packages=(
  cmake g++ make pkg-config
  libeigen3-dev libtbb-dev libfmt-dev libcli11-dev nlohmann-json3-dev libxsimd-dev
)
case "$profile" in
  demo) ;;
  test | full)
    packages+=(libgtest-dev libgmock-dev libgmp-dev clang-format python3-matplotlib)
    if [ "$profile" = full ]; then
      packages+=(pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest
        python3-meshio libbenchmark-dev clang libclang-rt-14-dev)
    fi
    ;;
  *) echo "setup.sh: unknown profile '$profile' (expected demo, test or full)" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "clothcd setup: installing ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "clothcd setup: run as root or install sudo" >&2; exit 1; }
  sudo="sudo"
fi
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
