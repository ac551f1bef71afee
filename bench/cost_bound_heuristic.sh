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
here=$(cd "$(dirname "$0")" && pwd)
per_map=${2:-40}
source "$here/patched_bench.sh" cost_bound_heuristic cost_bound_heuristic.patch "${1:-$here/../../shared/data/movingai}"
compare_with_variable VNSBA_COST_BOUND_HEURISTIC "cost-aware A* with the octile heuristic" \
  "cost-aware A* with the cost_bound heuristic" \
  costs --maps "$maps" --planners astar --max-scenarios "$per_map" --repetitions 1
