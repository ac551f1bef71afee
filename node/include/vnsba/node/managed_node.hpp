// vnsba_node as a ROS 2 managed (lifecycle) node, for Nav2's nav2_lifecycle_manager (issue 48).
// It serves, under the node's full name /<namespace>/<node_name>, on both rmw mappings
// (service_server.hpp), what rclcpp_lifecycle serves (rcl_lifecycle/src/com_interface.c):
//
//   ~/change_state, ~/get_state, ~/get_available_states, ~/get_available_transitions
//   (lifecycle_msgs/srv), and ~/transition_event (lifecycle_msgs/msg/TransitionEvent; reliable,
//   volatile, keep last 10: rcl's default publisher QoS)
//
// on a participant of its own named after the node, and drives a LifecycleMachine
// (lifecycle.hpp) whose transitions map onto the node's work (a PlannerNode):
//
//   configure   reads and validates the config again (the file given with --config, as a Nav2
//               node reads its parameters at configure; a bad file fails the transition and the
//               node stays unconfigured), then creates the PlannerNode: its participant,
//               writers, readers and action servers, not planning yet
//   activate    plans: plan_request, goal_pose and action goals are taken
//   deactivate  refuses new ones (plan_request and goal_pose: NODE_INACTIVE; action goals:
//               rejected, as Nav2's SimpleActionServer does while inactive); what was accepted
//               before is planned and answered
//   cleanup     deletes the PlannerNode: its map, planners, readers and writers are released
//   shutdown    the same from any primary state, then finalized: nothing is planned, and the
//               lifecycle services keep answering until SIGINT or SIGTERM (as an rclcpp node)
//
// lifecycle: self_activating (the default) runs configure and activate at start(), so a DDS
// user's node plans at once as before; its lifecycle services answer "active". lifecycle:
// managed starts unconfigured. One transition at a time: a change_state that arrives while one
// runs is answered success false.
#pragma once

#include <functional>
#include <memory>
#include <optional>

#include "vnsba/core/status.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/lifecycle.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::node {

class ManagedNode {
 public:
  // Reads and validates the configuration again, for configure; nullopt after logging every
  // problem (naming the key). Empty: configure uses `config` as it is.
  using LoadConfig = std::function<std::optional<NodeConfig>()>;

  ManagedNode(NodeConfig config, LoadConfig load_config);
  ~ManagedNode();  // stop()
  ManagedNode(const ManagedNode&) = delete;
  ManagedNode& operator=(const ManagedNode&) = delete;

  // Creates the lifecycle participant and endpoints and starts their thread; self_activating:
  // then configures and activates (the error of either is returned, nothing left running).
  core::Status start();
  // Ends the transition in progress, then the work (shutdown's), then the lifecycle endpoints.
  // Idempotent.
  void stop();
  // The work's figures as stop() ended it; nullopt when no work ran then (unconfigured or
  // finalized).
  std::optional<PlannerNode::Stats> final_stats() const;

  LifecycleState state() const;
  // The work while configured (null when unconfigured or finalized), for tests. A transition
  // may delete it: only while no change_state can arrive (tests that drive the node).
  PlannerNode* planner();
  // Readers matched by the transition_event writer now: the topic is volatile, so an event
  // published before a reader is matched never reaches it (a client that needs every event
  // waits for this, as for PlannerNode::Stats::status_readers).
  size_t event_readers() const;
  // The node's full ROS 2 name ("/vnsba_node"), its services' prefix.
  const std::string& full_name() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vnsba::node
