// Polyline pruning (paper 3.3) and local cubic-spline corner smoothing (paper 3.4), usable after
// any planner. docs/algorithm.md sections 4 and 5. All coordinates are continuous cell coordinates.
#pragma once

#include <vector>

#include "vnsba/core/budget.hpp"
#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"

namespace vnsba::core {

// The cost model of docs/algorithm.md section 8 for a polyline (continuous cell coordinates): the
// sum over its segments of MotionValidator::segment_cost (motion_validator.hpp), each its length
// * (1 + cost_weight * the highest cell cost along it); +inf when one lacks line of sight. With
// cost_weight 0, the length. The searches price their moves the same way.
double path_cost(const GridMap& map, const std::vector<Point2>& polyline, double cost_weight,
                 CornerPolicy policy);

// Turning points of a grid path: keeps P[0], then each P[i-1] where line of sight from the
// current anchor to P[i] first fails, then P[k]. The result is a subsequence of the input
// (as cell centres), collision-free by construction. An empty input gives an empty output.
// With a `budget` that expires part-way (polled once per line-of-sight check) the result is
// empty and budget->state() says why. With cost_weight > 0 a shortcut also has to cost no more
// than the stretch of grid path it replaces (docs/algorithm.md section 8), so pruning never makes
// the path dearer; with 0 that holds by the triangle inequality and nothing else is checked.
std::vector<Point2> prune_path(const GridMap& map, const std::vector<Cell>& path,
                               CornerPolicy policy, PlanningBudget* budget = nullptr,
                               double cost_weight = 0.0);

// The path's exact ends (docs/algorithm.md section 8): `waypoints` run between cell centres, the
// final path must begin at `start` and end at `goal` (continuous cell coordinates, each inside the
// cell of the first / last waypoint: a requested point, or the centre itself). Puts `start` in
// front of the first waypoint and `goal` after the last (a segment inside one free cell: always
// clear); then, with `drop_centres` (pruning on), removes the first centre when the segment from
// `start` to the waypoint after it has line of sight and costs no more than the two it replaces
// (the pruning rule, costs as path_cost's with `cost_weight`), and likewise the last centre before
// `goal`. A point equal to its centre adds nothing, so a path between centres is returned as is.
std::vector<Point2> join_exact_ends(const GridMap& map, std::vector<Point2> waypoints,
                                    const Point2& start, const Point2& goal, CornerPolicy policy,
                                    double cost_weight, bool drop_centres);

struct SmoothingOptions {
  double smoothing_distance = 1.5;  // cells: the d of section 5 before the |TA|/4, |TB|/4 caps
  double sample_step = 0.25;        // cells: the largest gap between spline samples
  int max_halvings = 3;             // retries with d halved before keeping the sharp corner
  CornerPolicy corner_policy = CornerPolicy::kNever;
  // > 0: a corner's curve is kept only when it costs no more than the two leg pieces it
  // replaces (docs/algorithm.md section 8); 0: section 5 as it stands.
  double cost_weight = 0.0;
};

// Replaces each interior corner T of `waypoints` by samples of a clamped parametric cubic
// spline through P1..P4 (chord-length parameter), keeping straight sections straight. A corner
// whose smoothed version fails line of sight after max_halvings retries stays sharp, so the
// result never enters a blocked cell when the input does not. With a `budget` that expires
// part-way (polled once per corner attempt) the result is empty and budget->state() says why.
std::vector<Point2> smooth_path(const GridMap& map, const std::vector<Point2>& waypoints,
                                const SmoothingOptions& options, PlanningBudget* budget = nullptr);

// The relax smoother (planner.smoother: relax): an elastic band in the spirit of Nav2's Simple and
// Constrained smoothers, run on any planner's final path (after pruning, the exact ends and the
// paper's corner smoothing). The path is first compacted as the result is at the end (a smoothed
// corner's samples, 0.25 cells apart, become about one a cell) and given a point at least every
// kRelaxSpacingCells; then, `iterations` times at most, each interior point in turn
// (Gauss-Seidel: its predecessor has already moved) is moved by
//   smoothness * (previous + next - 2 * point)        toward its neighbours' middle (above 0.5:
//                                                     over-relaxed, which straightens long
//                                                     stretches in fewer iterations),
// + closeness  * (its planned position - point)        back toward the path the planner found,
// - cost * cost_weight * (the gradient of cell cost)   down the cost gradient (costs interpolated
//                                                     bilinearly between cell centres, blocked
//                                                     cells counting 1),
// at most kRelaxMaxStepCells. A move is kept only when both segments at the point keep line of
// sight (`corner_policy`) and a clearance of at least `min_clearance_cells` (metrics.hpp
// segment_clearance_at_least; the caller passes the input's path_clearance_cells, or less);
// otherwise half the step is tried, then a quarter, then the point stays. So the result never
// enters a blocked cell, never comes closer to an obstacle than that, and keeps both ends exactly
// (path_clearance_cells of the result may still differ from that bound in its last bits: the
// caller compares the two when it must be exact). It stops early once no point moved more than
// kRelaxSettledCells in an iteration. Compaction: a run of points within kRelaxCompactCells of the
// chord that would replace them is dropped where that chord passes the same checks.
struct RelaxOptions {
  // The defaults are PlannerOptions' (planner_options.hpp, which gives the ranges).
  double smoothness = 0.9;
  double closeness = 0.0;
  double cost = 0.1;         // scales cost_weight
  double cost_weight = 0.0;  // the plan's (0, or a map without costs: no cost term)
  int iterations = 10;
  CornerPolicy corner_policy = CornerPolicy::kNever;
};
inline constexpr double kRelaxSpacingCells = 2.0;
inline constexpr double kRelaxMaxStepCells = 0.5;
inline constexpr double kRelaxSettledCells = 1e-3;
inline constexpr double kRelaxCompactCells = 0.1;

// `path`: continuous cell coordinates, the ends first and last. With a `budget` that expires
// part-way (polled once per point visited) the result is empty and budget->state() says why. Paths
// of fewer than 3 points come back as they are.
std::vector<Point2> relax_path(const GridMap& map, const std::vector<Point2>& path,
                               const RelaxOptions& options, double min_clearance_cells,
                               PlanningBudget* budget = nullptr);

}  // namespace vnsba::core
