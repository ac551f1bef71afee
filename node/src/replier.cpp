#include "replier.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <utility>

#include "request_intake.hpp"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"

namespace vnsba::node {

// Tells a robot's gate of the status readers its writer matched (a DDS thread).
class Replier::StatusReaders : public dds::DataWriterListener {
 public:
  StatusReaders(Replier& replier, RobotReplies& replies) : replier_(replier), replies_(replies) {}
  void on_publication_matched(dds::DataWriter*,
                              const dds::PublicationMatchedStatus& status) override {
    if (status.current_count_change == 0) return;
    // An instance handle of an endpoint is its GUID: the first 12 bytes are the participant's.
    GuidPrefix prefix;
    for (size_t i = 0; i < prefix.size(); ++i) prefix[i] = status.last_subscription_handle.value[i];
    {
      std::lock_guard<std::mutex> lock(replier_.mutex_);
      replies_.gate.reader_matched(prefix, status.current_count_change);
    }
    replier_.wake_.notify_all();
  }

 private:
  Replier& replier_;
  RobotReplies& replies_;
};

// What one pass of the replier found due, under the lock.
struct Replier::DueReplies {
  size_t timed_out = 0;    // statuses released after requests.reply_wait without their reader
  bool unwritten = false;  // some robot has statuses to write
  // The action servers' replies and status lists due now.
  std::vector<std::pair<ActionServer*, ActionServer::Due>> action_dues;
  // The plain services' replies due now.
  std::vector<std::pair<ServiceServerBase*, ServiceServerBase::Due>> service_dues;
  // Status writers whose gate asked for a heartbeat (reply_gate.hpp: a fresh requester).
  std::vector<dds::DataWriter*> status_heartbeats;
};

Replier::Replier(const NodeConfig& config, const Fleet& fleet, RequestIntake& intake)
    : cfg_(config), fleet_(fleet), intake_(intake) {
  for (size_t i = 0; i < fleet.size(); ++i)
    robots_.push_back(std::make_unique<RobotReplies>(config));
}

core::Status Replier::add_status_writer(Participant& participant, const Robot& robot) {
  RobotReplies& replies = *robots_[robot.index];
  replies.status_readers = std::make_unique<StatusReaders>(*this, replies);
  auto writer = participant.writer_on<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
      robot.topic(cfg_.topics.plan_status), writer_qos(TopicQos::kStatus, false),
      replies.status_readers.get());
  if (!writer) return writer.error();
  replies.status_writer = *writer;
  return core::Status::ok();
}

void Replier::add_action_server(const Robot& robot, ActionServer& server, bool created) {
  robots_[robot.index]->actions.push_back(&server);
  if (created) budgeted_.push_back(&server);
}

void Replier::add_service(ServiceServerBase& service) {
  std::lock_guard<std::mutex> lock(mutex_);
  services_.push_back(&service);
}

void Replier::hold(const Robot& robot, PlanStatusMsg&& msg, const std::string& what, bool is_answer,
                   std::optional<GuidPrefix> requester) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    robots_[robot.index]->gate.hold(requester, HeldStatus{std::move(msg), what, is_answer},
                                    ReplyGate<HeldStatus>::Clock::now());
  }
  wake_.notify_all();
}

void Replier::start() {
  thread_ = std::thread([this] { loop(); });
}

void Replier::stop(Clock::time_point drain_deadline) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    drain_deadline_ = drain_deadline;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();  // writes every status still held
}

void Replier::wait_for_acknowledgements(Clock::time_point drain_deadline) {
  // A reader that lost a packet needs it again, and deleting the writer would take the status
  // with it (a SIGTERM mid-burst lost 226 of one client's 1,764).
  auto acknowledged = [&](dds::DataWriter* writer) {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::max(Clock::duration::zero(), drain_deadline - Clock::now()));
    const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(left);
    const eprosima::fastrtps::Duration_t wait(static_cast<int32_t>(seconds.count()),
                                              static_cast<uint32_t>((left - seconds).count()));
    return writer->wait_for_acknowledgments(wait) == ReturnCode_t::RETCODE_OK;
  };
  for (const Robot& robot : fleet_) {
    const RobotReplies& replies = *robots_[robot.index];
    if (replies.status_writer == nullptr) continue;
    bool all = acknowledged(replies.status_writer);
    for (const ActionServer* action : replies.actions)
      for (dds::DataWriter* writer : action->reply_writers())
        if (writer != nullptr) all = acknowledged(writer) && all;
    if (!all)
      spdlog::warn(
          "shutdown{}: statuses or action replies written but not acknowledged by every reader "
          "within the drain's {} s",
          robot.label(), kDrainTimeout.count());
  }
  bool services_acknowledged = true;
  for (const ServiceServerBase* service : services_)
    if (service->reply_writer() != nullptr)
      services_acknowledged = acknowledged(service->reply_writer()) && services_acknowledged;
  if (!services_acknowledged)
    spdlog::warn(
        "shutdown: service replies written but not acknowledged by every reader within "
        "the drain's {} s",
        kDrainTimeout.count());
}

void Replier::forget_endpoints() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& replies : robots_) {
    replies->status_writer = nullptr;
    replies->status_readers.reset();
    replies->actions.clear();
  }
  services_.clear();
  budgeted_.clear();
}

size_t Replier::action_goals() const {
  std::lock_guard<std::mutex> lock(mutex_);
  size_t goals = 0;
  for (const auto& replies : robots_)
    for (const ActionServer* action : replies->actions) goals += action->goals();
  return goals;
}

size_t Replier::status_readers() const {
  size_t readers = 0;
  for (const auto& replies : robots_)
    if (replies->status_writer != nullptr)
      readers += static_cast<size_t>(matched_readers(replies->status_writer));
  return readers;
}

Replier::DueReplies Replier::take_due_replies(bool stopping) {
  using ReplyClock = ReplyGate<HeldStatus>::Clock;
  // At shutdown everything still held goes out at once: nothing accepted is lost.
  const ReplyClock::time_point now = stopping ? ReplyClock::time_point::max() : ReplyClock::now();
  DueReplies due;
  for (const auto& replies : robots_) {
    bool heartbeat = false;
    for (HeldStatus& held : replies->gate.release(now, &due.timed_out, &heartbeat))
      replies->unwritten.push_back(std::move(held));
    if (heartbeat && replies->status_writer != nullptr)
      due.status_heartbeats.push_back(replies->status_writer);
    due.unwritten = due.unwritten || !replies->unwritten.empty();
    for (ActionServer* action : replies->actions) {
      ActionServer::Due action_due;
      action->take_due(ReplyClock::now(), stopping, action_due);
      if (!action_due.empty()) due.action_dues.emplace_back(action, std::move(action_due));
    }
  }
  for (ServiceServerBase* service : services_) {
    ServiceServerBase::Due service_due;
    service->take_due(ReplyClock::now(), stopping, service_due);
    if (!service_due.empty()) due.service_dues.emplace_back(service, std::move(service_due));
  }
  return due;
}

// One budget for the results every action server keeps (actions.kept_results_mb); under the
// lock.
void Replier::forget_results_beyond_budget() {
  const size_t forgotten =
      forget_beyond_budget(budgeted_, static_cast<size_t>(cfg_.actions.kept_results_mb) << 20);
  if (forgotten == 0) return;
  results_forgotten_for_budget_ += forgotten;
  if (Clock::now() - budget_warned_ < std::chrono::seconds(60)) return;
  budget_warned_ = Clock::now();
  spdlog::warn(
      "action results forgotten before actions.result_timeout to stay within "
      "actions.kept_results_mb ({} MiB): {} so far (a late get_result of one answers UNKNOWN)",
      cfg_.actions.kept_results_mb, results_forgotten_for_budget_);
}

// Writes every robot's unwritten statuses, without the lock (a write may block up to the
// writer's max_blocking_time). Returns how many a full status history kept back.
size_t Replier::write_statuses(bool stopping, Clock::time_point drain_deadline) {
  size_t waiting = 0;
  for (const Robot& robot : fleet_) {
    RobotReplies& replies = *robots_[robot.index];
    std::deque<HeldStatus>& queue = replies.unwritten;
    if (queue.empty()) continue;
    dds::DataWriter* writer = replies.status_writer;
    // A heartbeat first, one that does not count these statuses (writer_qos: manual
    // liveliness for that). To a volatile reader that has acknowledged nothing yet, Fast DDS
    // sends a status right behind a heartbeat that counts it, and Cyclone DDS's volatile
    // reader skips everything up to the last sequence number of the first heartbeat it gets
    // from a writer. A client that matched this writer after the node matched its reader
    // (discovery is not symmetric) missed the earlier heartbeats: it would lose its status.
    // Not enough alone over multicast (reply_gate.hpp): a requester's first status also
    // waited a settle after a heartbeat of its own (status_heartbeats in take_due_replies).
    if (writer != nullptr) writer->assert_liveliness();
    while (!queue.empty()) {
      HeldStatus& held = queue.front();
      // A keep-all history full of unacknowledged statuses refuses after max_blocking_time:
      // the status stays first in line and is tried again; none is ever dropped for a newer
      // one. Only a shutdown whose drain ran out of time gives the rest up, and says so.
      const bool written = writer != nullptr && write_sample(writer, &held.msg);
      if (!written && writer != nullptr && !(stopping && Clock::now() >= drain_deadline)) {
        waiting += queue.size();
        break;
      }
      if (!written)
        spdlog::error("could not publish the status of {}{}", held.what,
                      writer == nullptr ? "" : ": the shutdown's drain ran out of time");
      if (held.answer) intake_.answered(robot);
      queue.pop_front();
    }
    intake_.resume(robot);
  }
  return waiting;
}

// The earliest time a held status or an action server's reply falls due; under the lock.
auto Replier::next_reply_deadline() const
    -> std::optional<ReplyGate<HeldStatus>::Clock::time_point> {
  std::optional<ReplyGate<HeldStatus>::Clock::time_point> deadline;
  for (const auto& replies : robots_) {
    const auto next = replies->gate.next_deadline();
    if (next && (!deadline || *next < *deadline)) deadline = next;
    for (const ActionServer* action : replies->actions) {
      const auto next_action = action->next_deadline();
      if (next_action && (!deadline || *next_action < *deadline)) deadline = next_action;
    }
  }
  for (const ServiceServerBase* service : services_) {
    const auto next_service = service->next_deadline();
    if (next_service && (!deadline || *next_service < *deadline)) deadline = next_service;
  }
  return deadline;
}

void Replier::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  bool warned_full = false;  // one warning per episode of a full status history
  for (;;) {
    const bool stopping = stopping_;
    const Clock::time_point drain_deadline = drain_deadline_;
    DueReplies due = take_due_replies(stopping);
    if (!due.status_heartbeats.empty()) {
      // Heartbeats that count no status held now: a fresh requester's settle starts with them.
      lock.unlock();
      for (dds::DataWriter* writer : due.status_heartbeats) writer->assert_liveliness();
      lock.lock();
    }
    forget_results_beyond_budget();
    if (!due.action_dues.empty() || !due.service_dues.empty()) {
      lock.unlock();
      const bool give_up = stopping && Clock::now() >= drain_deadline;
      bool all_written = true;
      for (auto& [action, action_due] : due.action_dues)
        all_written = action->write(action_due, stopping, give_up) && all_written;
      for (auto& [service, service_due] : due.service_dues)
        all_written = service->write(service_due, stopping, give_up) && all_written;
      lock.lock();
      // Statuses released this pass go out below, in the same pass.
      if (!due.unwritten) {
        // Replies waiting for their readers' acknowledgements (reply_flow.hpp), which arrive
        // without a callback: looked for again shortly.
        if (!all_written) wake_.wait_for(lock, std::chrono::milliseconds(2));
        continue;
      }
    }
    if (due.unwritten) {
      lock.unlock();
      if (due.timed_out > 0)
        spdlog::warn(
            "{} status(es) written after requests.reply_wait ({} ms) without a matched status "
            "reader of the requesting participant: a volatile reader that matches later misses it",
            due.timed_out, cfg_.reply_wait.count());
      const size_t waiting = write_statuses(stopping, drain_deadline);
      lock.lock();
      if (waiting > 0 && !warned_full) {
        spdlog::warn(
            "status history full: {} status(es) wait for readers to acknowledge earlier ones "
            "(requests are taken again once answers go out)",
            waiting);
      }
      warned_full = waiting > 0;
      // Kept back: the write waited max_blocking_time already; look again soon, or at once
      // when something new is held.
      if (waiting > 0) wake_.wait_for(lock, std::chrono::milliseconds(10));
      continue;
    }
    if (stopping) return;
    if (const auto deadline = next_reply_deadline())
      wake_.wait_until(lock, *deadline);
    else
      wake_.wait(lock);
  }
}

}  // namespace vnsba::node
