#include "vnsba/core/neighborhood.hpp"

#include "vnsba/core/motion_validator.hpp"

namespace vnsba::core {

std::string_view to_string(Neighborhood n) {
  return n == Neighborhood::kEight ? "8" : "8-11-13";
}

std::optional<Neighborhood> neighborhood_from_string(std::string_view name) {
  if (name == "8") return Neighborhood::kEight;
  if (name == "8-11-13") return Neighborhood::kEightElevenThirteen;
  return std::nullopt;
}

MoveList generate_moves(const GridMap& map, const Cell& from, const Cell& guide,
                        Neighborhood neighborhood, CornerPolicy policy) {
  MoveList out;
  MotionValidator(map, policy)
      .for_each_move(from, guide, neighborhood, [&](int dx, int dy, double cost) {
        out.moves[out.count++] = {static_cast<int8_t>(dx), static_cast<int8_t>(dy), cost};
      });
  return out;
}

}  // namespace vnsba::core
