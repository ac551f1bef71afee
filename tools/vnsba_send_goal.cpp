// vnsba_send_goal: one planning request from the command line, answered by one line.
//
//   vnsba_send_goal [--config FILE] [--domain N] [--namespace NS] --start X Y --goal X Y [--yaw
//   RAD]
//                   [--planner NAME] [--id ID] [--wait SECONDS] [--min-readers N]
//
// Publishes one vnsba_msgs/PlanRequest (start and goal in metres, in the config's frame_id; the
// goal facing --yaw radians, 0 = +x) and prints the PlanStatus the node answers it with as one
// line on stdout:
//
//   <id> <status> <length_m> <clearance_m> <turns> <planning_time_us>[ start_used=X,Y
//   start_moved_m=D][ goal_used=X,Y goal_moved_m=D]
//
// clearance_m is the path's smallest distance to an obstacle ("nan" unless OK, "inf" on a map
// without obstacles). The start_used / goal_used fields (the centre of the cell the plan used,
// metres) appear only when the node's start_tolerance / goal_tolerance moved that end. The
// status message of an OK plan (what was moved, warnings) goes to stderr.
//
// Exit codes (kExitCodesHelp, also in --help), so that a script can tell a refused plan from a
// mistake of its own: 0 the node answered OK; 1 the node answered with another status (the line
// is printed, its message goes to stderr); 2 usage error: the command line or the config is bad
// (stderr names the option or key), nothing was sent; 3 no answer: no node matched or no status
// came within --wait seconds (no node, wrong domain or topic names), or SIGINT or SIGTERM came
// first; 4 DDS failure (a participant, endpoint or write refused).
//
// Order matters on the bus: the status reader exists and has matched the node's status writer
// before the request goes out (the reader is volatile, as ROS 2's default; the node holds our
// answer until its writer has matched our reader, requests.reply_wait), and the
// request is written only once the node's request reader has matched our writer (requests are
// volatile: a request written before that would be lost). --min-readers N also waits for N
// request readers in all (the node plus, say, a recorder that should hear the request too).
#include <fastdds/rtps/common/WriteParams.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "vnsba/core/planner.hpp"
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
    "Exit codes: 0 the node answered OK; 1 it answered with another status (printed); 2 bad "
    "command line or config, nothing sent; 3 no answer within --wait (no node matched, no "
    "status) or interrupted; 4 DDS failure.";

// Longest --wait accepted, seconds: an hour is far beyond any planning budget.
constexpr double kMaxWaitSeconds = 3600.0;

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

}  // namespace

int main(int argc, char** argv) {
  // SIGINT/SIGTERM are blocked before DDS starts its threads and polled while waiting, so an
  // interrupt still tears the participant down cleanly.
  const node::StopSignals stop_signals;
  node::init_logging("vnsba_send_goal");
  CLI::App app{"vnsba_send_goal: send one plan request and print the status it gets"};
  app.footer(kExitCodesHelp);
  std::string config_path = "", planner, request_id;
  std::optional<int> domain;
  std::vector<double> start, goal;
  double yaw = 0.0;
  double wait_seconds = 10.0;
  int min_readers = 1;
  app.add_option("--config", config_path, vnsba::node::kConfigOptionHelp);
  app.add_option("--domain", domain, "DDS domain id 0..232 (overrides domain_id)")
      ->check(CLI::Range(0, 232));
  std::optional<std::string> ros_namespace;
  app.add_option("--namespace", ros_namespace, node::kNamespaceOptionHelp);
  std::optional<std::string> participant_profile;
  app.add_option("--participant-profile", participant_profile, node::kParticipantProfileOptionHelp);
  app.add_option("--start", start, "start X Y in metres, in the config's frame_id")
      ->expected(2)
      ->required();
  app.add_option("--goal", goal, "goal X Y in metres, in the config's frame_id")
      ->expected(2)
      ->required();
  app.add_option("--yaw", yaw,
                 "goal orientation in radians (0 = facing +x, counter-clockwise): the last "
                 "pose of the path")
      ->capture_default_str();
  app.add_option("--planner", planner,
                 "astar, weighted_astar, bidirectional_astar, alternating_bidirectional_astar, "
                 "vns_bastar or jps (default: the node's configured planner)");
  app.add_option("--id", request_id, "request id (default: send_goal-<pid>-<unix ms>)");
  app.add_option("--wait", wait_seconds,
                 "seconds to wait for the node and its answer, in (0, 3600]")
      ->capture_default_str();
  app.add_option("--min-readers", min_readers,
                 "send only once this many request readers matched (the node counts as one)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  if (const auto exit_code = node::parse_command_line(app, argc, argv)) return *exit_code;

  auto bad_input = [](const std::string& message) {
    spdlog::error("{}", message);
    return kBadInput;
  };
  for (const auto& [option, xy] : {std::pair{"--start", &start}, std::pair{"--goal", &goal}}) {
    for (size_t i = 0; i < 2; ++i) {
      if (!std::isfinite((*xy)[i])) {
        return bad_input(std::string(option) + ": " + (i == 0 ? "X" : "Y") + " is " +
                         std::to_string((*xy)[i]) + ", must be a finite number of metres");
      }
    }
  }
  if (!std::isfinite(yaw))
    return bad_input("--yaw: " + std::to_string(yaw) + ", must be a finite number of radians");
  if (!planner.empty() && !core::planner_kind_from_string(planner)) {
    std::string known;
    for (core::PlannerKind kind : core::all_planner_kinds())
      known += (known.empty() ? "" : ", ") + std::string(core::to_string(kind));
    return bad_input("--planner: unknown planner '" + planner + "', expected one of " + known);
  }
  if (!(wait_seconds > 0.0 && wait_seconds <= kMaxWaitSeconds)) {
    return bad_input(fmt::format("--wait: {} seconds, expected a number in (0, {}]", wait_seconds,
                                 kMaxWaitSeconds));
  }
  if (app.count("--id") > 0 && request_id.empty()) return bad_input("--id: must not be empty");
  if (request_id.size() > node::kMaxIdBytes) {
    return bad_input("--id: " + std::to_string(request_id.size()) +
                     " bytes, longer than the node's limit of " +
                     std::to_string(node::kMaxIdBytes) + " bytes");
  }
  if (request_id.empty()) request_id = default_request_id();

  const std::optional<node::NodeConfig> loaded = node::load_config_or_report(
      config_path, domain.value_or(-1), ros_namespace, participant_profile);
  if (!loaded) return kBadInput;
  const node::NodeConfig& config = *loaded;
  // Our own chatter stays quiet unless the config asks for debug detail: stdout is the one
  // status line, stderr only says what went wrong.
  const auto configured_level = spdlog::level::from_str(config.log_level);
  spdlog::set_level(configured_level <= spdlog::level::debug
                        ? configured_level
                        : std::max(configured_level, spdlog::level::warn));

  // The whole budget, from discovery to the answer.
  const auto deadline =
      Clock::now() + std::chrono::microseconds(static_cast<int64_t>(wait_seconds * 1e6));

  bool stopped_by_signal = false;
  auto interrupted = [&] {
    stopped_by_signal = stopped_by_signal || stop_signals.wait_for(std::chrono::milliseconds(0));
    return stopped_by_signal;
  };

  // The listeners outlive every entity that calls them (the participant is destroyed first).
  StatusReaderListener status_events;
  RequestWriterListener request_events;
  auto participant =
      node::Participant::create(config.domain_id, "vnsba_send_goal", nullptr, config.localhost_only,
                                node::with_default_enclave(config.security, node::kSendGoalEnclave),
                                config.discovery_servers, config.participant_profile);
  if (!participant) {
    spdlog::error("{}", participant.error().message);
    return kDdsFailure;
  }
  auto& bus = **participant;
  const std::string request_topic_name = node::dds_topic_name(config, config.topics.plan_request);
  const std::string status_topic_name = node::dds_topic_name(config, config.topics.plan_status);
  auto request_topic = bus.topic<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(request_topic_name);
  if (!request_topic) {
    spdlog::error("{}", request_topic.error().message);
    return kDdsFailure;
  }
  auto status_topic = bus.topic<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(status_topic_name);
  if (!status_topic) {
    spdlog::error("{}", status_topic.error().message);
    return kDdsFailure;
  }
  // The endpoints are created with their listeners attached, so that no match event is lost
  // (node_ready() tells the node's endpoints from other participants' by these events, and a
  // participant discovered while the status reader was created matches the request writer at
  // once). Hence a publisher and a subscriber of our own: the wrapper's writer() and reader()
  // attach no match listeners. The participant's teardown deletes them with everything else.
  node::dds::Subscriber* subscriber =
      bus.get()->create_subscriber(node::dds::SUBSCRIBER_QOS_DEFAULT);
  if (subscriber == nullptr) {
    spdlog::error("DDS: create_subscriber failed");
    return kDdsFailure;
  }
  // Volatile, as a ROS 2 client's default reader: no other client's old answers on start-up.
  // Ours still arrives: we send only once our reader has matched the node's writer, and the
  // node holds the answer until its writer has matched our reader (requests.reply_wait).
  // From the topic's XML profile, if any, under the node's rules (dds.hpp), as bus.reader() does.
  const node::dds::DataReaderQos status_qos = node::profiled_reader_qos(
      *subscriber, status_topic_name, node::reader_qos(node::TopicQos::kStatus));
  node::dds::DataReader* status_reader = subscriber->create_datareader(
      *status_topic, status_qos, &status_events,
      node::dds::StatusMask::data_available() << node::dds::StatusMask::subscription_matched());
  if (status_reader == nullptr) {
    spdlog::error("DDS: create_datareader({}) failed", status_topic_name);
    return kDdsFailure;
  }
  node::dds::Publisher* publisher = bus.get()->create_publisher(node::dds::PUBLISHER_QOS_DEFAULT);
  if (publisher == nullptr) {
    spdlog::error("DDS: create_publisher failed");
    return kDdsFailure;
  }
  node::dds::DataWriter* request_writer = publisher->create_datawriter(
      *request_topic,
      node::profiled_writer_qos(*publisher, request_topic_name,
                                node::writer_qos(node::TopicQos::kEvents, false)),
      &request_events, node::dds::StatusMask::publication_matched());
  if (request_writer == nullptr) {
    spdlog::error("DDS: create_datawriter({}) failed", request_topic_name);
    return kDdsFailure;
  }

  // Poll in short steps, milliseconds: quick to notice discovery, cheap while waiting.
  constexpr auto kPollStep = std::chrono::milliseconds(10);
  // Events lag their counts by a moment; should they disagree for longer than this, enough
  // readers plus a status writer is the best answer left.
  constexpr auto kEventLag = std::chrono::milliseconds(500);
  std::optional<Clock::time_point> unsure_since;
  bool matched = false;
  for (;;) {
    const auto now = Clock::now();
    const std::optional<bool> ready =
        node_ready(request_writer, request_events, status_reader, status_events, min_readers);
    if (ready) unsure_since.reset();
    if (!ready && !unsure_since) unsure_since = now;
    matched = ready ? *ready : now - *unsure_since >= kEventLag;
    if (matched || now >= deadline || interrupted()) break;
    std::this_thread::sleep_for(kPollStep);
  }
  if (!matched && stopped_by_signal) {
    spdlog::error("interrupted before a planner node matched: nothing was sent");
  } else if (!matched) {
    spdlog::error(
        "no planner node (with {} request reader(s) in all) on domain {} matched '{}' "
        "within {} s",
        min_readers, config.domain_id, request_topic_name, wait_seconds);
  }
  if (!matched) {
    bus.shutdown();
    return kNoStatus;
  }

  node::PlanRequestMsg request;
  request.id(request_id);
  const node::TimeMsg stamp = node::now_msg();
  request.start(node::to_pose_msg(start[0], start[1], 0.0, config.frame_id, stamp));
  // z = sin(yaw / 2), w = cos(yaw / 2): a rotation of `yaw` about the vertical.
  request.goal(node::to_pose_msg(goal[0], goal[1], yaw, config.frame_id, stamp));
  request.planner(planner);
  eprosima::fastrtps::rtps::WriteParams write_params;  // gets the request's sample identity
  if (!node::write_sample(request_writer, &request, write_params)) {
    spdlog::error("could not write the request on '{}'", request_topic_name);
    bus.shutdown();
    return kDdsFailure;
  }
  status_events.expect(node::identity_of(write_params, node::wire::SUBJECT_REQUEST));
  spdlog::debug("sent '{}' on '{}' (domain {})", node::printable(request_id), request_topic_name,
                config.domain_id);

  std::optional<node::PlanStatusMsg> status;
  while (!status) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0 || interrupted()) break;
    status = status_events.wait(std::min<std::chrono::milliseconds>(left, 10 * kPollStep));
  }
  bus.shutdown();
  if (!status) {
    if (stopped_by_signal) {
      spdlog::error("interrupted before the status of '{}' came", node::printable(request_id));
    } else {
      spdlog::error("no status for '{}' on '{}' within {} s", node::printable(request_id),
                    status_topic_name, wait_seconds);
    }
    return kNoStatus;
  }
  std::string adjusted;
  if (status->start_adjusted()) {
    adjusted += " start_used=" + render::format_metres(status->start_x()) + "," +
                render::format_metres(status->start_y()) +
                " start_moved_m=" + render::format_metres(status->start_moved_m());
  }
  if (status->goal_adjusted()) {
    adjusted += " goal_used=" + render::format_metres(status->goal_x()) + "," +
                render::format_metres(status->goal_y()) +
                " goal_moved_m=" + render::format_metres(status->goal_moved_m());
  }
  std::printf(
      "%s %s %s %s %d %lld%s\n", node::printable(status->request_id(), node::kMaxIdBytes).c_str(),
      node::code_name(status->code()).c_str(), render::format_metres(status->length_m()).c_str(),
      render::format_metres(status->clearance_m()).c_str(), static_cast<int>(status->turns()),
      static_cast<long long>(status->planning_time_us()), adjusted.c_str());
  if (status->code() != node::wire::OK) {
    spdlog::warn("{}", node::printable(status->message(), 4096));
    return kRefused;
  }
  // What an OK plan reports besides its metrics: moved endpoints, ignored goal orientation.
  if (!status->message().empty())
    std::fprintf(stderr, "%s\n", node::printable(status->message(), 4096).c_str());
  return kStatusOk;
}
