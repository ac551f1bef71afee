// The Nav2 actions the node serves, one traits type each: what the action server and the action
// client need to know of an action, so that their code is the same for every action.
//
// A traits type has
// - its names: kTypeName (its ROS 2 type), kIdName (its name in the node's job ids), kOptionName
//   (vnsba_send_goal --action), kTopic (the config key of its ROS 2 action name); kSeveralGoals,
//   whether a goal carries a list of poses;
// - its DDS types per ROS 2 distribution (Wire<RosDistro>: fastddsgen's, from
//   idl/nav2_msgs/action/ and, where Humble or Kilted differ, idl/nav2_msgs_<distro>/action/):
//   the send_goal, get_result and feedback messages and their PubSubTypes, named by
//   VNSBA_NAV2_ACTION_DDS_TYPES (cancel_goal and the status list are action_msgs', the same for
//   every action and distribution);
// - its error codes (kErrors: the code of its UNKNOWN and the names from there on);
// - the goal and the result: read_goal (a goal's message into the node's ActionGoal),
//   write_goal (a client's ActionGoalSpec into the message), write_result (the node's
//   ActionOutcome into the result message), read_result (the message into a client's
//   ActionResultReply; both from PlansAPath for an action that plans a path), and
//   goal_bytes_problem (a goal refused before it is decoded, "" for none).
//
// Nav2Actions lists them; an ActionKind is a place in that list, and nav2_actions()
// (action_catalog.hpp) describes each from its traits.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "action_msgs/msg/GoalStatusArrayPubSubTypes.h"
#include "action_msgs/srv/CancelGoalPubSubTypes.h"
#include "nav2_msgs/action/ComputePathThroughPosesPubSubTypes.h"
#include "nav2_msgs/action/ComputePathToPosePubSubTypes.h"
#include "nav2_msgs_humble/action/ComputePathThroughPosesPubSubTypes.h"
#include "nav2_msgs_humble/action/ComputePathToPosePubSubTypes.h"
#include "nav2_msgs_kilted/action/ComputePathThroughPosesPubSubTypes.h"
#include "ros_named.hpp"
#include "vnsba/node/action_catalog.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

using CancelRequest = action_msgs::srv::dds_::CancelGoal_Request_;
using CancelRequestType = action_msgs::srv::dds_::CancelGoal_Request_PubSubType;
using CancelResponse = action_msgs::srv::dds_::CancelGoal_Response_;
using CancelResponseType = action_msgs::srv::dds_::CancelGoal_Response_PubSubType;
using GoalInfoMsg = action_msgs::msg::dds_::GoalInfo_;
using GoalStatusArrayMsg = action_msgs::msg::dds_::GoalStatusArray_;
using GoalStatusArrayType = action_msgs::msg::dds_::GoalStatusArray_PubSubType;

// Nav2's planner error names, in the order of their codes from the action's UNKNOWN (nav2_msgs of
// Jazzy and Kilted, the same codes in both; Humble's results carry none): ComputePathThroughPoses
// has all ten, ComputePathToPose the first nine.
inline constexpr const char* kPlannerErrorNames[] = {
    "UNKNOWN",        "INVALID_PLANNER", "TF_ERROR", "START_OUTSIDE_MAP", "GOAL_OUTSIDE_MAP",
    "START_OCCUPIED", "GOAL_OCCUPIED",   "TIMEOUT",  "NO_VALID_PATH",     "NO_VIAPOINTS_GIVEN"};

// The goal fields both planner actions share (start, use_start, planner_id), read into the
// node's goal and written from a client's.
template <class Goal>
void read_start_and_planner(Goal&& goal, ActionGoal& out) {
  out.start = std::move(goal.start());
  out.use_start = goal.use_start();
  out.planner_id = std::move(goal.planner_id());
}
template <class Goal>
void write_start_and_planner(const ActionGoalSpec& spec, Goal& goal) {
  goal.start(spec.start);
  goal.planner_id(spec.planner_id);
  goal.use_start(spec.use_start);
}

// Whether a distribution's planner result carries error_code and error_msg (Jazzy and Kilted do,
// Humble does not: its failures are the ABORTED status and an empty path alone).
template <class Result, class = void>
struct ResultHasErrorCode : std::false_type {};
template <class Result>
struct ResultHasErrorCode<Result, std::void_t<decltype(std::declval<Result&>().error_code())>>
    : std::true_type {};
template <class Result>
inline constexpr bool kResultHasErrorCode = ResultHasErrorCode<Result>::value;

// The result both planner actions share (path, planning_time, and where the distribution has them
// error_code, error_msg), written from the node's outcome and read into a client's reply.
template <class Result>
void write_path_result(const ActionOutcome& outcome, Result& result) {
  result.path(outcome.path);
  const double seconds = std::max(0.0, outcome.planning_time_s);
  const auto whole = static_cast<int32_t>(std::min(seconds, 2147483647.0));
  result.planning_time().sec(whole);
  result.planning_time().nanosec(
      static_cast<uint32_t>(std::min(999999999.0, std::round((seconds - whole) * 1e9))));
  if constexpr (kResultHasErrorCode<Result>) {
    result.error_code(outcome.error_code);
    result.error_msg(outcome.error_msg);
  }
}
template <class Result>
void read_path_result(Result&& result, ActionResultReply& out) {
  out.path = std::move(result.path());
  out.planning_time_s = result.planning_time().sec() + result.planning_time().nanosec() * 1e-9;
  if constexpr (kResultHasErrorCode<std::decay_t<Result>>) {
    out.error_code = result.error_code();
    out.error_msg = std::move(result.error_msg());
  }
}

// A goal whose leading list of poses announces more of them than its bytes can hold: refused
// before decoding, which would allocate every announced pose first (a count of 2^31 in a 40-byte
// sample). A PoseStamped takes at least 68 bytes on the wire (stamp 8, frame_id length 4, pose
// 56). The count follows the header (rmw_cyclonedds), `leading_bytes` (a goal's 16-byte id), and
// with `after_a_header` (Kilted's nav_msgs/Goals, is_path_valid's nav_msgs/Path) a
// std_msgs/Header (stamp 8, frame_id). "" when it fits.
inline constexpr size_t kGoalIdBytes = 16;
// `list` names the list in the message.
std::string announced_poses_problem(const RawSample& raw, WireMapping mapping,
                                    bool after_a_header = false,
                                    size_t leading_bytes = kGoalIdBytes,
                                    const char* list = "goals");

// fastddsgen's types of the action `Name` in the IDL module `Module` (nav2_msgs for Jazzy's,
// idl/nav2_msgs/action/Name.idl) under the names every action's Wire gives them, each
// PubSubType registered under its ROS 2 name (RosNamed).
#define VNSBA_NAV2_ACTION_DDS_TYPES(Module, Name)                                                 \
  using Goal = Module::action::dds_::Name##_Goal_;                                                \
  using Result = Module::action::dds_::Name##_Result_;                                            \
  using SendGoalRequest = Module::action::dds_::Name##_SendGoal_Request_;                         \
  using SendGoalRequestType = RosNamed<Module::action::dds_::Name##_SendGoal_Request_PubSubType>; \
  using SendGoalResponse = Module::action::dds_::Name##_SendGoal_Response_;                       \
  using SendGoalResponseType =                                                                    \
      RosNamed<Module::action::dds_::Name##_SendGoal_Response_PubSubType>;                        \
  using GetResultRequest = Module::action::dds_::Name##_GetResult_Request_;                       \
  using GetResultRequestType =                                                                    \
      RosNamed<Module::action::dds_::Name##_GetResult_Request_PubSubType>;                        \
  using GetResultResponse = Module::action::dds_::Name##_GetResult_Response_;                     \
  using GetResultResponseType =                                                                   \
      RosNamed<Module::action::dds_::Name##_GetResult_Response_PubSubType>;                       \
  using FeedbackMessageType = RosNamed<Module::action::dds_::Name##_FeedbackMessage_PubSubType>

// An action's wire types per distribution: each traits type has `template <RosDistro> struct
// Wire` (Jazzy's types by default, a specialization where a distribution differs), and the server
// and client pick one when they are made (with_wire).

// The result of an action that plans a path (path, planning_time, and error_code, error_msg where
// the distribution has them), as both of Nav2's planner actions have it.
struct PlansAPath {
  template <class Result>
  static void write_result(const ActionOutcome& outcome, Result& result) {
    write_path_result(outcome, result);
  }
  template <class Result>
  static void read_result(Result&& result, ActionResultReply& out) {
    read_path_result(std::move(result), out);
  }
};

// nav2_msgs/action/ComputePathToPose: the same goal in every distribution; Humble's result has
// no error_code or error_msg (idl/nav2_msgs_humble/action/ComputePathToPose.idl), Kilted's is
// Jazzy's.
struct ComputePathToPose : PlansAPath {
  static constexpr const char* kTypeName = "nav2_msgs/action/ComputePathToPose";
  static constexpr const char* kIdName = "compute_path_to_pose";
  static constexpr const char* kOptionName = "to_pose";
  static constexpr std::string TopicNames::*kTopic = &TopicNames::compute_path_to_pose;
  static constexpr bool kSeveralGoals = false;
  static constexpr ActionErrorCodes kErrors{200, kPlannerErrorNames, 9};

  template <RosDistro>
  struct Wire {
    VNSBA_NAV2_ACTION_DDS_TYPES(nav2_msgs, ComputePathToPose);
  };

  template <class Goal>
  static std::string goal_bytes_problem(const RawSample&, WireMapping) {
    return "";
  }
  template <class Goal>
  static void read_goal(Goal&& goal, ActionGoal& out) {
    out.goals = {goal.goal()};
    read_start_and_planner(std::move(goal), out);
  }
  template <class Goal>
  static void write_goal(const ActionGoalSpec& spec, Goal& goal) {
    if (!spec.goals.empty()) goal.goal(spec.goals.front());
    write_start_and_planner(spec, goal);
  }
};
template <>
struct ComputePathToPose::Wire<RosDistro::kHumble> {
  VNSBA_NAV2_ACTION_DDS_TYPES(nav2_msgs_humble, ComputePathToPose);
};

// nav2_msgs/action/ComputePathThroughPoses: Humble's result has no error_code or error_msg;
// Kilted's goal lists its poses in a nav_msgs/Goals (goals.goals; its header is not read, as
// Kilted's planner_server reads each pose's own frame).
struct ComputePathThroughPoses : PlansAPath {
  static constexpr const char* kTypeName = "nav2_msgs/action/ComputePathThroughPoses";
  static constexpr const char* kIdName = "compute_path_through_poses";
  static constexpr const char* kOptionName = "through_poses";
  static constexpr std::string TopicNames::*kTopic = &TopicNames::compute_path_through_poses;
  static constexpr bool kSeveralGoals = true;
  static constexpr ActionErrorCodes kErrors{300, kPlannerErrorNames, 10};

  template <RosDistro>
  struct Wire {
    VNSBA_NAV2_ACTION_DDS_TYPES(nav2_msgs, ComputePathThroughPoses);
  };

  // Whether a goal of this type lists its poses in a nav_msgs/Goals (Kilted).
  template <class Goal, class = void>
  struct GoalsMessage : std::false_type {};
  template <class Goal>
  struct GoalsMessage<Goal, std::void_t<decltype(std::declval<Goal&>().goals().goals())>>
      : std::true_type {};
  template <class Goal>
  static constexpr bool kGoalsMessage = GoalsMessage<Goal>::value;

  // A goal may be megabytes of poses: a count its bytes cannot hold is refused undecoded.
  template <class Goal>
  static std::string goal_bytes_problem(const RawSample& raw, WireMapping mapping) {
    return announced_poses_problem(raw, mapping, kGoalsMessage<Goal>);
  }
  template <class Goal>
  static void read_goal(Goal&& goal, ActionGoal& out) {
    if constexpr (kGoalsMessage<std::decay_t<Goal>>)
      out.goals = std::move(goal.goals().goals());
    else
      out.goals = std::move(goal.goals());
    read_start_and_planner(std::move(goal), out);
  }
  template <class Goal>
  static void write_goal(const ActionGoalSpec& spec, Goal& goal) {
    if constexpr (kGoalsMessage<Goal>) {
      // The list's header: the frame of its first pose (each pose keeps its own).
      if (!spec.goals.empty())
        goal.goals().header().frame_id(spec.goals.front().header().frame_id());
      goal.goals().goals(spec.goals);
    } else {
      goal.goals(spec.goals);
    }
    write_start_and_planner(spec, goal);
  }
};
template <>
struct ComputePathThroughPoses::Wire<RosDistro::kHumble> {
  VNSBA_NAV2_ACTION_DDS_TYPES(nav2_msgs_humble, ComputePathThroughPoses);
};
template <>
struct ComputePathThroughPoses::Wire<RosDistro::kKilted> {
  VNSBA_NAV2_ACTION_DDS_TYPES(nav2_msgs_kilted, ComputePathThroughPoses);
};

// `f(Wire{})` with the wire types of `Traits`'s action or service in `distro`; what `f` returns
// (the same type for every distribution).
template <class Traits, class F>
decltype(auto) with_wire(RosDistro distro, F&& f) {
  switch (distro) {
    case RosDistro::kHumble:
      return f(typename Traits::template Wire<RosDistro::kHumble>{});
    case RosDistro::kKilted:
      return f(typename Traits::template Wire<RosDistro::kKilted>{});
    case RosDistro::kJazzy:
      break;
  }
  return f(typename Traits::template Wire<RosDistro::kJazzy>{});
}

template <class... Actions>
struct ActionList {};

// Every Nav2 action the node serves, one traits type each: the node makes their servers in this
// order, and an ActionKind is a place here. Adding an action is adding its traits type here.
using Nav2Actions = ActionList<ComputePathToPose, ComputePathThroughPoses>;

namespace action_list {

template <class Action, class First, class... Rest>
constexpr size_t index_of(ActionList<First, Rest...>) {
  if constexpr (std::is_same_v<Action, First>) {
    return 0;
  } else {
    static_assert(sizeof...(Rest) > 0, "the action is not in the list");
    return 1 + index_of<Action>(ActionList<Rest...>{});
  }
}

// `f(First{})` for place 0, else the same on the rest. An ActionKind is always a place in the
// list (an enumerator, or a kind nav2_actions() gave): past the end is the last.
template <class F, class First, class... Rest>
decltype(auto) visit(size_t place, F& f, ActionList<First, Rest...>) {
  if constexpr (sizeof...(Rest) == 0) {
    return f(First{});
  } else {
    if (place == 0) return f(First{});
    return visit(place - 1, f, ActionList<Rest...>{});
  }
}

template <class F, class... Actions>
void for_each(F& f, ActionList<Actions...>) {
  (f(Actions{}), ...);
}

}  // namespace action_list

// The ActionKind of an action's traits type: its place in Nav2Actions.
template <class Action>
constexpr ActionKind action_kind() {
  return static_cast<ActionKind>(action_list::index_of<Action>(Nav2Actions{}));
}
static_assert(action_kind<ComputePathToPose>() == ActionKind::kComputePathToPose);
static_assert(action_kind<ComputePathThroughPoses>() == ActionKind::kComputePathThroughPoses);

// `f(Traits{})` with the traits type of `kind`'s action; what `f` returns (the same type for
// every action).
template <class F>
decltype(auto) with_action_traits(ActionKind kind, F&& f) {
  return action_list::visit(static_cast<size_t>(kind), f, Nav2Actions{});
}

// `f(Traits{})` for every action, in ActionKind order.
template <class F>
void for_each_action(F&& f) {
  action_list::for_each(f, Nav2Actions{});
}

}  // namespace vnsba::node
