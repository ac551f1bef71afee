// Which motions on the occupancy grid are valid and what they cost: the one place that decides it
// (docs/algorithm.md sections 1, 2, 5 and 8), in the spirit of OMPL's MotionValidator. The
// searches ask it for the moves out of a cell and their costs; pruning, the exact ends and the
// corner splines for the validity and cost of straight segments; the relax smoother for segments
// that also keep a clearance. All coordinates are continuous cell coordinates, all lengths cells.
//
// The corner rule is detail::corner_passable and the segment walk is line_of_sight's supercover
// traversal (line_of_sight.hpp): this class applies both and writes neither again.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"
#include "vnsba/core/neighborhood.hpp"

namespace vnsba::core {

class MotionValidator {
 public:
  // `cost_weight`: section 8's weight of the cell costs (0: a motion costs its length).
  // `clearance_floor_cells`: the clearance segment_keeps_clearance asks (0: none asked).
  // Holds a reference to `map`, which must outlive it; O(1), so callers make one per use.
  MotionValidator(const GridMap& map, CornerPolicy policy, double cost_weight = 0.0,
                  double clearance_floor_cells = 0.0)
      : map_(&map),
        blocked_(map.blocked_data()),
        costs_(map.cost_data()),
        stride_(map.stride()),
        policy_(policy),
        cost_weight_(cost_weight),
        clearance_floor_(clearance_floor_cells),
        // Inflated cells have their centre within this of an obstacle's (grid_map.cpp snaps the
        // radius to a whole cell within 1e-9; the margin covers that), in cells.
        inflated_within_(map.build_options().robot_radius / map.resolution() + 1e-6),
        bound_decides_(!map.has_blocked_non_obstacles()) {}

  const GridMap& map() const { return *map_; }
  CornerPolicy corner_policy() const { return policy_; }
  double cost_weight() const { return cost_weight_; }
  double clearance_floor_cells() const { return clearance_floor_; }
  // Whether a move costs more than its length: a positive weight on a map with costs. Without,
  // the searches price every move at its length and never call move_cost.
  bool weighs_costs() const { return cost_weight_ > 0.0 && costs_ != nullptr; }

  // --- Moves of the searches (cell to cell) ---

  // Calls visit(dx, dy, length) for each move available from `from` when expanding toward
  // `guide`, `length` the quantized step cost of neighborhood.hpp (cells):
  // 1. the 8 neighbours that are in the map and free, diagonals subject to the corner policy;
  // 2. with kEightElevenThirteen and all 8 neighbours in the map and free, the extra cells at
  //    Chebyshev distance 2 in the guide's direction (3 on an axis, 5 in a quadrant, none when
  //    guide == from), each only when it is in the map and free.
  // The extra (2, 2)-type move passes exactly through the corner between (1, 2) and (2, 1), two
  // cells outside the 8-neighbourhood; the paper leaves this open, and we check them with the
  // same corner policy as every other corner, so that every move has line of sight.
  // `from` must be free and in the map.
  //
  // Works on the map's padded layout (no bounds checks: the border is blocked). A template that
  // calls back rather than returning a list because it is the innermost loop of every search;
  // [[gnu::always_inline]] because out of line it costs a call per move.
  template <class Visit>
  [[gnu::always_inline]] inline void for_each_move(const Cell& from, const Cell& guide,
                                                   Neighborhood neighborhood, Visit&& visit) const;

  // The cost of the move from padded index `from` to `to` = from + dy * stride + dx, one of
  // for_each_move's, whose quantized length is `length` (cells): length * (1 + cost_weight * the
  // highest cell cost the move's segment passes). Those cells are the ones the supercover walk
  // between the two centres enters: both ends and, for the 8-11-13 neighbourhood's longer moves,
  // the one or two cells in between (a straight or diagonal step of 2 passes the middle cell; a
  // knight move (2, 1) passes (1, 0) and (1, 1)), so segment_cost prices a move's segment as the
  // search does (tests/core/test_motion_validator.cpp checks the two agree). Symmetric (a move
  // and its reverse pass the same cells), as the backward searches need. Requires weighs_costs().
  [[gnu::always_inline]] inline double move_cost(uint32_t from, uint32_t to, int dx, int dy,
                                                 double length) const;

  // --- Straight segments (pruning, the exact ends, the corner splines, the relax smoother) ---

  // Line of sight between two points, or between two cell centres (exact integer walk).
  bool segment_valid(const Point2& a, const Point2& b) const {
    return line_of_sight(*map_, a, b, policy_);
  }
  bool segment_valid(const Cell& a, const Cell& b) const {
    return line_of_sight(*map_, a, b, policy_);
  }
  // Section 8's cost of the segment a -> b: its length * (1 + cost_weight * the highest cell cost
  // along it, max_cost_along); +inf when it lacks line of sight. With cost_weight 0, the length.
  double segment_cost(const Point2& a, const Point2& b) const;
  // The sum of segment_cost over a polyline's segments.
  double path_cost(const std::vector<Point2>& polyline) const;
  // Whether a segment may be part of a relaxed path: line of sight, and a clearance of at least
  // clearance_floor_cells() (metrics.hpp segment_clearance_at_least; the distance transform's
  // bound answers first where the segment lies far from anything blocked).
  bool segment_keeps_clearance(const Point2& a, const Point2& b) const;

 private:
  const GridMap* map_;
  const uint8_t* blocked_;  // GridMap::blocked_data(), padded
  const float* costs_;      // GridMap::cost_data(), padded; null without costs
  int32_t stride_;          // of the padded layout
  CornerPolicy policy_;
  double cost_weight_;
  double clearance_floor_;  // cells
  double inflated_within_;  // cells: an inflated cell's centre lies within this of an obstacle's
  bool bound_decides_;      // the distance transform's bound may clear a segment on its own
};

template <class Visit>
[[gnu::always_inline]] inline void MotionValidator::for_each_move(const Cell& from,
                                                                  const Cell& guide,
                                                                  Neighborhood neighborhood,
                                                                  Visit&& visit) const {
  using detail::corner_passable;
  const uint8_t* blocked = blocked_;
  const int32_t stride = stride_;
  const CornerPolicy policy = policy_;
  const uint32_t at = map_->padded_index(from);
  auto is_blocked = [&](int dx, int dy) -> bool { return blocked[at + dy * stride + dx] != 0; };

  const bool east = is_blocked(1, 0), west = is_blocked(-1, 0);
  const bool north = is_blocked(0, 1), south = is_blocked(0, -1);
  const bool ne = is_blocked(1, 1), nw = is_blocked(-1, 1);
  const bool se = is_blocked(1, -1), sw = is_blocked(-1, -1);
  using detail::kStepCostDiagonal;
  using detail::kStepCostKnight;
  using detail::kStepCostStraight;
  using detail::kStepCostTwoStraight;
  if (!east) visit(1, 0, kStepCostStraight);
  if (!west) visit(-1, 0, kStepCostStraight);
  if (!north) visit(0, 1, kStepCostStraight);
  if (!south) visit(0, -1, kStepCostStraight);
  if (!ne && corner_passable(east, north, policy)) visit(1, 1, kStepCostDiagonal);
  if (!nw && corner_passable(west, north, policy)) visit(-1, 1, kStepCostDiagonal);
  if (!se && corner_passable(east, south, policy)) visit(1, -1, kStepCostDiagonal);
  if (!sw && corner_passable(west, south, policy)) visit(-1, -1, kStepCostDiagonal);

  if (neighborhood == Neighborhood::kEight) return;
  if (east | west | north | south | ne | nw | se | sw) return;  // an obstacle near: 8 only
  const int sx = detail::sign(guide.x - from.x);
  const int sy = detail::sign(guide.y - from.y);
  if (sx == 0 && sy == 0) return;
  if (sy == 0 || sx == 0) {
    // 11-neighbourhood: 3 cells two steps along the axis, e.g. for +x: (2,-1), (2,0), (2,1).
    const int px = -sy, py = sx;  // perpendicular to the axis
    const int cx = 2 * sx, cy = 2 * sy;
    if (!is_blocked(cx, cy)) visit(cx, cy, kStepCostTwoStraight);
    if (!is_blocked(cx + px, cy + py)) visit(cx + px, cy + py, kStepCostKnight);
    if (!is_blocked(cx - px, cy - py)) visit(cx - px, cy - py, kStepCostKnight);
    return;
  }
  // 13-neighbourhood: (2sx,0), (2sx,sy), (2sx,2sy), (sx,2sy), (0,2sy).
  const bool b_2x_0 = is_blocked(2 * sx, 0), b_2x_1 = is_blocked(2 * sx, sy);
  const bool b_2x_2 = is_blocked(2 * sx, 2 * sy);
  const bool b_1_2y = is_blocked(sx, 2 * sy), b_0_2y = is_blocked(0, 2 * sy);
  if (!b_2x_0) visit(2 * sx, 0, kStepCostTwoStraight);
  if (!b_2x_1) visit(2 * sx, sy, kStepCostKnight);
  if (!b_2x_2 && corner_passable(b_2x_1, b_1_2y, policy))
    visit(2 * sx, 2 * sy, detail::kStepCostTwoDiagonal);
  if (!b_1_2y) visit(sx, 2 * sy, kStepCostKnight);
  if (!b_0_2y) visit(0, 2 * sy, kStepCostTwoStraight);
}

[[gnu::always_inline]] inline double MotionValidator::move_cost(uint32_t from, uint32_t to, int dx,
                                                                int dy, double length) const {
  const float* costs = costs_;
  float highest = std::max(costs[from], costs[to]);
  const int ax = dx < 0 ? -dx : dx, ay = dy < 0 ? -dy : dy;
  if (ax == 2 || ay == 2) {
    const int sx = detail::sign(dx), sy = detail::sign(dy);
    const int32_t x_step = sx, y_step = sy * stride_;
    if (ay == 0) {
      highest = std::max(highest, costs[from + x_step]);
    } else if (ax == 0) {
      highest = std::max(highest, costs[from + y_step]);
    } else if (ax == 2 && ay == 2) {
      highest = std::max(highest, costs[from + x_step + y_step]);
    } else if (ax == 2) {  // (2, 1): one step along x, then the diagonal cell
      highest = std::max({highest, costs[from + x_step], costs[from + x_step + y_step]});
    } else {  // (1, 2)
      highest = std::max({highest, costs[from + y_step], costs[from + x_step + y_step]});
    }
  }
  return length * (1.0 + cost_weight_ * static_cast<double>(highest));
}

}  // namespace vnsba::core
