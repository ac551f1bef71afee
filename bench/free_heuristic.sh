#!/usr/bin/env bash
# What VNS-BA* would cost with a heuristic that costs nothing: the ceiling of any speed-up of its
# heuristic (line of sight, summed-area table, exp) that keeps the results identical.
#
# Builds vnsba_bench from the current commit with bench/free_heuristic.patch applied,
# in a temporary worktree, and runs `vnsba_bench movingai` twice on the same queries: as is, and
# with VNSBA_REPLAY_HEURISTIC set, where every VNS-BA* query is first planned untimed to record
# its heuristic values and then timed while replaying them in the same order (same expansions,
# same paths; the replay costs one array read per value). Pruning and smoothing stay on.
#   bench/free_heuristic.sh [MAPS_DIR] [SCENARIOS_PER_MAP]
# Defaults: ../shared/data/movingai beside the repository, 300 scenarios a map.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
per_map=${2:-300}
source "$here/patched_bench.sh" free_heuristic free_heuristic.patch "${1:-$here/../../shared/data/movingai}"
compare_with_variable VNSBA_REPLAY_HEURISTIC "VNS-BA* heuristic as_is" "VNS-BA* heuristic replayed" \
  movingai --maps "$maps" --planners astar,vns_bastar --max-scenarios "$per_map"
