#!/usr/bin/env bash
# Regenerates docs/results/ in one command: simulates the scenes (scenes/*.json) into OUT/frames,
# runs `clothcd experiment` over their CD calls (every cone policy x culling rule x BVH build,
# OPTIMAL spread angles, a timing pass at 1 and 2 threads), the in-situ comparison inside the
# simulator (its per-substep figures also go into Tables 1 and 2), and copies every table and
# figure to docs/results/. Each part's wall time and the
# load average before and after it go to OUT/run_times.md (copied too).
#
#   scripts/results.sh OUT
#
# OUT may be empty or hold an earlier run: finished frames and results are reused (the simulator
# resumes bitwise identically; the experiment skips the (scene, build, step) units it finds).
# Settings (environment):
#   CLOTHCD_DATA      shared data folder (default: ../shared/data beside the source tree)
#   CLOTHCD_BIN       the clothcd binary (default: build/release/apps/clothcd, built if missing)
#   THREADS           worker threads of the simulations and the counting pass (default 2)
#   DRESS_EVERY       run every E-th CD call of the dress scenes (default 1: all 120)
#   MULTI_EVERY       the same for the multilayer scenes (default 1)
#   OTHER_EVERY       the same for sphere-drop and twist (default 1)
#   EVERY_<scene>     the same for one scene, '-' written '_' (e.g. EVERY_dress_kick=4)
#   OPTIMAL_EVERY     OPTIMAL spread angles on every K-th call run (default 1)
#   TIMING_EVERY      timing pass on every T-th call run (default 20)
#   TIMING_REPEATS    calls per configuration and thread count in the timing pass (default 3)
#   TIMING_THREADS    thread counts of the timing pass (default "1 2")
#   INSITU_FRAMES     frames per garment of the in-situ comparison (default 40; 0: skip it)
#   COPY              1: copy the outputs to docs/results/ (default 1)
#   OTHERS            the recorded and procedural sequences (default: fold stacked_sheets
#                     winding_strip crumpled_sheet twisted_strip cloth_ball)
#   SIMULATE          0: simulate nothing, run on the frames OUT/frames already holds (a scene's
#                     complete frames only; the tables then say how many calls of the whole)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
if [[ $# -ne 1 ]]; then
  echo "usage: scripts/results.sh OUT" >&2
  exit 2
fi
mkdir -p "$1"
out=$(cd "$1" && pwd)
export CLOTHCD_DATA=${CLOTHCD_DATA:-$root/../shared/data}
CLOTHCD_DATA=$(cd "$CLOTHCD_DATA" && pwd) || {
  echo "results.sh: CLOTHCD_DATA=$CLOTHCD_DATA is not a folder" >&2
  exit 2
}
bin=${CLOTHCD_BIN:-$root/build/release/apps/clothcd}
threads=${THREADS:-2}
dress_every=${DRESS_EVERY:-1}
multi_every=${MULTI_EVERY:-1}
other_every=${OTHER_EVERY:-1}
optimal_every=${OPTIMAL_EVERY:-1}
timing_every=${TIMING_EVERY:-20}
timing_repeats=${TIMING_REPEATS:-3}
read -r -a timing_threads <<<"${TIMING_THREADS:-1 2}"
insitu_frames=${INSITU_FRAMES:-40}
copy=${COPY:-1}
simulate=${SIMULATE:-1}

if [[ ! -x $bin ]]; then
  cmake -S "$root" -B "$root/build/release" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$root/build/release" --target clothcd_cli -j"$threads"
fi

times=$out/run_times.md
load() { cut -d' ' -f1-3 /proc/loadavg; }
{
  echo "# Wall time of each part of \`scripts/results.sh\`"
  echo
  echo "- commit: $(git -C "$root" rev-parse HEAD 2>/dev/null || echo unknown)"
  echo "- machine: $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'))"
  echo "- date: $(date -u '+%Y-%m-%d %H:%M:%S UTC')"
  echo "- settings: THREADS=$threads DRESS_EVERY=$dress_every MULTI_EVERY=$multi_every" \
    "OTHER_EVERY=$other_every OTHERS='${OTHERS:-(default)}' $(env | grep '^EVERY_' | tr '\n' ' ')SIMULATE=$simulate" \
    "OPTIMAL_EVERY=$optimal_every TIMING_EVERY=$timing_every TIMING_REPEATS=$timing_repeats" \
    "TIMING_THREADS='${timing_threads[*]}' INSITU_FRAMES=$insitu_frames"
  echo "- a part whose output OUT already held takes only the time to check it"
  echo
  echo "| part | wall s | load before (1, 5, 15 min) | load after |"
  echo "|---|---|---|---|"
} >"$times"

# part NAME COMMAND...: runs and times one part.
part() {
  local name=$1 before start
  shift
  before=$(load)
  start=$(date +%s)
  echo "== $name ($(date -u +%T), load $before)" >&2
  "$@"
  printf '| %s | %d | %s | %s |\n' "$name" "$(($(date +%s) - start))" "$before" "$(load)" \
    >>"$times"
}

scenes=(dress-rumba dress-kick multilayer-rumba multilayer-kick sphere-drop twist)
# window[NAME]: "" (the whole sequence) or "@N" (the N calls OUT/frames holds, SIMULATE=0).
declare -A window
for s in "${scenes[@]}"; do
  window[$s]=""
  if [[ $simulate == 0 ]]; then
    n=$(sed -n 's/^ *"complete_frames": *\([0-9]*\).*/\1/p' "$out/frames/$s/manifest.json" 2>/dev/null |
      head -1)
    if [[ -z $n || $n -lt 1 ]]; then
      echo "results.sh: SIMULATE=0 but $out/frames/$s holds no complete frame pair" >&2
      exit 1
    fi
    window[$s]="@$n"
    continue
  fi
  resume=()
  [[ -f $out/frames/$s/manifest.json ]] && resume=(--resume)
  part "simulate $s" "$bin" simulate "$root/scenes/$s.json" --out "$out/frames/$s" \
    --threads "$threads" "${resume[@]}"
done

# One experiment call per scene (results accumulate in OUT/runs/), then one over all of them
# that finds everything done and writes the tables and figures.
# spec NAME DEFAULT_EVERY: the scene's --scene argument.
spec() {
  local var="EVERY_${1//-/_}"
  echo "$1${window[$1]}%${!var:-$2}"
}
read -r -a others <<<"${OTHERS:-fold stacked_sheets winding_strip crumpled_sheet twisted_strip cloth_ball}"
specs=("${others[@]}"
  "$(spec sphere-drop "$other_every")" "$(spec twist "$other_every")"
  "$(spec dress-rumba "$dress_every")" "$(spec dress-kick "$dress_every")"
  "$(spec multilayer-rumba "$multi_every")" "$(spec multilayer-kick "$multi_every")")
common=(--out "$out" --threads "$threads" --optimal-every "$optimal_every"
  --timing-every "$timing_every" --timing-repeats "$timing_repeats"
  --timing-threads "${timing_threads[@]}" --timing-cullings cone sound)
for s in "${specs[@]}"; do
  part "experiment ${s%%[@%]*}" "$bin" experiment --scene "$s" "${common[@]}" --no-plots
done
# The in-situ run goes first: the tables read its OUT/in_situ.csv (per-substep sections). Its
# report is kept once it covers every garment with the frames asked for.
if [[ $insitu_frames -gt 0 ]]; then
  if grep -q '^- scenes: 4 of 4 done' "$out/in_situ.md" 2>/dev/null &&
    grep -q -- "--frames $insitu_frames " "$out/in_situ.md"; then
    part "in situ, $insitu_frames frames per garment" true
  else
    part "in situ, $insitu_frames frames per garment" "$bin" experiment --in-situ \
      "$root"/scenes/{dress-rumba,multilayer-rumba,dress-kick,multilayer-kick}.json \
      --frames "$insitu_frames" --threads "$threads" --out "$out/in_situ.md"
  fi
fi
part "tables and figures" "$bin" experiment --scene "${specs[@]}" "${common[@]}"


# What the simulations cost when they ran (also for frames an earlier run made): their manifests.
/usr/bin/python3 - "$out/frames" "${scenes[@]}" >>"$times" <<'PY'
import json, os, sys
root, names = sys.argv[1], sys.argv[2:]
print("\nSimulation cost recorded in each scene's manifest (the run that made the frames, whatever "
      "else loaded the machine then):\n")
print("| scene | frames | s total | s per frame (median) | self crossing pairs, worst frame |")
print("|---|---|---|---|---|")
for n in names:
    try:
        m = json.load(open(os.path.join(root, n, "manifest.json")))
    except OSError:
        continue
    fr = m.get("frames", [])
    secs = sorted(f.get("seconds", 0.0) for f in fr)
    worst = max([m.get("initial_self_intersections", 0)] +
                [f.get("self_intersections", 0) for f in fr])
    med = secs[len(secs) // 2] if secs else float("nan")
    print("| %s | %d | %.0f | %.1f | %d |" % (n, m.get("complete_frames", 0), sum(secs), med, worst))
print()
PY

if [[ $copy == 1 ]]; then
  files=(summary.md table1.md table2.md timing.md misses.md spread.md fig5.png fig6.png run_times.md)
  [[ $insitu_frames -gt 0 ]] && files+=(in_situ.md)
  for f in "${files[@]}"; do
    cp "$out/$f" "$root/docs/results/$f"
  done
  echo "results.sh: copied ${files[*]} to docs/results/" >&2
fi
