// The robots one node serves (`robots`), each under its own namespace; without `robots` one,
// under the node's. No DDS: names, topics and frames, fixed for the node's life, so that every
// role and thread reads them without a lock. Each role keeps its own state of a robot (its
// writers, its queue, its answers owed) by Robot::index.
#pragma once

#include <string>
#include <vector>

#include "vnsba/node/config.hpp"

namespace vnsba::node {

struct Robot {
  Robot(const NodeConfig& node, std::string robot_name, size_t robot_index);
  const size_t index;      // its place in the fleet, from 0
  const std::string name;  // "" without `robots`
  const NodeConfig cfg;    // the node's, with the robot's namespace
  // The robot's base frame in the tf tree: with several robots on one tree each has its own
  // frames ("<robot>/base_link").
  const std::string base_frame;

  // The DDS name of a configured topic, under the robot's namespace.
  std::string topic(const std::string& configured) const { return dds_topic_name(cfg, configured); }
  // In log lines: "" or " (robot robot7)".
  std::string label() const { return name.empty() ? "" : " (robot " + name + ")"; }
};

class Fleet {
 public:
  explicit Fleet(const NodeConfig& config);
  Fleet(const Fleet&) = delete;
  Fleet& operator=(const Fleet&) = delete;

  size_t size() const { return robots_.size(); }
  const Robot& operator[](size_t index) const { return robots_[index]; }
  const Robot& front() const { return robots_.front(); }
  const Robot& back() const { return robots_.back(); }
  std::vector<Robot>::const_iterator begin() const { return robots_.begin(); }
  std::vector<Robot>::const_iterator end() const { return robots_.end(); }

 private:
  // Filled once by the constructor and never changed: references to its robots stay valid.
  std::vector<Robot> robots_;
};

}  // namespace vnsba::node
