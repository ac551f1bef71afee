#include "vnsba/node/path_validity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vnsba::node {

uint8_t nav2_cost(const core::GridMap& map, const core::Cell& cell) {
  switch (map.layer(cell)) {
    case core::CellLayer::kOccupied:
      return kNav2LethalCost;
    case core::CellLayer::kInflated:
      return kNav2InscribedCost;
    case core::CellLayer::kUnknown:
      return kNav2NoInformation;
    case core::CellLayer::kFree:
      break;
  }
  // The gradient's highest cost, 0.99 (grid_map.cpp), is Nav2's highest graded cost.
  constexpr double kOurCostOfNav2MaxGraded = 0.99;
  const double scaled = std::round(map.cost(cell) / kOurCostOfNav2MaxGraded * kNav2MaxGradedCost);
  return static_cast<uint8_t>(std::clamp(scaled, 0.0, double{kNav2MaxGradedCost}));
}

bool pose_is_valid(const core::GridMap& map, const Eigen::Vector2d& position,
                   const PathCheckRules& rules) {
  const std::optional<core::Cell> cell = map.world_to_cell(position.x(), position.y());
  if (!cell) return false;  // off the map: Nav2's worldToMap fails, the cost is lethal
  uint8_t cost = nav2_cost(map, *cell);
  if (cost == kNav2NoInformation)
    cost = rules.unknown_is_obstacle ? kNav2LethalCost : kNav2FreeSpace;
  return cost != kNav2LethalCost && cost != kNav2InscribedCost && cost < rules.max_cost;
}

PathValidity check_path(const core::GridMap& map, const std::vector<Eigen::Vector2d>& positions,
                        const std::optional<Eigen::Vector2d>& robot, const PathCheckRules& rules) {
  PathValidity out;
  if (positions.empty()) return out;  // Nav2: an empty path is invalid
  if (robot) {
    // The first of the closest poses (strictly closer replaces it), as Nav2's loop; a pose that
    // is not finite is never closer.
    double closest = std::numeric_limits<double>::max();
    for (size_t i = 0; i < positions.size(); ++i) {
      const double distance = (positions[i] - *robot).norm();
      if (distance < closest) {
        closest = distance;
        out.first_checked = i;
      }
    }
  }
  for (size_t i = out.first_checked; i < positions.size(); ++i)
    if (!pose_is_valid(map, positions[i], rules))
      out.invalid_pose_indices.push_back(static_cast<int32_t>(i));
  out.is_valid = out.invalid_pose_indices.empty();
  return out;
}

}  // namespace vnsba::node
