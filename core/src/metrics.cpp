#include "vnsba/core/metrics.hpp"

#include <cmath>

namespace vnsba::core {

TurnStats turn_stats(const std::vector<Point2>& polyline) {
  TurnStats stats;
  for (size_t i = 1; i + 1 < polyline.size(); ++i) {
    const double change = std::abs(heading_change(polyline[i - 1], polyline[i], polyline[i + 1]));
    if (change > kTurnEpsilonRad) {
      ++stats.turns;
      stats.total_angle_deg += change * 180.0 / M_PI;
    }
  }
  return stats;
}

}  // namespace vnsba::core
