// Cells, points and heading math: the one place for each.
//
// Units: a Cell is an integer grid coordinate (x = column, y = row, row 0 at the map origin).
// A Point2 is a continuous position in *cell units*: cell (x, y) covers [x, x+1) x [y, y+1) and
// its centre is (x + 0.5, y + 0.5). World coordinates (metres) exist only in GridMap, which
// converts between the two (see grid_map.hpp).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

namespace vnsba::core {

struct Cell {
  int32_t x = 0;
  int32_t y = 0;
  friend bool operator==(const Cell& a, const Cell& b) { return a.x == b.x && a.y == b.y; }
  friend bool operator!=(const Cell& a, const Cell& b) { return !(a == b); }
};

using Point2 = Eigen::Vector2d;

// Centre of a cell in continuous cell coordinates.
inline Point2 cell_centre(const Cell& c) {
  return {c.x + 0.5, c.y + 0.5};
}

// Heading of the direction a -> b in radians, in (-pi, pi] (0 along +x, counter-clockwise);
// 0 when a == b.
double heading(const Point2& a, const Point2& b);

// Signed heading change in radians, in (-pi, pi], from the leg `in` to the leg `out` (vectors).
// Zero-length legs give 0. Inline: turn_stats calls it at every vertex of a grid path, most of
// them straight on, each leg the out of one vertex and the in of the next.
inline double heading_change_between(const Point2& in, const Point2& out) {
  // atan2(cross, dot) is the signed angle between the legs, exact for collinear legs (cross 0).
  const double cross = in.x() * out.y() - in.y() * out.x();
  const double dot = in.x() * out.x() + in.y() * out.y();
  // Straight on (most vertices of a grid path): atan2(0, dot > 0) is exactly 0; skip the call.
  // A positive dot needs two legs of some length, so this comes before the zero-length test.
  if (cross == 0.0 && dot > 0.0) return 0.0;
  if (in.squaredNorm() == 0.0 || out.squaredNorm() == 0.0) return 0.0;
  return std::atan2(cross, dot);
}

// Signed heading change in radians, in (-pi, pi], when going a -> b -> c. Zero-length legs give 0.
inline double heading_change(const Point2& a, const Point2& b, const Point2& c) {
  return heading_change_between(b - a, c - b);
}

// Distance from p to the segment [a, b] (a point when a == b), same units as the points.
double distance_to_segment(const Point2& p, const Point2& a, const Point2& b);

// Euclidean length of a polyline (same units as the points).
double polyline_length(const std::vector<Point2>& points);

std::vector<Point2> cell_centres(const std::vector<Cell>& cells);

// --- Grid conversion: the one implementation (metres <-> continuous cell coordinates). ---
// For a grid whose cell (0, 0) has its corner at (origin_x, origin_y) metres and whose cells
// are `resolution` metres wide. GridMap and the pictures of recorded runs both use these.
inline Point2 world_to_grid(const Eigen::Vector2d& world, double origin_x, double origin_y,
                            double resolution) {
  return {(world.x() - origin_x) / resolution, (world.y() - origin_y) / resolution};
}
inline Eigen::Vector2d grid_to_world(const Point2& grid, double origin_x, double origin_y,
                                     double resolution) {
  return {origin_x + grid.x() * resolution, origin_y + grid.y() * resolution};
}

}  // namespace vnsba::core
