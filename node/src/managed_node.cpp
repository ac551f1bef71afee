#include "vnsba/node/managed_node.hpp"

#include <spdlog/spdlog.h>

#include <condition_variable>
#include <mutex>
#include <thread>

#include "lifecycle_msgs/msg/TransitionEventPubSubTypes.h"
#include "lifecycle_msgs/srv/ChangeStatePubSubTypes.h"
#include "lifecycle_msgs/srv/GetAvailableStatesPubSubTypes.h"
#include "lifecycle_msgs/srv/GetAvailableTransitionsPubSubTypes.h"
#include "lifecycle_msgs/srv/GetStatePubSubTypes.h"
#include "service_server.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/planner_node.hpp"
#include "vnsba/node/security.hpp"

namespace vnsba::node {

namespace {

namespace lsrv = lifecycle_msgs::srv::dds_;
namespace lmsg = lifecycle_msgs::msg::dds_;

using ChangeStateServer =
    ServiceServer<lsrv::ChangeState_Request_PubSubType, lsrv::ChangeState_Response_PubSubType>;
using GetStateServer =
    ServiceServer<lsrv::GetState_Request_PubSubType, lsrv::GetState_Response_PubSubType>;
using GetAvailableStatesServer = ServiceServer<lsrv::GetAvailableStates_Request_PubSubType,
                                               lsrv::GetAvailableStates_Response_PubSubType>;
using GetAvailableTransitionsServer =
    ServiceServer<lsrv::GetAvailableTransitions_Request_PubSubType,
                  lsrv::GetAvailableTransitions_Response_PubSubType>;

lmsg::State_ state_msg(LifecycleState state) {
  lmsg::State_ msg;
  msg.id(static_cast<uint8_t>(state));
  msg.label(state_label(state));
  return msg;
}

lmsg::TransitionDescription_ description_msg(const LifecycleEdge& edge) {
  lmsg::TransitionDescription_ msg;
  msg.transition().id(static_cast<uint8_t>(edge.id));
  msg.transition().label(edge.label);
  msg.start_state(state_msg(edge.start));
  msg.goal_state(state_msg(edge.goal));
  return msg;
}

// rcl's default publisher QoS (rmw_qos_profile_default): reliable, volatile, keep last 10.
dds::DataWriterQos transition_event_qos() {
  dds::DataWriterQos qos = writer_qos(TopicQos::kLatest, false);
  qos.history().depth = 10;
  return qos;
}

}  // namespace

class ManagedNode::Impl {
 public:
  Impl(NodeConfig config, LoadConfig load)
      : cfg_(std::move(config)),
        load_(std::move(load)),
        full_name_(node_full_name(cfg_)),
        machine_([this](const LifecycleEdge& edge) { on_step(edge); }) {}

  core::Status start();
  void stop();

  const NodeConfig cfg_;  // as at start: the participant's domain, the name, the mode
  LoadConfig load_;
  const std::string full_name_;
  LifecycleMachine machine_;
  std::unique_ptr<PlannerNode> planner_;  // the transition thread's (and stop's, once it ended)
  mutable std::mutex planner_mutex_;      // guards planner_ for planner()

  // What the work does at each step: info for a managed node (its manager's steps), debug for a
  // self-activating one, whose start and stop stay as short in the log as before it had a
  // lifecycle (each transition is logged at info either way, on_step).
  template <class... Args>
  void narrate(spdlog::format_string_t<Args...> format, Args&&... args) const {
    spdlog::log(
        cfg_.lifecycle == LifecycleMode::kManaged ? spdlog::level::info : spdlog::level::debug,
        format, std::forward<Args>(args)...);
  }
  std::optional<PlannerNode::Stats> final_stats_;  // set by stop()

  size_t event_readers() const {
    return events_ == nullptr ? 0 : static_cast<size_t>(matched_readers(events_));
  }

 private:
  // The endpoints: a participant of the node's name, the four services, transition_event.
  core::Status create_endpoints();
  // Deletes them (a self-activating node whose endpoints could not all be made).
  void drop_endpoints();
  // The transition in `request`, on the transition thread; answered when it ends.
  void run_change(const ReplyAddress& from, lsrv::ChangeState_Request_ request);
  CallbackResult on_transition(LifecycleState state);
  CallbackResult configure();
  void release_work(const char* why);
  void on_step(const LifecycleEdge& edge);
  void serve_replies();  // the service thread: writes the services' replies (service_server.hpp)
  void transitions();    // the transition thread

  std::unique_ptr<ParticipantWatch> watch_;
  std::unique_ptr<Participant> participant_;
  std::vector<std::unique_ptr<TakingListener>> listeners_;
  dds::DataWriter* events_ = nullptr;
  std::unique_ptr<ChangeStateServer> change_state_;
  std::unique_ptr<GetStateServer> get_state_;
  std::unique_ptr<GetAvailableStatesServer> get_available_states_;
  std::unique_ptr<GetAvailableTransitionsServer> get_available_transitions_;
  std::vector<ServiceServerBase*> services_;

  std::mutex mutex_;  // the services' replies, the stop flag and the pending change
  std::condition_variable cv_;
  bool stopping_ = false;
  bool changing_ = false;  // a change is pending or running: another is answered false
  std::optional<std::pair<ReplyAddress, lsrv::ChangeState_Request_>> pending_;
  std::thread replier_;
  std::thread transitioner_;
  bool first_configure_ = true;
  std::optional<core::Status> work_error_;  // why the work could not start (configure)
};

core::Status ManagedNode::Impl::create_endpoints() {
  // The watch gives each client's vendor (the reply mapping) and the incompatible-QoS warnings;
  // a peer that security refuses is reported by the work's participant (ParticipantWatch), once,
  // as before the node had a lifecycle.
  watch_ = std::make_unique<ParticipantWatch>(std::set<std::string>{},
                                              [](const std::string&, const std::string&) {});
  watch_->leave_refused_peers_unreported();
  auto participant =
      Participant::create_configured(cfg_, cfg_.node_name, kNodeEnclave, watch_.get());
  if (!participant) return participant.error();
  participant_ = std::move(participant).value();
  auto events = participant_->writer_on<lmsg::TransitionEvent_PubSubType>(
      dds_topic_name(cfg_, full_name_ + "/transition_event"), transition_event_qos());
  if (!events) return events.error();
  events_ = *events;

  const ParticipantWatch* vendors = watch_.get();
  change_state_ = std::make_unique<ChangeStateServer>(
      full_name_ + "/change_state", cfg_, vendors, mutex_, cv_,
      [this](ChangeStateServer& server, const ReplyAddress& from,
             lsrv::ChangeState_Request_&& request) {
        bool busy = false;
        {
          std::lock_guard<std::mutex> lock(mutex_);
          busy = changing_ || stopping_;
          if (!busy) {
            changing_ = true;
            pending_.emplace(from, std::move(request));
          }
        }
        if (!busy) {
          cv_.notify_all();
          return;
        }
        spdlog::warn("{}: change_state refused: another transition is running (state {})",
                     full_name_, state_label(machine_.state()));
        lsrv::ChangeState_Response_ response;
        response.success(false);
        server.reply(from, response, "a change_state reply");
      });
  get_state_ = std::make_unique<GetStateServer>(
      full_name_ + "/get_state", cfg_, vendors, mutex_, cv_,
      [this](GetStateServer& server, const ReplyAddress& from, lsrv::GetState_Request_&&) {
        lsrv::GetState_Response_ response;
        response.current_state(state_msg(machine_.state()));
        server.reply(from, response, "a get_state reply");
      });
  get_available_states_ = std::make_unique<GetAvailableStatesServer>(
      full_name_ + "/get_available_states", cfg_, vendors, mutex_, cv_,
      [](GetAvailableStatesServer& server, const ReplyAddress& from,
         lsrv::GetAvailableStates_Request_&&) {
        lsrv::GetAvailableStates_Response_ response;
        for (LifecycleState state : lifecycle_states())
          response.available_states().push_back(state_msg(state));
        server.reply(from, response, "a get_available_states reply");
      });
  get_available_transitions_ = std::make_unique<GetAvailableTransitionsServer>(
      full_name_ + "/get_available_transitions", cfg_, vendors, mutex_, cv_,
      [this](GetAvailableTransitionsServer& server, const ReplyAddress& from,
             lsrv::GetAvailableTransitions_Request_&&) {
        lsrv::GetAvailableTransitions_Response_ response;
        for (const LifecycleEdge& edge : machine_.available())
          response.available_transitions().push_back(description_msg(edge));
        server.reply(from, response, "a get_available_transitions reply");
      });
  {
    std::lock_guard<std::mutex> lock(mutex_);
    services_ = {change_state_.get(), get_state_.get(), get_available_states_.get(),
                 get_available_transitions_.get()};
  }
  if (auto s = change_state_->create(*participant_, listeners_); !s.is_ok()) return s;
  if (auto s = get_state_->create(*participant_, listeners_); !s.is_ok()) return s;
  if (auto s = get_available_states_->create(*participant_, listeners_); !s.is_ok()) return s;
  return get_available_transitions_->create(*participant_, listeners_);
}

void ManagedNode::Impl::drop_endpoints() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    services_.clear();
  }
  if (participant_) participant_->shutdown();  // readers first: no listener runs after this
  participant_.reset();
  events_ = nullptr;
}

core::Status ManagedNode::Impl::start() {
  core::Status created = create_endpoints();
  const bool managed = cfg_.lifecycle == LifecycleMode::kManaged;
  if (!created.is_ok()) {
    if (managed) return created;
    // A self-activating node plans without them (a secured node whose permissions do not list
    // the lifecycle topics, say); its participant goes, so that it takes no part in discovery
    // or security handshakes.
    spdlog::warn("{}: lifecycle services not served: {}", full_name_, created.message);
    drop_endpoints();
  }
  // A request taken while the endpoints were made waits in its reply gate or in pending_.
  replier_ = std::thread([this] { serve_replies(); });
  transitioner_ = std::thread([this] { transitions(); });
  narrate("{}: lifecycle {}: {}", full_name_, managed ? "managed" : "self_activating",
          managed ? "unconfigured, waiting for change_state" : "configuring and activating");
  if (managed) return core::Status::ok();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    changing_ = true;  // a change_state meanwhile is answered false
  }
  core::Status status = core::Status::ok();
  for (LifecycleTransition step :
       {LifecycleTransition::kConfigure, LifecycleTransition::kActivate}) {
    const ChangeOutcome outcome = machine_.change(
        step, [this](LifecycleState state, LifecycleState) { return on_transition(state); });
    if (!outcome.succeeded()) {
      // What the work said, as vnsba_node said it before it had a lifecycle.
      if (work_error_) {
        status = *work_error_;
        break;
      }
      status =
          core::Status::error(core::StatusCode::kInternalError,
                              std::string("lifecycle ") +
                                  (outcome.transition ? outcome.transition->label : "transition") +
                                  ": " + to_string(outcome.result) + " (see the log above)");
      break;
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    changing_ = false;
  }
  return status;
}

void ManagedNode::Impl::transitions() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    cv_.wait(lock, [&] { return stopping_ || pending_.has_value(); });
    if (stopping_) return;
    auto [from, request] = std::move(*pending_);
    pending_.reset();
    lock.unlock();
    run_change(from, std::move(request));  // clears changing_ before it replies
    lock.lock();
  }
}

void ManagedNode::Impl::run_change(const ReplyAddress& from, lsrv::ChangeState_Request_ request) {
  const uint8_t id = request.transition().id();
  const std::string label = request.transition().label();
  const LifecycleState before = machine_.state();
  const ChangeOutcome outcome = machine_.change(
      id, label, [this](LifecycleState state, LifecycleState) { return on_transition(state); });
  if (outcome.result == ChangeResult::kNotAvailable)
    spdlog::warn("{}: change_state to transition {} '{}' refused: {} (state {})", full_name_,
                 static_cast<int>(id), printable(label), to_string(outcome.result),
                 state_label(before));
  else
    spdlog::info("{}: change_state {}: {} (state {} -> {})", full_name_,
                 outcome.transition ? outcome.transition->label : "?", to_string(outcome.result),
                 state_label(before), state_label(outcome.state));
  // Free for the next change before the reply goes out: a manager that asks again as soon as it
  // has the reply (nav2_lifecycle_manager: get_state, then the next transition) is not refused
  // as busy (a Cyclone DDS client was, between the reply and the end of this function).
  {
    std::lock_guard<std::mutex> lock(mutex_);
    changing_ = false;
  }
  lsrv::ChangeState_Response_ response;
  response.success(outcome.succeeded());
  change_state_->reply(from, response, "a change_state reply");
}

// Each transition state's work (the transition thread, or start()).
CallbackResult ManagedNode::Impl::on_transition(LifecycleState state) {
  switch (state) {
    case LifecycleState::kConfiguring:
      return configure();
    case LifecycleState::kActivating:
      if (planner_ == nullptr) return CallbackResult::kError;
      planner_->set_accepting(true);
      narrate("{}: active: planning plan_request, goal_pose and action goals", full_name_);
      return CallbackResult::kSuccess;
    case LifecycleState::kDeactivating:
      if (planner_ == nullptr) return CallbackResult::kError;
      planner_->set_accepting(false);
      spdlog::info(
          "{}: inactive: new requests are answered NODE_INACTIVE and goals rejected; those "
          "accepted before are planned and answered",
          full_name_);
      return CallbackResult::kSuccess;
    case LifecycleState::kCleaningUp:
      release_work("cleanup");
      return CallbackResult::kSuccess;
    case LifecycleState::kShuttingDown:
      release_work("shutdown");
      return CallbackResult::kSuccess;
    case LifecycleState::kErrorProcessing:
      release_work("error processing");
      return CallbackResult::kSuccess;
    default:
      return CallbackResult::kError;
  }
}

// The config read again (except at a self-activating node's start, which has just read it),
// checked against what cannot change without a restart, then the work created, not planning.
CallbackResult ManagedNode::Impl::configure() {
  std::optional<NodeConfig> config = cfg_;
  const bool reread =
      load_ && !(first_configure_ && cfg_.lifecycle == LifecycleMode::kSelfActivating);
  first_configure_ = false;
  if (reread) {
    spdlog::info("{}: configure: reading the config again", full_name_);
    config = load_();
    if (!config) {
      spdlog::error("{}: configure failed: the config has errors (above); still unconfigured",
                    full_name_);
      return CallbackResult::kFailure;
    }
    // The lifecycle endpoints live where the node started: these take effect at a restart.
    const std::pair<const char*, bool> fixed[] = {
        {"domain_id", config->domain_id != cfg_.domain_id},
        {"namespace", config->ros_namespace != cfg_.ros_namespace},
        {"node_name", config->node_name != cfg_.node_name},
        {"lifecycle", config->lifecycle != cfg_.lifecycle}};
    for (const auto& [key, changed] : fixed)
      if (changed) {
        spdlog::error(
            "{}: configure failed: {} changed in the config file since the node "
            "started (it takes effect at a restart); still unconfigured",
            full_name_, key);
        return CallbackResult::kFailure;
      }
  }
  auto planner = std::make_unique<PlannerNode>(std::move(*config));
  planner->set_accepting(false);
  if (core::Status status = planner->start(); !status.is_ok()) {
    spdlog::error("{}: configure failed: {}; still unconfigured", full_name_, status.message);
    work_error_ = std::move(status);
    return CallbackResult::kFailure;
  }
  {
    std::lock_guard<std::mutex> lock(planner_mutex_);
    planner_ = std::move(planner);
  }
  narrate("{}: configured: readers and writers created, not planning until activated", full_name_);
  return CallbackResult::kSuccess;
}

// Stops the work (what is queued is answered CANCELED, as at a node's shutdown) and frees it:
// its map, planners and DDS entities.
void ManagedNode::Impl::release_work(const char* why) {
  std::unique_ptr<PlannerNode> planner;
  {
    std::lock_guard<std::mutex> lock(planner_mutex_);
    planner = std::move(planner_);
  }
  if (planner == nullptr) return;
  planner->stop();
  planner.reset();
  narrate("{}: {}: map, planners, readers and writers released", full_name_, why);
}

void ManagedNode::Impl::on_step(const LifecycleEdge& edge) {
  spdlog::info("{}: lifecycle transition {} '{}': {} -> {}", full_name_, static_cast<int>(edge.id),
               edge.label, state_label(edge.start), state_label(edge.goal));
  if (events_ == nullptr) return;
  lmsg::TransitionEvent_ event;
  // rcl_lifecycle_com_interface_publish_notification leaves the transition and the timestamp
  // zero; the transition taken is filled in here (a listener can tell configure from cleanup).
  event.timestamp(0);
  event.transition().id(static_cast<uint8_t>(edge.id));
  event.transition().label(edge.label);
  event.start_state(state_msg(edge.start));
  event.goal_state(state_msg(edge.goal));
  if (!write_sample(events_, &event))
    spdlog::warn("{}: could not publish a transition_event", full_name_);
}

// The services' replies, each once its client's reply reader is matched (service_server.hpp);
// the same steps as the node's replier thread (replier.cpp) for its services.
void ManagedNode::Impl::serve_replies() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    const bool stopping = stopping_;
    std::vector<std::pair<ServiceServerBase*, ServiceServerBase::Due>> due;
    std::optional<ServiceServerBase::Clock::time_point> next;
    for (ServiceServerBase* service : services_) {
      ServiceServerBase::Due service_due;
      service->take_due(ServiceServerBase::Clock::now(), stopping, service_due);
      if (!service_due.empty()) due.emplace_back(service, std::move(service_due));
    }
    if (!due.empty()) {
      lock.unlock();
      bool all_written = true;
      for (auto& [service, service_due] : due)
        all_written = service->write(service_due, stopping, stopping) && all_written;
      lock.lock();
      if (!all_written) cv_.wait_for(lock, std::chrono::milliseconds(2));
      continue;
    }
    if (stopping) return;
    for (const ServiceServerBase* service : services_)
      if (auto at = service->next_deadline(); at && (!next || *at < *next)) next = at;
    if (next)
      cv_.wait_until(lock, *next);
    else
      cv_.wait(lock);
  }
}

void ManagedNode::Impl::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  cv_.notify_all();
  if (transitioner_.joinable()) transitioner_.join();  // a running transition ends first
  {
    std::lock_guard<std::mutex> lock(planner_mutex_);
    if (planner_ != nullptr) {
      planner_->stop();
      final_stats_ = planner_->stats();
    }
  }
  release_work("stop");
  if (participant_) participant_->delete_readers();  // no more requests
  if (replier_.joinable()) replier_.join();          // writes what is held
  if (participant_) participant_->shutdown();
  participant_.reset();
  listeners_.clear();
}

ManagedNode::ManagedNode(NodeConfig config, LoadConfig load_config)
    : impl_(std::make_unique<Impl>(std::move(config), std::move(load_config))) {}

ManagedNode::~ManagedNode() {
  stop();
}

core::Status ManagedNode::start() {
  core::Status status = impl_->start();
  if (!status.is_ok()) impl_->stop();
  return status;
}

void ManagedNode::stop() {
  impl_->stop();
}

std::optional<PlannerNode::Stats> ManagedNode::final_stats() const {
  return impl_->final_stats_;
}

LifecycleState ManagedNode::state() const {
  return impl_->machine_.state();
}

PlannerNode* ManagedNode::planner() {
  std::lock_guard<std::mutex> lock(impl_->planner_mutex_);
  return impl_->planner_.get();
}

size_t ManagedNode::event_readers() const {
  return impl_->event_readers();
}

const std::string& ManagedNode::full_name() const {
  return impl_->full_name_;
}

}  // namespace vnsba::node
