#include "vnsba/core/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
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

// Distance from the segment [a, b] to the square [x, x + 1] x [y, y + 1] (cells): 0 where the
// segment meets the square (Liang-Barsky clipping), otherwise the least of its ends' distances to
// the square and the square's corners' distances to the segment (two disjoint convex polygons are
// nearest at a vertex of one of them).
double segment_square_distance(const Point2& a, const Point2& b, int32_t x, int32_t y) {
  const Point2 ab = b - a;
  double t_in = 0.0, t_out = 1.0;
  bool meets = true;
  for (int axis = 0; axis < 2 && meets; ++axis) {
    const double low = axis == 0 ? x : y;
    const double from = a[axis], step = ab[axis];
    if (step == 0.0) {
      meets = from >= low && from <= low + 1.0;
      continue;
    }
    double t0 = (low - from) / step, t1 = (low + 1.0 - from) / step;
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
    meets = t_in <= t_out;
  }
  if (meets) return 0.0;
  double best = std::min(distance_to_square(a, x, y), distance_to_square(b, x, y));
  const double length_squared = ab.squaredNorm();
  for (const int32_t cx : {x, x + 1}) {
    for (const int32_t cy : {y, y + 1}) {
      const Point2 corner(cx, cy);
      const double t =
          length_squared > 0.0 ? std::clamp((corner - a).dot(ab) / length_squared, 0.0, 1.0) : 0.0;
      best = std::min(best, (a + t * ab - corner).norm());
    }
  }
  return best;
}

bool is_obstacle(CellLayer layer) {
  return layer == CellLayer::kOccupied || layer == CellLayer::kUnknown;
}

}  // namespace

double path_clearance_cells(const GridMap& map, const std::vector<Point2>& polyline) {
  double best = std::numeric_limits<double>::infinity();
  if (polyline.empty() || map.cell_count() == 0) return best;
  if (!std::isfinite(map.obstacle_distance({0, 0}))) return best;  // the map has no obstacle
  // Each segment is probed at most one cell apart (kProbeStep), so every point of it lies within
  // half a cell of a probe, and within sqrt 2 / 2 + 1/2 of the probe's cell's centre. An obstacle
  // square nearer than `best` to such a point has its centre within best + sqrt 2 + 1/2 of that
  // centre (a square's points lie within sqrt 2 / 2 of its centre): those obstacles are the
  // probe's candidates, found in the map's bit rows (which the search has just read; the blocked
  // bits are the obstacles plus inflation, which layer() tells apart). Before any distance is
  // known, the distance transform's d (the nearest obstacle centre) bounds the nearest square by
  // d + sqrt 2 / 2 + sqrt 2 / 2 + 1/2. Each candidate is measured against the whole segment, first
  // by its centre (no square is nearer to the segment than its centre less sqrt 2 / 2), exactly
  // where that could beat best. best only falls, so a cell's candidates stay enough for every
  // later probe in it.
  constexpr double kProbeStep = 1.0;                   // cells
  constexpr double kProbeReach = kSqrt2 + 0.5 + 1e-9;  // cells; 1e-9 so rounding drops nothing
  constexpr double kHalfDiagonal = kSqrt2 / 2;
  const BlockedBits rows = map.blocked_rows();
  const bool inflation = map.build_options().robot_radius > 0.0;
  std::vector<Cell> candidates;
  std::optional<Cell> candidates_of;
  std::vector<Cell> measured_before;  // the previous probe's candidates, on this segment
  auto probe = [&](const Point2& p, const Point2& a, const Point2& b) {
    const Cell c{std::clamp(static_cast<int32_t>(std::floor(p.x())), 0, map.width() - 1),
                 std::clamp(static_cast<int32_t>(std::floor(p.y())), 0, map.height() - 1)};
    // Far from every obstacle (d: c's centre to the nearest obstacle centre, from the distance
    // transform), no point near the probe can beat best. Read only once best is over a cell: on
    // a path that passes obstacles closer, the bit rows answer as fast without it.
    if (best > 1.0 && map.obstacle_distance(c) - kProbeReach >= best) return;
    if (candidates_of != c) {
      candidates.clear();
      const double reach = std::isfinite(best) ? best + kProbeReach
                                               : map.obstacle_distance(c) + kSqrt2 + kProbeReach;
      const double reach_squared = reach * reach;
      const int32_t r = static_cast<int32_t>(std::floor(reach));
      const int32_t x0 = std::max(0, c.x - r), x1 = std::min(map.width() - 1, c.x + r);
      for (int32_t y = std::max(0, c.y - r); y <= std::min(map.height() - 1, c.y + r); ++y) {
        const double dy = y - c.y;
        const uint64_t* line = rows.line(y);
        for (int32_t word = x0 >> 6; word <= x1 >> 6; ++word) {
          const int32_t from = std::max(x0, word << 6) & 63;
          const int32_t to = std::min(x1, (word << 6) + 63) & 63;
          uint64_t bits = line[word] & (~uint64_t{0} << from) & (~uint64_t{0} >> (63 - to));
          while (bits != 0) {
            const int32_t x = (word << 6) + __builtin_ctzll(bits);
            bits &= bits - 1;
            const double dx = x - c.x;
            if (dx * dx + dy * dy > reach_squared) continue;
            if (inflation && !is_obstacle(map.layer({x, y}))) continue;
            candidates.push_back({x, y});
          }
        }
      }
      candidates_of = c;
    }
    const Point2 ab = b - a;
    const double length_squared = ab.squaredNorm();
    for (const Cell& o : candidates) {
      // Neighbouring probes of a segment share most candidates: each is measured once.
      if (std::find(measured_before.begin(), measured_before.end(), o) != measured_before.end())
        continue;
      const Point2 centre(o.x + 0.5, o.y + 0.5);
      const double t =
          length_squared > 0.0 ? std::clamp((centre - a).dot(ab) / length_squared, 0.0, 1.0) : 0.0;
      const double bound = best + kHalfDiagonal + 1e-9;
      if ((a + t * ab - centre).squaredNorm() >= bound * bound) continue;
      best = std::min(best, segment_square_distance(a, b, o.x, o.y));
    }
    measured_before = candidates;
  };
  // Collinear runs (a grid path's straight moves) are measured as one segment.
  std::vector<Point2> vertices;
  vertices.reserve(polyline.size());
  for (const Point2& p : polyline) {
    if (vertices.size() >= 2) {
      const Point2 u = vertices.back() - vertices[vertices.size() - 2];
      const Point2 v = p - vertices.back();
      if (u.x() * v.y() - u.y() * v.x() == 0.0 && u.dot(v) > 0.0) {
        vertices.back() = p;
        continue;
      }
    }
    vertices.push_back(p);
  }
  if (vertices.size() == 1) probe(vertices.front(), vertices.front(), vertices.front());
  for (size_t i = 1; i < vertices.size(); ++i) {
    const Point2& a = vertices[i - 1];
    const Point2& b = vertices[i];
    const double length = (b - a).norm();
    if (!std::isfinite(length)) continue;  // not a path a planner makes; no endless probing
    measured_before.clear();               // a new segment: every candidate is new to it
    const int steps = std::max(1, static_cast<int>(std::ceil(length / kProbeStep)));
    for (int k = 0; k <= steps; ++k) probe(a + (b - a) * (static_cast<double>(k) / steps), a, b);
  }
  return best;
}

}  // namespace vnsba::core
