// What the searches of one planning run did, with the geometry of the grid its cells index: the
// content of a PlannerDebug message in core types. The node publishes it; the recorder reads it
// back, stores it in run records and draws it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vnsba/core/geometry.hpp"

namespace vnsba::core {

struct SearchTrace {
  std::string planner;
  int32_t width = 0;  // cells: the grid the cells below index
  int32_t height = 0;
  double resolution = 0.0;  // metres per cell
  double origin_x = 0.0;    // metres
  double origin_y = 0.0;
  std::vector<Cell> expanded_forward;  // closed cells, in order
  std::vector<Cell> expanded_backward;
  std::optional<Cell> meeting_cell;
  std::vector<Cell> raw_path;
  std::vector<Eigen::Vector2d> pruned_waypoints;  // metres, map frame
};

}  // namespace vnsba::core
