#include "vnsba/core/motion_validator.hpp"

#include <algorithm>
#include <limits>
#include <optional>

#include "vnsba/core/metrics.hpp"

namespace vnsba::core {

double MotionValidator::segment_cost(const Point2& a, const Point2& b) const {
  const double length = (b - a).norm();
  if (cost_weight_ == 0.0) {
    return segment_valid(a, b) ? length : std::numeric_limits<double>::infinity();
  }
  const std::optional<double> highest = max_cost_along(*map_, a, b, policy_);
  if (!highest) return std::numeric_limits<double>::infinity();
  return length * (1.0 + cost_weight_ * *highest);
}

double MotionValidator::path_cost(const std::vector<Point2>& polyline) const {
  double total = 0.0;
  for (size_t i = 1; i < polyline.size(); ++i) total += segment_cost(polyline[i - 1], polyline[i]);
  return total;
}

// Most of a path lies far from anything blocked, and there metrics.hpp's segment_clearance_bound
// answers both questions: it bounds the clearance, and also the distance from the centre of every
// cell the segment touches (or passes at a corner) to an obstacle's centre, so above the robot's
// radius in cells none of those cells is inflated. Near obstacles (and within a cell of the map's
// edge) the exact line of sight and segment_clearance_at_least decide, and so they do everywhere
// on a map with blocked cells that are no obstacles (unknown cells not inflated), which the
// distance transform does not see.
bool MotionValidator::segment_keeps_clearance(const Point2& a, const Point2& b) const {
  // The map's border counts as blocked, and the distance transform does not see it: the bound
  // decides only for segments at least a cell inside the map.
  const GridMap& map = *map_;
  const double low_x = std::min(a.x(), b.x()), high_x = std::max(a.x(), b.x());
  const double low_y = std::min(a.y(), b.y()), high_y = std::max(a.y(), b.y());
  if (bound_decides_ && low_x >= 1.0 && low_y >= 1.0 && high_x <= map.width() - 1.0 &&
      high_y <= map.height() - 1.0) {
    const double bound = segment_clearance_bound(map, a, b);
    if (bound > inflated_within_ && bound >= clearance_floor_) return true;
  }
  return segment_valid(a, b) && segment_clearance_at_least(map, a, b, clearance_floor_);
}

}  // namespace vnsba::core
