#include "action_server.hpp"

#include <fastdds/rtps/common/WriteParams.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstring>
#include <deque>
#include <set>

#include "action_raw_type.hpp"
#include "action_traits.hpp"
#include "vnsba/node/reply_flow.hpp"

namespace vnsba::node {

namespace {

using eprosima::fastrtps::rtps::GUID_t;
using eprosima::fastrtps::rtps::SampleIdentity;

constexpr size_t service_index(ActionService service) {
  return static_cast<size_t>(service);
}

GuidPrefix prefix_of(const GUID_t& guid) {
  GuidPrefix prefix;
  std::copy(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value), prefix.begin());
  return prefix;
}

// Bytes as lowercase hex digits, for ids in messages.
template <size_t N>
std::string hex(const std::array<uint8_t, N>& bytes) {
  std::string out;
  char buf[4];
  for (uint8_t b : bytes) {
    std::snprintf(buf, sizeof buf, "%02x", b);
    out += buf;
  }
  return out;
}

// An action service's reply writer: writer_qos(kStatus)'s, but keeping the last
// `history_depth` replies, as rclcpp_action's servers keep their last 10, so that a reader that
// does not acknowledge can never block a write (reply_flow.hpp paces the writes).
dds::DataWriterQos reply_writer_qos(int32_t history_depth, bool large_samples) {
  dds::DataWriterQos qos = writer_qos(TopicQos::kStatus, large_samples);
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = history_depth;
  qos.resource_limits().max_samples = history_depth;
  qos.resource_limits().max_samples_per_instance = history_depth;
  // Readers acknowledge when a heartbeat asks them to: the replies' flow waits for those
  // acknowledgements (reply_flow.hpp), so they are asked for often while replies are unacknowledged
  // (a writer sends none while everything is acknowledged).
  qos.reliable_writer_qos().times.heartbeatPeriod = {0, 20'000'000};
  return qos;
}

// Feeds a reply writer's gate with its matched readers (per remote participant).
class MatchedReaders : public dds::DataWriterListener {
 public:
  MatchedReaders(std::mutex& mutex, std::condition_variable& cv,
                 ReplyGate<ActionServer::Reply>& gate)
      : mutex_(mutex), cv_(cv), gate_(gate) {}
  void on_publication_matched(dds::DataWriter*,
                              const dds::PublicationMatchedStatus& status) override {
    if (status.current_count_change == 0) return;
    GuidPrefix prefix;  // an endpoint's instance handle is its GUID
    for (size_t i = 0; i < prefix.size(); ++i) prefix[i] = status.last_subscription_handle.value[i];
    {
      std::lock_guard<std::mutex> lock(mutex_);
      gate_.reader_matched(prefix, status.current_count_change);
    }
    cv_.notify_all();
  }

 private:
  std::mutex& mutex_;
  std::condition_variable& cv_;
  ReplyGate<ActionServer::Reply>& gate_;
};

// Where a reply goes: the client's mapping, its header (rmw_cyclonedds) or the identity to
// relate the reply to (rmw_fastrtps), and its participant (the reply gate).
struct ReplyAddress {
  WireMapping mapping = WireMapping::kSampleIdentity;
  RequestHeader header{};
  SampleIdentity related;
  GuidPrefix prefix{};
};

// A finished goal's get_result reply message (status and result), encoded once.
using EncodedResult = std::shared_ptr<const std::vector<uint8_t>>;

// Replies written or given up on in one pass, per service and client.
using RepliesDone = std::array<std::map<GuidPrefix, size_t>, kActionServices>;

// The replies of an action's three services on their way to the clients: each held until a
// reply reader of its client's participant is matched (ReplyGate), at most
// actions.max_pending_replies per client and service, then written as the service's reply
// writer's flow allows (ReplyFlow), in order per service. hold, take_due, next_deadline and
// release_pending run under the server's mutex; write_replies on the replier thread without it.
class ActionReplies {
 public:
  using Reply = ActionServer::Reply;
  using Clock = ActionServer::Clock;

  ActionReplies(const std::string& ros_name, const NodeConfig& config, std::mutex& mutex,
                std::condition_variable& cv)
      : ros_name_(ros_name),
        cfg_(config),
        mutex_(mutex),
        cv_(cv),
        gates_{ReplyGate<Reply>(config.reply_wait, kReaderSettle),
               ReplyGate<Reply>(config.reply_wait, kReaderSettle),
               ReplyGate<Reply>(config.reply_wait, kReaderSettle)},
        flows_{ReplyFlow(reply_budget(config), config.actions.reply_ack_timeout),
               ReplyFlow(reply_budget(config), config.actions.reply_ack_timeout),
               ReplyFlow(reply_budget(config), config.actions.reply_ack_timeout)} {}

  // The service's reply writer on `participant`, of ReplyType's DDS type (`large`: results).
  template <class ReplyType>
  core::Status create_writer(Participant& participant, ActionService service, bool large) {
    const size_t s = service_index(service);
    matched_[s] = std::make_unique<MatchedReaders>(mutex_, cv_, gates_[s]);
    auto writer = participant.writer_on<RawOf<ReplyType>>(service_topic(ros_name_, service, false),
                                                          reply_writer_qos(kReplyHistory, large),
                                                          matched_[s].get());
    if (!writer) return writer.error();
    writers_[s] = *writer;
    return core::Status::ok();
  }

  void hold(ActionService service, const ReplyAddress& to, RawSample sample, std::string what);
  void take_due(Clock::time_point now, bool all, ActionServer::Due& out);
  // Writes what `due` holds, as ActionServer::write says; returns the replies written or given
  // up on, for release_pending (under the mutex).
  RepliesDone write_replies(ActionServer::Due& due, bool stopping, bool give_up);
  void release_pending(const RepliesDone& done);
  bool all_written() const { return unwritten_.empty(); }
  void next_deadline(std::optional<Clock::time_point>& earliest) const;
  const std::array<dds::DataWriter*, kActionServices>& writers() const { return writers_; }

 private:
  static size_t reply_budget(const NodeConfig& config) {
    return static_cast<size_t>(config.actions.replies_in_flight_mb) << 20;
  }
  void warn_dropped(size_t service, const GuidPrefix& client, size_t pending,
                    const std::string& what);
  void check_acknowledgements(Clock::time_point now);
  void warn_stalled(size_t service, const std::vector<std::pair<GuidPrefix, size_t>>& clients);
  static void assert_liveliness(const ActionServer::Due& due);
  bool write_now(Reply& reply, Clock::time_point now, bool stopping, bool& waiting);

  const std::string& ros_name_;
  const NodeConfig& cfg_;
  std::mutex& mutex_;
  std::condition_variable& cv_;
  std::array<ReplyGate<Reply>, kActionServices> gates_;  // under mutex_
  // Per service: replies held (gate, then unwritten_) per client, under mutex_, and the last
  // warning about dropping one.
  std::array<std::map<GuidPrefix, size_t>, kActionServices> pending_;
  std::map<GuidPrefix, Clock::time_point> drop_warned_;
  std::array<ReplyFlow, kActionServices> flows_;  // the replier thread's
  std::array<dds::DataWriter*, kActionServices> writers_{};
  std::array<std::unique_ptr<MatchedReaders>, kActionServices> matched_;
  // Replies not written yet (their writer's flow said wait, or the write failed), retried first
  // on the next pass, in order (replier thread). Bounded by pending_'s cap.
  std::deque<Reply> unwritten_;
};

// Holds a reply for the replier thread, unless the client has max_pending_replies held by this
// service already (then it is dropped with a warning, at most one a second per client).
void ActionReplies::hold(ActionService service, const ReplyAddress& to, RawSample sample,
                         std::string what) {
  const size_t s = service_index(service);
  size_t& pending = pending_[s][to.prefix];
  if (pending >= static_cast<size_t>(cfg_.actions.max_pending_replies)) {
    warn_dropped(s, to.prefix, pending, what);
    return;
  }
  ++pending;
  Reply reply;
  reply.writer = writers_[s];
  reply.service = static_cast<int>(s);
  reply.client = to.prefix;
  reply.sample = std::move(sample);
  if (to.mapping == WireMapping::kSampleIdentity) reply.related = to.related;
  reply.what = std::move(what);
  gates_[s].hold(to.prefix, std::move(reply), ReplyGate<Reply>::Clock::now());
}

void ActionReplies::warn_dropped(size_t service, const GuidPrefix& client, size_t pending,
                                 const std::string& what) {
  const Clock::time_point now = Clock::now();
  auto [warned, first] = drop_warned_.try_emplace(client, now);
  if (!first && now - warned->second < std::chrono::seconds(1)) return;
  warned->second = now;
  spdlog::warn(
      "{}: {} to participant {} dropped: {} {} replies to it wait already "
      "(actions.max_pending_replies; its reply reader is not matched or not taking them)",
      ros_name_, what, hex(client), pending, service_name(static_cast<ActionService>(service)));
}

void ActionReplies::take_due(Clock::time_point now, bool all, ActionServer::Due& out) {
  const auto release_at = all ? ReplyGate<Reply>::Clock::time_point::max() : now;
  while (!unwritten_.empty()) {
    out.replies.push_back(std::move(unwritten_.front()));
    unwritten_.pop_front();
  }
  for (size_t s = 0; s < gates_.size(); ++s) {
    bool heartbeat = false;
    for (Reply& reply : gates_[s].release(release_at, nullptr, &heartbeat))
      out.replies.push_back(std::move(reply));
    if (heartbeat && writers_[s] != nullptr) out.heartbeats.push_back(writers_[s]);
  }
  for (const ReplyFlow& flow : flows_)
    if (const auto next = flow.next_check(!unwritten_.empty()); next && now >= *next)
      out.check_flows = true;
}

RepliesDone ActionReplies::write_replies(ActionServer::Due& due, bool stopping, bool give_up) {
  const Clock::time_point now = Clock::now();
  check_acknowledgements(now);
  assert_liveliness(due);
  // In order per service: a reply that must wait keeps every later one of its service waiting.
  std::array<bool, kActionServices> waiting{};
  RepliesDone done;
  std::deque<Reply> keep;
  for (Reply& reply : due.replies) {
    const int s = reply.service;
    if (reply.writer == nullptr || write_now(reply, now, stopping, waiting[s])) {
      ++done[s][reply.client];
      continue;
    }
    if (give_up) {
      spdlog::error("{}: could not write {}: the shutdown's drain ran out of time", ros_name_,
                    reply.what);
      ++done[s][reply.client];
      continue;
    }
    keep.push_back(std::move(reply));
  }
  due.replies.clear();
  // Kept in order, ahead of what the next take_due brings.
  while (!keep.empty()) {
    unwritten_.push_front(std::move(keep.back()));
    keep.pop_back();
  }
  return done;
}

// A writer whose readers have acknowledged every reply written opens its window again; one
// whose window waited reply_ack_timeout names the clients of the replies in it, once.
void ActionReplies::check_acknowledgements(Clock::time_point now) {
  for (size_t s = 0; s < kActionServices; ++s) {
    ReplyFlow& flow = flows_[s];
    dds::DataWriter* writer = writers_[s];
    if (writer == nullptr || flow.unacknowledged_bytes() == 0) continue;
    if (writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0, 0)) ==
        ReturnCode_t::RETCODE_OK) {
      flow.all_acknowledged();
    } else if (const auto clients = flow.stalled(now)) {
      warn_stalled(s, *clients);
    }
  }
}

void ActionReplies::warn_stalled(size_t service,
                                 const std::vector<std::pair<GuidPrefix, size_t>>& clients) {
  std::string names;
  for (size_t i = 0; i < clients.size() && i < 3; ++i)
    names +=
        (i ? ", " : "") + hex(clients[i].first) + " (" + std::to_string(clients[i].second) + ")";
  if (clients.size() > 3) names += " and more";
  // DDS does not say which reader lags: every participant with a reader on this topic.
  std::vector<GuidPrefix> readers;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    readers = gates_[service].matched_participants();
  }
  std::string readers_text;
  for (const GuidPrefix& participant : readers)
    readers_text += (readers_text.empty() ? "" : ", ") + hex(participant);
  spdlog::warn(
      "{}: {} replies not acknowledged by every reader within actions.reply_ack_timeout "
      "({:g} s): a reader does not take its replies (a stopped or overloaded client). "
      "Replies waiting in it by client participant: {}; participants with a reader of it: "
      "{}. The others' replies go on without waiting for it, and what only it lacks is "
      "dropped",
      ros_name_, service_name(static_cast<ActionService>(service)),
      static_cast<double>(cfg_.actions.reply_ack_timeout.count()) / 1000.0, names, readers_text);
}

// A heartbeat that does not count these replies first, as the node does before statuses
// (Replier::loop): Cyclone DDS's volatile reader skips everything up to the last sequence
// number of the first heartbeat it accepts from a writer, and a client that discovered the
// reply writer after the node matched its reader missed the earlier heartbeats. An 885 kB
// result (14 fragments) was lost so in 7 of 15 runs of the Cyclone client's cancel test.
// Not enough alone when the heartbeat goes to a multicast group and Fast DDS sends the reply's
// own heartbeat to the client's unicast locator (reply_gate.hpp): the gate's heartbeats
// (`due.heartbeats`) go out a settle ahead of such a reply.
void ActionReplies::assert_liveliness(const ActionServer::Due& due) {
  std::set<dds::DataWriter*> asserted;
  for (dds::DataWriter* writer : due.heartbeats)
    if (asserted.insert(writer).second) writer->assert_liveliness();
  for (const Reply& reply : due.replies)
    if (reply.writer != nullptr && asserted.insert(reply.writer).second)
      reply.writer->assert_liveliness();
}

// Writes `reply` now if its service is not `waiting` and its flow allows (`stopping`: the flow
// is not asked); true when written. A reply that must wait, or that the writer refuses, sets
// `waiting` for the rest of its service in this pass.
bool ActionReplies::write_now(Reply& reply, Clock::time_point now, bool stopping, bool& waiting) {
  ReplyFlow& flow = flows_[reply.service];
  const size_t bytes = reply.sample.size();
  if (!waiting && !stopping) {
    const ReplyFlow::Step step = flow.next(bytes, now);
    if (step == ReplyFlow::Step::kWait) waiting = true;
    if (step == ReplyFlow::Step::kClearHistory) {
      size_t removed = 0;
      reply.writer->clear_history(&removed);
      flow.history_cleared();
      spdlog::warn(
          "{}: {} replies a reader has not acknowledged for actions.reply_ack_timeout "
          "dropped from the writer's history ({} of them)",
          ros_name_, service_name(static_cast<ActionService>(reply.service)), removed);
    }
  }
  if (waiting) return false;
  eprosima::fastrtps::rtps::WriteParams params;
  if (reply.related) params.related_sample_identity(*reply.related);
  if (write_sample(reply.writer, &reply.sample, params)) {
    flow.written(reply.client, bytes, now);
    return true;
  }
  waiting = true;  // refused: tried again on the next pass
  return false;
}

void ActionReplies::release_pending(const RepliesDone& done) {
  for (size_t s = 0; s < kActionServices; ++s)
    for (const auto& [client, count] : done[s]) {
      auto it = pending_[s].find(client);
      if (it == pending_[s].end()) continue;
      it->second -= std::min(it->second, count);
      if (it->second == 0) pending_[s].erase(it);
    }
}

// The flows' next look (the acknowledgements themselves are looked for every few milliseconds
// by the replier while replies wait) and the gates' next deadlines.
void ActionReplies::next_deadline(std::optional<Clock::time_point>& earliest) const {
  for (const ReplyFlow& flow : flows_)
    if (auto next = flow.next_check(!unwritten_.empty()); next && (!earliest || *next < *earliest))
      earliest = next;
  for (const auto& gate : gates_)
    if (auto next = gate.next_deadline(); next && (!earliest || *next < *earliest)) earliest = next;
}

}  // namespace

std::string announced_poses_problem(const RawSample& raw, WireMapping mapping,
                                    bool after_a_header) {
  // Offsets in bytes from the sample's start: the 4-byte encapsulation, the request header,
  // the goal id; CDR aligns from the end of the encapsulation.
  size_t at = 4 + (mapping == WireMapping::kRequestHeader ? 16 : 0) + 16;
  if (after_a_header) {  // stamp (8), then frame_id (length 4, characters), aligned to 4
    at += 8;
    if (raw.bytes.size() < at + 4) return "";  // too short: decoding says so
    uint32_t frame_bytes = 0;
    std::memcpy(&frame_bytes, raw.bytes.data() + at, 4);
    if (raw.bytes[1] == 0) frame_bytes = __builtin_bswap32(frame_bytes);  // big-endian CDR
    if (frame_bytes > raw.bytes.size()) return "";                        // decoding says so
    at += 4 + frame_bytes;
    at = 4 + (at - 4 + 3) / 4 * 4;
  }
  if (raw.bytes.size() < at + 4) return "";  // too short: decoding says so
  uint32_t count = 0;
  std::memcpy(&count, raw.bytes.data() + at, 4);
  if (raw.bytes[1] == 0) count = __builtin_bswap32(count);  // big-endian CDR
  const size_t room = (raw.bytes.size() - at - 4) / 68;
  if (count <= room) return "";
  return "goals: announces " + std::to_string(count) + " poses in " +
         std::to_string(raw.bytes.size()) + " bytes (at most " + std::to_string(room) + " fit)";
}

std::string uuid_text(const GoalUuid& id) {
  return hex(id);
}

class ActionServer::Impl {
 public:
  Impl(ActionServer& self, const NodeConfig& config, const ParticipantWatch* vendors,
       std::mutex& mutex, std::condition_variable& cv, Hooks hooks)
      : self_(self),
        cfg_(config),
        vendors_(vendors),
        mutex_(mutex),
        cv_(cv),
        hooks_(std::move(hooks)),
        goals_(config.actions.result_timeout, static_cast<size_t>(config.actions.max_results)),
        replies_(self.ros_name_, config, mutex, cv) {}
  virtual ~Impl() = default;

  // The action's own part (ImplOf): its endpoints, and its result message encoded.
  virtual core::Status create(
      Participant& participant, std::vector<std::unique_ptr<TakingListener>>& listeners,
      std::vector<std::pair<TakingListener*, dds::DataReader*>>& inputs) = 0;
  virtual EncodedResult encode_result(GoalState state, const ActionOutcome& outcome) const = 0;
  // Whether the distribution's result carries error_code and error_msg (Humble's does not).
  virtual bool result_has_error_code() const = 0;

  ActionServer& self_;
  const NodeConfig& cfg_;
  const ParticipantWatch* vendors_;
  std::mutex& mutex_;
  std::condition_variable& cv_;
  Hooks hooks_;
  ActionGoals<EncodedResult, ReplyAddress> goals_;  // under mutex_
  ActionReplies replies_;
  dds::DataWriter* status_writer_ = nullptr;
  dds::DataWriter* feedback_writer_ = nullptr;
  bool status_dirty_ = true;         // under mutex_; the first pass publishes the (empty) list
  Clock::time_point last_status_{};  // when the list was last published, under mutex_
  std::set<GuidPrefix> warned_;      // clients whose undecodable requests were logged, under mutex_

  ReplyAddress address_of(const dds::SampleInfo& info) const {
    ReplyAddress address;
    const GUID_t& writer = info.sample_identity.writer_guid();
    address.prefix = prefix_of(writer);
    const bool has_related = info.related_sample_identity.writer_guid() != GUID_t::unknown();
    std::optional<VendorId> vendor;
    if (vendors_ != nullptr) vendor = vendors_->vendor_of(writer.guidPrefix);
    address.mapping = choose_mapping(cfg_.actions.reply_mapping, vendor, has_related);
    // As rmw_fastrtps's server: the request's identity, with the client's reply reader as the
    // writer GUID when the request names it.
    address.related = info.sample_identity;
    if (has_related) address.related.writer_guid() = info.related_sample_identity.writer_guid();
    return address;
  }

  // A reply for the replier thread (under mutex_).
  template <class Msg>
  void hold(ActionService service, const ReplyAddress& to, const Msg& msg, std::string what) {
    replies_.hold(service, to, encode_reply(msg, to.mapping, to.header), std::move(what));
  }
  void hold_result(const ReplyAddress& to, const EncodedResult& result, std::string what) {
    replies_.hold(ActionService::kGetResult, to, reply_with_message(result, to.mapping, to.header),
                  std::move(what));
  }

  // A request that cannot be decoded: logged once per client, never answered (without its
  // goal id there is nothing to answer, as in rcl_action).
  void refuse(const ReplyAddress& from, ActionService service, const std::string& problem) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (warned_.size() >= 1000 || !warned_.insert(from.prefix).second) return;
    }
    spdlog::warn("{}: a {} request from participant {} dropped: {} (mapping {})", self_.ros_name_,
                 service_name(service), hex(from.prefix), problem, to_string(from.mapping));
  }

  void on_cancel(RawSample&& raw, const dds::SampleInfo& info);
  void take_status(Clock::time_point now, bool all, Due& out);

  // The status and feedback writers; FeedbackType is the action's feedback message type.
  template <class FeedbackType>
  core::Status create_topic_writers(Participant& participant) {
    auto status = participant.writer_on<GoalStatusArrayType>(
        action_topic(self_.ros_name_, "status"), writer_qos(TopicQos::kLatched, false));
    if (!status) return status.error();
    status_writer_ = *status;
    auto feedback = participant.writer_on<FeedbackType>(action_topic(self_.ros_name_, "feedback"),
                                                        writer_qos(TopicQos::kLatest, false));
    if (!feedback) return feedback.error();
    feedback_writer_ = *feedback;
    return core::Status::ok();
  }

  // A reader of the service's requests, of RequestType's DDS type; its listener goes to
  // `listeners`, and with `inputs` the reader is the intake's.
  template <class RequestType>
  core::Status add_request_reader(
      Participant& participant, ActionService service, std::unique_ptr<TakingListener> listener,
      std::vector<std::unique_ptr<TakingListener>>& listeners,
      std::vector<std::pair<TakingListener*, dds::DataReader*>>* inputs) {
    listeners.push_back(std::move(listener));
    auto reader = participant.reader_on<RawOf<RequestType>>(
        service_topic(self_.ros_name_, service, true), reader_qos(TopicQos::kEvents),
        listeners.back().get());
    if (!reader) return reader.error();
    if (inputs != nullptr) inputs->emplace_back(listeners.back().get(), *reader);
    return core::Status::ok();
  }
};

void ActionServer::Impl::on_cancel(RawSample&& raw, const dds::SampleInfo& info) {
  ReplyAddress from = address_of(info);
  CancelRequest request;
  if (std::string problem = decode_request(raw, from.mapping, request, from.header);
      !problem.empty())
    return refuse(from, ActionService::kCancelGoal, problem);
  const GoalUuid id = request.goal_info().goal_id().uuid();
  const GoalStamp stamp{request.goal_info().stamp().sec(), request.goal_info().stamp().nanosec()};
  std::vector<GoalUuid> canceling;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto outcome = goals_.cancel(id, stamp);
    CancelResponse response;
    response.return_code(static_cast<int8_t>(outcome.code));
    for (const auto& entry : outcome.canceling) {
      GoalInfoMsg info_msg;
      info_msg.goal_id().uuid(entry.id);
      info_msg.stamp().sec(entry.stamp.sec);
      info_msg.stamp().nanosec(entry.stamp.nanosec);
      response.goals_canceling().push_back(info_msg);
      canceling.push_back(entry.id);
    }
    hold(ActionService::kCancelGoal, from, response, "a cancel_goal reply");
    status_dirty_ = status_dirty_ || !canceling.empty();
  }
  cv_.notify_all();
  if (!canceling.empty()) hooks_.on_cancel(self_, canceling);
}

// The list holds every goal not finished and the last actions.status_finished_goals that
// finished: under a burst of goals, one list per kStatusPeriod carries every change since the
// last.
void ActionServer::Impl::take_status(Clock::time_point now, bool all, Due& out) {
  if (goals_.expire(now) > 0) status_dirty_ = true;
  if (!status_dirty_ || (!all && now < last_status_ + kStatusPeriod)) return;
  status_dirty_ = false;
  last_status_ = now;
  GoalStatusArrayMsg msg;
  for (const auto& entry :
       goals_.statuses(static_cast<size_t>(cfg_.actions.status_finished_goals))) {
    action_msgs::msg::dds_::GoalStatus_ status;
    status.goal_info().goal_id().uuid(entry.id);
    status.goal_info().stamp().sec(entry.stamp.sec);
    status.goal_info().stamp().nanosec(entry.stamp.nanosec);
    status.status(static_cast<int8_t>(entry.state));
    msg.status_list().push_back(status);
  }
  out.status = std::move(msg);
}

template <class Traits, class Wire>
class ActionServer::ImplOf final : public ActionServer::Impl {
 public:
  using Impl::Impl;

  // Writers first, so that every request read can be answered.
  core::Status create(Participant& participant,
                      std::vector<std::unique_ptr<TakingListener>>& listeners,
                      std::vector<std::pair<TakingListener*, dds::DataReader*>>& inputs) override {
    if (auto s = create_writers(participant); !s.is_ok()) return s;
    return create_readers(participant, listeners, inputs);
  }

  EncodedResult encode_result(GoalState state, const ActionOutcome& outcome) const override {
    return encode_message(result_response(state, outcome));
  }
  bool result_has_error_code() const override { return kResultHasErrorCode<typename Wire::Result>; }

 private:
  core::Status create_writers(Participant& participant) {
    if (auto s = replies_.create_writer<typename Wire::SendGoalResponseType>(
            participant, ActionService::kSendGoal, false);
        !s.is_ok())
      return s;
    if (auto s = replies_.create_writer<typename Wire::GetResultResponseType>(
            participant, ActionService::kGetResult, true);
        !s.is_ok())
      return s;
    if (auto s = replies_.create_writer<CancelResponseType>(participant, ActionService::kCancelGoal,
                                                            false);
        !s.is_ok())
      return s;
    return create_topic_writers<typename Wire::FeedbackMessageType>(participant);
  }

  // Goals are taken by the node's intake thread, as requests are (bounded by the robot's
  // answers owed); results and cancels are cheap and taken as they come.
  core::Status create_readers(Participant& participant,
                              std::vector<std::unique_ptr<TakingListener>>& listeners,
                              std::vector<std::pair<TakingListener*, dds::DataReader*>>& inputs) {
    auto take_goal = [this](RawSample&& raw, const dds::SampleInfo& info) {
      on_send_goal(std::move(raw), info);
    };
    if (auto s = add_request_reader<typename Wire::SendGoalRequestType>(
            participant, ActionService::kSendGoal,
            make_intake_listener<RawSample>(take_goal, hooks_.may_take, hooks_.wake_intake),
            listeners, &inputs);
        !s.is_ok())
      return s;
    if (auto s = add_request_reader<typename Wire::GetResultRequestType>(
            participant, ActionService::kGetResult,
            make_listener<RawSample>([this](RawSample&& raw, const dds::SampleInfo& info) {
              on_get_result(std::move(raw), info);
            }),
            listeners, nullptr);
        !s.is_ok())
      return s;
    return add_request_reader<CancelRequestType>(
        participant, ActionService::kCancelGoal,
        make_listener<RawSample>([this](RawSample&& raw, const dds::SampleInfo& info) {
          on_cancel(std::move(raw), info);
        }),
        listeners, nullptr);
  }

  void on_send_goal(RawSample&& raw, const dds::SampleInfo& info) {
    ReplyAddress from = address_of(info);
    typename Wire::SendGoalRequest request;
    if (std::string problem =
            Traits::template goal_bytes_problem<typename Wire::Goal>(raw, from.mapping);
        !problem.empty())
      return refuse(from, ActionService::kSendGoal, problem);
    if (std::string problem = decode_request(raw, from.mapping, request, from.header);
        !problem.empty())
      return refuse(from, ActionService::kSendGoal, problem);
    raw = RawSample();  // a goal may be megabytes of poses: the decoded copy is enough
    ActionGoal goal;
    goal.id = request.goal_id().uuid();
    Traits::read_goal(std::move(request.goal()), goal);
    goal.identity = identity_of(info, wire::SUBJECT_REQUEST);
    const TimeMsg stamp = hooks_.now();
    bool accepted = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      accepted = goals_.accept(goal.id, GoalStamp{stamp.sec(), stamp.nanosec()});
      typename Wire::SendGoalResponse response;
      response.accepted(accepted);
      response.stamp(stamp);
      hold(ActionService::kSendGoal, from, response,
           "the send_goal reply of goal " + uuid_text(goal.id));
      status_dirty_ = status_dirty_ || accepted;
    }
    cv_.notify_all();
    if (!accepted) {
      spdlog::warn("{}: goal {} rejected: a goal with this id is running or its result is kept",
                   self_.ros_name_, uuid_text(goal.id));
      return;
    }
    hooks_.on_goal(self_, std::move(goal));
  }

  void on_get_result(RawSample&& raw, const dds::SampleInfo& info) {
    ReplyAddress from = address_of(info);
    typename Wire::GetResultRequest request;
    if (std::string problem = decode_request(raw, from.mapping, request, from.header);
        !problem.empty())
      return refuse(from, ActionService::kGetResult, problem);
    const GoalUuid id = request.goal_id().uuid();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto answer = goals_.result_or_wait(id, from);
      if (!answer) return;  // answered when the goal finishes
      const std::string what = "the result of goal " + uuid_text(id);
      if (answer->result) {
        hold_result(from, answer->result, what);
      } else {  // a goal never seen, or forgotten: UNKNOWN with an empty result
        hold(ActionService::kGetResult, from, result_response(GoalState::kUnknown, ActionOutcome{}),
             what);
      }
    }
    cv_.notify_all();
  }

  typename Wire::GetResultResponse result_response(GoalState state,
                                                   const ActionOutcome& outcome) const {
    typename Wire::GetResultResponse response;
    response.status(static_cast<int8_t>(state));
    Traits::write_result(outcome, response.result());
    return response;
  }
};

ActionServer::ActionServer(ActionKind kind, std::string ros_name, const NodeConfig& config,
                           const ParticipantWatch* vendors, std::mutex& reply_mutex,
                           std::condition_variable& reply_cv, Hooks hooks)
    : kind_(kind), ros_name_(std::move(ros_name)) {
  // One server for every distribution: the action's wire types are config.ros_distro's.
  impl_ = with_action_traits(kind, [&](auto traits) -> std::unique_ptr<Impl> {
    using Traits = decltype(traits);
    return with_action_wire<Traits>(config.ros_distro, [&](auto wire) -> std::unique_ptr<Impl> {
      return std::make_unique<ImplOf<Traits, decltype(wire)>>(*this, config, vendors, reply_mutex,
                                                              reply_cv, std::move(hooks));
    });
  });
}

ActionServer::~ActionServer() = default;

core::Status ActionServer::create(
    Participant& participant, std::vector<std::unique_ptr<TakingListener>>& listeners,
    std::vector<std::pair<TakingListener*, dds::DataReader*>>& inputs) {
  return impl_->create(participant, listeners, inputs);
}

void ActionServer::execute(const GoalUuid& id) {
  {
    std::lock_guard<std::mutex> lock(impl_->mutex_);
    if (!impl_->goals_.execute(id)) return;
    impl_->status_dirty_ = true;
  }
  impl_->cv_.notify_all();
}

bool ActionServer::canceling(const GoalUuid& id) const {
  std::lock_guard<std::mutex> lock(impl_->mutex_);
  return impl_->goals_.state(id) == GoalState::kCanceling;
}

void ActionServer::finish(const GoalUuid& id, ActionOutcome outcome) {
  if (outcome.error_msg.size() > kMaxErrorMessageBytes) {
    outcome.error_msg.resize(kMaxErrorMessageBytes - 3);
    while (!outcome.error_msg.empty() && (outcome.error_msg.back() & 0xC0) == 0x80)
      outcome.error_msg.pop_back();  // never cut a UTF-8 character
    if (!outcome.error_msg.empty() && (outcome.error_msg.back() & 0x80) != 0)
      outcome.error_msg.pop_back();
    outcome.error_msg += "...";
  }
  // What the distribution's result cannot carry (Humble: no error_code, no error_msg; the client
  // sees ABORTED and an empty path) is said in the log beside the plan's own line.
  if (outcome.error_code != 0 && !impl_->result_has_error_code())
    spdlog::info("{}: goal {} ends {} with error_code {}{}{}, which the {} result cannot carry",
                 ros_name_, uuid_text(id),
                 outcome.state == GoalState::kCanceled ? "CANCELED" : "ABORTED", outcome.error_code,
                 outcome.error_msg.empty() ? "" : ": ", outcome.error_msg,
                 distro_name(impl_->cfg_.ros_distro));
  // Encoded before the lock: a result of 100,000 poses takes milliseconds.
  const EncodedResult result = impl_->encode_result(outcome.state, outcome);
  const size_t bytes = result->size() + kKeptResultOverheadBytes;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex_);
    const std::vector<ReplyAddress> waiting =
        impl_->goals_.finish(id, outcome.state, result, Clock::now(), bytes);
    for (const ReplyAddress& to : waiting)
      impl_->hold_result(to, result, "the result of goal " + uuid_text(id));
    impl_->status_dirty_ = true;
  }
  impl_->cv_.notify_all();
}

void ActionServer::take_due(Clock::time_point now, bool all, Due& out) {
  impl_->replies_.take_due(now, all, out);
  impl_->take_status(now, all, out);
}

bool ActionServer::write(Due& due, bool stopping, bool give_up) {
  const RepliesDone done = impl_->replies_.write_replies(due, stopping, give_up);
  if (due.status && impl_->status_writer_ != nullptr && !impl_->status_writer_->write(&*due.status))
    spdlog::error("{}: could not publish the goal status list", ros_name_);
  {
    std::lock_guard<std::mutex> lock(impl_->mutex_);
    impl_->replies_.release_pending(done);
  }
  return impl_->replies_.all_written();
}

std::optional<ActionServer::Clock::time_point> ActionServer::next_deadline() const {
  std::optional<Clock::time_point> earliest = impl_->goals_.next_expiry();
  if (impl_->status_dirty_) {
    const Clock::time_point list_due = impl_->last_status_ + kStatusPeriod;
    if (!earliest || list_due < *earliest) earliest = list_due;
  }
  impl_->replies_.next_deadline(earliest);
  return earliest;
}

std::array<dds::DataWriter*, kActionServices> ActionServer::reply_writers() const {
  return impl_->replies_.writers();
}

size_t ActionServer::goals() const {
  return impl_->goals_.size();
}

size_t ActionServer::kept_bytes() const {
  return impl_->goals_.kept_bytes();
}

std::optional<FinishedGoal> ActionServer::oldest_finished(std::optional<bool> delivered) const {
  return impl_->goals_.oldest_finished(delivered);
}

bool ActionServer::forget(const GoalUuid& id) {
  if (!impl_->goals_.forget(id)) return false;
  impl_->status_dirty_ = true;
  return true;
}

}  // namespace vnsba::node
