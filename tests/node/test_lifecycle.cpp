// The lifecycle state machine without DDS (node/include/vnsba/node/lifecycle.hpp), against the
// table of ros2/rcl's rcl_lifecycle/src/default_state_machine.c and lifecycle_msgs' ids, written
// here from those sources (not from the class's output), and rclcpp_lifecycle's handling of a
// callback's SUCCESS, FAILURE and ERROR.
#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <stdexcept>
#include <thread>
#include <tuple>
#include <vector>

#include "vnsba/node/lifecycle.hpp"

namespace vnsba::node {
namespace {

// {transition id, label, start state id, goal state id}, as default_state_machine.c registers
// them (lifecycle_msgs/msg/Transition.msg and State.msg give the numbers).
struct RclEdge {
  int id;
  std::string label;
  int start;
  int goal;
};
const std::vector<RclEdge> kRclEdges = {
    {1, "configure", 1, 10},
    {10, "transition_success", 10, 2},
    {11, "transition_failure", 10, 1},
    {12, "transition_error", 10, 15},
    {2, "cleanup", 2, 11},
    {20, "transition_success", 11, 1},
    {21, "transition_failure", 11, 2},
    {22, "transition_error", 11, 15},
    {3, "activate", 2, 13},
    {30, "transition_success", 13, 3},
    {31, "transition_failure", 13, 2},
    {32, "transition_error", 13, 15},
    {4, "deactivate", 3, 14},
    {40, "transition_success", 14, 2},
    {41, "transition_failure", 14, 3},
    {42, "transition_error", 14, 15},
    {5, "shutdown", 1, 12},
    {6, "shutdown", 2, 12},
    {7, "shutdown", 3, 12},
    {50, "transition_success", 12, 4},
    {51, "transition_failure", 12, 4},
    {52, "transition_error", 12, 15},
    {60, "transition_success", 15, 1},
    {61, "transition_failure", 15, 4},
    {62, "transition_error", 15, 4},
};
// {id, label} of every state, primary states first, as registered.
const std::vector<std::pair<int, std::string>> kRclStates = {
    {0, "unknown"},     {1, "unconfigured"},  {2, "inactive"},        {3, "active"},
    {4, "finalized"},   {10, "configuring"},  {11, "cleaningup"},     {12, "shuttingdown"},
    {13, "activating"}, {14, "deactivating"}, {15, "errorprocessing"}};

int id_of(LifecycleState s) {
  return static_cast<int>(s);
}

CallbackResult always(CallbackResult r, LifecycleState, LifecycleState) {
  return r;
}

TEST(Lifecycle, TableIsRclsDefaultStateMachine) {
  const auto& edges = lifecycle_edges();
  ASSERT_EQ(edges.size(), kRclEdges.size());
  for (size_t i = 0; i < edges.size(); ++i) {
    SCOPED_TRACE(kRclEdges[i].label + " " + std::to_string(kRclEdges[i].id));
    EXPECT_EQ(static_cast<int>(edges[i].id), kRclEdges[i].id);
    EXPECT_EQ(edges[i].label, kRclEdges[i].label);
    EXPECT_EQ(id_of(edges[i].start), kRclEdges[i].start);
    EXPECT_EQ(id_of(edges[i].goal), kRclEdges[i].goal);
  }
  const auto& states = lifecycle_states();
  ASSERT_EQ(states.size(), kRclStates.size());
  for (size_t i = 0; i < states.size(); ++i) {
    EXPECT_EQ(id_of(states[i]), kRclStates[i].first);
    EXPECT_EQ(state_label(states[i]), kRclStates[i].second);
    EXPECT_EQ(is_primary(states[i]), kRclStates[i].first <= 4);
  }
}

TEST(Lifecycle, AvailableTransitionsPerPrimaryState) {
  // From the table above: the edges whose start is the state, in registration order.
  const std::vector<std::pair<LifecycleState, std::vector<int>>> expected = {
      {LifecycleState::kUnconfigured, {1, 5}},
      {LifecycleState::kInactive, {2, 3, 6}},
      {LifecycleState::kActive, {4, 7}},
      {LifecycleState::kFinalized, {}}};
  for (const auto& [state, ids] : expected) {
    std::vector<int> got;
    for (const LifecycleEdge& edge : edges_from(state)) got.push_back(static_cast<int>(edge.id));
    EXPECT_EQ(got, ids) << state_label(state);
  }
}

TEST(Lifecycle, WalkUnconfiguredToFinalizedWithEvents) {
  std::vector<std::tuple<int, int, int>> events;  // transition, start, goal
  LifecycleMachine machine([&](const LifecycleEdge& e) {
    events.emplace_back(static_cast<int>(e.id), id_of(e.start), id_of(e.goal));
  });
  EXPECT_EQ(machine.state(), LifecycleState::kUnconfigured);
  std::vector<std::pair<LifecycleState, LifecycleState>> calls;  // callback's state, from
  auto ok = [&](LifecycleState s, LifecycleState from) {
    calls.emplace_back(s, from);
    return CallbackResult::kSuccess;
  };
  EXPECT_EQ(machine.change(LifecycleTransition::kConfigure, ok).result, ChangeResult::kSucceeded);
  EXPECT_EQ(machine.state(), LifecycleState::kInactive);
  EXPECT_EQ(machine.change(LifecycleTransition::kActivate, ok).state, LifecycleState::kActive);
  EXPECT_EQ(machine.change(LifecycleTransition::kDeactivate, ok).state, LifecycleState::kInactive);
  // By label (ros2 lifecycle set ... shutdown): "shutdown" from inactive is id 6.
  const ChangeOutcome shutdown = machine.change(0, "shutdown", ok);
  EXPECT_TRUE(shutdown.succeeded());
  ASSERT_TRUE(shutdown.transition);
  EXPECT_EQ(shutdown.transition->id, LifecycleTransition::kInactiveShutdown);
  EXPECT_EQ(machine.state(), LifecycleState::kFinalized);
  EXPECT_TRUE(machine.available().empty());
  const std::vector<std::tuple<int, int, int>> expected_events = {
      {1, 1, 10}, {10, 10, 2}, {3, 2, 13}, {30, 13, 3},
      {4, 3, 14}, {40, 14, 2}, {6, 2, 12}, {50, 12, 4}};
  EXPECT_EQ(events, expected_events);
  const std::vector<std::pair<LifecycleState, LifecycleState>> expected_calls = {
      {LifecycleState::kConfiguring, LifecycleState::kUnconfigured},
      {LifecycleState::kActivating, LifecycleState::kInactive},
      {LifecycleState::kDeactivating, LifecycleState::kActive},
      {LifecycleState::kShuttingDown, LifecycleState::kInactive}};
  EXPECT_EQ(calls, expected_calls);
}

TEST(Lifecycle, UnavailableTransitionsChangeNothing) {
  int events = 0;
  LifecycleMachine machine([&](const LifecycleEdge&) { ++events; });
  auto ok = [](LifecycleState s, LifecycleState f) {
    return always(CallbackResult::kSuccess, s, f);
  };
  // activate (3) from unconfigured; a callback transition's id (10); a label of another state.
  for (const auto& [id, label] :
       std::vector<std::pair<uint8_t, std::string>>{{3, ""},
                                                    {10, ""},
                                                    {0, "activate"},
                                                    {0, "transition_success"},
                                                    {1, "cleanup"},
                                                    {99, ""}}) {
    const ChangeOutcome outcome = machine.change(id, label, ok);
    EXPECT_EQ(outcome.result, ChangeResult::kNotAvailable) << int(id) << " " << label;
    EXPECT_FALSE(outcome.succeeded());
  }
  EXPECT_EQ(machine.state(), LifecycleState::kUnconfigured);
  EXPECT_EQ(events, 0);
  // A label wins over the id, as in rclcpp_lifecycle: id 3 (activate) with label "configure".
  EXPECT_EQ(machine.change(3, "configure", ok).state, LifecycleState::kInactive);
}

TEST(Lifecycle, FailureGoesBackAndErrorGoesThroughErrorProcessing) {
  std::vector<int> goals;
  LifecycleMachine machine([&](const LifecycleEdge& e) { goals.push_back(id_of(e.goal)); });
  auto fail = [](LifecycleState s, LifecycleState f) {
    return always(CallbackResult::kFailure, s, f);
  };
  const ChangeOutcome failed = machine.change(LifecycleTransition::kConfigure, fail);
  EXPECT_EQ(failed.result, ChangeResult::kCallbackFailed);
  EXPECT_EQ(machine.state(), LifecycleState::kUnconfigured);
  EXPECT_EQ(goals, (std::vector<int>{10, 1}));

  // Error in configuring, then on_error succeeds: back to unconfigured (60).
  goals.clear();
  std::vector<LifecycleState> called;
  auto error_then_ok = [&](LifecycleState s, LifecycleState) {
    called.push_back(s);
    return s == LifecycleState::kErrorProcessing ? CallbackResult::kSuccess
                                                 : CallbackResult::kError;
  };
  EXPECT_EQ(machine.change(LifecycleTransition::kConfigure, error_then_ok).result,
            ChangeResult::kCallbackError);
  EXPECT_EQ(machine.state(), LifecycleState::kUnconfigured);
  EXPECT_EQ(goals, (std::vector<int>{10, 15, 1}));
  EXPECT_EQ(called, (std::vector<LifecycleState>{LifecycleState::kConfiguring,
                                                 LifecycleState::kErrorProcessing}));

  // Error, and on_error fails (or throws): finalized (61, 62).
  goals.clear();
  auto throws = [](LifecycleState, LifecycleState) -> CallbackResult {
    throw std::runtime_error("boom");
  };
  EXPECT_EQ(machine.change(LifecycleTransition::kConfigure, throws).result,
            ChangeResult::kCallbackError);
  EXPECT_EQ(machine.state(), LifecycleState::kFinalized);
  EXPECT_EQ(goals, (std::vector<int>{10, 15, 4}));

  // A failed shutdown still ends finalized (51).
  LifecycleMachine second;
  EXPECT_EQ(second.change(LifecycleTransition::kUnconfiguredShutdown, fail).state,
            LifecycleState::kFinalized);
  // A failed deactivate stays active (41).
  LifecycleMachine third;
  auto ok = [](LifecycleState s, LifecycleState f) {
    return always(CallbackResult::kSuccess, s, f);
  };
  third.change(LifecycleTransition::kConfigure, ok);
  third.change(LifecycleTransition::kActivate, ok);
  EXPECT_EQ(third.change(LifecycleTransition::kDeactivate, fail).state, LifecycleState::kActive);
}

TEST(Lifecycle, OneChangeAtATime) {
  LifecycleMachine machine;
  std::atomic<bool> inside{false};
  std::atomic<bool> release{false};
  std::thread slow([&] {
    machine.change(LifecycleTransition::kConfigure, [&](LifecycleState, LifecycleState) {
      inside = true;
      while (!release) std::this_thread::yield();
      return CallbackResult::kSuccess;
    });
  });
  while (!inside) std::this_thread::yield();
  // While configuring: the state is the transition state, and another change is refused.
  EXPECT_EQ(machine.state(), LifecycleState::kConfiguring);
  EXPECT_EQ(machine.available().size(), 3u);  // configuring's success, failure, error edges
  const ChangeOutcome busy = machine.change(
      LifecycleTransition::kConfigure,
      [](LifecycleState s, LifecycleState f) { return always(CallbackResult::kSuccess, s, f); });
  EXPECT_EQ(busy.result, ChangeResult::kBusy);
  release = true;
  slow.join();
  EXPECT_EQ(machine.state(), LifecycleState::kInactive);
}

}  // namespace
}  // namespace vnsba::node
