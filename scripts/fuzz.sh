#!/usr/bin/env bash
# Runs each libFuzzer target for a bounded time on its seed corpus (fuzz/corpus/<target>/) and
# fails on any crash, sanitizer report, leak or timeout.
# Usage: scripts/fuzz.sh [--build-dir DIR] [--no-build] [--jobs N] [--seed S] [--runs R]
#                        [SECONDS_PER_TARGET] [TARGET...]
#   default: builds the targets with clang (ASan + UBSan) in build/fuzz, 20 s per target, a random
#   seed, and keeps the inputs it finds in DIR/fuzz-corpus/<target>/ for the next run.
#   --runs R: a fixed number of executions per target instead of a time, from a fresh copy of the
#   seed corpus; with --seed, every run then tries exactly the same inputs (test.sh --full does
#   this, so a green CI means the same thing every time).
#   scripts/test.sh uses `--build-dir build/asan --no-build`: its sanitizer tree already holds them.
#   --jobs N runs N targets at a time (each target is one single-threaded process).
# Crashes go to DIR/fuzz-crashes/, logs to DIR/fuzz-logs/.
set -euo pipefail
cd "$(dirname "$0")/.."
build=build/fuzz
do_build=1
parallel=1
seed=${CLOTHCD_FUZZ_SEED:-0}
runs=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --no-build) do_build=0; shift ;;
    --jobs) parallel=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    *) break ;;
  esac
done
seconds=${1:-20}
shift || true
jobs=$(nproc)

if [ "$do_build" = 1 ]; then
  CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCLOTHCD_FUZZ=ON \
    -DCLOTHCD_BUILD_TESTS=OFF -DCLOTHCD_BUILD_APPS=OFF -DCLOTHCD_BUILD_BENCH=OFF >/dev/null
  cmake --build "$build" --target fuzzers -j "$jobs"
fi

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  # The targets fuzz/CMakeLists.txt declares, not whatever binaries the build folder holds (a
  # target removed from the source would otherwise still run from an old build).
  mapfile -t targets < <(grep -o 'clothcd_add_fuzzer(fuzz_[a-z_0-9]*' fuzz/CMakeLists.txt |
    sed 's/clothcd_add_fuzzer(//' | sort)
fi
mkdir -p "$build/fuzz-crashes" "$build/fuzz-logs"
fuzz_one() {
  local t=$1 seeds="fuzz/corpus/$1" log="$build/fuzz-logs/$1.log" corpus limit
  [ -d "$seeds" ] || seeds=""
  if [ "$runs" -gt 0 ]; then
    # A fresh corpus each time: inputs kept from an earlier run would change what is explored.
    corpus="$build/fuzz-corpus-fixed/$t"
    rm -rf "$corpus"
    limit=(-runs="$runs")
  else
    corpus="$build/fuzz-corpus/$t"
    limit=(-max_total_time="$seconds")
  fi
  mkdir -p "$corpus"
  # -timeout: one input running 10 s is a hang; -rss_limit_mb: a claimed count must not allocate.
  local t0=$SECONDS
  if ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
     "$build/fuzz/$t" "${limit[@]}" -seed="$seed" -timeout=10 -rss_limit_mb=2048 \
       -print_final_stats=1 -artifact_prefix="$build/fuzz-crashes/$t-" \
       "$corpus" $seeds >"$log" 2>&1; then
    execs=$(grep -m1 'stat::number_of_executed_units' "$log" | awk '{print $2}')
    cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1 | awk '{print $2}')
    echo "fuzz $t: ok, ${execs:-?} executions in $((SECONDS - t0)) s, coverage ${cov:-?} edges"
  else
    echo "fuzz $t: FAILED (log $log, input in $build/fuzz-crashes/)"; tail -40 "$log"; return 1
  fi
}

status=0
running=0
for t in "${targets[@]}"; do
  if [ "$running" -ge "$parallel" ]; then
    wait -n || status=1
    running=$((running - 1))
  fi
  fuzz_one "$t" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || status=1
  running=$((running - 1))
done
exit $status
