#include "vnsba/node/lifecycle.hpp"

namespace vnsba::node {

namespace {

using S = LifecycleState;
using T = LifecycleTransition;

// rcl_lifecycle's transition labels (default_state_machine.c).
constexpr const char* kSuccessLabel = "transition_success";
constexpr const char* kFailureLabel = "transition_failure";
constexpr const char* kErrorLabel = "transition_error";

}  // namespace

const char* state_label(LifecycleState state) {
  switch (state) {
    case S::kUnknown:
      return "unknown";
    case S::kUnconfigured:
      return "unconfigured";
    case S::kInactive:
      return "inactive";
    case S::kActive:
      return "active";
    case S::kFinalized:
      return "finalized";
    case S::kConfiguring:
      return "configuring";
    case S::kCleaningUp:
      return "cleaningup";
    case S::kShuttingDown:
      return "shuttingdown";
    case S::kActivating:
      return "activating";
    case S::kDeactivating:
      return "deactivating";
    case S::kErrorProcessing:
      return "errorprocessing";
  }
  return "unknown";
}

bool is_primary(LifecycleState state) {
  return static_cast<uint8_t>(state) <= static_cast<uint8_t>(S::kFinalized);
}

const std::vector<LifecycleState>& lifecycle_states() {
  static const std::vector<LifecycleState> states = {
      S::kUnknown,    S::kUnconfigured, S::kInactive,       S::kActive,
      S::kFinalized,  S::kConfiguring,  S::kCleaningUp,     S::kShuttingDown,
      S::kActivating, S::kDeactivating, S::kErrorProcessing};
  return states;
}

// _register_transitions in default_state_machine.c, edge for edge and in its order.
const std::vector<LifecycleEdge>& lifecycle_edges() {
  static const std::vector<LifecycleEdge> edges = {
      {T::kConfigure, "configure", S::kUnconfigured, S::kConfiguring},
      {T::kOnConfigureSuccess, kSuccessLabel, S::kConfiguring, S::kInactive},
      {T::kOnConfigureFailure, kFailureLabel, S::kConfiguring, S::kUnconfigured},
      {T::kOnConfigureError, kErrorLabel, S::kConfiguring, S::kErrorProcessing},
      {T::kCleanup, "cleanup", S::kInactive, S::kCleaningUp},
      {T::kOnCleanupSuccess, kSuccessLabel, S::kCleaningUp, S::kUnconfigured},
      {T::kOnCleanupFailure, kFailureLabel, S::kCleaningUp, S::kInactive},
      {T::kOnCleanupError, kErrorLabel, S::kCleaningUp, S::kErrorProcessing},
      {T::kActivate, "activate", S::kInactive, S::kActivating},
      {T::kOnActivateSuccess, kSuccessLabel, S::kActivating, S::kActive},
      {T::kOnActivateFailure, kFailureLabel, S::kActivating, S::kInactive},
      {T::kOnActivateError, kErrorLabel, S::kActivating, S::kErrorProcessing},
      {T::kDeactivate, "deactivate", S::kActive, S::kDeactivating},
      {T::kOnDeactivateSuccess, kSuccessLabel, S::kDeactivating, S::kInactive},
      {T::kOnDeactivateFailure, kFailureLabel, S::kDeactivating, S::kActive},
      {T::kOnDeactivateError, kErrorLabel, S::kDeactivating, S::kErrorProcessing},
      {T::kUnconfiguredShutdown, "shutdown", S::kUnconfigured, S::kShuttingDown},
      {T::kInactiveShutdown, "shutdown", S::kInactive, S::kShuttingDown},
      {T::kActiveShutdown, "shutdown", S::kActive, S::kShuttingDown},
      {T::kOnShutdownSuccess, kSuccessLabel, S::kShuttingDown, S::kFinalized},
      {T::kOnShutdownFailure, kFailureLabel, S::kShuttingDown, S::kFinalized},
      {T::kOnShutdownError, kErrorLabel, S::kShuttingDown, S::kErrorProcessing},
      {T::kOnErrorSuccess, kSuccessLabel, S::kErrorProcessing, S::kUnconfigured},
      {T::kOnErrorFailure, kFailureLabel, S::kErrorProcessing, S::kFinalized},
      {T::kOnErrorError, kErrorLabel, S::kErrorProcessing, S::kFinalized},
  };
  return edges;
}

std::vector<LifecycleEdge> edges_from(LifecycleState state) {
  std::vector<LifecycleEdge> out;
  for (const LifecycleEdge& edge : lifecycle_edges())
    if (edge.start == state) out.push_back(edge);
  return out;
}

const char* to_string(ChangeResult result) {
  switch (result) {
    case ChangeResult::kSucceeded:
      return "succeeded";
    case ChangeResult::kCallbackFailed:
      return "the transition failed";
    case ChangeResult::kCallbackError:
      return "the transition raised an error";
    case ChangeResult::kNotAvailable:
      return "no such transition from the current state";
    case ChangeResult::kBusy:
      return "another transition is running";
  }
  return "?";
}

LifecycleMachine::LifecycleMachine(OnStep on_step) : on_step_(std::move(on_step)) {}

LifecycleState LifecycleMachine::state() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_;
}

std::vector<LifecycleEdge> LifecycleMachine::available() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return edges_from(state_);
}

// rclcpp_lifecycle's on_change_state: a non-empty label is looked up among the current state's
// transitions and wins over the id (`ros2 service call` leaves the id 0).
std::optional<LifecycleEdge> LifecycleMachine::find(uint8_t id, const std::string& label) const {
  for (const LifecycleEdge& edge : edges_from(state_))
    if (label.empty() ? static_cast<uint8_t>(edge.id) == id : label == edge.label) return edge;
  return std::nullopt;
}

void LifecycleMachine::step(const LifecycleEdge& edge) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = edge.goal;
  }
  if (on_step_) on_step_(edge);
}

LifecycleEdge LifecycleMachine::follow(const char* label) {
  std::optional<LifecycleEdge> edge;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    edge = find(0, label);
  }
  // Every transition state has all three labels (lifecycle_edges), so this always finds one.
  step(*edge);
  return *edge;
}

ChangeOutcome LifecycleMachine::change(uint8_t id, const std::string& label,
                                       const Callback& callback) {
  ChangeOutcome outcome;
  LifecycleState from = LifecycleState::kUnknown;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    outcome.state = state_;
    if (changing_) {
      outcome.result = ChangeResult::kBusy;
      return outcome;
    }
    outcome.transition = find(id, label);
    if (!outcome.transition) {
      outcome.result = ChangeResult::kNotAvailable;
      return outcome;
    }
    changing_ = true;
    from = state_;
  }
  auto label_of = [](CallbackResult result) {
    return result == CallbackResult::kSuccess   ? kSuccessLabel
           : result == CallbackResult::kFailure ? kFailureLabel
                                                : kErrorLabel;
  };
  // A callback that throws returned an error (rclcpp_lifecycle catches and reports ERROR too).
  auto run = [&](LifecycleState state) {
    try {
      return callback(state, from);
    } catch (...) {
      return CallbackResult::kError;
    }
  };
  step(*outcome.transition);
  const CallbackResult result = run(outcome.transition->goal);
  const LifecycleEdge ended = follow(label_of(result));
  if (result == CallbackResult::kError) follow(label_of(run(ended.goal)));
  outcome.result = result == CallbackResult::kSuccess   ? ChangeResult::kSucceeded
                   : result == CallbackResult::kFailure ? ChangeResult::kCallbackFailed
                                                        : ChangeResult::kCallbackError;
  std::lock_guard<std::mutex> lock(mutex_);
  outcome.state = state_;
  changing_ = false;
  return outcome;
}

}  // namespace vnsba::node
