#!/usr/bin/env bash
# Installs the Debian packages clothcd needs, and the npm packages of the viewer page (three.js and
# esbuild, pinned by apps/viewer/package-lock.json, into apps/viewer/node_modules); does nothing
# when they are all present.
# Usage: scripts/setup.sh [demo|test|full]
#   demo: the library and the command-line tool; test (default): also the test suite's needs;
#   full: also the Python module and its tests, the benchmarks, the clang sanitizer and fuzzing
#   tree and Chromium for the viewer's browser test (test.sh --full).
set -euo pipefail

profile=${1:-test}
packages=(
  cmake g++ make pkg-config
  libeigen3-dev libtbb-dev libfmt-dev libcli11-dev nlohmann-json3-dev libxsimd-dev libpng-dev
)
# node and npm build the viewer page (`clothcd view`); a node that brings its own npm will do.
command -v npm >/dev/null || packages+=(nodejs npm)
case "$profile" in
  demo) ;;
  test | full)
    packages+=(libgtest-dev libgmock-dev libgmp-dev clang-format python3-matplotlib)
    if [ "$profile" = full ]; then
      packages+=(pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest
        python3-meshio libbenchmark-dev clang libclang-rt-14-dev chromium)
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

if [ ${#missing[@]} -gt 0 ]; then
  echo "clothcd setup: installing ${missing[*]}"
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "clothcd setup: run as root or install sudo" >&2; exit 1; }
    sudo="sudo"
  fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The viewer's npm packages, exactly as locked; skipped when they were installed from this lock
# (node_modules/.clothcd-lock is the lock they came from).
viewer=$(cd "$(dirname "$0")/../apps/viewer" && pwd)
if ! cmp -s "$viewer/package-lock.json" "$viewer/node_modules/.clothcd-lock"; then
  echo "clothcd setup: installing the viewer's npm packages into $viewer/node_modules"
  (cd "$viewer" && npm ci --no-audit --no-fund --loglevel=error)
  cp "$viewer/package-lock.json" "$viewer/node_modules/.clothcd-lock"
fi
