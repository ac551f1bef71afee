// What Nav2's lifecycle manager does to one managed node, without ROS 2: the calls of
// nav2_lifecycle_manager (lifecycle_manager.cpp, Jazzy: changeStateForNode, createBondConnection,
// startup, shutdownAllNodes, reset, checkBondConnections) through nav2_util's
// LifecycleServiceClient (<node>/change_state and <node>/get_state, lifecycle_msgs), on the
// generic service client (service_client.hpp) in either rmw mapping, and its side of the bond
// (bond_link.hpp). vnsba_lifecycle and the bringup tests use it.
//
//   change_state(t)  change_state, then get_state must be the transition's goal (Nav2's
//                    transition_state_map_); after activate the bond is created with bond_timeout
//                    as its heartbeat timeout (period 0.1 s) and must form within bond_timeout / 2;
//                    after deactivate it is dropped (broken: active=false), as bond_map_.erase
//   startup()        configure, activate
//   shutdown()       deactivate, cleanup, shutdown (unconfigured_shutdown), each tried even when
//                    an earlier one failed, as shutdownAllNodes does
//   reset()          deactivate, cleanup (what the manager does to the stack when a bond breaks)
#pragma once

#include <chrono>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>

#include "vnsba/core/status.hpp"
#include "vnsba/node/bond_link.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/lifecycle.hpp"
#include "vnsba/node/service_client.hpp"

namespace vnsba::node {

// How one of the manager's steps ended.
enum class ManagerStep {
  kDone,           // the node is where the step leads (and for activate: bonded)
  kNoService,      // change_state or get_state not available within the wait
  kNoReply,        // a call sent, no reply in time
  kRefused,        // change_state answered success: false
  kWrongState,     // change_state succeeded but get_state says another state
  kBondNotFormed,  // activated, but no heartbeat of the node within bond_timeout / 2
};
const char* to_string(ManagerStep step);

struct LifecycleManagerOptions {
  // The node's full ROS 2 name ("/planner_server", node_full_name) and its bond id (its name).
  std::string node_full_name;
  std::string bond_id;
  // The bond's DDS topic (dds_topic_name(config, "bond")).
  std::string bond_topic;
  WireMapping mapping = WireMapping::kSampleIdentity;
  // Nav2's bond_timeout parameter (4 s); 0: no bond, as in Nav2.
  std::chrono::milliseconds bond_timeout{4000};
  // How long a step waits for the services and each reply (Nav2's change_state waits without
  // bound, get_state 2 s; a tool must give up some time).
  std::chrono::milliseconds service_wait{10000};
  std::chrono::milliseconds reply_wait{30000};
};

class LifecycleManagerClient {
 public:
  static core::Expected<std::unique_ptr<LifecycleManagerClient>> create(
      Participant& participant, LifecycleManagerOptions options);
  ~LifecycleManagerClient();

  // Until change_state's and get_state's servers are ready (Nav2's wait_for_service).
  bool wait_for_services(std::chrono::milliseconds timeout);
  // get_state: the node's state, nullopt without a reply.
  std::optional<LifecycleState> get_state();
  // change_state with a transition's id (or its label when `label` is not empty), nothing more:
  // the reply's success, nullopt without a reply.
  std::optional<bool> change_state_only(LifecycleTransition transition,
                                        const std::string& label = "");
  // Nav2's changeStateForNode (see above).
  ManagerStep change_state(LifecycleTransition transition);
  // Each step as it ends (a tool prints it).
  using OnStep = std::function<void(LifecycleTransition transition, ManagerStep step)>;
  // The first step that did not end kDone stops startup; shutdown and reset try every step and
  // return the first failure (kDone when all went through).
  ManagerStep startup(const OnStep& on_step = nullptr);
  ManagerStep shutdown(const OnStep& on_step = nullptr);
  ManagerStep reset(const OnStep& on_step = nullptr);

  // The manager's side of the bond (kNotStarted before the first activate; kDead once broken,
  // or dropped at deactivate).
  BondState bond_state() const;
  // Waits until the bond is broken (checkBondConnections: isBroken()).
  bool wait_bond_broken(std::chrono::milliseconds timeout) const;
  const LifecycleManagerOptions& options() const { return options_; }

 private:
  explicit LifecycleManagerClient(LifecycleManagerOptions options);
  ManagerStep steps(std::initializer_list<LifecycleTransition> transitions, bool stop_at_failure,
                    const OnStep& on_step);
  LifecycleManagerOptions options_;
  std::unique_ptr<ServiceClient> change_state_;
  std::unique_ptr<ServiceClient> get_state_;
  std::unique_ptr<BondLink> bond_;
};

}  // namespace vnsba::node
