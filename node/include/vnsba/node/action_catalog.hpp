// The Nav2 actions the node serves, as the code around their DDS types sees them: which actions
// there are (ActionKind, nav2_actions()), what each is called where (its ROS 2 type, its topic
// key in the config, its name in job ids and on vnsba_send_goal's command line), its result's
// error codes, and a goal and a result as the node and a client hold them.
//
// Each entry is made from one traits type of node/src/action_traits.hpp, which also holds the
// action's DDS types; docs/nav2.md, "Adding a Nav2 action", says what a new action takes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vnsba/node/action_goals.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"

namespace vnsba::node {

// An action's place in the list of the Nav2 actions the node serves (Nav2Actions,
// action_traits.hpp). The enumerators name the two Nav2 planner actions (nav2_msgs/action, ROS 2
// Jazzy) for callers that pick one by name; any place in the list is a valid ActionKind.
enum class ActionKind : uint8_t { kComputePathToPose = 0, kComputePathThroughPoses = 1 };

// An action's three services (rcl_action), in the order the servers and clients index them.
enum class ActionService { kSendGoal = 0, kGetResult = 1, kCancelGoal = 2 };
constexpr size_t kActionServices = 3;
// "send_goal", "get_result", "cancel_goal": the service's part of its topic names.
const char* service_name(ActionService service);
// The DDS topic of a service's requests ("rq/<name>/_action/send_goalRequest") or replies
// ("rr/<name>/_action/send_goalReply"), as ROS 2 derives it from the action's full name.
std::string service_topic(const std::string& ros_name, ActionService service, bool request);
// The DDS topic of the action's "status" or "feedback" ("rt/<name>/_action/status").
std::string action_topic(const std::string& ros_name, const char* topic);

// An action's result error codes (nav2_msgs, ROS 2 Jazzy): 0 is NONE, then `names` in the order
// of their codes, from `base` (the action's UNKNOWN) on.
struct ActionErrorCodes {
  uint16_t base = 0;
  const char* const* names = nullptr;
  size_t count = 0;

  // The code of `name`, or the action's UNKNOWN when it has no code of that name.
  constexpr uint16_t code(std::string_view name) const {
    for (size_t i = 0; i < count; ++i)
      if (name == names[i]) return static_cast<uint16_t>(base + i);
    return base;
  }
  // "NONE" for 0, the name of one of the action's codes, else "NOT_A_NAV2_CODE".
  std::string name(uint16_t code) const;
};

// One Nav2 action, as nav2_actions() lists it.
struct Nav2ActionInfo {
  ActionKind kind{};
  const char* type_name = "";    // "nav2_msgs/action/ComputePathToPose", for messages
  const char* id_name = "";      // "compute_path_to_pose": the action in the node's job ids
  const char* option_name = "";  // "to_pose": vnsba_send_goal --action
  // Its ROS 2 action name in the config (topics.compute_path_to_pose).
  std::string TopicNames::*topic = nullptr;
  bool several_goals = false;  // a goal carries a list of poses (ComputePathThroughPoses)
  ActionErrorCodes errors;
};

// Every Nav2 action the node serves, in ActionKind order (the node makes their servers so).
const std::vector<Nav2ActionInfo>& nav2_actions();
const Nav2ActionInfo& nav2_action(ActionKind kind);

// Nav2's error code for a plan's wire code (`invalid_planner`: the planner could not be chosen):
// the code of the same failure among the action's own (wire::GOAL_OCCUPIED is
// ComputePathToPose's 206, ComputePathThroughPoses's 306); 0 for OK, the action's UNKNOWN for a
// failure Nav2 has no code for (NO_MAP, INVALID_MAP, INVALID_REQUEST, CANCELED, INTERNAL_ERROR).
uint16_t nav2_error_code(ActionKind kind, uint8_t wire_code, bool invalid_planner);

// A goal the server accepted, as the node plans it.
struct ActionGoal {
  GoalUuid id{};
  std::vector<PoseStampedMsg> goals;  // one for ComputePathToPose; the poses in order otherwise
  PoseStampedMsg start;
  bool use_start = false;
  std::string planner_id;
  RequestIdentity identity;  // of the send_goal request (its client)
};

// How a goal ended, as its result says it.
struct ActionOutcome {
  GoalState state = GoalState::kAborted;  // SUCCEEDED, ABORTED or CANCELED
  PathMsg path;
  double planning_time_s = 0.0;
  uint16_t error_code = 0;
  std::string error_msg;
};

// What a client's goal asks (nav2_msgs ComputePathToPose: one pose in `goals`; ThroughPoses: the
// list).
struct ActionGoalSpec {
  std::vector<PoseStampedMsg> goals;
  PoseStampedMsg start;
  std::string planner_id;
  bool use_start = true;
};

// A get_result reply, as a client reads it.
struct ActionResultReply {
  GoalState status = GoalState::kUnknown;
  PathMsg path;
  double planning_time_s = 0.0;
  uint16_t error_code = 0;
  std::string error_msg;
};

}  // namespace vnsba::node
