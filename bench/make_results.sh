#!/bin/sh
# Regenerates docs/RESULTS.md and the pictures in docs/results/ from fresh measurements:
# builds vnsba_bench (Release, no DDS needed), runs `vnsba_bench paper`, `sweep`, `movingai` and
# `large` and `costs`, and fills the measured tables into bench/RESULTS.md.in.
#
#   bench/make_results.sh                 # about 5 minutes on 2 cores
#   VNSBA_MOVINGAI_SCENARIOS=0 bench/make_results.sh   # every Moving AI scenario (an hour)
#
# Environment: VNSBA_BUILD_DIR (default build/bench), VNSBA_DATA_DIR (default ../shared/data
# beside the project), VNSBA_MOVINGAI_SCENARIOS (per map, default 300; 0 = all),
# VNSBA_REPETITIONS (timed plans per paper run, default 51), VNSBA_LARGE_QUERIES (per large map
# and size, default 12), VNSBA_COSTS_SCENARIOS (per map for `costs`, default 40).
#
# The head-to-head table against the reference JPS (docs/results/reference_jps.md) needs that
# program, which is not a dependency: bench/reference_jps.sh writes it, and this script
# includes the last one written.
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
build=${VNSBA_BUILD_DIR:-$root/build/bench}
data=${VNSBA_DATA_DIR:-$(cd "$root/.." && pwd)/shared/data}
scenarios=${VNSBA_MOVINGAI_SCENARIOS:-300}
repetitions=${VNSBA_REPETITIONS:-51}
costs_scenarios=${VNSBA_COSTS_SCENARIOS:-40}

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DVNSBA_CORE_ONLY=ON \
  -DVNSBA_DATA_DIR="$data" >/dev/null
cmake --build "$build" --target vnsba_bench -j"$(nproc)" >/dev/null
bench="$build/tools/vnsba_bench"

out="$root/docs/results"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
rm -rf "$out/paper" "$out/sweep"
mkdir -p "$out/paper" "$out/sweep"

echo "paper (maps A-D, $repetitions repetitions) ..." >&2
"$bench" paper --out "$out/paper" --repetitions "$repetitions" > "$work/paper.md"
echo "sweep (omega / eta on the Figure 3 maps) ..." >&2
"$bench" sweep --out "$out/sweep" > "$work/sweep.md"
echo "movingai ($scenarios scenarios per map; 0 = all) ..." >&2
"$bench" movingai --maps "$data/movingai" --max-scenarios "$scenarios" --with-post-processing \
  > "$work/movingai.md"
echo "costs (binary against cost-aware: the demo scene, $costs_scenarios scenarios per map) ..." >&2
"$bench" costs --maps "$data/movingai" --max-scenarios "$costs_scenarios" --repetitions 11 \
  > "$work/costs.md"
echo "large (2048 and 4096 cells square slices) ..." >&2
"$bench" large --maps "$data/movingai" --queries "${VNSBA_LARGE_QUERIES:-12}" > "$work/large.md"
# The CSV tables are kept for other tools; the Markdown copies are in RESULTS.md itself.
rm -f "$out/paper/paper_tables.md"

# Links in the fragments are relative to their folder; RESULTS.md sits in docs/.
sed 's#](\([a-z]\)#](results/paper/\1#g' "$work/paper.md" > "$work/paper.rel.md"
sed 's#](\([a-z]\)#](results/sweep/\1#g' "$work/sweep.md" > "$work/sweep.rel.md"

cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)
compiler=$(c++ --version | head -n 1)
machine="$(nproc) cores ($cpu), $(uname -s) $(uname -m), $compiler, Release build (-O3), $(date -u +%Y-%m-%d)"

awk -v machine="$machine" -v scenarios="$scenarios" -v repetitions="$repetitions" \
    -v paper="$work/paper.rel.md" -v sweep="$work/sweep.rel.md" -v movingai="$work/movingai.md" \
    -v large="$work/large.md" -v costs="$work/costs.md" -v costs_scenarios="$costs_scenarios" \
    -v reference="$out/reference_jps.md" '
  function include(file,   line) { while ((getline line < file) > 0) print line; close(file) }
  /^@PAPER@$/ { include(paper); next }
  /^@SWEEP@$/ { include(sweep); next }
  /^@MOVINGAI@$/ { include(movingai); next }
  /^@LARGE@$/ { include(large); next }
  /^@COSTS@$/ { include(costs); next }
  /^@REFERENCE_JPS@$/ {
    if ((getline line < reference) > 0) { print line; include(reference) }
    else print "(not measured: run bench/reference_jps.sh with the reference program)"
    next
  }
  { gsub(/@MACHINE@/, machine); gsub(/@SCENARIOS@/, scenarios); gsub(/@REPETITIONS@/, repetitions); gsub(/@COSTS_SCENARIOS@/, costs_scenarios); print }
' "$root/bench/RESULTS.md.in" > "$root/docs/RESULTS.md"
echo "wrote docs/RESULTS.md and docs/results/" >&2
