#!/usr/bin/env bash
# Sets up, builds and runs every test: the Release suite (unit, data, slow, install, cli) with gcc
# and a format check; then one clang tree with AddressSanitizer + UndefinedBehaviorSanitizer that
# holds both the unit tests (run again there) and the libFuzzer targets (library objects built with
# -fsanitize=fuzzer-no-link), each fuzzed briefly on its seed corpus. Fails on any failure.
# Data-driven tests read CLOTHCD_DATA (default ../shared/data) and skip when it is absent.
# CLOTHCD_FUZZ_SECONDS (default 12) bounds each fuzz target's run.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc)
start=$SECONDS

echo "== Release build"
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$jobs"
cmake --build build/release --target format-check
echo "== Release tests"
ctest --test-dir build/release --output-on-failure -j "$jobs"

echo "== Sanitizer + fuzzer build (clang, ASan + UBSan)"
# A tree configured with another compiler cannot switch in place.
if [ -f build/asan/CMakeCache.txt ] && ! grep -q '^CMAKE_CXX_COMPILER:FILEPATH=.*clang' build/asan/CMakeCache.txt; then
  rm -rf build/asan
fi
CXX=clang++ cmake -S . -B build/asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCLOTHCD_SANITIZE=ON \
  -DCLOTHCD_FUZZ=ON -DCLOTHCD_BUILD_BENCH=OFF >/dev/null
cmake --build build/asan -j "$jobs"
echo "== Sanitizer unit tests"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/asan --output-on-failure -j "$jobs" -L unit
echo "== Fuzzing (${CLOTHCD_FUZZ_SECONDS:-12} s per target)"
CLOTHCD_FUZZ_SEED=${CLOTHCD_FUZZ_SEED:-1} scripts/fuzz.sh --build-dir build/asan --no-build --jobs "$jobs" "${CLOTHCD_FUZZ_SECONDS:-12}"
echo "== All tests passed in $((SECONDS - start)) s"
