#!/usr/bin/env bash
# Sets up, builds (Release) and runs the clothcd demo. Needs no data.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh demo
jobs=$(nproc)
# A new tree is configured without tests and benchmarks, whose packages the demo does not
# install; scripts/test.sh turns them on in the same tree.
options=()
[ -f build/release/CMakeCache.txt ] || options=(-DCLOTHCD_BUILD_TESTS=OFF -DCLOTHCD_BUILD_BENCH=OFF)
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release "${options[@]}" >/dev/null
cmake --build build/release --target clothcd_cli -j "$jobs"
build/release/apps/clothcd demo "$@"
