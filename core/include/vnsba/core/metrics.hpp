// The paper's five metrics plus the length ratio (ALGORITHM.md section 7).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"

namespace vnsba::core {

struct Metrics {
  double length_cells = 0.0;     // final path length in cells
  double length_m = 0.0;         // final path length in metres
  double raw_cost_cells = 0.0;   // cost of the grid path before pruning and smoothing, cells
  int32_t turns = 0;             // interior vertices of the polyline smoothing starts from
                                 // whose heading changes by more than kTurnEpsilonRad
  double turn_angle_deg = 0.0;   // sum of absolute heading changes at those vertices
  int64_t expanded = 0;          // nodes closed by all searches together
  int64_t planning_time_us = 0;  // search + post-processing, steady clock
  // final length / optimal A* cost on the same query; NaN unless compute_length_ratio was set.
  double length_ratio = std::numeric_limits<double>::quiet_NaN();
  // The final path's smallest distance to an obstacle (ALGORITHM.md section 8), metres; +inf on
  // a map without obstacles. NaN on failures.
  double clearance_m = std::numeric_limits<double>::quiet_NaN();
};

// The smallest distance, in cells, from any point of `polyline` (continuous cell coordinates) to
// the square of an obstacle cell (occupied or unknown: GridMap::obstacle_distance's cells;
// inflation is not an obstacle). +inf when the map has no obstacle or the polyline is empty.
// Exact: the distance from each segment itself, the limit of the sampling ALGORITHM.md section 8
// allows (points at most 0.1 cell apart, which can only overstate it, by up to 0.05 cell). The
// distance transform bounds which obstacles can be nearest, and only those are measured, about
// once per cell of the path's length.
double path_clearance_cells(const GridMap& map, const std::vector<Point2>& polyline);

constexpr double kTurnEpsilonRad = 1e-6;

struct TurnStats {
  int32_t turns = 0;
  double total_angle_deg = 0.0;
};

// Turns and total turn angle of a polyline (see Metrics::turns).
TurnStats turn_stats(const std::vector<Point2>& polyline);

}  // namespace vnsba::core
