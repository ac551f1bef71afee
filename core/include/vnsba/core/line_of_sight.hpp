// Line of sight: the one implementation (ALGORITHM.md section 1). Used by the heuristic's
// Euclid/Manhattan switch, by polyline pruning and by the smoothing check.
#pragma once

#include <string_view>
#include <optional>

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

// Between two cell centres. Uses the summed-area table as an exact shortcut: when the bounding
// rectangle of the two cells is all free the answer is true without a traversal, and for an
// axis-aligned pair the rectangle *is* the traversal.
bool line_of_sight(const GridMap& map, const Cell& a, const Cell& b, CornerPolicy policy);

}  // namespace vnsba::core
