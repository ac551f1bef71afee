#!/bin/sh
# Proves that a speed-up changes no output: builds vnsba_bench at two revisions, runs every
# planner on the same Moving AI scenarios with each, and compares everything but the time:
# status, raw grid path cost, final length, turns, turn angle and expanded nodes, per scenario.
#
#   bench/compare_outputs.sh BASE [HEAD]     # revisions; HEAD defaults to the work tree
#   bench/compare_outputs.sh 1a2b3c4 HEAD
#
# Then the cost-aware side: vnsba_plan --json of each revision on VNSBA_COST_SCENARIOS (default 8)
# scenario lines per map, every cost-aware planner with pruning and smoothing, on the map with
# config/default.yaml's gradient and cost weight (in cells: inflation_radius 11, scaling 0.15 per
# cell, as `vnsba_bench costs` reads Moving AI maps), once with the smoother off and, where both
# revisions have it, once with `--smoother relax` (its every segment check is a line of sight):
# the whole run record (path, waypoints, metrics, expansions) but the planning time must be
# byte-identical.
#
# Exit 0 when every row is identical, 1 when any differs (the first differences are printed),
# 2 on bad use. Environment: VNSBA_DATA_DIR (default ../shared/data beside the project),
# VNSBA_MOVINGAI_SCENARIOS (per map, default 300; 0 = all), VNSBA_COMPARE_DIR (where the two
# builds and the CSV files go; default a temporary folder, removed afterwards), VNSBA_PLANNERS
# (comma-separated, default all). About 10-15 minutes on 2 cores for two fresh builds and 300
# scenarios per map.
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  sed -n '2,21p' "$0" >&2
  exit 2
fi
base=$1
head=${2:-}
data=${VNSBA_DATA_DIR:-$(cd "$root/.." && pwd)/shared/data}
scenarios=${VNSBA_MOVINGAI_SCENARIOS:-300}
if [ ! -d "$data/movingai" ]; then
  echo "compare_outputs: no Moving AI data in $data/movingai (set VNSBA_DATA_DIR)" >&2
  exit 2
fi
if [ -n "${VNSBA_COMPARE_DIR:-}" ]; then
  work=$VNSBA_COMPARE_DIR
  mkdir -p "$work"
else
  work=$(mktemp -d)
  trap 'git -C "$root" worktree remove --force "$work/base-src" >/dev/null 2>&1 || true;
        git -C "$root" worktree remove --force "$work/head-src" >/dev/null 2>&1 || true;
        rm -rf "$work"' EXIT
fi

# Builds vnsba_bench from the revision $1 (or the work tree when empty) into $work/$2.
build_bench() {
  revision=$1
  name=$2
  if [ -n "$revision" ]; then
    src="$work/$name-src"
    git -C "$root" worktree remove --force "$src" >/dev/null 2>&1 || true
    git -C "$root" worktree add --detach "$src" "$revision" >/dev/null
  else
    src=$root
  fi
  echo "building vnsba_bench at ${revision:-the work tree} ..." >&2
  cmake -S "$src" -B "$work/$name-build" -DCMAKE_BUILD_TYPE=Release -DVNSBA_CORE_ONLY=ON \
    -DVNSBA_BUILD_TESTS=OFF -DVNSBA_BUILD_BENCH=ON -DVNSBA_DATA_DIR="$data" >/dev/null
  cmake --build "$work/$name-build" --target vnsba_bench vnsba_plan -j"$(nproc)" >/dev/null
}

# Every cost-aware planner on a few scenario lines per map, each run's record without its time.
run_cost_records() {
  name=$1
  plan="$work/$name-build/tools/vnsba_plan"
  out="$work/$name-records"
  rm -rf "$out"
  mkdir -p "$out"
  echo "running $name's vnsba_plan, cost-aware, on $cost_scenarios lines per map ..." >&2
  for scen in "$data"/movingai/*.map.scen; do
    map=${scen%.scen}
    lines=$(($(wc -l < "$scen") - 1))
    step=$((lines / cost_scenarios))
    [ "$step" -ge 1 ] || step=1
    index=0
    while [ "$index" -lt "$lines" ] && [ "$index" -lt $((step * cost_scenarios)) ]; do
      for planner in astar weighted_astar bidirectional_astar alternating_bidirectional_astar \
        vns_bastar; do
        for smoother in $smoothers; do
          record="$out/$(basename "$map")-$index-$planner-$smoother.json"
          flag=""
          [ "$smoother" = "default" ] || flag="--smoother $smoother"
          # shellcheck disable=SC2086
          "$plan" "$map" --scen "$scen" --scen-index "$index" --planner "$planner" --prune --smooth \
            --cost-weight 2 --inflation-radius 11 --cost-scaling-factor 0.15 $flag \
            --json "$record" >/dev/null 2>&1 || echo "failed" > "$record"
          sed -i '/"planning_time_us"/d' "$record"
        done
      done
      index=$((index + step))
    done
  done
}

# Runs every planner on the scenarios and keeps all columns but the last (the time).
run_bench() {
  name=$1
  echo "running $name on $scenarios scenarios per map ..." >&2
  set -- movingai --maps "$data/movingai" --max-scenarios "$scenarios" --csv
  if [ -n "${VNSBA_PLANNERS:-}" ]; then set -- "$@" --planners "$VNSBA_PLANNERS"; fi
  "$work/$name-build/tools/vnsba_bench" "$@" | sed 's/,[^,]*$//' > "$work/$name.csv"
}

build_bench "$base" base
build_bench "$head" head
run_bench base
run_bench head

cost_scenarios=${VNSBA_COST_SCENARIOS:-8}
# The smoother settings both revisions know: none and relax, or the one default of an older one.
smoothers=default
if "$work/base-build/tools/vnsba_plan" --help 2>/dev/null | grep -q -- '--smoother ' &&
  "$work/head-build/tools/vnsba_plan" --help 2>/dev/null | grep -q -- '--smoother '; then
  smoothers="none relax"
fi
run_cost_records base
run_cost_records head

status=0
rows=$(($(wc -l < "$work/base.csv") - 1))
if cmp -s "$work/base.csv" "$work/head.csv"; then
  echo "identical: $rows plans (map, scenario, planner: status, raw cost, length, turns, turn angle, expanded)"
else
  changed=$(diff "$work/base.csv" "$work/head.csv" | grep -c '^>' || true)
  echo "DIFFERENT: $changed of $rows rows changed; first differences (< ${base}, > ${head:-work tree}):"
  diff "$work/base.csv" "$work/head.csv" | head -20
  status=1
fi
records=$(find "$work/base-records" -name '*.json' | wc -l)
if diff -r -q "$work/base-records" "$work/head-records" >/dev/null; then
  echo "identical: $records cost-aware run records (path, waypoints, metrics, expansions; not the time)"
else
  echo "DIFFERENT cost-aware run records (< ${base}, > ${head:-work tree}):"
  diff -r -q "$work/base-records" "$work/head-records" | head -10
  status=1
fi
exit "$status"
