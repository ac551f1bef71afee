// Line of sight: the one implementation (docs/algorithm.md section 1). Used by the heuristic's
// Euclid/Manhattan switch, by polyline pruning and by the smoothing check.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string_view>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"

namespace vnsba::core {

// How a diagonal move (or a segment through a cell corner) may pass blocked cells beside it.
enum class CornerPolicy {
  kNever,   // both cells beside the corner must be free (Moving AI convention; default)
  kTouch,   // at least one of them must be free (the paper's "touching a corner is safe")
  kAlways,  // the cells beside a corner are not checked
};

std::string_view to_string(CornerPolicy policy);

namespace detail {

// Whether the corner between two side cells may be passed (see CornerPolicy).
inline bool corner_passable(bool side_a_blocked, bool side_b_blocked, CornerPolicy policy) {
  switch (policy) {
    case CornerPolicy::kNever:
      return !side_a_blocked && !side_b_blocked;
    case CornerPolicy::kTouch:
      return !side_a_blocked || !side_b_blocked;
    case CornerPolicy::kAlways:
      return true;
  }
  return false;
}

// The supercover traversal, cell by cell: line of sight for continuous segments (line_of_sight
// on points) and, on exact integers, the reference that the faster walk between cell centres
// (centre_segment_clear) must equal. Generic over the number type so that cell centres run on
// exact integers and continuous points on doubles. Walks from cell (cx, cy) to cell (ex, ey)
// over the padded blocked array, starting at padded index `at`. `next_x` / `next_y` are the
// distances from the start point to the first cell boundary along each axis, `unit` the width
// of a cell, `adx` / `ady` the absolute extents of the segment, `sx` / `sy` its direction signs;
// all in the same units. The start cell is not checked.
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

// Between two cell centres by walking the map's bit grids (GridMap::blocked_rows / _columns)
// one line of cells at a time, each line's span of cells checked with word masks: exactly the
// answer of the supercover traversal, in O(lines + span words) instead of O(cells) steps.
// Any two cells in the map (a == b and axis-aligned pairs included). line_of_sight.cpp derives
// the spans.
bool centre_segment_clear(const GridMap& map, const Cell& a, const Cell& b, CornerPolicy policy);

// The same question answered by traverse_supercover<int64_t> on doubled coordinates (a centre is
// 1 from each boundary of its cell, a cell 2 wide), without any shortcut; false when a cell is
// outside the map. The oracle the tests and benchmarks hold centre_segment_clear against.
bool line_of_sight_centres_scalar(const GridMap& map, const Cell& a, const Cell& b,
                                  CornerPolicy policy);

}  // namespace detail

std::optional<CornerPolicy> corner_policy_from_string(std::string_view name);

// True when the straight segment a -> b (continuous cell coordinates) passes only through free
// cells: a supercover traversal of every cell the segment touches. Where the segment passes
// exactly through a cell corner, the two cells beside that corner are checked according to
// `policy`. Endpoints outside the map give false.
//
// Comparisons are made by cross-multiplication, so for cell centres (half-integer coordinates)
// corner crossings are detected exactly; for arbitrary real coordinates the traversal is exact
// up to floating-point rounding of those products.
bool line_of_sight(const GridMap& map, const Point2& a, const Point2& b, CornerPolicy policy);

// The highest cell cost (GridMap::cost) over the cells of that same traversal, both end cells
// included; nullopt when the segment lacks line of sight. 0 on a map without costs.
std::optional<double> max_cost_along(const GridMap& map, const Point2& a, const Point2& b,
                                     CornerPolicy policy);

// Between two cell centres, exactly (integer arithmetic): the same answer as the supercover
// traversal above, computed over the bit grids (detail::centre_segment_clear). Uses the
// summed-area table as an exact shortcut: when the bounding rectangle of the two cells is all
// free the answer is true without a walk, and for an axis-aligned pair the rectangle *is* the
// traversal. `blocked_between` must be map.blocked_in_rect(a, b) (callers that have it
// already pass it in). Both cells must be in the map.
inline bool line_of_sight_in_map(const GridMap& map, const Cell& a, const Cell& b,
                                 int64_t blocked_between, CornerPolicy policy) {
  if (blocked_between == 0) return true;
  if (a.x == b.x || a.y == b.y) return false;
  return detail::centre_segment_clear(map, a, b, policy);
}

inline bool line_of_sight(const GridMap& map, const Cell& a, const Cell& b, CornerPolicy policy) {
  if (!map.in_bounds(a) || !map.in_bounds(b)) return false;
  return line_of_sight_in_map(map, a, b, map.blocked_in_rect(a, b), policy);
}

}  // namespace vnsba::core
