// The 8-11-13 variable neighbourhood (ALGORITHM.md section 2; paper section 3.1).
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
  double cost = 0.0;  // Euclidean length in cells: 1, sqrt 2, 2, sqrt 5 or 2 sqrt 2
};

namespace detail {
constexpr double kSqrt2 = 1.4142135623730950488;
constexpr double kSqrt5 = 2.2360679774997896964;

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
template <class Visit>
inline void for_each_move(const GridMap& map, const Cell& from, const Cell& guide,
                          Neighborhood neighborhood, CornerPolicy policy, Visit&& visit) {
  using detail::corner_passable;
  const uint8_t* blocked = map.blocked_data();
  const int32_t stride = map.stride();
  const uint32_t at = map.padded_index(from);
  auto is_blocked = [&](int dx, int dy) -> bool { return blocked[at + dy * stride + dx] != 0; };

  const bool east = is_blocked(1, 0), west = is_blocked(-1, 0);
  const bool north = is_blocked(0, 1), south = is_blocked(0, -1);
  const bool ne = is_blocked(1, 1), nw = is_blocked(-1, 1);
  const bool se = is_blocked(1, -1), sw = is_blocked(-1, -1);
  if (!east) visit(1, 0, 1.0);
  if (!west) visit(-1, 0, 1.0);
  if (!north) visit(0, 1, 1.0);
  if (!south) visit(0, -1, 1.0);
  if (!ne && corner_passable(east, north, policy)) visit(1, 1, detail::kSqrt2);
  if (!nw && corner_passable(west, north, policy)) visit(-1, 1, detail::kSqrt2);
  if (!se && corner_passable(east, south, policy)) visit(1, -1, detail::kSqrt2);
  if (!sw && corner_passable(west, south, policy)) visit(-1, -1, detail::kSqrt2);

  if (neighborhood == Neighborhood::kEight) return;
  if (east | west | north | south | ne | nw | se | sw) return;  // an obstacle near: 8 only
  const int sx = detail::sign(guide.x - from.x);
  const int sy = detail::sign(guide.y - from.y);
  if (sx == 0 && sy == 0) return;
  if (sy == 0 || sx == 0) {
    // 11-neighbourhood: 3 cells two steps along the axis, e.g. for +x: (2,-1), (2,0), (2,1).
    const int px = -sy, py = sx;  // perpendicular to the axis
    const int cx = 2 * sx, cy = 2 * sy;
    if (!is_blocked(cx, cy)) visit(cx, cy, 2.0);
    if (!is_blocked(cx + px, cy + py)) visit(cx + px, cy + py, detail::kSqrt5);
    if (!is_blocked(cx - px, cy - py)) visit(cx - px, cy - py, detail::kSqrt5);
    return;
  }
  // 13-neighbourhood: (2sx,0), (2sx,sy), (2sx,2sy), (sx,2sy), (0,2sy).
  const bool b_2x_0 = is_blocked(2 * sx, 0), b_2x_1 = is_blocked(2 * sx, sy);
  const bool b_2x_2 = is_blocked(2 * sx, 2 * sy);
  const bool b_1_2y = is_blocked(sx, 2 * sy), b_0_2y = is_blocked(0, 2 * sy);
  if (!b_2x_0) visit(2 * sx, 0, 2.0);
  if (!b_2x_1) visit(2 * sx, sy, detail::kSqrt5);
  if (!b_2x_2 && corner_passable(b_2x_1, b_1_2y, policy))
    visit(2 * sx, 2 * sy, 2.0 * detail::kSqrt2);
  if (!b_1_2y) visit(sx, 2 * sy, detail::kSqrt5);
  if (!b_0_2y) visit(0, 2 * sy, 2.0);
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
