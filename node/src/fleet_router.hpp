// Each robot's inputs on the bus: its goal_pose and plan_request readers and its two Nav2 action
// servers (actions.enabled), routed to the admission with the robot they belong to. Taken by the
// intake thread, only while the robot has room for their answers (request_intake.hpp).
#pragma once

#include <memory>
#include <vector>

#include "action_server.hpp"
#include "fleet.hpp"
#include "node_readers.hpp"
#include "vnsba/node/time_source.hpp"

namespace vnsba::node {

class Replier;
class RequestAdmission;
class RequestIntake;

class FleetRouter {
 public:
  FleetRouter(const NodeConfig& config, const Fleet& fleet, RequestAdmission& admission,
              RequestIntake& intake, Replier& replier, const TimeSource& time);
  ~FleetRouter();
  FleetRouter(const FleetRouter&) = delete;
  FleetRouter& operator=(const FleetRouter&) = delete;

  // `robot`'s goal_pose reader, then its plan_request reader.
  core::Status add_request_readers(NodeReaders& readers, const Robot& robot);
  // `robot`'s compute_path_to_pose and compute_path_through_poses servers; `vendors` tells
  // each client's reply mapping (ParticipantWatch::vendor_of).
  core::Status add_action_servers(NodeReaders& readers, const ParticipantWatch* vendors,
                                  const Robot& robot);
  // The action servers go, once the participant is gone.
  void release();

 private:
  const NodeConfig& cfg_;
  RequestAdmission& admission_;
  RequestIntake& intake_;
  Replier& replier_;
  const TimeSource& time_;
  // By Robot::index. Kept even when create() failed: the listeners it made may call it until
  // the participant is gone.
  std::vector<std::vector<std::unique_ptr<ActionServer>>> actions_;
};

}  // namespace vnsba::node
