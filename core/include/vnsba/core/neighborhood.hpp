// The 8-11-13 variable neighbourhood (docs/algorithm.md section 2; paper section 3.1): its names,
// moves and step costs. Which moves a cell has is MotionValidator's (motion_validator.hpp).
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

// The moves out of `from` toward `guide` as a list, in the order MotionValidator::for_each_move
// (motion_validator.hpp, which says which moves there are) visits them: for tests and tools; the
// searches call for_each_move.
MoveList generate_moves(const GridMap& map, const Cell& from, const Cell& guide,
                        Neighborhood neighborhood, CornerPolicy policy);

}  // namespace vnsba::core
