// The is_path_valid service of each robot (nav2_msgs/srv/IsPathValid of ros.distro, served while
// actions.enabled on topics.is_path_valid): each request answered at once, on the DDS thread that
// read it, from the node's current map and the robot's pose (is_path_valid.hpp,
// path_validity.hpp); its reply goes out on the replier thread as every service's does
// (service_server.hpp), in either middleware's mapping.
#pragma once

#include <memory>
#include <vector>

#include "fleet.hpp"
#include "map_input.hpp"
#include "node_readers.hpp"
#include "replier.hpp"
#include "robot_poses.hpp"
#include "service_server.hpp"

namespace vnsba::node {

class PathValidityService {
 public:
  PathValidityService(const NodeConfig& config, const MapInput& maps, RobotPoses& poses);
  ~PathValidityService();
  PathValidityService(const PathValidityService&) = delete;
  PathValidityService& operator=(const PathValidityService&) = delete;

  // `robot`'s server: its reply writer and request reader, its replies to `replier`'s thread.
  core::Status add(NodeReaders& readers, const ParticipantWatch* vendors, const Robot& robot,
                   Replier& replier);
  // The servers go, once the participant is gone.
  void release();

 private:
  const NodeConfig& cfg_;
  const MapInput& maps_;
  RobotPoses& poses_;
  // One per robot; kept when create() failed (its listener may run until the participant goes).
  std::vector<std::unique_ptr<ServiceServerBase>> servers_;
};

}  // namespace vnsba::node
