#!/usr/bin/env bash
# How far a cost-seeing heuristic built from obstacle distances gets cost-aware A* (issue 15's
# target: at most 1.3x binary A*'s time). An experiment, not part of the planner.
#
# Builds vnsba_bench from the current commit with bench/cost_bound_heuristic.patch applied, in a
# temporary worktree, and runs `vnsba_bench costs --planners astar` twice on the same queries:
# with the octile heuristic (as shipped) and with VNSBA_COST_BOUND_HEURISTIC set, where A* adds
# cost_weight x a lower bound on the gradient cost any path must pay near its two ends (see the
# comment in the patch: admissible and consistent, so the costs stay optimal). Compare the
# "expanded ratio" columns: the heuristic's reach does not depend on how fast it is evaluated.
#   bench/cost_bound_heuristic.sh [MAPS_DIR] [SCENARIOS_PER_MAP]
# Defaults: ../shared/data/movingai beside the repository, 40 scenarios a map.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
maps=${1:-$repo/../shared/data/movingai}
per_map=${2:-40}
[[ -d $maps ]] || { echo "cost_bound_heuristic: no Moving AI maps at $maps" >&2; exit 2; }
maps=$(cd "$maps" && pwd)
work=$(mktemp -d)
trap 'git -C "$repo" worktree remove --force "$work/tree" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
git -C "$repo" worktree add --detach "$work/tree" HEAD >/dev/null
git -C "$work/tree" apply "$repo/bench/cost_bound_heuristic.patch"
cmake -S "$work/tree" -B "$work/build" -DCMAKE_BUILD_TYPE=Release -DVNSBA_CORE_ONLY=ON \
  -DVNSBA_BUILD_TESTS=OFF >/dev/null
cmake --build "$work/build" -j "$(nproc)" --target vnsba_bench >/dev/null
bench="$work/build/tools/vnsba_bench"
for heuristic in octile cost_bound; do
  echo "## cost-aware A* with the $heuristic heuristic"
  if [[ $heuristic == cost_bound ]]; then export VNSBA_COST_BOUND_HEURISTIC=1; fi
  "$bench" costs --maps "$maps" --planners astar --max-scenarios "$per_map" --repetitions 1 \
    2>/dev/null | sed -n '/^| class/,$p'
done
