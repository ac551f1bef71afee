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
#
# Then the cost-aware side: vnsba_plan --json of each revision on VNSBA_COST_SCENARIOS (default 8)
# scenario lines per map, every cost-aware planner with pruning and smoothing, on the map with
# config/default.yaml's gradient and cost weight (in cells: inflation_radius 11, scaling 0.15 per
# cell, as `vnsba_bench costs` reads Moving AI maps), once with the smoother off and, where both
# revisions have it, once with `--smoother relax` (its every segment check is a line of sight):
# the whole run record (raw path, pruned waypoints, path, metrics, each search's expansions in
# order, meeting cell) but the planning time must be byte-identical.
#
# Then the time, from the same CSV runs: each revision's vnsba_bench runs VNSBA_TIME_RUNS times
# (default 2), in turns (BASE, HEAD, BASE, HEAD ...), and for each planner the script prints the
# median over queries of (HEAD's time / BASE's time on that query), each side's time being the
# fastest of its runs of the query (a plan slowed by the machine's other work counts least), with
# the 10th and 90th percentiles of those ratios. Under 1: HEAD is faster. The first run's outputs
# are the ones compared above; every run's must match them.
#
# A revision whose vnsba_plan has `--vns-threads` (the short-lived two-thread VNS-BA*, removed
# since: it could hang) gets `--vns-threads 1`, and its records' vns_threads key is dropped. One
# whose vnsba_plan has `--paper` (without it, default.yaml since issue 45) gets `--paper`.
#
# Exit 0 when every row is identical, 1 when any differs (the first differences are printed) or a
# run fails, 2 on bad use. Environment: VNSBA_DATA_DIR (default ../shared/data beside the
# project), VNSBA_MOVINGAI_SCENARIOS (per map, default 300; 0 = all), VNSBA_COMPARE_DIR (where the
# two builds and the CSV files go; default a temporary folder, removed afterwards),
# VNSBA_PLANNERS (comma-separated, default all), VNSBA_TIME_RUNS (above). About 15-20
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
    commit=$(git -C "$root" rev-parse --verify "$revision^{commit}")
    # A VNSBA_COMPARE_DIR kept from an earlier run at the same commit is reused as it is, so
    # that its build is up to date.
    if [ "$(git -C "$src" rev-parse HEAD 2>/dev/null || true)" != "$commit" ]; then
      git -C "$root" worktree remove --force "$src" >/dev/null 2>&1 || true
      git -C "$root" worktree add --detach "$src" "$commit" >/dev/null
    fi
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
  revision_flags=""  # what this revision needs to plan as the other: see above
  if "$plan" --help 2>/dev/null | grep -q -- '--vns-threads'; then revision_flags=" --vns-threads 1"; fi
  # Revisions with --paper read default.yaml without it: --paper keeps the bare setting that
  # older revisions plan on without a config, the flags below adding the same costs to both.
  if "$plan" --help 2>/dev/null | grep -q -- '--paper'; then revision_flags="$revision_flags --paper"; fi
  out="$work/$name-records"
  rm -rf "$out"
  mkdir -p "$out"
  echo "running $name's vnsba_plan${revision_flags:+$revision_flags}, cost-aware, on $cost_scenarios lines per map ..." >&2
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
            --cost-weight 2 --inflation-radius 11 --cost-scaling-factor 0.15 $flag $revision_flags \
            --json "$record" >/dev/null 2>&1 || echo "failed" > "$record"
          # Without the time, and without the thread count a two-thread-era record names; a comma
          # left before a closing bracket by that goes too.
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

# Runs every planner on the scenarios into $work/$name$2.raw.csv ($2: the run's suffix).
run_bench() {
  name=$1
  suffix=${2:-}
  run_number=${suffix#.}
  echo "running $name's vnsba_bench on $scenarios scenarios per map (run ${run_number:-1}) ..." >&2
  set -- movingai --maps "$data/movingai" --max-scenarios "$scenarios" --csv
  if [ -n "${VNSBA_PLANNERS:-}" ]; then set -- "$@" --planners "$VNSBA_PLANNERS"; fi
  if ! "$work/$name-build/tools/vnsba_bench" "$@" > "$work/$name$suffix.raw.csv"; then
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

# $1's rows, only the columns named in $2 (in that order).
select_columns() {
  awk -F, -v want="$2" '
    NR == 1 { n = split(want, w, ","); for (i = 1; i <= NF; ++i) at[$i] = i }
    { row = ""
      for (k = 1; k <= n; ++k) row = row (k > 1 ? "," : "") $(at[w[k]])
      print row }' "$1"
}

build_bench "$base" base
build_bench "$head" head

time_runs=${VNSBA_TIME_RUNS:-2}
case $time_runs in
  [1-9]) ;;
  *)
    echo "compare_outputs: VNSBA_TIME_RUNS must be 1..9, got '$time_runs'" >&2
    exit 2
    ;;
esac
run_bench base
run_bench head
run=2
while [ "$run" -le "$time_runs" ]; do
  run_bench base ".$run"
  run_bench head ".$run"
  run=$((run + 1))
done
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
run_cost_records base
run_cost_records head

status=0
rows=$(($(wc -l < "$work/base.csv") - 1))
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
# Every further run gave the first run's outputs.
run=2
while [ "$run" -le "$time_runs" ]; do
  for side in base head; do
    select_columns "$work/$side.$run.raw.csv" "$columns" > "$work/$side.$run.csv"
    if ! cmp -s "$work/$side.csv" "$work/$side.$run.csv"; then
      echo "DIFFERENT: $side's run $run gave other outputs than its run 1 (a nondeterministic plan)"
      status=1
    fi
  done
  run=$((run + 1))
done

# Time per query: HEAD / BASE, each the fastest of its runs, per planner (see the header).
echo "time per query, ${head:-work tree} / $base: median of per-query ratios (p10, p90) over $time_runs run(s) each, the fastest run of each query"
cat "$work"/base*.raw.csv | awk -F, -v side=base '{ print side "," $0 }' > "$work/times.csv"
cat "$work"/head*.raw.csv | awk -F, -v side=head '{ print side "," $0 }' >> "$work/times.csv"
awk -F, '
  $2 == "map" { for (i = 2; i <= NF; ++i) at[$i] = i; next }
  { key = $(at["map"]) SUBSEP $(at["scenario"]) SUBSEP $(at["planner"]); t = $(at["time_us"]) + 0
    if (!((key, $1) in best) || t < best[key, $1]) best[key, $1] = t
    planner_of[key] = $(at["planner"]) }
  END {
    for (key in planner_of) {
      if (!((key, "base") in best) || !((key, "head") in best) || best[key, "base"] <= 0) continue
      r = best[key, "head"] / best[key, "base"]
      print planner_of[key], r
      print "(all_planners)", r
    }
  }' "$work/times.csv" | LC_ALL=C sort -k1,1 -k2,2g | awk '
  function flush() {
    if (m == 0) return
    mid = (m % 2) ? v[(m + 1) / 2] : (v[m / 2] + v[m / 2 + 1]) / 2
    printf "  %-34s %6d queries  %.3f  (%.3f, %.3f)\n", name, m, mid, v[int(0.1 * (m - 1)) + 1], v[int(0.9 * (m - 1)) + 1]
  }
  $1 != name { flush(); name = $1; m = 0 }
  { v[++m] = $2 }
  END { flush() }'

records=$(find "$work/base-records" -name '*.json' | wc -l)
if diff -r -q "$work/base-records" "$work/head-records" >/dev/null; then
  echo "identical: $records cost-aware run records (raw path, waypoints, path, metrics, expansions, meeting cell; not the time)"
else
  echo "DIFFERENT cost-aware run records (< ${base}, > ${head:-work tree}):"
  diff -r -q "$work/base-records" "$work/head-records" | head -10
  status=1
fi
exit "$status"
