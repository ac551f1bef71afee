#include "vnsba/core/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace vnsba::core {

double heading(const Point2& a, const Point2& b) {
  const Point2 d = b - a;
  return d.squaredNorm() == 0.0 ? 0.0 : std::atan2(d.y(), d.x());
}

double heading_change(const Point2& a, const Point2& b, const Point2& c) {
  const Point2 in = b - a;
  const Point2 out = c - b;
  if (in.squaredNorm() == 0.0 || out.squaredNorm() == 0.0) return 0.0;
  // atan2(cross, dot) is the signed angle between the legs, exact for collinear legs (cross 0).
  const double cross = in.x() * out.y() - in.y() * out.x();
  const double dot = in.dot(out);
  // Straight on (most vertices of a grid path): atan2(0, dot > 0) is exactly 0; skip the call.
  if (cross == 0.0 && dot > 0.0) return 0.0;
  return std::atan2(cross, dot);
}

double distance_to_segment(const Point2& p, const Point2& a, const Point2& b) {
  const Point2 ab = b - a;
  const double length_squared = ab.squaredNorm();
  const double t =
      length_squared > 0.0 ? std::clamp((p - a).dot(ab) / length_squared, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double polyline_length(const std::vector<Point2>& points) {
  double length = 0.0;
  for (size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

std::vector<Point2> cell_centres(const std::vector<Cell>& cells) {
  std::vector<Point2> out;
  out.reserve(cells.size());
  for (const Cell& c : cells) out.push_back(cell_centre(c));
  return out;
}

}  // namespace vnsba::core
