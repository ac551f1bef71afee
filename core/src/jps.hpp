// Online Jump Point Search on the 8-connected grid without corner cutting (internal).
//
// Harabor & Grastien, "Online Graph Pruning for Pathfinding on Grid Maps" (AAAI 2011), with two
// ideas of their "Improving Jump Point Search" (ICAPS 2014): straight jumps decide 56 cells per
// 8-byte read of the map's bit lines (GridMap::blocked_rows / blocked_columns), and the jump
// points found by the straight jumps that a diagonal launches become successors of the diagonal's
// origin directly (intermediate diagonal jump points enter the open list only where a long walk
// leads away from the goal, see jps.cpp). Same moves, step costs and path costs as A* with
// Neighborhood::kEight and CornerPolicy::kNever; far fewer expansions.
#pragma once

#include <cstdint>
#include <vector>

#include "search_space.hpp"
#include "vnsba/core/budget.hpp"
#include "vnsba/core/grid_map.hpp"

namespace vnsba::core::detail {

struct JpsOutcome {
  StatusCode code = StatusCode::kNoValidPath;  // kOk, kNoValidPath, kTimeout or kCanceled
  // Every cell from start to goal inclusive: 8-connected, no diagonal step past a blocked cell.
  std::vector<Cell> path;
  int64_t expanded = 0;  // jump points popped from the open list
};

// Online JPS from `start` to `goal` on the 8-connected grid where a diagonal move needs both
// orthogonal side cells free (CornerPolicy::kNever). Step costs are those of every search
// (neighborhood.hpp: 1 and sqrt 2 quantized to 2^-26 cells), the heuristic is octile(), so the
// path's cost equals A*'s bit for bit.
//
// Both cells must be in the map and free (kInternalError otherwise: the caller checks the query);
// start == goal gives the one-cell path. `space` is reused across queries (this begins a query on
// it): a record per jump point touched, so the memory grows with the search, not the map. The
// budget is polled once per expansion and once per cell a diagonal walk visits (one expansion can
// walk the whole map); when it runs out the search stops with its code (kTimeout, kCanceled).
// `expanded_cells` may be null; when not, the popped jump points are appended to it in order.
//
// Allocates per query only the result path, what `expanded_cells` grows by, and `space`'s
// records where this query touches more cells than any before it.
JpsOutcome jps_search(const GridMap& map, SparseSearchSpace& space, const Cell& start,
                      const Cell& goal, PlanningBudget& budget, std::vector<Cell>* expanded_cells);

}  // namespace vnsba::core::detail
