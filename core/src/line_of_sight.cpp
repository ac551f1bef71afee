#include "vnsba/core/line_of_sight.hpp"

#include <cmath>
#include <cstdlib>

namespace vnsba::core {

std::string_view to_string(CornerPolicy policy) {
  switch (policy) {
    case CornerPolicy::kNever:
      return "never";
    case CornerPolicy::kTouch:
      return "touch";
    case CornerPolicy::kAlways:
      return "always";
  }
  return "never";
}

std::optional<CornerPolicy> corner_policy_from_string(std::string_view name) {
  if (name == "never") return CornerPolicy::kNever;
  if (name == "touch") return CornerPolicy::kTouch;
  if (name == "always") return CornerPolicy::kAlways;
  return std::nullopt;
}

bool line_of_sight(const GridMap& map, const Point2& a, const Point2& b, CornerPolicy policy) {
  if (!std::isfinite(a.x()) || !std::isfinite(a.y()) || !std::isfinite(b.x()) ||
      !std::isfinite(b.y())) {
    return false;
  }
  const double fax = std::floor(a.x()), fay = std::floor(a.y());
  const double fbx = std::floor(b.x()), fby = std::floor(b.y());
  // Every cell of the traversal lies in the bounding box of the end cells, so checking the ends
  // against the map once makes the unchecked padded lookups below safe.
  if (fax < 0 || fay < 0 || fbx < 0 || fby < 0 || fax >= map.width() || fbx >= map.width() ||
      fay >= map.height() || fby >= map.height()) {
    return false;
  }
  const int32_t cx = static_cast<int32_t>(fax), cy = static_cast<int32_t>(fay);
  const uint32_t at = map.padded_index(cx, cy);
  if (map.blocked_data()[at]) return false;
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const int sx = (dx > 0) - (dx < 0), sy = (dy > 0) - (dy < 0);
  // Distance from a to the next cell boundary along each axis (in cells, >= 0). Products of
  // these are exact for cell centres and dyadic coordinates; for arbitrary reals the traversal
  // is exact up to the rounding of those products.
  const double next_x = sx > 0 ? (cx + 1 - a.x()) : (a.x() - cx);
  const double next_y = sy > 0 ? (cy + 1 - a.y()) : (a.y() - cy);
  return detail::traverse_supercover<double>(
      map.blocked_data(), map.stride(), at, cx, cy, static_cast<int32_t>(fbx),
      static_cast<int32_t>(fby), next_x, next_y, std::abs(dx), std::abs(dy), 1.0, sx, sy, policy);
}

}  // namespace vnsba::core
