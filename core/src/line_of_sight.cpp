#include "vnsba/core/line_of_sight.hpp"

#include <cmath>
#include <cstdlib>

#include "vnsba/core/neighborhood.hpp"

namespace vnsba::core {

std::string_view to_string(CornerPolicy policy) {
  switch (policy) {
    case CornerPolicy::kNever: return "never";
    case CornerPolicy::kTouch: return "touch";
    case CornerPolicy::kAlways: return "always";
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
  int32_t cx = static_cast<int32_t>(fax), cy = static_cast<int32_t>(fay);
  const int32_t ex = static_cast<int32_t>(fbx), ey = static_cast<int32_t>(fby);
  const uint8_t* blocked = map.blocked_data();
  const int32_t stride = map.stride();
  uint32_t at = map.padded_index(cx, cy);
  if (blocked[at]) return false;

  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const int sx = (dx > 0) - (dx < 0), sy = (dy > 0) - (dy < 0);
  const double adx = std::abs(dx), ady = std::abs(dy);
  // Distance from a to the next cell boundary along each axis (in cells, >= 0).
  double next_x = sx > 0 ? (cx + 1 - a.x()) : (a.x() - cx);
  double next_y = sy > 0 ? (cy + 1 - a.y()) : (a.y() - cy);

  // Each iteration steps one cell along x, along y, or diagonally through a corner. The
  // parameter of the next x boundary is next_x / adx, of the next y boundary next_y / ady;
  // comparing next_x * ady with next_y * adx avoids the divisions (and is exact for cell
  // centres). A step is never taken past the end cell on its axis, which bounds the loop.
  while (cx != ex || cy != ey) {
    int step_x = 0, step_y = 0;
    if (cy == ey) {
      step_x = sx;
    } else if (cx == ex) {
      step_y = sy;
    } else {
      const double tx = next_x * ady, ty = next_y * adx;
      if (tx < ty) {
        step_x = sx;
      } else if (ty < tx) {
        step_y = sy;
      } else {
        step_x = sx;
        step_y = sy;
      }
    }
    if (step_x != 0 && step_y != 0) {
      // Through a corner: the cells beside it decide, by policy.
      const bool side_x = blocked[at + step_x] != 0;
      const bool side_y = blocked[at + step_y * stride] != 0;
      if (!detail::corner_passable(side_x, side_y, policy)) return false;
    }
    cx += step_x;
    cy += step_y;
    at += step_x + step_y * stride;
    next_x += step_x != 0 ? 1.0 : 0.0;
    next_y += step_y != 0 ? 1.0 : 0.0;
    if (blocked[at]) return false;
  }
  return true;
}

bool line_of_sight(const GridMap& map, const Cell& a, const Cell& b, CornerPolicy policy) {
  if (!map.in_bounds(a) || !map.in_bounds(b)) return false;
  const int64_t blocked_cells = map.blocked_in_rect(a, b);
  // The traversal (and any corner's side cells) lies inside the rectangle spanned by a and b.
  if (blocked_cells == 0) return true;
  // Axis-aligned: the rectangle is exactly the traversal.
  if (a.x == b.x || a.y == b.y) return false;
  return line_of_sight(map, cell_centre(a), cell_centre(b), policy);
}

}  // namespace vnsba::core
