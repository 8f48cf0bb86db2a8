#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for a bounded time on its
# seed corpus. Usage: scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]
# New inputs go to build/fuzz/corpus/<target>/, crashes to build/fuzz/crashes/; fails on any crash.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
shift || true
jobs=$(nproc)

CXX=clang++ cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCLOTHCD_FUZZ=ON \
  -DCLOTHCD_BUILD_TESTS=OFF -DCLOTHCD_BUILD_APPS=OFF -DCLOTHCD_BUILD_BENCH=OFF >/dev/null
cmake --build build/fuzz --target fuzzers -j "$jobs"

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(cd build/fuzz/fuzz && ls fuzz_* | grep -v '\.' | sort)
fi
mkdir -p build/fuzz/crashes
status=0
for t in "${targets[@]}"; do
  mkdir -p "build/fuzz/corpus/$t"
  seeds="fuzz/corpus/$t"
  [ -d "$seeds" ] || seeds=""
  log="build/fuzz/$t.log"
  if ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
     "build/fuzz/fuzz/$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
       -print_final_stats=1 -artifact_prefix="build/fuzz/crashes/$t-" \
       "build/fuzz/corpus/$t" $seeds >"$log" 2>&1; then
    execs=$(grep -m1 'stat::number_of_executed_units' "$log" | awk '{print $2}')
    echo "fuzz $t: ok, ${execs:-?} executions in ${seconds}s"
  else
    echo "fuzz $t: FAILED (see $log)"; tail -30 "$log"; status=1
  fi
done
exit $status
