#!/usr/bin/env bash
# Sets up, builds (Release) and runs the clothcd demo. Needs no data.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc)
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release --target clothcd_cli -j "$jobs"
build/release/apps/clothcd demo "$@"
