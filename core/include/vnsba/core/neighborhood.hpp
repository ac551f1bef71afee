// The 8-11-13 variable neighbourhood (docs/algorithm.md section 2; paper section 3.1).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/line_of_sight.hpp"

namespace vnsba::core {

enum class Neighborhood {
  kEight,                // the classic 8-neighbourhood
  kEightElevenThirteen,  // 8, plus 3 (axis) or 5 (quadrant) cells at distance 2 toward the guide
};

std::string_view to_string(Neighborhood n);
std::optional<Neighborhood> neighborhood_from_string(std::string_view name);  // "8", "8-11-13"

struct Move {
  int8_t dx = 0;
  int8_t dy = 0;
  double cost = 0.0;  // step cost in cells: 1, sqrt 2, 2, sqrt 5 or 2 sqrt 2 (see kStepCost*)
};

namespace detail {
constexpr double kSqrt2 = 1.4142135623730950488;
constexpr double kSqrt5 = 2.2360679774997896964;

// Step costs as every search adds them up into g: each Euclidean length rounded to the nearest
// multiple of 2^-26 cells (relative error below 1e-8). Sums of multiples of 2^-26 below 2^27
// cells are exact in double arithmetic, so two paths with the same numbers of each kind of step
// get bit-identical g whatever the order of their steps, and equal-cost nodes compare equal. With
// the irrational lengths themselves, rounding in the last bits made equal-f nodes differ and the
// open list's tie-break towards larger g fail (many more expansions on open ground for the same
// optimal cost). Costs are only ordered with these values; every reported length is measured on
// the path's geometry. A* stays optimal to within that relative 1e-8.
constexpr double kCostQuantum = 1.0 / 67108864.0;  // 2^-26 cells
constexpr double quantized_cost(double length) {
  return static_cast<double>(static_cast<int64_t>(length / kCostQuantum + 0.5)) * kCostQuantum;
}
constexpr double kStepCostStraight = 1.0;
constexpr double kStepCostDiagonal = quantized_cost(kSqrt2);
constexpr double kStepCostTwoStraight = 2.0;
constexpr double kStepCostKnight = quantized_cost(kSqrt5);
constexpr double kStepCostTwoDiagonal = 2.0 * kStepCostDiagonal;

inline int sign(int v) {
  return (v > 0) - (v < 0);
}
}  // namespace detail

// At most 13 moves from one cell.
struct MoveList {
  std::array<Move, 13> moves{};
  int count = 0;
  const Move* begin() const { return moves.data(); }
  const Move* end() const { return moves.data() + count; }
};

// Calls visit(dx, dy, cost) for each move available from `from` when expanding toward `guide`:
// 1. the 8 neighbours that are in the map and free, diagonals subject to `policy`;
// 2. with kEightElevenThirteen and all 8 neighbours in the map and free, the extra cells at
//    Chebyshev distance 2 in the guide's direction (3 on an axis, 5 in a quadrant, none when
//    guide == from), each only when it is in the map and free.
// The extra (2, 2)-type move passes exactly through the corner between (1, 2) and (2, 1), two
// cells outside the 8-neighbourhood; the paper leaves this open, and we check them with the
// same corner policy as every other corner, so that every move has line of sight.
// `from` must be free and in the map.
//
// Works on the map's padded layout (no bounds checks: the border is blocked). A template that
// calls back rather than returning a list because it is the innermost loop of every search.
// [[gnu::always_inline]]: the searches' innermost loop; out of line it costs a call per move.
template <class Visit>
[[gnu::always_inline]] inline void for_each_move(const GridMap& map, const Cell& from,
                                                 const Cell& guide, Neighborhood neighborhood,
                                                 CornerPolicy policy, Visit&& visit) {
  using detail::corner_passable;
  const uint8_t* blocked = map.blocked_data();
  const int32_t stride = map.stride();
  const uint32_t at = map.padded_index(from);
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

// The same moves as a list (for tests and tools; the searches use for_each_move).
inline MoveList generate_moves(const GridMap& map, const Cell& from, const Cell& guide,
                               Neighborhood neighborhood, CornerPolicy policy) {
  MoveList out;
  for_each_move(map, from, guide, neighborhood, policy, [&](int dx, int dy, double cost) {
    out.moves[out.count++] = {static_cast<int8_t>(dx), static_cast<int8_t>(dy), cost};
  });
  return out;
}

}  // namespace vnsba::core
