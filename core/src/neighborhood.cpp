#include "vnsba/core/neighborhood.hpp"

namespace vnsba::core {

std::string_view to_string(Neighborhood n) {
  return n == Neighborhood::kEight ? "8" : "8-11-13";
}

std::optional<Neighborhood> neighborhood_from_string(std::string_view name) {
  if (name == "8") return Neighborhood::kEight;
  if (name == "8-11-13") return Neighborhood::kEightElevenThirteen;
  return std::nullopt;
}

}  // namespace vnsba::core
