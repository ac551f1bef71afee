#include "vnsba/node/lifecycle_manager.hpp"

#include <spdlog/spdlog.h>

#include "lifecycle_msgs/srv/ChangeStatePubSubTypes.h"
#include "lifecycle_msgs/srv/GetStatePubSubTypes.h"

namespace vnsba::node {

namespace lifecycle_srv = lifecycle_msgs::srv::dds_;

const char* to_string(ManagerStep step) {
  switch (step) {
    case ManagerStep::kDone:
      return "done";
    case ManagerStep::kNoService:
      return "no change_state / get_state service";
    case ManagerStep::kNoReply:
      return "no reply";
    case ManagerStep::kRefused:
      return "change_state answered success false";
    case ManagerStep::kWrongState:
      return "get_state gave another state than the transition's";
    case ManagerStep::kBondNotFormed:
      return "the bond did not form within bond_timeout / 2";
  }
  return "?";
}

namespace {

// Nav2's transition_state_map_ (lifecycle_manager.cpp): where each transition it makes leads.
LifecycleState manager_goal_of(LifecycleTransition transition) {
  switch (transition) {
    case LifecycleTransition::kConfigure:
      return LifecycleState::kInactive;
    case LifecycleTransition::kCleanup:
      return LifecycleState::kUnconfigured;
    case LifecycleTransition::kActivate:
      return LifecycleState::kActive;
    case LifecycleTransition::kDeactivate:
      return LifecycleState::kInactive;
    case LifecycleTransition::kUnconfiguredShutdown:
    case LifecycleTransition::kInactiveShutdown:
    case LifecycleTransition::kActiveShutdown:
      return LifecycleState::kFinalized;
    default:
      return LifecycleState::kUnknown;
  }
}

}  // namespace

LifecycleManagerClient::LifecycleManagerClient(LifecycleManagerOptions options)
    : options_(std::move(options)) {}

LifecycleManagerClient::~LifecycleManagerClient() {
  // The manager's Bond objects break at destruction (bondcpp's ~Bond); so does this one.
  if (bond_) {
    bond_->break_bond();
    bond_->close();
  }
}

core::Expected<std::unique_ptr<LifecycleManagerClient>> LifecycleManagerClient::create(
    Participant& participant, LifecycleManagerOptions options) {
  std::unique_ptr<LifecycleManagerClient> client(new LifecycleManagerClient(std::move(options)));
  const std::string& name = client->options_.node_full_name;
  auto change = ServiceClient::create<lifecycle_srv::ChangeState_Request_PubSubType,
                                      lifecycle_srv::ChangeState_Response_PubSubType>(
      participant, name + "/change_state", client->options_.mapping);
  if (!change) return change.error();
  client->change_state_ = std::move(change).value();
  auto get = ServiceClient::create<lifecycle_srv::GetState_Request_PubSubType,
                                   lifecycle_srv::GetState_Response_PubSubType>(
      participant, name + "/get_state", client->options_.mapping);
  if (!get) return get.error();
  client->get_state_ = std::move(get).value();
  if (client->options_.bond_timeout.count() > 0) {
    auto link = BondLink::create(participant, client->options_.bond_topic);
    if (!link) return link.error();
    client->bond_ = std::move(link).value();
  }
  return client;
}

bool LifecycleManagerClient::wait_for_services(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (ServiceClient* service : {change_state_.get(), get_state_.get()}) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        end - std::chrono::steady_clock::now());
    if (!service->wait_for_server(std::max(left, std::chrono::milliseconds(0)))) return false;
  }
  return true;
}

std::optional<LifecycleState> LifecycleManagerClient::get_state() {
  if (!get_state_->server_ready() && !get_state_->wait_for_server(options_.service_wait))
    return std::nullopt;
  auto reply = get_state_->call<lifecycle_srv::GetState_Response_>(
      lifecycle_srv::GetState_Request_(), options_.reply_wait);
  if (!reply) return std::nullopt;
  return static_cast<LifecycleState>(reply->current_state().id());
}

std::optional<bool> LifecycleManagerClient::change_state_only(LifecycleTransition transition,
                                                              const std::string& label) {
  if (!change_state_->server_ready() && !change_state_->wait_for_server(options_.service_wait))
    return std::nullopt;
  lifecycle_srv::ChangeState_Request_ request;
  request.transition().id(static_cast<uint8_t>(transition));
  request.transition().label(label);
  auto reply =
      change_state_->call<lifecycle_srv::ChangeState_Response_>(request, options_.reply_wait);
  if (!reply) return std::nullopt;
  return reply->success();
}

ManagerStep LifecycleManagerClient::change_state(LifecycleTransition transition) {
  if (!wait_for_services(options_.service_wait)) return ManagerStep::kNoService;
  const std::optional<bool> changed = change_state_only(transition);
  if (!changed) return ManagerStep::kNoReply;
  if (!*changed) return ManagerStep::kRefused;
  const std::optional<LifecycleState> now = get_state();
  if (!now) return ManagerStep::kNoReply;
  if (*now != manager_goal_of(transition)) return ManagerStep::kWrongState;
  if (!bond_) return ManagerStep::kDone;
  if (transition == LifecycleTransition::kActivate) {
    // createBondConnection: a bond per node, heartbeat timeout bond_timeout, period 0.1 s,
    // waitUntilFormed(bond_timeout / 2).
    bond_->start(options_.bond_id, BondTimings::nav2_lifecycle_manager(options_.bond_timeout));
    if (!bond_->wait_until_formed(options_.bond_timeout / 2) ||
        bond_->state() != BondState::kAlive) {
      spdlog::error(
          "Server {} was unable to be reached after {:.2f}s by bond. This server may be "
          "misconfigured.",
          options_.bond_id, options_.bond_timeout.count() / 1000.0);
      return ManagerStep::kBondNotFormed;
    }
    spdlog::info("Server {} connected with bond.", options_.bond_id);
  } else if (transition == LifecycleTransition::kDeactivate) {
    bond_->break_bond();  // bond_map_.erase(node_name): the Bond's destructor breaks it
  }
  return ManagerStep::kDone;
}

ManagerStep LifecycleManagerClient::steps(std::initializer_list<LifecycleTransition> transitions,
                                          bool stop_at_failure, const OnStep& on_step) {
  ManagerStep first = ManagerStep::kDone;
  for (LifecycleTransition t : transitions) {
    const ManagerStep step = change_state(t);
    if (on_step) on_step(t, step);
    if (first == ManagerStep::kDone) first = step;
    if (step != ManagerStep::kDone && stop_at_failure) break;
  }
  return first;
}

ManagerStep LifecycleManagerClient::startup(const OnStep& on_step) {
  return steps({LifecycleTransition::kConfigure, LifecycleTransition::kActivate},
               /*stop_at_failure=*/true, on_step);
}

// shutdownAllNodes: deactivate, cleanup, unconfigured_shutdown, whatever each returned.
ManagerStep LifecycleManagerClient::shutdown(const OnStep& on_step) {
  return steps({LifecycleTransition::kDeactivate, LifecycleTransition::kCleanup,
                LifecycleTransition::kUnconfiguredShutdown},
               /*stop_at_failure=*/false, on_step);
}

// reset(hard_reset = true), as checkBondConnections calls it when a bond broke.
ManagerStep LifecycleManagerClient::reset(const OnStep& on_step) {
  return steps({LifecycleTransition::kDeactivate, LifecycleTransition::kCleanup},
               /*stop_at_failure=*/false, on_step);
}

BondState LifecycleManagerClient::bond_state() const {
  return bond_ ? bond_->state() : BondState::kNotStarted;
}

bool LifecycleManagerClient::wait_bond_broken(std::chrono::milliseconds timeout) const {
  return bond_ && bond_->wait_until_broken(timeout);
}

}  // namespace vnsba::node
