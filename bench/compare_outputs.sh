#!/bin/sh
# Proves that a speed-up changes no output: builds vnsba_bench at two revisions, runs every
# planner on the same Moving AI scenarios with each (`vnsba_bench movingai --csv`), and compares
# every column both revisions' CSV have but the times (time_us, cpu_time_us: every column named
# *time_us), per scenario: status, raw grid path cost, final length, turns, turn angle, expanded
# nodes, clearance and, from the revision that added them on, the closed cells of each search
# (expanded_forward, expanded_backward) and a hash of their order, the meeting cell, and hashes of
# the grid path, the pruned waypoints and the final path (bench/movingai.hpp). A column only one
# revision writes is named and not compared.
#
#   bench/compare_outputs.sh BASE [HEAD]     # revisions; HEAD defaults to the work tree
#   bench/compare_outputs.sh 1a2b3c4 HEAD
#   VNSBA_HEAD_VNS_THREADS=2 bench/compare_outputs.sh BASE HEAD
#                                            # HEAD's VNS-BA* on two threads, BASE's on one
#
# Then the cost-aware side: vnsba_plan --json of each revision on VNSBA_COST_SCENARIOS (default 8)
# scenario lines per map, every cost-aware planner with pruning and smoothing, on the map with
# config/default.yaml's gradient and cost weight (in cells: inflation_radius 11, scaling 0.15 per
# cell, as `vnsba_bench costs` reads Moving AI maps), once with the smoother off and, where both
# revisions have it, once with `--smoother relax` (its every segment check is a line of sight):
# the whole run record (raw path, pruned waypoints, path, metrics, each search's expansions in
# order, meeting cell) but the planning time must be byte-identical.
#
# VNSBA_HEAD_VNS_THREADS=N (1 or 2) runs HEAD's VNS-BA* with vns_threads N: `--vns-threads N` to
# its vnsba_bench (which must have the option) and, where its vnsba_plan has the option, to that
# too (otherwise a line says its records keep its default). BASE then runs on one thread:
# vnsba_bench's default, and `--vns-threads 1` to its vnsba_plan where it has the option (a
# config's default may be 2). HEAD's two-thread rows are named vns_bastar+2threads; the
# comparison reads them as vns_bastar. So `VNSBA_HEAD_VNS_THREADS=2 compare_outputs.sh OLD NEW`
# proves that NEW on two threads gives OLD's single-thread outputs, row for row.
#
# Exit 0 when every row is identical, 1 when any differs (the first differences are printed) or a
# run fails, 2 on bad use. Environment: VNSBA_DATA_DIR (default ../shared/data beside the
# project), VNSBA_MOVINGAI_SCENARIOS (per map, default 300; 0 = all), VNSBA_COMPARE_DIR (where the
# two builds and the CSV files go; default a temporary folder, removed afterwards),
# VNSBA_PLANNERS (comma-separated, default all), VNSBA_HEAD_VNS_THREADS (above). About 15-20
# minutes on 2 cores for two fresh builds and 300 scenarios per map (each CSV row plans its query
# twice: timed, then untimed recording the expansions).
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
usage() { awk 'NR > 1 && /^#/ { print; next } NR > 1 { exit }' "$0" >&2; }
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  usage
  exit 2
fi
base=$1
head=${2:-}
head_threads=${VNSBA_HEAD_VNS_THREADS:-}
case $head_threads in
  "" | 1 | 2) ;;
  *)
    echo "compare_outputs: VNSBA_HEAD_VNS_THREADS must be 1 or 2, got '$head_threads'" >&2
    exit 2
    ;;
esac
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
# $2: extra flags of this side's vnsba_plan (its thread count).
run_cost_records() {
  name=$1
  threads_flag=$2
  plan="$work/$name-build/tools/vnsba_plan"
  out="$work/$name-records"
  rm -rf "$out"
  mkdir -p "$out"
  echo "running $name's vnsba_plan${threads_flag:+ $threads_flag}, cost-aware, on $cost_scenarios lines per map ..." >&2
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
            --cost-weight 2 --inflation-radius 11 --cost-scaling-factor 0.15 $flag $threads_flag \
            --json "$record" >/dev/null 2>&1 || echo "failed" > "$record"
          # Without the time, and without a thread count should a record name one (the thread
          # count changes no output); a comma left before a closing bracket by that goes too.
          awk '/"planning_time_us"|"vns_threads"/ { dropped = 1; next }
               { if (held_set) { if (dropped && $0 ~ /^[ \t]*[]}]/) sub(/,$/, "", held); print held }
                 held = $0; held_set = 1; dropped = 0 }
               END { if (held_set) print held }' "$record" > "$record.tmp"
          mv "$record.tmp" "$record"
        done
      done
      index=$((index + step))
    done
  done
}

# Runs every planner on the scenarios ($2: extra flags, the thread count) into $work/$name.raw.csv.
run_bench() {
  name=$1
  threads_flag=$2
  echo "running $name's vnsba_bench${threads_flag:+ $threads_flag} on $scenarios scenarios per map ..." >&2
  set -- movingai --maps "$data/movingai" --max-scenarios "$scenarios" --csv
  if [ -n "${VNSBA_PLANNERS:-}" ]; then set -- "$@" --planners "$VNSBA_PLANNERS"; fi
  # shellcheck disable=SC2086
  if ! "$work/$name-build/tools/vnsba_bench" "$@" $threads_flag > "$work/$name.raw.csv"; then
    echo "compare_outputs: $name's vnsba_bench movingai failed (above)" >&2
    exit 1
  fi
}

# Columns of $1's CSV header that $2's header has too, but the times (*time_us), comma-separated.
common_columns() {
  printf '%s\n' "$1" | awk -F, -v other="$2" '
    BEGIN { n = split(other, o, ","); for (i = 1; i <= n; ++i) in_other[o[i]] = 1 }
    { for (i = 1; i <= NF; ++i) if (($i in in_other) && $i !~ /time_us$/) printf "%s%s", (k++ ? "," : ""), $i
      print "" }'
}

# $1's rows, only the columns named in $2 (in that order); a planner named <name>+2threads (VNS-BA*
# on two threads) reads as <name>.
select_columns() {
  awk -F, -v want="$2" -v suffix="+2threads" '
    NR == 1 { n = split(want, w, ","); for (i = 1; i <= NF; ++i) at[$i] = i }
    { row = ""
      for (k = 1; k <= n; ++k) {
        v = $(at[w[k]])
        if (w[k] == "planner" && length(v) > length(suffix) &&
            substr(v, length(v) - length(suffix) + 1) == suffix)
          v = substr(v, 1, length(v) - length(suffix))
        row = row (k > 1 ? "," : "") v
      }
      print row }' "$1"
}

build_bench "$base" base
build_bench "$head" head

# The thread counts: HEAD's as asked, BASE on one thread (see the header).
base_bench_flag=""
head_bench_flag=""
base_plan_flag=""
head_plan_flag=""
if [ -n "$head_threads" ]; then
  if ! "$work/head-build/tools/vnsba_bench" movingai --help 2>/dev/null | grep -q -- '--vns-threads'; then
    echo "compare_outputs: VNSBA_HEAD_VNS_THREADS is set, but ${head:-the work tree}'s vnsba_bench has no --vns-threads" >&2
    exit 2
  fi
  head_bench_flag="--vns-threads $head_threads"
  if "$work/head-build/tools/vnsba_plan" --help 2>/dev/null | grep -q -- '--vns-threads'; then
    head_plan_flag="--vns-threads $head_threads"
  else
    echo "compare_outputs: ${head:-the work tree}'s vnsba_plan has no --vns-threads: its cost-aware records keep its default thread count" >&2
  fi
  if "$work/base-build/tools/vnsba_plan" --help 2>/dev/null | grep -q -- '--vns-threads'; then
    base_plan_flag="--vns-threads 1"
  fi
fi

run_bench base "$base_bench_flag"
run_bench head "$head_bench_flag"
base_header=$(head -n 1 "$work/base.raw.csv")
head_header=$(head -n 1 "$work/head.raw.csv")
columns=$(common_columns "$base_header" "$head_header")
only_one=$( (printf '%s\n' "$base_header" | tr , '\n'; printf '%s\n' "$head_header" | tr , '\n') |
  grep -v 'time_us$' | sort | uniq -u | tr '\n' ' ')
select_columns "$work/base.raw.csv" "$columns" > "$work/base.csv"
select_columns "$work/head.raw.csv" "$columns" > "$work/head.csv"

cost_scenarios=${VNSBA_COST_SCENARIOS:-8}
# The smoother settings both revisions know: none and relax, or the one default of an older one.
smoothers=default
if "$work/base-build/tools/vnsba_plan" --help 2>/dev/null | grep -q -- '--smoother ' &&
  "$work/head-build/tools/vnsba_plan" --help 2>/dev/null | grep -q -- '--smoother '; then
  smoothers="none relax"
fi
run_cost_records base "$base_plan_flag"
run_cost_records head "$head_plan_flag"

status=0
rows=$(($(wc -l < "$work/base.csv") - 1))
if [ -n "$head_threads" ]; then
  echo "VNS-BA*: ${head:-the work tree} with vns_threads $head_threads (vnsba_bench ${head_bench_flag}; vnsba_plan ${head_plan_flag:-its default}), $base with one thread"
fi
if [ -n "$only_one" ]; then
  echo "not compared (one revision's CSV only): $only_one"
fi
if cmp -s "$work/base.csv" "$work/head.csv"; then
  echo "identical: $rows plans, columns $columns"
else
  changed=$(diff "$work/base.csv" "$work/head.csv" | grep -c '^>' || true)
  echo "DIFFERENT: $changed of $rows rows changed; first differences (< ${base}, > ${head:-work tree}):"
  diff "$work/base.csv" "$work/head.csv" | head -20
  status=1
fi
records=$(find "$work/base-records" -name '*.json' | wc -l)
if diff -r -q "$work/base-records" "$work/head-records" >/dev/null; then
  echo "identical: $records cost-aware run records (raw path, waypoints, path, metrics, expansions, meeting cell; not the time)"
else
  echo "DIFFERENT cost-aware run records (< ${base}, > ${head:-work tree}):"
  diff -r -q "$work/base-records" "$work/head-records" | head -10
  status=1
fi
exit "$status"
