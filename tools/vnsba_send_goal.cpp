// vnsba_send_goal: one planning request from the command line, answered by one line.
//
//   vnsba_send_goal [--config FILE] [--domain N] [--namespace NS] --start X Y --goal X Y
//                   [--yaw RAD] [--planner NAME] [--id ID] [--wait SECONDS] [--min-readers N]
//   vnsba_send_goal --action [to_pose | through_poses] [--start X Y] --goal X Y [--goal X Y ...]
//                   [--yaw RAD] [--planner NAME] [--mapping fastrtps | cyclonedds]
//                   [--distro humble | jazzy | kilted]
//                   [--cancel-after SECONDS] [--wait SECONDS] [--config FILE] [--domain N] ...
//
// Without --action it publishes one vnsba_msgs/PlanRequest (start and goal in metres, in the
// config's frame_id; the goal facing --yaw radians, 0 = +x) and prints the PlanStatus the node
// answers it with as one line on stdout:
//
//   <id> <status> <length_m> <clearance_m> <turns> <planning_time_us>[ start_used=X,Y
//   start_moved_m=D][ goal_used=X,Y goal_moved_m=D]
//
// clearance_m is the path's smallest distance to an obstacle ("nan" unless OK, "inf" on a map
// without obstacles). The start_used / goal_used fields (the centre of the cell the plan used,
// metres) appear only when the node's start_tolerance / goal_tolerance moved that end. The
// status message of an OK plan (what was moved, warnings) goes to stderr.
//
// With --action it calls the node's Nav2 action as a ROS 2 action client does (rclcpp_action:
// send_goal, get_result once the goal is accepted, cancel_goal), through node::ActionClient:
// to_pose (the default) is nav2_msgs/action/ComputePathToPose on topics.compute_path_to_pose,
// through_poses is ComputePathThroughPoses on topics.compute_path_through_poses with one pose per
// --goal, in order. Without --start the goal has use_start false and the node starts from the
// robot's pose (robot_pose_source). The last goal faces --yaw; each earlier one faces the next
// goal. --mapping is how replies are tied to requests: fastrtps (rmw_fastrtps's sample identity)
// or cyclonedds (rmw_cyclonedds's request header); left out, the config's actions.reply_mapping
// when it forces one, else fastrtps (what a node on `auto` answers a Fast DDS client with).
// --distro is the ROS 2 distribution whose wire types the goal and result use (left out, the
// config's ros.distro); a Humble result has no error_code, so the line's error_code is 0 there.
// --cancel-after S cancels the goal S seconds after it was accepted. The result is one line:
//
//   <goal_id> <status> <error_code> <error_name> <length_m> <poses> <planning_time_us>
//
// goal_id is the goal's UUID in hex; status is the action's (SUCCEEDED, ABORTED, CANCELED, or
// REJECTED when the server refused the goal); error_code and error_name are Nav2's (206
// GOAL_OCCUPIED); length_m is the result path's length and poses its pose count. error_msg goes
// to stderr. A goal given up on (--wait ran out, SIGINT or SIGTERM) is canceled first, as
// `ros2 action send_goal` cancels its goal on Ctrl-C.
//
// Exit codes (kExitCodesHelp, also in --help), so that a script can tell a refused plan from a
// mistake of its own: 0 the node answered OK (--action: the goal SUCCEEDED); 1 the node answered
// with another status (the line is printed, its message goes to stderr; --action: the goal was
// rejected, ABORTED or CANCELED); 2 usage error: the command line or the config is bad (stderr
// names the option or key), nothing was sent; 3 no answer: no node (action server) matched or no
// status (result) came within --wait seconds (no node, wrong domain or topic names); 4 DDS
// failure (a participant, endpoint or write refused); 130 or 143: SIGINT or SIGTERM came first
// (the tool tears DDS down, then ends killed by that signal, which a shell reports as 128 + the
// signal: a script that runs this tool stops on Ctrl-C too, where bash would take a child that
// caught SIGINT and exited normally as having handled it).
//
// Order matters on the bus: the status reader exists and has matched the node's status writer
// before the request goes out (the reader is volatile, as ROS 2's default; the node holds our
// answer until its writer has matched our reader, requests.reply_wait), and the
// request is written only once the node's request reader has matched our writer (requests are
// volatile: a request written before that would be lost). --min-readers N also waits for N
// request readers in all (the node plus, say, a recorder that should hear the request too).
// An action goal goes out once the server's endpoints of all three services and both topics
// have matched ours (what rclcpp_action's wait_for_action_server checks).
#include <fastdds/rtps/common/WriteParams.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/node/action_catalog.hpp"
#include "vnsba/node/action_client.hpp"
#include "vnsba/node/command_line.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/process.hpp"
#include "vnsba/node/requests.hpp"
#include "vnsba/node/security.hpp"
#include "vnsba/render/text_format.hpp"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"

namespace {

using namespace vnsba;
using Clock = std::chrono::steady_clock;

constexpr int kStatusOk = 0;
constexpr int kRefused = 1;  // the node answered with another status than OK
constexpr int kBadInput = node::kExitUsage;
constexpr int kNoStatus = 3;
constexpr int kDdsFailure = 4;
constexpr const char* kExitCodesHelp =
    "Exit codes: 0 the node answered OK (--action: the goal SUCCEEDED); 1 it answered with "
    "another status (printed; --action: the goal was rejected, ABORTED or CANCELED); 2 bad "
    "command line or config, nothing sent; 3 no answer within --wait (no node or action server "
    "matched, no status or result); 4 DDS failure; 130 / 143 interrupted by SIGINT / SIGTERM.";

// Longest --wait and --cancel-after accepted, seconds: an hour is far beyond any planning
// budget.
constexpr double kMaxWaitSeconds = 3600.0;
// Most --goal poses accepted on the command line: far beyond the node's 1000 per
// ComputePathThroughPoses goal, so that the node, not this tool, names its limit.
constexpr size_t kMaxGoalPoses = 100000;

// Poll in short steps, milliseconds: quick to notice discovery, a reply or a signal, cheap while
// waiting.
constexpr auto kPollStep = std::chrono::milliseconds(10);
// How long a goal given up on waits for its cancel to be answered: a server on the bus answers
// in milliseconds, and the user who pressed Ctrl-C should not wait longer than this.
constexpr auto kCancelWait = std::chrono::seconds(1);

// The whole budget of a run, from discovery to the answer (--wait), and the stop signals polled
// while waiting for it.
class Budget {
 public:
  Budget(double seconds, const node::StopSignals& signals)
      : seconds_(seconds),
        deadline_(Clock::now() + std::chrono::microseconds(static_cast<int64_t>(seconds * 1e6))),
        signals_(signals) {}
  double seconds() const { return seconds_; }  // --wait
  // Whether SIGINT or SIGTERM came (polled; stays true once seen).
  bool interrupted() {
    if (!stopped_)
      if (const auto signal = signals_.wait_for(std::chrono::milliseconds(0))) {
        stopped_ = true;
        signal_ = *signal;
      }
    return stopped_;
  }
  bool stopped_by_signal() const { return stopped_; }
  // The exit code of a run the signal ended: 128 + the signal (130 SIGINT, 143 SIGTERM).
  int signal_exit_code() const { return 128 + signal_; }
  bool expired() const { return Clock::now() >= deadline_; }
  // Time left, never negative.
  std::chrono::milliseconds left() const {
    return std::max(
        std::chrono::milliseconds(0),
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline_ - Clock::now()));
  }
  // One wait of at most `step`, within the budget.
  std::chrono::milliseconds slice(std::chrono::milliseconds step) const {
    return std::min(left(), step);
  }

 private:
  double seconds_;
  Clock::time_point deadline_;
  const node::StopSignals& signals_;
  bool stopped_ = false;
  int signal_ = SIGINT;  // the one that came, once stopped_
};

// Shuts the participant down when it goes out of scope: declared after the listeners its readers
// call, it runs before they are destroyed, so no listener is called after that.
// Participant::shutdown is idempotent.
struct ShutdownOnExit {
  node::Participant& bus;
  ~ShutdownOnExit() { bus.shutdown(); }
};

// What to plan, as the command line gave it: metres in the config's frame_id.
struct GoalRequest {
  std::optional<std::array<double, 2>> start;  // nullopt: the robot's pose (--action only)
  std::vector<std::array<double, 2>> goals;    // one, or several for through_poses
  double yaw = 0.0;                            // radians, the last goal's orientation
  std::string planner;                         // "" = the node's planner.name
};

// The 12-byte GUID prefix of an endpoint's instance handle names its participant.
using ParticipantKey = std::array<unsigned char, 12>;
ParticipantKey participant_of(const node::dds::InstanceHandle_t& handle) {
  ParticipantKey key{};
  std::memcpy(key.data(), handle.value, key.size());
  return key;
}

// The participants of the endpoints matched with one of ours, as match events report them.
// (Fast DDS 2.9 cannot list matched endpoints on demand: get_matched_subscriptions() is
// unsupported, so the events are collected instead.)
class MatchedParticipants {
 public:
  void on_match(const node::dds::InstanceHandle_t& remote, int32_t change) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (change > 0) endpoints_.insert(remote);
    if (change < 0) endpoints_.erase(remote);
  }
  std::set<ParticipantKey> participants(size_t* endpoint_count) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::set<ParticipantKey> keys;
    for (const auto& e : endpoints_) keys.insert(participant_of(e));
    *endpoint_count = endpoints_.size();
    return keys;
  }

 private:
  mutable std::mutex mutex_;
  std::set<node::dds::InstanceHandle_t> endpoints_;
};

class RequestWriterListener : public node::dds::DataWriterListener {
 public:
  void on_publication_matched(node::dds::DataWriter*,
                              const node::dds::PublicationMatchedStatus& status) override {
    readers.on_match(status.last_subscription_handle, status.current_count_change);
  }
  MatchedParticipants readers;  // the request readers: node, recorder, ...
};

// Keeps the status that answers our request: the one carrying the sample identity our write got
// (request_writer_guid, request_sequence_number). The request id alone is not enough: the
// transient-local history replays the node's older answers, and an earlier run with the same
// --id got one too. Statuses that arrive before the write returned are held until
// the identity is known (the write returns at once after; the history replays at most 1,024).
class StatusReaderListener : public node::dds::DataReaderListener {
 public:
  void on_data_available(node::dds::DataReader* reader) override {
    node::PlanStatusMsg msg;
    node::dds::SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      // The identity alone decides: the node may echo a shortened id.
      if (!info.valid_data || msg.subject() == node::wire::SUBJECT_MAP) continue;
      std::lock_guard<std::mutex> lock(mutex_);
      if (status_) continue;
      if (!expected_) {
        held_.push_back(std::move(msg));
      } else if (answers(msg, *expected_)) {
        status_ = std::move(msg);
        arrived_.notify_all();
      }
    }
  }
  void on_subscription_matched(node::dds::DataReader*,
                               const node::dds::SubscriptionMatchedStatus& status) override {
    writers.on_match(status.last_publication_handle, status.current_count_change);
  }

  // Our request went out with `identity`: from now on only its answer counts.
  void expect(const node::RequestIdentity& identity) {
    std::lock_guard<std::mutex> lock(mutex_);
    expected_ = identity;
    for (node::PlanStatusMsg& msg : held_) {
      if (!status_ && answers(msg, identity)) status_ = std::move(msg);
    }
    held_.clear();
    if (status_) arrived_.notify_all();
  }

  // Waits up to `timeout` for our status.
  std::optional<node::PlanStatusMsg> wait(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    arrived_.wait_for(lock, timeout, [&] { return status_.has_value(); });
    return status_;
  }

  MatchedParticipants writers;  // the status writers: planner nodes

 private:
  static bool answers(const node::PlanStatusMsg& msg, const node::RequestIdentity& identity) {
    return msg.request_writer_guid() == identity.writer_guid &&
           msg.request_sequence_number() == identity.sequence_number;
  }

  std::mutex mutex_;
  std::condition_variable arrived_;
  std::optional<node::RequestIdentity> expected_;
  std::vector<node::PlanStatusMsg> held_;  // before the write returned
  std::optional<node::PlanStatusMsg> status_;
};

// Whether a planner node is ready to hear the request: `min_readers` request readers matched,
// one of them in a participant that also writes statuses. (A recorder reads requests too but
// writes no statuses, so "some reader matched" alone could send the request before the node
// hears it.) nullopt while the match events disagree with the match counts: an event not yet
// delivered, or one missed before the listeners were attached.
std::optional<bool> node_ready(node::dds::DataWriter* request_writer,
                               const RequestWriterListener& request_events,
                               node::dds::DataReader* status_reader,
                               const StatusReaderListener& status_events, int min_readers) {
  const int reader_count = node::matched_readers(request_writer);
  if (reader_count < min_readers) return false;
  node::dds::SubscriptionMatchedStatus status_matches;
  status_reader->get_subscription_matched_status(status_matches);
  if (status_matches.current_count == 0) return false;
  size_t readers_seen = 0, writers_seen = 0;
  const auto readers = request_events.readers.participants(&readers_seen);
  const auto writers = status_events.writers.participants(&writers_seen);
  if (readers_seen != static_cast<size_t>(reader_count) ||
      writers_seen != static_cast<size_t>(status_matches.current_count)) {
    return std::nullopt;
  }
  for (const auto& participant : writers) {
    if (readers.count(participant) > 0) return true;
  }
  return false;
}

std::string default_request_id() {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  return "send_goal-" + std::to_string(getpid()) + "-" + std::to_string(ms);
}

// action_msgs/GoalStatus's names, with REJECTED for a goal the server did not accept.
const char* goal_state_name(node::GoalState state) {
  switch (state) {
    case node::GoalState::kUnknown:
      return "UNKNOWN";
    case node::GoalState::kAccepted:
      return "ACCEPTED";
    case node::GoalState::kExecuting:
      return "EXECUTING";
    case node::GoalState::kCanceling:
      return "CANCELING";
    case node::GoalState::kSucceeded:
      return "SUCCEEDED";
    case node::GoalState::kCanceled:
      return "CANCELED";
    case node::GoalState::kAborted:
      return "ABORTED";
  }
  return "UNKNOWN";
}

// action_msgs/srv/CancelGoal's return codes.
const char* cancel_code_name(node::CancelCode code) {
  switch (code) {
    case node::CancelCode::kNone:
      return "ERROR_NONE";
    case node::CancelCode::kRejected:
      return "ERROR_REJECTED";
    case node::CancelCode::kUnknownGoalId:
      return "ERROR_UNKNOWN_GOAL_ID";
    case node::CancelCode::kGoalTerminated:
      return "ERROR_GOAL_TERMINATED";
  }
  return "ERROR_REJECTED";
}

std::string uuid_hex(const node::GoalUuid& id) {
  std::string hex;
  for (uint8_t byte : id) hex += fmt::format("{:02x}", byte);
  return hex;
}

// Metres along a path's poses.
double path_length(const node::PathMsg& path) {
  std::vector<core::Point2> points;
  points.reserve(path.poses().size());
  for (const auto& pose : path.poses())
    points.emplace_back(pose.pose().position().x(), pose.pose().position().y());
  return core::polyline_length(points);
}

// The goal as nav2_msgs has it: each pose in frame_id, the last facing `yaw`, each earlier one
// facing the next (a through_poses path passes its poses on the way to the next).
node::ActionGoalSpec action_goal(const GoalRequest& request, const std::string& frame_id) {
  node::ActionGoalSpec spec;
  const node::TimeMsg stamp = node::now_msg();
  for (size_t i = 0; i < request.goals.size(); ++i) {
    const core::Point2 here(request.goals[i][0], request.goals[i][1]);
    const double yaw =
        i + 1 == request.goals.size()
            ? request.yaw
            : core::heading(here, {request.goals[i + 1][0], request.goals[i + 1][1]});
    spec.goals.push_back(node::to_pose_msg(here.x(), here.y(), yaw, frame_id, stamp));
  }
  spec.use_start = request.start.has_value();
  if (request.start)
    spec.start = node::to_pose_msg((*request.start)[0], (*request.start)[1], 0.0, frame_id, stamp);
  spec.planner_id = request.planner;
  return spec;
}

// One goal through an action's server, as a ROS 2 action client sends it: once the server has
// matched, send_goal, then get_result once the goal is accepted (canceled after --cancel-after,
// or when the goal is given up on), then the result line. run() returns the exit code.
class ActionGoalRun {
 public:
  ActionGoalRun(const node::NodeConfig& config, const node::Nav2ActionInfo& action,
                node::WireMapping mapping, Budget& budget)
      : config_(config),
        action_(action),
        mapping_(mapping),
        budget_(budget),
        action_name_(node::ros_topic_name(config, config.topics.*action.topic)),
        mapping_flag_(mapping == node::WireMapping::kRequestHeader ? "cyclonedds" : "fastrtps") {}

  // The whole run on `bus`, which outlives this object.
  int run(node::Participant& bus, const GoalRequest& request, std::optional<double> cancel_after,
          int min_servers);

 private:
  std::optional<int> connect(node::Participant& bus, int min_servers);
  std::optional<node::ActionResultReply> wait_result(int64_t result_request,
                                                     std::optional<double> cancel_after,
                                                     Clock::time_point accepted_at);
  int give_up(const std::string& what);
  int report(const node::ActionResultReply& result);

  const node::NodeConfig& config_;
  const node::Nav2ActionInfo& action_;
  const node::WireMapping mapping_;
  Budget& budget_;
  const std::string action_name_;
  const char* const mapping_flag_;  // the --mapping value that names mapping_
  // The participant outlives the client, whose destructor deletes its endpoints (and so stops
  // their calls into it) before its listeners go.
  std::unique_ptr<node::ActionClient> client_;
  node::GoalUuid id_{};
  std::string goal_;  // id_ in hex
};

int ActionGoalRun::run(node::Participant& bus, const GoalRequest& request,
                       std::optional<double> cancel_after, int min_servers) {
  if (const auto exit_code = connect(bus, min_servers)) return *exit_code;
  id_ = node::ActionClient::random_id();
  goal_ = uuid_hex(id_);
  const int64_t goal_request = client_->send_goal(id_, action_goal(request, config_.frame_id));
  if (goal_request < 0) {
    spdlog::error("could not write the goal on '{}'", action_name_);
    return kDdsFailure;
  }
  spdlog::debug("sent goal {} to '{}' (domain {}, {} mapping)", goal_, action_name_,
                config_.domain_id, node::to_string(mapping_));
  std::optional<bool> accepted;
  while (!accepted && !budget_.expired() && !budget_.interrupted())
    accepted = client_->wait_accepted(goal_request, budget_.slice(10 * kPollStep));
  if (!accepted) return give_up("answer to");
  if (!*accepted) {
    std::printf("%s REJECTED 0 NONE %s 0 0\n", goal_.c_str(), render::format_metres(0.0).c_str());
    spdlog::warn("the server rejected goal {}", goal_);
    return kRefused;
  }
  const auto accepted_at = Clock::now();
  spdlog::debug("goal {} accepted; asking for its result", goal_);
  // As rclcpp_action asks for the result: once the goal is accepted (asked before, it would find
  // no goal).
  const int64_t result_request = client_->request_result(id_);
  if (result_request < 0) {
    spdlog::error("could not write the get_result request on '{}'", action_name_);
    return kDdsFailure;
  }
  const std::optional<node::ActionResultReply> result =
      wait_result(result_request, cancel_after, accepted_at);
  if (!result) return give_up("result of");
  return report(*result);
}

// The client, and the wait for a server; the exit code when none matched.
std::optional<int> ActionGoalRun::connect(node::Participant& bus, int min_servers) {
  auto created =
      node::ActionClient::create(bus, action_name_, action_.kind, mapping_, config_.ros_distro);
  if (!created) {
    spdlog::error("{}", created.error().message);
    return kDdsFailure;
  }
  client_ = std::move(*created);
  bool matched = false;
  while (!matched && !budget_.expired() && !budget_.interrupted())
    matched = client_->wait_for_server(budget_.slice(kPollStep), min_servers);
  if (matched) return std::nullopt;
  if (budget_.stopped_by_signal())
    spdlog::error("interrupted before a {} server matched: nothing was sent", action_.type_name);
  else
    spdlog::error(
        "no {} server on domain {} matched '{}' within {} s (no node, another domain "
        "or action name, or a node with actions.enabled false)",
        action_.type_name, config_.domain_id, action_name_, budget_.seconds());
  return budget_.stopped_by_signal() ? budget_.signal_exit_code() : kNoStatus;
}

// The result, within the budget; the goal is canceled --cancel-after seconds after
// `accepted_at` (a cancel left unanswered ends the wait).
std::optional<node::ActionResultReply> ActionGoalRun::wait_result(
    int64_t result_request, std::optional<double> cancel_after, Clock::time_point accepted_at) {
  std::optional<Clock::time_point> cancel_at;
  if (cancel_after)
    cancel_at = accepted_at + std::chrono::microseconds(static_cast<int64_t>(*cancel_after * 1e6));
  std::optional<node::ActionResultReply> result;
  while (!result && !budget_.expired() && !budget_.interrupted()) {
    if (cancel_at && Clock::now() >= *cancel_at) {
      cancel_at.reset();
      const auto cancel = client_->wait_cancel(client_->request_cancel(id_), budget_.left());
      if (!cancel) break;
      std::fprintf(stderr, "cancel of goal %s after %s s: %s\n", goal_.c_str(),
                   fmt::format("{:.3f}", *cancel_after).c_str(), cancel_code_name(cancel->code));
    }
    auto step = budget_.slice(10 * kPollStep);
    if (cancel_at)
      step = std::min(step, std::max(std::chrono::milliseconds(0),
                                     std::chrono::duration_cast<std::chrono::milliseconds>(
                                         *cancel_at - Clock::now())));
    result = client_->wait_result(result_request, step);
  }
  return result;
}

// A goal given up on is canceled first, so the node does not plan for nobody. `what`: "answer
// to" (the goal was sent, no acceptance came) or "result of".
int ActionGoalRun::give_up(const std::string& what) {
  if (budget_.stopped_by_signal()) {
    spdlog::error("interrupted before the {} goal {} came", what, goal_);
  } else {
    spdlog::error("no {} goal {} on '{}' within {} s", what, goal_, action_name_,
                  budget_.seconds());
    if (what == "answer to")
      spdlog::error(
          "the server matched but did not answer: one that ties replies to requests "
          "otherwise than --mapping {} (its actions.reply_mapping; a node on auto "
          "answers this Fast DDS client in fastrtps's) never answers this client",
          mapping_flag_);
  }
  if (client_->unmatched_replies() > 0) {
    spdlog::error(
        "{} replies came that answer no request of this client (other clients', or "
        "the server's in another mapping than --mapping {})",
        client_->unmatched_replies(), mapping_flag_);
  }
  const auto cancel = client_->wait_cancel(client_->request_cancel(id_), kCancelWait);
  if (cancel)
    spdlog::error("cancel of goal {}: {}", goal_, cancel_code_name(cancel->code));
  else
    spdlog::error("cancel of goal {}: no answer within {} s", goal_,
                  std::chrono::duration<double>(kCancelWait).count());
  return budget_.stopped_by_signal() ? budget_.signal_exit_code() : kNoStatus;
}

// The result line, and what else the result says on stderr.
int ActionGoalRun::report(const node::ActionResultReply& result) {
  const uint16_t code = result.error_code;
  std::printf("%s %s %u %s %s %zu %lld\n", goal_.c_str(), goal_state_name(result.status),
              static_cast<unsigned>(code), action_.errors.name(code).c_str(),
              render::format_metres(path_length(result.path)).c_str(), result.path.poses().size(),
              std::llround(result.planning_time_s * 1e6));
  const std::string message = node::printable(result.error_msg, 4096);
  if (client_->servers_seen() > 1)
    spdlog::warn(
        "{} servers of '{}' on domain {}: more than one node serves this action, each "
        "plans every goal it hears and the first answer was taken; give each node a namespace "
        "or a domain of its own",
        client_->servers_seen(), action_name_, config_.domain_id);
  if (result.status != node::GoalState::kSucceeded) {
    if (!message.empty())
      spdlog::warn("{}", message);
    else if (result.status == node::GoalState::kUnknown)
      spdlog::warn(
          "the server does not know goal {} (a result it no longer keeps, or another "
          "server's answer)",
          goal_);
    else
      spdlog::warn("goal {} ended {} with no message", goal_, goal_state_name(result.status));
    return kRefused;
  }
  if (!message.empty()) std::fprintf(stderr, "%s\n", message.c_str());
  return kStatusOk;
}

// The endpoints of a plan_request run: the request writer and the status reader, each created
// with its listener attached, so that no match event is lost (node_ready() tells the node's
// endpoints from other participants' by these events, and a participant discovered while the
// status reader was created matches the request writer at once). Hence a publisher and a
// subscriber of our own: the wrapper's writer() and reader() attach no match listeners. The
// participant's teardown deletes them with everything else.
struct PlanRequestEndpoints {
  std::string request_topic_name;
  std::string status_topic_name;
  node::dds::DataReader* status_reader = nullptr;
  node::dds::DataWriter* request_writer = nullptr;
};

// Creates them on `bus`; false (the failure logged) when DDS refused one.
bool create_plan_request_endpoints(node::Participant& bus, const node::NodeConfig& config,
                                   StatusReaderListener& status_events,
                                   RequestWriterListener& request_events,
                                   PlanRequestEndpoints& out) {
  out.request_topic_name = node::dds_topic_name(config, config.topics.plan_request);
  out.status_topic_name = node::dds_topic_name(config, config.topics.plan_status);
  auto request_topic =
      bus.topic<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(out.request_topic_name);
  if (!request_topic) {
    spdlog::error("{}", request_topic.error().message);
    return false;
  }
  auto status_topic =
      bus.topic<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(out.status_topic_name);
  if (!status_topic) {
    spdlog::error("{}", status_topic.error().message);
    return false;
  }
  node::dds::Subscriber* subscriber =
      bus.get()->create_subscriber(node::dds::SUBSCRIBER_QOS_DEFAULT);
  if (subscriber == nullptr) {
    spdlog::error("DDS: create_subscriber failed");
    return false;
  }
  // Volatile, as a ROS 2 client's default reader: no other client's old answers on start-up.
  // Ours still arrives: we send only once our reader has matched the node's writer, and the
  // node holds the answer until its writer has matched our reader (requests.reply_wait).
  // From the topic's XML profile, if any, under the node's rules (dds.hpp), as bus.reader() does.
  const node::dds::DataReaderQos status_qos = node::profiled_reader_qos(
      *subscriber, out.status_topic_name, node::reader_qos(node::TopicQos::kStatus));
  out.status_reader = subscriber->create_datareader(
      *status_topic, status_qos, &status_events,
      node::dds::StatusMask::data_available() << node::dds::StatusMask::subscription_matched());
  if (out.status_reader == nullptr) {
    spdlog::error("DDS: create_datareader({}) failed", out.status_topic_name);
    return false;
  }
  node::dds::Publisher* publisher = bus.get()->create_publisher(node::dds::PUBLISHER_QOS_DEFAULT);
  if (publisher == nullptr) {
    spdlog::error("DDS: create_publisher failed");
    return false;
  }
  out.request_writer = publisher->create_datawriter(
      *request_topic,
      node::profiled_writer_qos(*publisher, out.request_topic_name,
                                node::writer_qos(node::TopicQos::kEvents, false)),
      &request_events, node::dds::StatusMask::publication_matched());
  if (out.request_writer == nullptr) {
    spdlog::error("DDS: create_datawriter({}) failed", out.request_topic_name);
    return false;
  }
  return true;
}

// Whether a planner node became ready to hear the request (node_ready) within the budget.
bool wait_for_planner_node(const PlanRequestEndpoints& endpoints,
                           const RequestWriterListener& request_events,
                           const StatusReaderListener& status_events, int min_readers,
                           Budget& budget) {
  // Events lag their counts by a moment; should they disagree for longer than this, enough
  // readers plus a status writer is the best answer left.
  constexpr auto kEventLag = std::chrono::milliseconds(500);
  std::optional<Clock::time_point> unsure_since;
  bool matched = false;
  for (;;) {
    const auto now = Clock::now();
    const std::optional<bool> ready =
        node_ready(endpoints.request_writer, request_events, endpoints.status_reader, status_events,
                   min_readers);
    if (ready) unsure_since.reset();
    if (!ready && !unsure_since) unsure_since = now;
    matched = ready ? *ready : now - *unsure_since >= kEventLag;
    if (matched || budget.expired() || budget.interrupted()) break;
    std::this_thread::sleep_for(kPollStep);
  }
  return matched;
}

// Writes the request; its sample identity goes to `identity`. False when the writer refused it.
bool write_plan_request(node::dds::DataWriter* request_writer, const node::NodeConfig& config,
                        const GoalRequest& goal_request, const std::string& request_id,
                        node::RequestIdentity& identity) {
  node::PlanRequestMsg request;
  request.id(request_id);
  const node::TimeMsg stamp = node::now_msg();
  const auto& start = *goal_request.start;
  const auto& goal = goal_request.goals.front();
  request.start(node::to_pose_msg(start[0], start[1], 0.0, config.frame_id, stamp));
  // z = sin(yaw / 2), w = cos(yaw / 2): a rotation of `yaw` about the vertical.
  request.goal(node::to_pose_msg(goal[0], goal[1], goal_request.yaw, config.frame_id, stamp));
  request.planner(goal_request.planner);
  eprosima::fastrtps::rtps::WriteParams write_params;  // gets the request's sample identity
  if (!node::write_sample(request_writer, &request, write_params)) return false;
  identity = node::identity_of(write_params, node::wire::SUBJECT_REQUEST);
  return true;
}

// The status line, and the status message on stderr; the exit code.
int report_plan_status(const node::PlanStatusMsg& status) {
  std::string adjusted;
  if (status.start_adjusted()) {
    adjusted += " start_used=" + render::format_metres(status.start_x()) + "," +
                render::format_metres(status.start_y()) +
                " start_moved_m=" + render::format_metres(status.start_moved_m());
  }
  if (status.goal_adjusted()) {
    adjusted += " goal_used=" + render::format_metres(status.goal_x()) + "," +
                render::format_metres(status.goal_y()) +
                " goal_moved_m=" + render::format_metres(status.goal_moved_m());
  }
  std::printf(
      "%s %s %s %s %d %lld%s\n", node::printable(status.request_id(), node::kMaxIdBytes).c_str(),
      node::code_name(status.code()).c_str(), render::format_metres(status.length_m()).c_str(),
      render::format_metres(status.clearance_m()).c_str(), static_cast<int>(status.turns()),
      static_cast<long long>(status.planning_time_us()), adjusted.c_str());
  if (status.code() != node::wire::OK) {
    spdlog::warn("{}", node::printable(status.message(), 4096));
    return kRefused;
  }
  // What an OK plan reports besides its metrics: moved endpoints, ignored goal orientation.
  if (!status.message().empty())
    std::fprintf(stderr, "%s\n", node::printable(status.message(), 4096).c_str());
  return kStatusOk;
}

// The goal as one vnsba_msgs/PlanRequest, answered by one PlanStatus. Returns the exit code.
int run_plan_request(node::Participant& bus, const node::NodeConfig& config,
                     const GoalRequest& goal_request, const std::string& request_id,
                     int min_readers, Budget& budget) {
  // The listeners outlive every entity that calls them (the participant is shut down first).
  StatusReaderListener status_events;
  RequestWriterListener request_events;
  const ShutdownOnExit shutdown{bus};
  PlanRequestEndpoints endpoints;
  if (!create_plan_request_endpoints(bus, config, status_events, request_events, endpoints))
    return kDdsFailure;
  const bool matched =
      wait_for_planner_node(endpoints, request_events, status_events, min_readers, budget);
  if (!matched && budget.stopped_by_signal()) {
    spdlog::error("interrupted before a planner node matched: nothing was sent");
  } else if (!matched) {
    spdlog::error(
        "no planner node (with {} request reader(s) in all) on domain {} matched '{}' "
        "within {} s",
        min_readers, config.domain_id, endpoints.request_topic_name, budget.seconds());
  }
  if (!matched) return budget.stopped_by_signal() ? budget.signal_exit_code() : kNoStatus;
  node::RequestIdentity identity;
  if (!write_plan_request(endpoints.request_writer, config, goal_request, request_id, identity)) {
    spdlog::error("could not write the request on '{}'", endpoints.request_topic_name);
    return kDdsFailure;
  }
  status_events.expect(identity);
  spdlog::debug("sent '{}' on '{}' (domain {})", node::printable(request_id),
                endpoints.request_topic_name, config.domain_id);
  std::optional<node::PlanStatusMsg> status;
  while (!status && !budget.expired() && !budget.interrupted())
    status = status_events.wait(budget.slice(10 * kPollStep));
  bus.shutdown();
  if (!status) {
    if (budget.stopped_by_signal()) {
      spdlog::error("interrupted before the status of '{}' came", node::printable(request_id));
    } else {
      spdlog::error("no status for '{}' on '{}' within {} s", node::printable(request_id),
                    endpoints.status_topic_name, budget.seconds());
    }
    return budget.stopped_by_signal() ? budget.signal_exit_code() : kNoStatus;
  }
  return report_plan_status(*status);
}

// The command line's values, as CLI11 parsed them.
struct CommandLine {
  std::string config_path = "", planner, request_id;
  std::optional<int> domain;
  std::optional<std::string> ros_namespace;
  std::optional<std::string> participant_profile;
  std::vector<double> start, goal_values;
  double yaw = 0.0;
  double wait_seconds = 10.0;
  int min_readers = 1;
  std::optional<std::string> action, mapping_name, distro_name;
  std::optional<double> cancel_after;
  bool id_given = false;  // --id was on the command line
};

// `names` joined by ", ", the last by " or " ("a", "a or b", "a, b or c").
std::string either_of(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return out;
}

// --action's values (the first, the default) and its help: each action's option name and its
// type's name ("to_pose (ComputePathToPose, the default) or through_poses (...)").
std::vector<std::string> action_option_names() {
  std::vector<std::string> names;
  for (const node::Nav2ActionInfo& action : node::nav2_actions())
    names.emplace_back(action.option_name);
  return names;
}
std::string action_option_help() {
  std::vector<std::string> choices;
  for (const node::Nav2ActionInfo& action : node::nav2_actions()) {
    const std::string type = action.type_name;
    choices.push_back(std::string(action.option_name) + " (" + type.substr(type.rfind('/') + 1) +
                      (choices.empty() ? ", the default" : "") + ")");
  }
  return "call the node's Nav2 action instead of sending a plan_request: " + either_of(choices);
}
// The --action values whose goal carries several poses.
std::string several_goals_actions() {
  std::vector<std::string> names;
  for (const node::Nav2ActionInfo& action : node::nav2_actions())
    if (action.several_goals) names.emplace_back(action.option_name);
  return either_of(names);
}

// The action --action names; the default (the first) when it names none.
const node::Nav2ActionInfo& chosen_action(const std::optional<std::string>& option) {
  for (const node::Nav2ActionInfo& action : node::nav2_actions())
    if (option == action.option_name) return action;
  return node::nav2_actions().front();
}

void add_options(CLI::App& app, CommandLine& line) {
  app.add_option("--config", line.config_path, vnsba::node::kConfigOptionHelp);
  app.add_option("--domain", line.domain,
                 "DDS domain id 0..232 (overrides ROS_DOMAIN_ID and domain_id)")
      ->check(CLI::Range(0, 232));
  app.add_option("--namespace", line.ros_namespace, node::kNamespaceOptionHelp);
  app.add_option("--participant-profile", line.participant_profile,
                 node::kParticipantProfileOptionHelp);
  CLI::Option* action_option = app.add_option("--action", line.action, action_option_help())
                                   ->expected(0, 1)
                                   ->default_str(node::nav2_actions().front().option_name)
                                   ->check(CLI::IsMember(action_option_names()));
  app.add_option("--start", line.start,
                 "start X Y in metres, in the config's frame_id; required without --action, "
                 "where leaving it out plans from the robot's pose (use_start false)")
      ->expected(2);
  app.add_option("--goal", line.goal_values,
                 "goal X Y in metres, in the config's frame_id; with --action " +
                     several_goals_actions() + " one --goal per pose, in order")
      ->type_size(2)
      ->expected(1, static_cast<int>(kMaxGoalPoses))
      ->required();
  app.add_option("--yaw", line.yaw,
                 "goal orientation in radians (0 = facing +x, counter-clockwise): the last "
                 "pose of the path")
      ->capture_default_str();
  app.add_option("--planner", line.planner,
                 "auto, astar, weighted_astar, bidirectional_astar, "
                 "alternating_bidirectional_astar, vns_bastar or jps (default: the node's "
                 "configured planner)");
  app.add_option("--id", line.request_id, "request id (default: send_goal-<pid>-<unix ms>)")
      ->excludes(action_option);
  app.add_option("--wait", line.wait_seconds,
                 "seconds to wait for the node and its answer, in (0, 3600]")
      ->capture_default_str();
  app.add_option("--min-readers", line.min_readers,
                 "send only once this many request readers matched (the node counts as one; "
                 "with --action: this many servers)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--mapping", line.mapping_name,
                 "with --action: how replies are tied to requests, fastrtps (rmw_fastrtps) or "
                 "cyclonedds (rmw_cyclonedds; the node must answer so: actions.reply_mapping "
                 "cyclonedds) (default: the config's actions.reply_mapping if it names one, "
                 "else fastrtps)")
      ->check(CLI::IsMember({"fastrtps", "cyclonedds"}))
      ->needs(action_option);
  app.add_option("--distro", line.distro_name,
                 "with --action: the ROS 2 distribution whose wire types the goal and its result "
                 "use, humble, jazzy or kilted (default: the config's ros.distro; the node must "
                 "serve the same)")
      ->check(CLI::IsMember({"humble", "jazzy", "kilted"}))
      ->needs(action_option);
  app.add_option("--cancel-after", line.cancel_after,
                 "with --action: cancel the goal this many seconds after it was accepted, in "
                 "[0, 3600]")
      ->needs(action_option);
}

int bad_input(const std::string& message) {
  spdlog::error("{}", message);
  return kBadInput;
}

// `xy` as a point, or false (logged) when a coordinate is not finite.
bool finite_point(const std::string& option, const double* xy,
                  std::optional<std::array<double, 2>>& out) {
  for (size_t i = 0; i < 2; ++i) {
    if (!std::isfinite(xy[i])) {
      spdlog::error("{}: {} is {}, must be a finite number of metres", option, i == 0 ? "X" : "Y",
                    std::to_string(xy[i]));
      return false;
    }
  }
  out = std::array<double, 2>{xy[0], xy[1]};
  return true;
}

// --start and --goal into `goal_request`; the exit code when they are bad.
std::optional<int> read_poses(const CommandLine& line, const node::Nav2ActionInfo& action,
                              GoalRequest& goal_request) {
  const bool use_action = line.action.has_value();
  if (line.start.empty() && !use_action) {
    return bad_input(
        "--start is required (with --action it may be left out: the node then plans from the "
        "robot's pose)");
  }
  if (line.goal_values.size() % 2 != 0) {
    return bad_input("--goal: " + std::to_string(line.goal_values.size()) +
                     " numbers, expected X Y for each goal");
  }
  const size_t goal_count = line.goal_values.size() / 2;
  if (goal_count > 1 && !(use_action && action.several_goals)) {
    return bad_input("--goal: " + std::to_string(goal_count) +
                     " goals, expected one (several only with --action " + several_goals_actions() +
                     ")");
  }
  if (!line.start.empty() && !finite_point("--start", line.start.data(), goal_request.start))
    return kBadInput;
  for (size_t k = 0; k < goal_count; ++k) {
    std::optional<std::array<double, 2>> point;
    const std::string option = goal_count == 1 ? "--goal" : "--goal #" + std::to_string(k + 1);
    if (!finite_point(option, line.goal_values.data() + 2 * k, point)) return kBadInput;
    goal_request.goals.push_back(*point);
  }
  return std::nullopt;
}

// The rest of the command line's checks, after the poses; the exit code when it is bad.
std::optional<int> check_options(const CommandLine& line, GoalRequest& goal_request,
                                 std::string& request_id) {
  if (!std::isfinite(line.yaw))
    return bad_input("--yaw: " + std::to_string(line.yaw) + ", must be a finite number of radians");
  goal_request.yaw = line.yaw;
  if (!line.planner.empty() && line.planner != core::kAutoPlannerName &&
      !core::planner_kind_from_string(line.planner)) {
    return bad_input("--planner: unknown planner '" + line.planner + "', expected one of " +
                     core::accepted_planner_names());
  }
  goal_request.planner = line.planner;
  if (!(line.wait_seconds > 0.0 && line.wait_seconds <= kMaxWaitSeconds)) {
    return bad_input(fmt::format("--wait: {} seconds, expected a number in (0, {}]",
                                 line.wait_seconds, kMaxWaitSeconds));
  }
  if (line.cancel_after && !(*line.cancel_after >= 0.0 && *line.cancel_after <= kMaxWaitSeconds)) {
    return bad_input(fmt::format("--cancel-after: {} seconds, expected a number in [0, {}]",
                                 *line.cancel_after, kMaxWaitSeconds));
  }
  if (line.id_given && line.request_id.empty()) return bad_input("--id: must not be empty");
  if (line.request_id.size() > node::kMaxIdBytes) {
    return bad_input("--id: " + std::to_string(line.request_id.size()) +
                     " bytes, longer than the node's limit of " +
                     std::to_string(node::kMaxIdBytes) + " bytes");
  }
  request_id = line.request_id.empty() ? default_request_id() : line.request_id;
  return std::nullopt;
}

// How replies are tied to requests: --mapping, else the config's actions.reply_mapping when it
// forces one. A node on `auto` answers this Fast DDS client in rmw_fastrtps's mapping; one told
// to use a mapping answers every client in it.
node::WireMapping reply_mapping(const CommandLine& line, const node::NodeConfig& config) {
  return line.mapping_name
             ? (*line.mapping_name == "cyclonedds" ? node::WireMapping::kRequestHeader
                                                   : node::WireMapping::kSampleIdentity)
         : config.actions.reply_mapping == node::ReplyMapping::kCycloneDds
             ? node::WireMapping::kRequestHeader
             : node::WireMapping::kSampleIdentity;
}

// The whole run, from the command line to the answer; the participant is torn down when it
// returns.
int send_goal(int argc, char** argv, const node::StopSignals& stop_signals) {
  node::init_logging("vnsba_send_goal");
  CLI::App app{"vnsba_send_goal: send one plan request (or Nav2 action goal) and print the answer"};
  app.footer(kExitCodesHelp);
  CommandLine line;
  add_options(app, line);
  if (const auto exit_code = node::parse_command_line(app, argc, argv)) return *exit_code;
  line.id_given = app.count("--id") > 0;
  const node::Nav2ActionInfo& action = chosen_action(line.action);
  GoalRequest goal_request;
  std::string request_id;
  if (const auto exit_code = read_poses(line, action, goal_request)) return *exit_code;
  if (const auto exit_code = check_options(line, goal_request, request_id)) return *exit_code;

  const std::optional<node::NodeConfig> loaded = node::load_config_or_report(
      line.config_path, line.domain.value_or(-1), line.ros_namespace, line.participant_profile);
  if (!loaded) return kBadInput;
  node::NodeConfig config = *loaded;
  if (line.distro_name)  // --distro over ros.distro (the option's check took only known names)
    for (const node::RosDistro distro : node::kRosDistros)
      if (*line.distro_name == node::distro_name(distro)) config.ros_distro = distro;
  // Our own chatter stays quiet unless the config asks for debug detail: stdout is the one
  // result line, stderr only says what went wrong.
  const auto configured_level = spdlog::level::from_str(config.log_level);
  spdlog::set_level(configured_level <= spdlog::level::debug
                        ? configured_level
                        : std::max(configured_level, spdlog::level::warn));
  const node::WireMapping mapping = reply_mapping(line, config);

  Budget budget(line.wait_seconds, stop_signals);
  auto participant =
      node::Participant::create_configured(config, "vnsba_send_goal", node::kSendGoalEnclave);
  if (!participant) {
    spdlog::error("{}", participant.error().message);
    return kDdsFailure;
  }
  if (line.action) {
    ActionGoalRun run(config, action, mapping, budget);
    return run.run(**participant, goal_request, line.cancel_after, line.min_readers);
  }
  return run_plan_request(**participant, config, goal_request, request_id, line.min_readers,
                          budget);
}
}  // namespace

int main(int argc, char** argv) {
  // SIGINT/SIGTERM are blocked before DDS starts its threads and polled while waiting, so an
  // interrupt still tears the participant down cleanly.
  const node::StopSignals stop_signals;
  const int code = send_goal(argc, argv, stop_signals);
  std::fflush(stdout);  // the answer line is out before a signal may end the process below
  // A signal that came after the answer, while DDS was torn down, ends the process here as the
  // signal it is; so does one the run took and stopped for (130, 143). A shell that ran us sees a
  // command the signal killed and stops its script too (bash takes a child that exited normally
  // as having handled the interrupt, and goes on).
  stop_signals.release();
  if (code == 128 + SIGINT || code == 128 + SIGTERM) std::raise(code - 128);
  return code;
}
