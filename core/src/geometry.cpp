#include "vnsba/core/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace vnsba::core {

double heading(const Point2& a, const Point2& b) {
  const Point2 d = b - a;
  return d.squaredNorm() == 0.0 ? 0.0 : std::atan2(d.y(), d.x());
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
  // Each leg as Eigen's norm() computes it, sqrt(x * x + y * y), on scalars: a third cheaper.
  for (size_t i = 1; i < points.size(); ++i) {
    const double dx = points[i].x() - points[i - 1].x(), dy = points[i].y() - points[i - 1].y();
    length += std::sqrt(dx * dx + dy * dy);
  }
  return length;
}

std::vector<Point2> cell_centres(const std::vector<Cell>& cells) {
  std::vector<Point2> out(cells.size());  // Eigen leaves the points uninitialised
  for (size_t i = 0; i < cells.size(); ++i) out[i] = cell_centre(cells[i]);
  return out;
}

}  // namespace vnsba::core
