// The scalar line of sight: the supercover traversal one cell at a time, reading the padded
// blocked bytes (GridMap::blocked_data). The independent oracle of the core's one line-of-sight
// walk over the bit grids (line_of_sight.cpp) in tests and in vnsba_core_bench; not part of the
// library.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"

namespace vnsba::test_oracle {

using core::Cell;
using core::CornerPolicy;
using core::GridMap;
using core::Point2;
using core::detail::corner_passable;

// The supercover traversal, cell by cell, as the core walked it before its one line walk over
// the bit grids (line_of_sight.cpp): the scalar line of sight the tests and benchmarks hold
// that walk against, between cell centres (on exact integers) and between any points (doubles).
// Generic over the number type so that cell centres run on exact integers and continuous points on
// doubles. Walks from cell (cx, cy) to cell (ex, ey) over the padded blocked array, starting at
// padded index `at`. `next_x` / `next_y` are the distances from the start point to the first cell
// boundary along each axis, `unit` the width of a cell, `adx` / `ady` the absolute extents of the
// segment, `sx` / `sy` its direction signs; all in the same units. The start cell is not checked.
//
// Each iteration steps one cell along x, along y, or diagonally through a corner. The parameter
// of the next x boundary is next_x / adx, of the next y boundary next_y / ady; comparing
// next_x * ady with next_y * adx avoids the divisions (and is exact for integers). A step is
// never taken past the end cell on its axis, which bounds the loop at |ex-cx| + |ey-cy| steps.
// `enter(at)` is called with the padded index of every cell entered (after the start cell, up to
// the end cell) and returns whether the walk goes on; by default a blocked cell stops it.
template <class Number, class Enter>
inline bool traverse_supercover(const uint8_t* blocked, int32_t stride, uint32_t at, int32_t cx,
                                int32_t cy, int32_t ex, int32_t ey, Number next_x, Number next_y,
                                Number adx, Number ady, Number unit, int sx, int sy,
                                CornerPolicy policy, Enter&& enter) {
  while (cx != ex || cy != ey) {
    int step_x = 0, step_y = 0;
    if (cy == ey) {
      step_x = sx;
    } else if (cx == ex) {
      step_y = sy;
    } else {
      const Number tx = next_x * ady, ty = next_y * adx;
      if (tx < ty) {
        step_x = sx;
      } else if (ty < tx) {
        step_y = sy;
      } else {
        // Through a corner: the cells beside it decide, by policy.
        if (!corner_passable(blocked[at + sx] != 0, blocked[at + sy * stride] != 0, policy)) {
          return false;
        }
        step_x = sx;
        step_y = sy;
      }
    }
    if (step_x != 0) {
      cx += step_x;
      next_x += unit;
    }
    if (step_y != 0) {
      cy += step_y;
      next_y += unit;
    }
    at += step_x + step_y * stride;
    if (!enter(at)) return false;
  }
  return true;
}

// Between two cell centres, on doubled integer coordinates (a centre is 1 from each boundary of
// its cell, a cell 2 wide); false when a cell is outside the map.
inline bool line_of_sight_centres_scalar(const GridMap& map, const Cell& a, const Cell& b,
                                         CornerPolicy policy) {
  if (!map.in_bounds(a) || !map.in_bounds(b)) return false;
  const uint32_t at = map.padded_index(a.x, a.y);
  if (map.blocked_data()[at]) return false;
  const int32_t dx = b.x - a.x, dy = b.y - a.y;
  // Doubled coordinates: a centre is 1 from each boundary of its cell, a cell is 2 wide.
  const uint8_t* blocked = map.blocked_data();
  return traverse_supercover<int64_t>(blocked, map.stride(), at, a.x, a.y, b.x, b.y, 1, 1,
                                      2 * int64_t{std::abs(dx)}, 2 * int64_t{std::abs(dy)}, 2,
                                      dx > 0 ? 1 : -1, dy > 0 ? 1 : -1, policy,
                                      [blocked](uint32_t cell) { return blocked[cell] == 0; });
}

// The supercover traversal of the segment a -> b (continuous cell coordinates), calling
// enter(padded index) for the start cell and every cell entered after it; false when an
// endpoint is outside the map or not finite, when a corner is not passable, or when enter
// returns false.
template <class Enter>
inline bool walk_segment(const GridMap& map, const Point2& a, const Point2& b, CornerPolicy policy,
                         Enter&& enter) {
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
  if (!enter(at)) return false;
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const int sx = (dx > 0) - (dx < 0), sy = (dy > 0) - (dy < 0);
  // Distance from a to the next cell boundary along each axis (in cells, >= 0). Products of
  // these are exact for cell centres and dyadic coordinates; for arbitrary reals the traversal
  // is exact up to the rounding of those products.
  const double next_x = sx > 0 ? (cx + 1 - a.x()) : (a.x() - cx);
  const double next_y = sy > 0 ? (cy + 1 - a.y()) : (a.y() - cy);
  return traverse_supercover<double>(map.blocked_data(), map.stride(), at, cx, cy,
                                     static_cast<int32_t>(fbx), static_cast<int32_t>(fby), next_x,
                                     next_y, std::abs(dx), std::abs(dy), 1.0, sx, sy, policy,
                                     enter);
}

// line_of_sight and max_cost_along, cell by cell.
inline bool line_of_sight_scalar(const GridMap& map, const Point2& a, const Point2& b,
                                 CornerPolicy policy) {
  const uint8_t* blocked = map.blocked_data();
  return walk_segment(map, a, b, policy, [blocked](uint32_t cell) { return blocked[cell] == 0; });
}

inline std::optional<double> max_cost_along_scalar(const GridMap& map, const Point2& a,
                                                   const Point2& b, CornerPolicy policy) {
  const uint8_t* blocked = map.blocked_data();
  const float* costs = map.cost_data();
  float highest = 0.0f;
  const bool clear = walk_segment(map, a, b, policy, [&](uint32_t cell) {
    if (blocked[cell] != 0) return false;
    if (costs != nullptr) highest = std::max(highest, costs[cell]);
    return true;
  });
  if (!clear) return std::nullopt;
  return highest;
}

}  // namespace vnsba::test_oracle
