#!/usr/bin/env bash
# Sets up, builds and runs every test: the Release suite (unit, data, slow, install), a format
# check, then the unit tests again under AddressSanitizer + UndefinedBehaviorSanitizer.
# Data-driven tests read CLOTHCD_DATA (default ../shared/data) and skip when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc)

echo "== Release build"
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$jobs"
cmake --build build/release --target format-check
echo "== Release tests"
ctest --test-dir build/release --output-on-failure -j "$jobs"

echo "== Sanitizer build (ASan + UBSan)"
cmake -S . -B build/asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCLOTHCD_SANITIZE=ON \
  -DCLOTHCD_BUILD_BENCH=OFF -DCLOTHCD_BUILD_APPS=OFF >/dev/null
cmake --build build/asan -j "$jobs"
echo "== Sanitizer unit tests"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/asan --output-on-failure -j "$jobs" -L unit
