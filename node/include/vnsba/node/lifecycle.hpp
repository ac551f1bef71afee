// ROS 2's managed-node lifecycle as a plain state machine (no DDS): rcl_lifecycle's default
// state machine (ros2/rcl, rcl_lifecycle/src/default_state_machine.c: its states, transitions,
// labels and ids, registered in that order) driven as rclcpp_lifecycle drives it
// (rclcpp_lifecycle/src/lifecycle_node_interface_impl.cpp, change_state and on_change_state):
//
// - A change starts from a primary state with one of its transitions, named by id or by label
//   (a non-empty label wins over the id, as a ChangeState request with a label).
// - The machine enters the transition state (configuring, activating, ...), runs the callback,
//   and follows the callback's result: transition_success, transition_failure or
//   transition_error from that transition state (rcl's table: a failure goes back to the start
//   state, or on to finalized for shutdown; an error goes to errorprocessing).
// - From errorprocessing it runs the callback again (on_error): success leads to unconfigured,
//   failure or error to finalized.
// - Each step is an event {transition, start state, goal state} (what a node publishes on
//   transition_event). The change succeeds only when the callback returned success.
// One change at a time: a change asked for while another runs is refused (kBusy), never queued.
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace vnsba::node {

// lifecycle_msgs/msg/State's ids.
enum class LifecycleState : uint8_t {
  kUnknown = 0,
  kUnconfigured = 1,
  kInactive = 2,
  kActive = 3,
  kFinalized = 4,
  kConfiguring = 10,
  kCleaningUp = 11,
  kShuttingDown = 12,
  kActivating = 13,
  kDeactivating = 14,
  kErrorProcessing = 15,
};

// lifecycle_msgs/msg/Transition's ids.
enum class LifecycleTransition : uint8_t {
  kCreate = 0,
  kConfigure = 1,
  kCleanup = 2,
  kActivate = 3,
  kDeactivate = 4,
  kUnconfiguredShutdown = 5,
  kInactiveShutdown = 6,
  kActiveShutdown = 7,
  kDestroy = 8,
  kOnConfigureSuccess = 10,
  kOnConfigureFailure = 11,
  kOnConfigureError = 12,
  kOnCleanupSuccess = 20,
  kOnCleanupFailure = 21,
  kOnCleanupError = 22,
  kOnActivateSuccess = 30,
  kOnActivateFailure = 31,
  kOnActivateError = 32,
  kOnDeactivateSuccess = 40,
  kOnDeactivateFailure = 41,
  kOnDeactivateError = 42,
  kOnShutdownSuccess = 50,
  kOnShutdownFailure = 51,
  kOnShutdownError = 52,
  kOnErrorSuccess = 60,
  kOnErrorFailure = 61,
  kOnErrorError = 62,
};

// What a transition's callback returned (rclcpp_lifecycle's CallbackReturn).
enum class CallbackResult { kSuccess, kFailure, kError };

// rcl's label of a state ("unconfigured", "configuring", ...; "unknown" for any other id).
const char* state_label(LifecycleState state);
// Whether `state` is a primary state (unknown, unconfigured, inactive, active, finalized).
bool is_primary(LifecycleState state);

// One edge of rcl's default state machine.
struct LifecycleEdge {
  LifecycleTransition id;
  const char* label;  // "configure", ..., "shutdown", "transition_success", ...
  LifecycleState start;
  LifecycleState goal;
};

// Every state, in rcl's registration order (the primary states, then the transition states):
// what get_available_states answers.
const std::vector<LifecycleState>& lifecycle_states();
// Every edge, in rcl's registration order.
const std::vector<LifecycleEdge>& lifecycle_edges();
// The edges that leave `state`, in rcl's order: what get_available_transitions answers there.
std::vector<LifecycleEdge> edges_from(LifecycleState state);

// How a change ended.
enum class ChangeResult {
  kSucceeded,       // the callback returned success: the machine is in the transition's goal
  kCallbackFailed,  // failure: back where it started (finalized for shutdown)
  kCallbackError,   // error: through errorprocessing, to unconfigured or finalized
  kNotAvailable,    // no such transition from the current state (nothing happened)
  kBusy,            // another change runs (nothing happened)
};
const char* to_string(ChangeResult result);

struct ChangeOutcome {
  ChangeResult result = ChangeResult::kNotAvailable;
  LifecycleState state = LifecycleState::kUnknown;  // where the machine is now
  std::optional<LifecycleEdge> transition;          // the transition started, if any
  bool succeeded() const { return result == ChangeResult::kSucceeded; }
};

class LifecycleMachine {
 public:
  // The callback of transition state `state` (configuring, ..., errorprocessing); `from` is the
  // primary state the change started in (rclcpp's previous_state).
  using Callback = std::function<CallbackResult(LifecycleState state, LifecycleState from)>;
  // Each step taken: the edge and its start and goal (transition_event).
  using OnStep = std::function<void(const LifecycleEdge& edge)>;

  explicit LifecycleMachine(OnStep on_step = nullptr);

  // The current state (a transition state while a change runs).
  LifecycleState state() const;
  // The edges that leave the current state.
  std::vector<LifecycleEdge> available() const;

  // Runs a whole change with `callback` (on the calling thread; the machine is not locked while
  // the callback runs, so state() and available() answer meanwhile). `label` non-empty: the
  // transition with that label from the current state, else the one with id `id`.
  ChangeOutcome change(uint8_t id, const std::string& label, const Callback& callback);
  ChangeOutcome change(LifecycleTransition id, const Callback& callback) {
    return change(static_cast<uint8_t>(id), "", callback);
  }

 private:
  // The edge from the current state labelled `label`, or with id `id` (under mutex_).
  std::optional<LifecycleEdge> find(uint8_t id, const std::string& label) const;
  // Follows the edge from the current state with `label` (transition_success, ...).
  LifecycleEdge follow(const char* label);
  void step(const LifecycleEdge& edge);

  mutable std::mutex mutex_;
  LifecycleState state_ = LifecycleState::kUnconfigured;  // rcl's initial state
  bool changing_ = false;                                 // under mutex_
  OnStep on_step_;
};

}  // namespace vnsba::node
