#include "vnsba/core/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

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

namespace vnsba::core {

namespace {

constexpr double kSqrt2 = 1.4142135623730950488;

// Distance from p to the square [x, x + 1] x [y, y + 1] (cells).
double distance_to_square(const Point2& p, int32_t x, int32_t y) {
  const double dx = std::max({x - p.x(), 0.0, p.x() - (x + 1)});
  const double dy = std::max({y - p.y(), 0.0, p.y() - (y + 1)});
  return std::hypot(dx, dy);
}

bool is_obstacle(CellLayer layer) {
  return layer == CellLayer::kOccupied || layer == CellLayer::kUnknown;
}

}  // namespace

double path_clearance_cells(const GridMap& map, const std::vector<Point2>& polyline) {
  double best = std::numeric_limits<double>::infinity();
  if (polyline.empty() || map.cell_count() == 0) return best;
  // Consecutive samples mostly fall in the same cell, which shares its candidate obstacles.
  std::vector<Cell> candidates;
  std::optional<Cell> candidates_of;
  auto measure = [&](const Point2& p) {
    const Cell c{std::clamp(static_cast<int32_t>(std::floor(p.x())), 0, map.width() - 1),
                 std::clamp(static_cast<int32_t>(std::floor(p.y())), 0, map.height() - 1)};
    const double d = map.obstacle_distance(c);  // cells, centre of c to the nearest obstacle's
    if (!std::isfinite(d)) return;              // the map has no obstacle
    // A point of c is within sqrt 2 / 2 of c's centre, a square's points within sqrt 2 / 2 of its
    // centre: no obstacle square is nearer to p than d - sqrt 2 ...
    if (d - kSqrt2 >= best) return;
    if (candidates_of != c) {
      // ... and the nearest one has its centre within d + 1.5 sqrt 2 of c's centre (the nearest
      // obstacle centre's square is at most d + sqrt 2 / 2 from p). No centre is nearer than d.
      candidates.clear();
      const double reach = d + 1.5 * kSqrt2;
      const int32_t rows = static_cast<int32_t>(std::floor(reach));
      for (int32_t dy = -rows; dy <= rows; ++dy) {
        const int32_t y = c.y + dy;
        if (y < 0 || y >= map.height()) continue;
        const double outer = reach * reach - double(dy) * dy;
        if (outer < 0.0) continue;
        const int32_t dx_max = static_cast<int32_t>(std::floor(std::sqrt(outer)));
        const double inner = d * d - double(dy) * dy;
        // One cell inside the exact bound: rounding must not drop a centre exactly d away.
        const int32_t dx_min =
            inner > 0.0 ? std::max(0, static_cast<int32_t>(std::ceil(std::sqrt(inner))) - 1) : 0;
        for (int32_t dx = dx_min; dx <= dx_max; ++dx) {
          for (const int32_t x : {c.x + dx, c.x - dx}) {
            if (x >= 0 && x < map.width() && is_obstacle(map.layer({x, y})))
              candidates.push_back({x, y});
            if (dx == 0) break;
          }
        }
      }
      candidates_of = c;
    }
    for (const Cell& b : candidates) best = std::min(best, distance_to_square(p, b.x, b.y));
  };
  measure(polyline.front());
  for (size_t i = 1; i < polyline.size(); ++i) {
    const Point2& a = polyline[i - 1];
    const Point2& b = polyline[i];
    const double length = (b - a).norm();
    if (!std::isfinite(length)) continue;  // not a path a planner makes; no endless sampling
    const int steps = std::max(1, static_cast<int>(std::ceil(length / kClearanceSampleStep)));
    for (int k = 1; k <= steps; ++k) measure(a + (b - a) * (static_cast<double>(k) / steps));
  }
  return best;
}

}  // namespace vnsba::core
