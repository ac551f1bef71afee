// is_path_valid (nav2_msgs/srv/IsPathValid) on the node's map, without DDS: which poses of a path
// the robot can no longer be at, as nav2_planner's planner_server answers it (PlannerServer::
// isPathValid of navigation2's humble, jazzy and kilted branches, planner_server.cpp), on the
// node's GridMap and its one classification of cells (core::CellLayer) instead of a costmap.
//
// What follows Nav2 (the same in the three branches unless said):
// - an empty path is invalid;
// - the check starts at the pose closest to the robot (the first of equally close ones, distance
//   in x and y), so that poses already passed do not count; each pose is checked at its position
//   (a robot of radius robot_radius: Nav2's use_radius, the cell under the pose's centre);
// - a pose off the map (or not finite) is lethal;
// - lethal and inscribed cells are invalid (our occupied and inflated cells, and a costmap
//   slice's 99 and 100); Kilted also refuses a cell whose cost is max_cost or more (on Nav2's
//   scale, nav2_cost) and decides for unknown cells with consider_unknown_as_obstacle (false:
//   free, cost 0).
// Where it differs, and why:
// - without the robot's pose Nav2 checks nothing (is_valid stays true); here every pose is
//   checked from the first, so that a blocked path is never called valid for want of a pose;
// - Humble and Jazzy carry no consider_unknown_as_obstacle: a cell the map keeps unknown
//   (map.allow_unknown false) is invalid, as the node plans (Nav2 with a radius footprint takes
//   its NO_INFORMATION 255 as neither lethal nor inscribed);
// - invalid_pose_indices lists every invalid pose from the first checked (Nav2's branches stop
//   at the first and leave the list empty); is_valid is whether it is empty.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "vnsba/core/grid_map.hpp"

namespace vnsba::node {

// Nav2's costmap values (nav2_costmap_2d/cost_values.hpp): free 0, graded 1..252, inscribed
// 253, lethal 254, no information 255.
inline constexpr uint8_t kNav2FreeSpace = 0;
inline constexpr uint8_t kNav2MaxGradedCost = 252;
inline constexpr uint8_t kNav2InscribedCost = 253;
inline constexpr uint8_t kNav2LethalCost = 254;
inline constexpr uint8_t kNav2NoInformation = 255;

// A cell of `map` on Nav2's scale: occupied 254, inflated 253, unknown 255, a free cell its cost
// c in [0, 1) as round(c / 0.99 * 252) (the gradient's 0.99 just outside the robot's radius is
// Nav2's 252 there; a costmap slice's value v, c = v / 100, comes back within 3 of the cost Nav2
// translated to v). The cell must be in the map.
uint8_t nav2_cost(const core::GridMap& map, const core::Cell& cell);

// What makes a pose invalid beside lethal and inscribed cells: Kilted's request fields, or for
// Humble and Jazzy their defaults (max_cost 254 refuses nothing more; unknown cells invalid).
struct PathCheckRules {
  uint8_t max_cost = kNav2LethalCost;  // a cell of this cost (Nav2's scale) or more is invalid
  bool unknown_is_obstacle = true;     // an unknown cell is invalid (false: free, cost 0)
};

struct PathValidity {
  bool is_valid = false;
  std::vector<int32_t> invalid_pose_indices;  // ascending, from first_checked on
  size_t first_checked = 0;                   // the pose closest to the robot (0 without one)
};

// The check of `positions` (x, y metres in the map's frame, in the path's order) on `map`, the
// robot at `robot` (metres, the same frame; nullopt: unknown).
PathValidity check_path(const core::GridMap& map, const std::vector<Eigen::Vector2d>& positions,
                        const std::optional<Eigen::Vector2d>& robot, const PathCheckRules& rules);

// Whether a robot may be at `position` under `rules` (false off the map or not finite).
bool pose_is_valid(const core::GridMap& map, const Eigen::Vector2d& position,
                   const PathCheckRules& rules);

}  // namespace vnsba::node
