// Line of sight: the one implementation (docs/algorithm.md section 1). Used by the heuristic's
// Euclid/Manhattan switch, and through MotionValidator (motion_validator.hpp) by pruning, the
// exact ends, the smoothing check and the relax smoother.
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

// Between two cell centres, on exact integers: line_of_sight's one traversal (line_of_sight.cpp)
// on doubled coordinates, walking the map's bit grids (GridMap::blocked_rows / _columns) one line
// of cells at a time, each line's span checked with word masks, in O(lines + span words) instead
// of O(cells) steps. Any two cells in the map (a == b and axis-aligned pairs included).
bool centre_segment_clear(const GridMap& map, const Cell& a, const Cell& b, CornerPolicy policy);

}  // namespace detail

std::optional<CornerPolicy> corner_policy_from_string(std::string_view name);

// True when the straight segment a -> b (continuous cell coordinates) passes only through free
// cells: a supercover traversal of every cell the segment touches. Where the segment passes
// exactly through a cell corner, the two cells beside that corner are checked according to
// `policy`. Endpoints outside the map give false.
//
// Comparisons are made by cross-multiplication, so for cell centres (half-integer coordinates)
// corner crossings are detected exactly; for arbitrary real coordinates the traversal is exact
// up to floating-point rounding of those products. The same walk over the bit grids as between
// cell centres (detail::centre_segment_clear), on doubles.
bool line_of_sight(const GridMap& map, const Point2& a, const Point2& b, CornerPolicy policy);

// The highest cell cost (GridMap::cost) over the cells of that same traversal, both end cells
// included; nullopt when the segment lacks line of sight. 0 on a map without costs.
std::optional<double> max_cost_along(const GridMap& map, const Point2& a, const Point2& b,
                                     CornerPolicy policy);

// Between two cell centres, exactly (integer arithmetic): the same answer as the supercover
// traversal above, computed over the bit grids (detail::centre_segment_clear). Uses the
// summed-area table (when built) as an exact shortcut: when the bounding rectangle of the two cells
// is all free the answer is true without a walk, and for an axis-aligned pair the rectangle *is*
// the traversal. `blocked_between` must be map.blocked_in_rect(a, b) (callers that have it already
// pass it in). Both cells must be in the map.
inline bool line_of_sight_in_map(const GridMap& map, const Cell& a, const Cell& b,
                                 int64_t blocked_between, CornerPolicy policy) {
  if (blocked_between == 0) return true;
  if (a.x == b.x || a.y == b.y) return false;
  return detail::centre_segment_clear(map, a, b, policy);
}

// Never builds the summed-area table: its shortcut only where a planner has built it already,
// the walk over the bit grids otherwise (the same answer).
inline bool line_of_sight(const GridMap& map, const Cell& a, const Cell& b, CornerPolicy policy) {
  if (!map.in_bounds(a) || !map.in_bounds(b)) return false;
  if (const std::optional<int64_t> blocked = map.blocked_in_rect_if_counted(a, b))
    return line_of_sight_in_map(map, a, b, *blocked, policy);
  return detail::centre_segment_clear(map, a, b, policy);
}

}  // namespace vnsba::core
