// Every request, whatever its interface (a plan_request, a goal_pose goal, a Nav2 action goal),
// becomes a Job, is checked once on arrival against the configuration and the active map
// (requests.hpp, resolve_request) and then queued for a worker, or answered at once: refused by
// its checks, waiting for a first map (requests.map_wait), or CANCELED while the node shuts
// down. Only a request that would be planned preempts, replaces or queues. The accepted
// request carries what was resolved (Job::resolved), so the worker does not check it again.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "action_server.hpp"
#include "fleet.hpp"
#include "vnsba/node/requests.hpp"

namespace vnsba::node {

class Answers;
class MapInput;
class RequestIntake;
class RobotPoses;
class WorkQueues;

class RequestAdmission {
 public:
  RequestAdmission(const NodeConfig& config, const Fleet& fleet, RequestIntake& intake,
                   MapInput& maps, WorkQueues& queues, RobotPoses& poses, Answers& answers);
  RequestAdmission(const RequestAdmission&) = delete;
  RequestAdmission& operator=(const RequestAdmission&) = delete;

  // A plan_request of `robot`, taken by the intake.
  void on_request(const Robot& robot, Job job);
  // A goal_pose goal of `robot`: its start is the robot's pose (robot_pose_source).
  void on_goal(const Robot& robot, PoseStampedMsg&& goal, const RequestIdentity& identity);
  // A goal an action server accepted: checked like a request, then planned or answered.
  void on_action_goal(const Robot& robot, ActionServer& server, ActionGoal&& goal);
  // Goals a client asked to cancel: waiting ones are answered CANCELED, a running one stops.
  void on_action_cancel(const Robot& robot, ActionServer& server, const std::vector<GoalUuid>& ids);
  // A request counted as taken: checked, then queued or answered. Also a request that waited
  // for the first map (MapInput), as if it came now.
  void submit(const Robot& robot, Job job);

  // Whether requests are planned (lifecycle: active). While not, every request and goal_pose
  // goal is answered NODE_INACTIVE at once (action goals are rejected by their server).
  void set_accepting(bool accepting) { accepting_ = accepting; }
  bool accepting() const { return accepting_; }

  // plan_request samples, goal_pose goals and action goals taken.
  uint64_t received() const { return received_; }

 private:
  const NodeConfig& cfg_;
  RequestIntake& intake_;
  MapInput& maps_;
  WorkQueues& queues_;
  RobotPoses& poses_;
  Answers& answers_;
  std::atomic<uint64_t> received_{0};
  std::atomic<bool> accepting_{true};
  // Each robot's goal_pose goals so far, for their ids ("goal-7"); by Robot::index.
  std::vector<std::atomic<uint64_t>> goals_;

  // Why an action goal is refused before it becomes a request (Nav2's own codes: no poses,
  // too many, a path that cannot fit actions.max_result_poses); "" when it is not.
  std::string goal_refusal(const ActionGoal& goal) const;
};

}  // namespace vnsba::node
