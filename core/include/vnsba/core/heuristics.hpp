// Distances and heuristics of docs/algorithm.md sections 3 and 6. Inline: they run once per pushed
// node in every search.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"
#include "vnsba/core/neighborhood.hpp"

namespace vnsba::core {

// Length of the shortest 8-connected path on an empty grid, in cells, in the searches' step
// costs (neighborhood.hpp: sqrt 2 quantized), so that A*'s f = g + octile is exact and equal-cost
// nodes tie exactly; within a relative 1e-8 of the Euclidean octile distance.
inline double octile(const Cell& a, const Cell& b) {
  const double dx = std::abs(a.x - b.x), dy = std::abs(a.y - b.y);
  return dx + dy + (detail::kStepCostDiagonal - 2.0) * std::min(dx, dy);
}

// dist(a, b) of the paper (section 2): Euclidean when a and b have line of sight, Manhattan
// otherwise, in cells. `blocked_between` must be map.blocked_in_rect(a, b); it settles most cases
// without a traversal: an all-free rectangle means line of sight, and for an axis-aligned pair the
// two distances are equal. Same value as the definition, only cheaper.
inline double switching_distance(const GridMap& map, const Cell& a, const Cell& b,
                                 int64_t blocked_between, CornerPolicy policy) {
  const double dx = std::abs(a.x - b.x), dy = std::abs(a.y - b.y);
  if (dx == 0.0 || dy == 0.0) return dx + dy;
  const double euclid = std::sqrt(dx * dx + dy * dy);
  return line_of_sight_in_map(map, a, b, blocked_between, policy) ? euclid : dx + dy;
}

inline double switching_distance(const GridMap& map, const Cell& a, const Cell& b,
                                 CornerPolicy policy) {
  return switching_distance(map, a, b, map.blocked_in_rect(a, b), policy);
}

// h(n) = exp(rho) * (omega * dist(n, opposite_current) + eta * dist(n, opposite_start)), rho the
// obstacle density of the rectangle spanned by n and opposite_current (both included).
// With eta = 0 and opposite_current fixed at the goal this is the improved A* of Liao et al.;
// with eta = 0 and the opposite search's current node, the improved BA* of Li et al.; with both
// weights, VNS-BA*. A zero weight skips its distance entirely.
inline double density_weighted_heuristic(const GridMap& map, const Cell& n,
                                         const Cell& opposite_current, const Cell& opposite_start,
                                         double omega, double eta, CornerPolicy policy) {
  const int64_t blocked = map.blocked_in_rect(n, opposite_current);
  const double area =
      (std::abs(n.x - opposite_current.x) + 1.0) * (std::abs(n.y - opposite_current.y) + 1.0);
  double p = 0.0;
  if (omega != 0.0) p += omega * switching_distance(map, n, opposite_current, blocked, policy);
  if (eta != 0.0) p += eta * switching_distance(map, n, opposite_start, policy);
  return std::exp(static_cast<double>(blocked) / area) * p;
}

}  // namespace vnsba::core
