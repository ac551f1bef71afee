#include "fleet.hpp"

#include <utility>

namespace vnsba::node {

Robot::Robot(const NodeConfig& node, std::string robot_name, size_t robot_index)
    : index(robot_index),
      name(std::move(robot_name)),
      cfg(robot_view(node, name)),
      base_frame(name.empty() ? node.base_frame : name + "/" + node.base_frame) {}

Fleet::Fleet(const NodeConfig& config) {
  if (config.robots.empty()) {
    robots_.emplace_back(config, "", 0);
    return;
  }
  robots_.reserve(config.robots.size());
  for (const std::string& robot : config.robots)
    robots_.emplace_back(config, robot, robots_.size());
}

}  // namespace vnsba::node
