// The replier thread: writes every robot's plan_status, the action servers' replies and the
// node's plain services' replies (service_server.hpp), each
// once its requester can read it. A status is held until a status reader of the requesting
// participant is matched, at most requests.reply_wait (reply_gate.hpp); action replies likewise
// (action_server.hpp), paced by their flow (reply_flow.hpp). A status is never dropped for a
// newer one: one that a full status history refuses stays first in line. It also keeps the one
// budget of results every action server keeps (actions.kept_results_mb), and at shutdown writes
// everything still held and waits, within the drain's bound, for every reader to acknowledge it.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "action_server.hpp"
#include "fleet.hpp"
#include "service_server.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/reply_gate.hpp"

namespace vnsba::node {

class RequestIntake;

// How long a shutdown waits, in all, for the statuses it still owes to be written and
// acknowledged.
inline constexpr std::chrono::seconds kDrainTimeout{10};

class Replier {
 public:
  using Clock = std::chrono::steady_clock;

  // `intake` hears of every answer handed to DDS (RequestIntake::answered, resume).
  Replier(const NodeConfig& config, const Fleet& fleet, RequestIntake& intake);
  Replier(const Replier&) = delete;
  Replier& operator=(const Replier&) = delete;

  // `robot`'s plan_status writer, whose matched readers open its gate.
  core::Status add_status_writer(Participant& participant, const Robot& robot);
  // An action server of `robot`, whose replies this thread writes. `created`: its kept results
  // count toward actions.kept_results_mb (one that failed to create keeps none).
  void add_action_server(const Robot& robot, ActionServer& server, bool created);
  // A plain service of the node's (service_server.hpp: lifecycle_msgs, is_path_valid), whose
  // replies this thread writes; added before start().
  void add_service(ServiceServerBase& service);
  // The lock and the wake-up the action servers share with this thread (ActionServer's
  // constructor): their reply gates and goals are under the lock.
  std::mutex& mutex() { return mutex_; }
  std::condition_variable& wake() { return wake_; }

  // A status for `robot`'s status topic, written once `requester` (a plan_request's client)
  // has a matched status reader, or at once without one. `what` names it in the error log;
  // `is_answer`: a request's answer, owed to the intake until it is handed to DDS.
  void hold(const Robot& robot, PlanStatusMsg&& msg, const std::string& what, bool is_answer,
            std::optional<GuidPrefix> requester = std::nullopt);

  void start();
  // Writes everything still held at once, and ends the thread; statuses still unwritten at
  // `drain_deadline` are given up (and logged).
  void stop(Clock::time_point drain_deadline);
  // Written is not delivered: waits until `drain_deadline` for every reader's acknowledgement
  // of every status and action reply (deleting a writer would take them with it).
  void wait_for_acknowledgements(Clock::time_point drain_deadline);
  // Once the participant and the action servers are gone.
  void forget_endpoints();

  // Goals the action servers know (running, or finished and kept).
  size_t action_goals() const;
  // Readers matched by the plan_status writers.
  size_t status_readers() const;

 private:
  // A status held until the requester's status reader is matched.
  struct HeldStatus {
    PlanStatusMsg msg;
    std::string what;     // for the error log
    bool answer = false;  // a request's answer (owed to the intake), not a map report
  };
  class StatusReaders;  // a status writer's listener
  struct RobotReplies {
    explicit RobotReplies(const NodeConfig& config) : gate(config.reply_wait, kReaderSettle) {}
    dds::DataWriter* status_writer = nullptr;
    std::unique_ptr<dds::DataWriterListener> status_readers;  // feeds `gate` its matches
    ReplyGate<HeldStatus> gate;                               // under mutex_
    // Statuses released by `gate` and not yet accepted by the status writer, in order. The
    // replier thread's alone.
    std::deque<HeldStatus> unwritten;
    std::vector<ActionServer*> actions;  // walked under mutex_
  };
  struct DueReplies;

  const NodeConfig& cfg_;
  const Fleet& fleet_;
  RequestIntake& intake_;
  std::vector<std::unique_ptr<RobotReplies>> robots_;  // by Robot::index
  std::vector<ServiceServerBase*> services_;           // walked under mutex_

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;  // under mutex_
  // Set by stop() with stopping_: statuses still unwritten then are given up (and counted in
  // the log), and the acknowledgement wait ends.
  Clock::time_point drain_deadline_ = Clock::time_point::max();
  std::thread thread_;
  // Every robot's created action servers, for the one budget of kept results (under mutex_),
  // and the results that budget made the node forget, with the last warning.
  std::vector<ActionServer*> budgeted_;
  uint64_t results_forgotten_for_budget_ = 0;
  Clock::time_point budget_warned_{};

  void loop();
  // loop()'s steps.
  DueReplies take_due_replies(bool stopping);
  void forget_results_beyond_budget();
  size_t write_statuses(bool stopping, Clock::time_point drain_deadline);
  std::optional<ReplyGate<HeldStatus>::Clock::time_point> next_reply_deadline() const;
};

}  // namespace vnsba::node
