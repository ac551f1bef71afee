// Polyline pruning (paper 3.3) and local cubic-spline corner smoothing (paper 3.4), usable after
// any planner. ALGORITHM.md sections 4 and 5. All coordinates are continuous cell coordinates.
#pragma once

#include <vector>

#include "vnsba/core/budget.hpp"
#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"

namespace vnsba::core {

// Turning points of a grid path: keeps P[0], then each P[i-1] where line of sight from the
// current anchor to P[i] first fails, then P[k]. The result is a subsequence of the input
// (as cell centres), collision-free by construction. An empty input gives an empty output.
// With a `budget` that expires part-way (polled once per line-of-sight check) the result is
// empty and budget->state() says why.
std::vector<Point2> prune_path(const GridMap& map, const std::vector<Cell>& path,
                               CornerPolicy policy, PlanningBudget* budget = nullptr);

struct SmoothingOptions {
  double smoothing_distance = 1.5;  // cells: the d of section 5 before the |TA|/4, |TB|/4 caps
  double sample_step = 0.25;        // cells: the largest gap between spline samples
  int max_halvings = 3;             // retries with d halved before keeping the sharp corner
  CornerPolicy corner_policy = CornerPolicy::kNever;
};

// Replaces each interior corner T of `waypoints` by samples of a clamped parametric cubic
// spline through P1..P4 (chord-length parameter), keeping straight sections straight. A corner
// whose smoothed version fails line of sight after max_halvings retries stays sharp, so the
// result never enters a blocked cell when the input does not. With a `budget` that expires
// part-way (polled once per corner attempt) the result is empty and budget->state() says why.
std::vector<Point2> smooth_path(const GridMap& map, const std::vector<Point2>& waypoints,
                                const SmoothingOptions& options, PlanningBudget* budget = nullptr);

}  // namespace vnsba::core
