// The paper's five metrics plus the length ratio (docs/algorithm.md section 7).
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
  // The search alone (from the first node opened to the grid path traced), steady clock, to the
  // fraction of a microsecond: what a reference search that builds no path is compared with.
  double search_time_us = 0.0;
  // final length / optimal A* cost on the same query; NaN unless compute_length_ratio was set.
  double length_ratio = std::numeric_limits<double>::quiet_NaN();
  // The final path's smallest distance to an obstacle (docs/algorithm.md section 8), metres; +inf
  // on a map without obstacles. NaN on failures.
  double clearance_m = std::numeric_limits<double>::quiet_NaN();
};

// The smallest distance, in cells, from any point of `polyline` (continuous cell coordinates) to
// the square of an obstacle cell (GridMap::is_obstacle: occupied, and unknown with
// inflate_unknown; inflation is not an obstacle). +inf when the map has no obstacle or the polyline
// is empty. Exact: the distance from each segment itself, the limit of the sampling that
// docs/algorithm.md section 8 allows (points at most 0.1 cell apart, which can only overstate it,
// by up to 0.05 cell). A grid path that passes an obstacle side on is answered by that obstacle
// (no straight run with line of sight comes nearer); otherwise the distance transform, or scans
// of growing reach, bound which obstacles can be nearest, and only those are measured, about once
// per cell of the path's length.
double path_clearance_cells(const GridMap& map, const std::vector<Point2>& polyline);

// path_clearance_cells of the cells' centres, the same number, without making the polyline where
// the path passes an obstacle side on (Planner::plan's final path when it is the grid path).
double grid_path_clearance_cells(const GridMap& map, const std::vector<Cell>& cells);

// The distance (cells) from the centre of `c` to the nearest obstacle centre (GridMap::is_obstacle,
// inflation not counted): 0 on an obstacle, exact (the square root of an integer) whenever it is at
// most `within` cells; +inf when the map has no obstacle, when `c` is outside it, or (possibly)
// when the distance exceeds `within`. A local search on the bit grids, squares of doubling
// half-width around c: O(d^2 / 64) words for a distance d, with or without the distance field.
double nearest_obstacle_distance(const GridMap& map, const Cell& c,
                                 double within = std::numeric_limits<double>::infinity());

// A lower bound, in cells, of the segment a -> b's distance to every obstacle square, from the
// distance field alone (no scan; -1, no bound, on a map without the field): every point of the
// segment lies within |ab| / 2 of a or b, each |p - centre| from its cell's centre, whose centre
// is at least GridMap::obstacle_distance_at_least from the nearest obstacle's centre, and that
// obstacle's square reaches sqrt(1/2) closer. The same number bounds the distance from the centre
// of any cell the segment touches (or passes at a corner) to an obstacle's centre, since that
// centre lies within sqrt(1/2) of the segment. -1 when an end lies outside the map. O(1).
double segment_clearance_bound(const GridMap& map, const Point2& a, const Point2& b);

// Whether the segment a -> b (continuous cell coordinates) keeps at least `cells` from every
// obstacle square, measured as path_clearance_cells measures it (the same scan of the bit lines
// within `cells` of the segment, after segment_clearance_bound). For short segments (the relax
// smoother's), where path_clearance_cells' set-up would dominate.
bool segment_clearance_at_least(const GridMap& map, const Point2& a, const Point2& b, double cells);

constexpr double kTurnEpsilonRad = 1e-6;

struct TurnStats {
  int32_t turns = 0;
  double total_angle_deg = 0.0;
};

// Turns and total turn angle of a polyline (see Metrics::turns).
TurnStats turn_stats(const std::vector<Point2>& polyline);

// The corners of a densely sampled path: its Douglas-Peucker simplification, every dropped point
// within `tolerance` of the kept chord that replaces it (same units as the points). What turns
// are counted on for a relaxed path, whose points follow a curve rather than turn at corners:
// kRelaxedCornerToleranceCells, so a corner the curve rounds counts as about one turn.
std::vector<Point2> simplify_polyline(const std::vector<Point2>& polyline, double tolerance);
inline constexpr double kRelaxedCornerToleranceCells = 0.5;

// The largest discrete curvature of a polyline, per unit of its points: at each interior vertex
// the heading change (radians) over the mean length of its two segments (the curvature of the
// circle a controller would drive there); 0 for fewer than 3 points. A sharp corner between long
// segments shows a small value: it is the path a controller must round, not a bound.
double max_curvature(const std::vector<Point2>& polyline);

}  // namespace vnsba::core
