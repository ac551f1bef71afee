// ROS 2 services served by the node: the reply path every service shares, and a server of one
// plain request/reply service (issue 48: lifecycle_msgs, is_path_valid), on the DDS topics ROS 2
// derives from the service's name:
//
//   rq/<name>Request -> rr/<name>Reply
//
// The mapping of a reply to its request is chosen per client (service_wire.hpp: rmw_fastrtps's
// related sample identity, rmw_cyclonedds's request header). Replies go out on the node's
// replier thread (replier.hpp), each once a reply reader of the client's participant is matched
// (ReplyGate, at most requests.reply_wait): a fresh ROS 2 client matches the reply writer after
// it sent its request, and a reply written before would be lost to it. A service holds at most
// actions.max_pending_replies replies per client; its reply writer keeps its last replies only
// (never blocking) and its writes are paced (ReplyFlow, actions.replies_in_flight_mb,
// actions.reply_ack_timeout). A request that cannot be decoded is dropped with one log line per
// client. The action servers (action_server.hpp) serve their send_goal, get_result and
// cancel_goal with the same ServiceReplies.
#pragma once

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "take_listener.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/raw_type.hpp"
#include "vnsba/node/reply_flow.hpp"
#include "vnsba/node/reply_gate.hpp"
#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

// Each reply writer's history (keep last): more replies than a burst leaves unacknowledged at
// once (their bytes are bounded by the flow, reply_flow.hpp).
constexpr int32_t kReplyHistory = 10000;

// Bytes as lowercase hex digits, for ids in messages (participant prefixes, goal ids).
template <size_t N>
std::string hex_text(const std::array<uint8_t, N>& bytes) {
  std::string out;
  char buf[4];
  for (uint8_t b : bytes) {
    std::snprintf(buf, sizeof buf, "%02x", b);
    out += buf;
  }
  return out;
}

// Where a reply goes: the client's mapping, its header (rmw_cyclonedds) or the identity to
// relate the reply to (rmw_fastrtps), and its participant (the reply gate).
struct ReplyAddress {
  WireMapping mapping = WireMapping::kSampleIdentity;
  RequestHeader header{};
  eprosima::fastrtps::rtps::SampleIdentity related;
  GuidPrefix prefix{};
};

// The address of the request `info` describes, its mapping chosen by `configured`
// (actions.reply_mapping), the vendor its participant announced (`vendors` may be null) and
// whether it names a related sample identity.
ReplyAddress reply_address(const dds::SampleInfo& info, ReplyMapping configured,
                           const ParticipantWatch* vendors);

// A service's reply writer: writer_qos(kStatus)'s, but keeping the last `history_depth`
// replies, as rclcpp_action's servers keep their last 10, so that a reader that does not
// acknowledge can never block a write (reply_flow.hpp paces the writes).
dds::DataWriterQos reply_writer_qos(int32_t history_depth, bool large_samples);

// One reply on its way out.
struct ServiceReply {
  dds::DataWriter* writer = nullptr;
  GuidPrefix client{};
  RawSample sample;
  std::optional<eprosima::fastrtps::rtps::SampleIdentity> related;  // rmw_fastrtps
  std::string what;                                                 // for the log
};

// Requests that could not be decoded, logged once per client participant (at most 1,000
// clients remembered). Thread-safe.
class RefusedRequests {
 public:
  // Logs "<owner>: a <service> request from participant <p> dropped: <problem> (mapping m)" the
  // first time `from` sends one.
  void refuse(const std::string& owner, const std::string& service, const ReplyAddress& from,
              const std::string& problem);

 private:
  std::mutex mutex_;
  std::set<GuidPrefix> warned_;
};

// One service's replies on their way to the clients: each held until a reply reader of its
// client's participant is matched (ReplyGate), at most actions.max_pending_replies per client,
// then written as the reply writer's flow allows (ReplyFlow), in order. hold, take_due,
// next_deadline and release_pending run under the owner's mutex (`mutex`); write on the replier
// thread without it.
class ServiceReplies {
 public:
  using Clock = std::chrono::steady_clock;
  using Done = std::map<GuidPrefix, size_t>;  // replies written or given up on, per client
  struct Due {
    std::vector<ServiceReply> replies;
    // The reply writer's flow is due a look (its readers' acknowledgements, a reader that does
    // not acknowledge to report) although no reply is due.
    bool check_flows = false;
    // Send a heartbeat on the reply writer now, whether or not a reply goes out on it
    // (reply_gate.hpp: a fresh requester's settle starts).
    bool heartbeat = false;
    bool empty() const { return replies.empty() && !check_flows && !heartbeat; }
  };

  // `owner` and `service` name the service in logs ("/compute_path_to_pose" and "send_goal",
  // or "/vnsba_node" and "get_state"); `matched` wakes `cv` under `mutex`.
  ServiceReplies(std::string owner, std::string service, const NodeConfig& config,
                 std::mutex& mutex, std::condition_variable& cv);
  ~ServiceReplies();
  ServiceReplies(const ServiceReplies&) = delete;
  ServiceReplies& operator=(const ServiceReplies&) = delete;

  // The reply writer on `participant`, on `topic`, of ReplyType's DDS type (`large`: results
  // that may be megabytes).
  template <class ReplyType>
  core::Status create_writer(Participant& participant, const std::string& topic, bool large) {
    auto writer = participant.writer_on<RawOf<ReplyType>>(
        topic, reply_writer_qos(kReplyHistory, large), matched_listener());
    if (!writer) return writer.error();
    writer_ = *writer;
    return core::Status::ok();
  }

  void hold(const ReplyAddress& to, RawSample sample, std::string what);
  void take_due(Clock::time_point now, bool all, Due& out);
  // Writes what `due` holds (`stopping`: all at once, the flow not asked); a reply that must
  // wait, or that the writer refuses, is kept with the later ones, in order, for the next pass;
  // with `give_up` (a shutdown out of time) nothing is kept. Returns the replies written or
  // given up on, for release_pending (under the mutex).
  Done write(Due& due, bool stopping, bool give_up);
  void release_pending(const Done& done);
  bool all_written() const { return unwritten_.empty(); }
  void next_deadline(std::optional<Clock::time_point>& earliest) const;
  dds::DataWriter* writer() const { return writer_; }

 private:
  class MatchedReaders;
  dds::DataWriterListener* matched_listener();
  void warn_dropped(const GuidPrefix& client, size_t pending, const std::string& what);
  void check_acknowledgements(Clock::time_point now);
  void warn_stalled(const std::vector<std::pair<GuidPrefix, size_t>>& clients);
  bool write_now(ServiceReply& reply, Clock::time_point now, bool stopping, bool& waiting);

  const std::string owner_;
  const std::string service_;
  const NodeConfig& cfg_;
  std::mutex& mutex_;
  std::condition_variable& cv_;
  ReplyGate<ServiceReply> gate_;  // under mutex_
  // Replies held (gate, then unwritten_) per client, under mutex_, and the last warning about
  // dropping one.
  std::map<GuidPrefix, size_t> pending_;
  std::map<GuidPrefix, Clock::time_point> drop_warned_;
  ReplyFlow flow_;  // the replier thread's
  dds::DataWriter* writer_ = nullptr;
  std::unique_ptr<MatchedReaders> matched_;
  // Replies not written yet (the flow said wait, or the write failed), retried first on the
  // next pass, in order (replier thread). Bounded by pending_'s cap.
  std::deque<ServiceReply> unwritten_;
};

// A plain service the node serves, as the replier thread sees it (Replier::add_service).
class ServiceServerBase {
 public:
  using Clock = ServiceReplies::Clock;
  using Due = ServiceReplies::Due;
  virtual ~ServiceServerBase() = default;

  // The service's full ROS 2 name ("/vnsba_node/get_state").
  const std::string& name() const { return ros_name_; }
  // The replier thread's steps, as ActionServer's (take_due and next_deadline under the mutex).
  void take_due(Clock::time_point now, bool all, Due& out) { replies_.take_due(now, all, out); }
  bool write(Due& due, bool stopping, bool give_up);
  std::optional<Clock::time_point> next_deadline() const;
  dds::DataWriter* reply_writer() const { return replies_.writer(); }

 protected:
  ServiceServerBase(std::string ros_name, const NodeConfig& config, const ParticipantWatch* vendors,
                    std::mutex& mutex, std::condition_variable& cv);
  // The part before the last '/' and the part after it, for logs.
  static std::string owner_of(const std::string& ros_name);
  static std::string short_name_of(const std::string& ros_name);

  const std::string ros_name_;
  const NodeConfig& cfg_;
  const ParticipantWatch* vendors_;
  std::mutex& mutex_;
  std::condition_variable& cv_;
  ServiceReplies replies_;
  RefusedRequests refused_;
};

// A plain ROS 2 service of RequestType and ResponseType (fastddsgen PubSubTypes of
// <pkg>::srv::dds_::<Srv>_Request_ and _Response_). `on_request(server, from, request)` runs
// on a DDS thread for each request decoded; it answers with reply(from, ...), at once or later
// from any thread (a lifecycle transition answers when it ends).
template <class RequestType, class ResponseType>
class ServiceServer final : public ServiceServerBase {
 public:
  using Request = typename RequestType::type;
  using Response = typename ResponseType::type;
  using OnRequest = std::function<void(ServiceServer&, const ReplyAddress&, Request&&)>;

  // `ros_name`: the service's full ROS 2 name. The reply gate is guarded by `mutex`, and `cv`
  // wakes the node's replier.
  ServiceServer(std::string ros_name, const NodeConfig& config, const ParticipantWatch* vendors,
                std::mutex& mutex, std::condition_variable& cv, OnRequest on_request)
      : ServiceServerBase(std::move(ros_name), config, vendors, mutex, cv),
        on_request_(std::move(on_request)) {}

  // The reply writer, then the request reader (whose listener goes to `listeners`; the caller
  // deletes the reader before it).
  core::Status create(Participant& participant,
                      std::vector<std::unique_ptr<TakingListener>>& listeners) {
    if (auto s = replies_.create_writer<ResponseType>(participant, service_topic(ros_name_, false),
                                                      false);
        !s.is_ok())
      return s;
    listeners.push_back(make_listener<RawSample>(
        [this](RawSample&& raw, const dds::SampleInfo& info) { on_sample(std::move(raw), info); }));
    auto reader = participant.reader_on<RawOf<RequestType>>(
        service_topic(ros_name_, true), reader_qos(TopicQos::kEvents), listeners.back().get());
    if (!reader) return reader.error();
    return core::Status::ok();
  }

  // A request whose bytes `problem` refuses (its text, "" to decode it) is dropped undecoded, as
  // an undecodable one is: a list announcing more elements than its bytes hold would otherwise
  // be allocated first (is_path_valid's poses). Set before create().
  using BytesProblem = std::function<std::string(const RawSample&, WireMapping)>;
  void refuse_before_decoding(BytesProblem problem) { bytes_problem_ = std::move(problem); }

  // Holds `response` for the replier thread; `what` names it in logs.
  void reply(const ReplyAddress& to, const Response& response, std::string what) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      replies_.hold(to, encode_reply(response, to.mapping, to.header), std::move(what));
    }
    cv_.notify_all();
  }

 private:
  void on_sample(RawSample&& raw, const dds::SampleInfo& info) {
    ReplyAddress from = reply_address(info, cfg_.actions.reply_mapping, vendors_);
    if (bytes_problem_)
      if (std::string problem = bytes_problem_(raw, from.mapping); !problem.empty())
        return refused_.refuse(owner_of(ros_name_), short_name_of(ros_name_), from, problem);
    Request request;
    if (std::string problem = decode_request(raw, from.mapping, request, from.header);
        !problem.empty())
      return refused_.refuse(owner_of(ros_name_), short_name_of(ros_name_), from, problem);
    on_request_(*this, from, std::move(request));
  }

  OnRequest on_request_;
  BytesProblem bytes_problem_;
};

}  // namespace vnsba::node
