#include "action_server.hpp"

#include <fastdds/rtps/common/WriteParams.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstring>
#include <deque>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <set>

#include "action_types.hpp"
#include "vnsba/node/reply_flow.hpp"

namespace vnsba::node {

namespace {

using eprosima::fastrtps::rtps::GUID_t;
using eprosima::fastrtps::rtps::SampleIdentity;

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

}  // namespace

uint16_t nav2_error_code(ActionKind kind, uint8_t wire_code, bool invalid_planner) {
  const uint16_t unknown = kind == ActionKind::kComputePathToPose ? 200 : 300;
  if (wire_code == wire::OK) return 0;
  if (invalid_planner) return unknown + 1;
  switch (wire_code) {
    case wire::FRAME_MISMATCH:
      return unknown + 2;  // TF_ERROR
    case wire::START_OUTSIDE_MAP:
      return unknown + 3;
    case wire::GOAL_OUTSIDE_MAP:
      return unknown + 4;
    case wire::START_OCCUPIED:
      return unknown + 5;
    case wire::GOAL_OCCUPIED:
      return unknown + 6;
    case wire::TIMEOUT:
      return unknown + 7;
    case wire::NO_VALID_PATH:
      return unknown + 8;
    default:
      return unknown;  // NO_MAP, INVALID_MAP, INVALID_REQUEST, CANCELED, INTERNAL_ERROR
  }
}

std::string uuid_text(const GoalUuid& id) {
  return hex(id);
}

// A ComputePathThroughPoses send_goal whose `goals` count cannot fit in its bytes: refused before
// decoding, which would allocate every announced pose first (a count of 2^31 in a 40-byte
// sample). A PoseStamped takes at least 68 bytes on the wire (stamp 8, frame_id length 4, pose
// 56). The count follows the header (rmw_cyclonedds) and the 16-byte goal id.
std::string announced_poses_problem(const RawSample& raw, WireMapping mapping) {
  const size_t at = 4 + (mapping == WireMapping::kRequestHeader ? 16 : 0) + 16;
  if (raw.bytes.size() < at + 4) return "";  // too short: decoding says so
  uint32_t count = 0;
  std::memcpy(&count, raw.bytes.data() + at, 4);
  if (raw.bytes[1] == 0) count = __builtin_bswap32(count);  // big-endian CDR
  const size_t room = (raw.bytes.size() - at - 4) / 68;
  if (count <= room) return "";
  return "goals: announces " + std::to_string(count) + " poses in " +
         std::to_string(raw.bytes.size()) + " bytes (at most " + std::to_string(room) + " fit)";
}

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

class ActionServer::Impl {
 public:
  enum Service { kSendGoal = 0, kGetResult = 1, kCancel = 2 };
  static constexpr const char* kServiceNames[3] = {"send_goal", "get_result", "cancel_goal"};

  Impl(ActionServer& self, const NodeConfig& config, const ParticipantWatch* vendors,
       std::mutex& mutex, std::condition_variable& cv, Hooks hooks)
      : self_(self),
        cfg_(config),
        vendors_(vendors),
        mutex_(mutex),
        cv_(cv),
        hooks_(std::move(hooks)),
        goals_(config.actions.result_timeout, static_cast<size_t>(config.actions.max_results)),
        gates_{ReplyGate<Reply>(config.reply_wait, kReaderSettle),
               ReplyGate<Reply>(config.reply_wait, kReaderSettle),
               ReplyGate<Reply>(config.reply_wait, kReaderSettle)},
        flows_{ReplyFlow(reply_budget(config), config.actions.reply_ack_timeout),
               ReplyFlow(reply_budget(config), config.actions.reply_ack_timeout),
               ReplyFlow(reply_budget(config), config.actions.reply_ack_timeout)} {}

  static size_t reply_budget(const NodeConfig& config) {
    return static_cast<size_t>(config.actions.replies_in_flight_mb) << 20;
  }

  ActionServer& self_;
  const NodeConfig& cfg_;
  const ParticipantWatch* vendors_;
  std::mutex& mutex_;
  std::condition_variable& cv_;
  Hooks hooks_;
  ActionGoals<EncodedResult, ReplyAddress> goals_;  // under mutex_
  std::array<ReplyGate<Reply>, 3> gates_;           // under mutex_
  // Per service: replies held (gate, then unwritten_) per client, under mutex_, and the last
  // warning about dropping one.
  std::array<std::map<GuidPrefix, size_t>, 3> pending_;
  std::map<GuidPrefix, Clock::time_point> drop_warned_;
  std::array<ReplyFlow, 3> flows_;  // the replier thread's
  std::array<dds::DataWriter*, 3> reply_writers_{};
  std::array<std::unique_ptr<MatchedReaders>, 3> matched_;
  dds::DataWriter* status_writer_ = nullptr;
  dds::DataWriter* feedback_writer_ = nullptr;
  bool status_dirty_ = true;         // under mutex_; the first pass publishes the (empty) list
  Clock::time_point last_status_{};  // when the list was last published, under mutex_
  // Replies not written yet (their writer's flow said wait, or the write failed), retried first
  // on the next pass, in order (replier thread). Bounded by pending_'s cap.
  std::deque<Reply> unwritten_;
  std::set<GuidPrefix> warned_;  // clients whose undecodable requests were logged, under mutex_

  std::string topic(const char* service, bool request) const {
    return std::string(request ? "rq" : "rr") + self_.ros_name_ + "/_action/" + service +
           (request ? "Request" : "Reply");
  }

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

  // Holds a reply for the replier thread, unless the client has max_pending_replies held by
  // this service already (then it is dropped with a warning, at most one a second per client);
  // under mutex_.
  void hold_sample(Service service, const ReplyAddress& to, RawSample sample, std::string what) {
    size_t& pending = pending_[service][to.prefix];
    if (pending >= static_cast<size_t>(cfg_.actions.max_pending_replies)) {
      const Clock::time_point now = Clock::now();
      auto [warned, first] = drop_warned_.try_emplace(to.prefix, now);
      if (first || now - warned->second >= std::chrono::seconds(1)) {
        warned->second = now;
        spdlog::warn(
            "{}: {} to participant {} dropped: {} {} replies to it wait already "
            "(actions.max_pending_replies; its reply reader is not matched or not taking them)",
            self_.ros_name_, what, hex(to.prefix), pending, kServiceNames[service]);
      }
      return;
    }
    ++pending;
    Reply reply;
    reply.writer = reply_writers_[service];
    reply.service = service;
    reply.client = to.prefix;
    reply.sample = std::move(sample);
    if (to.mapping == WireMapping::kSampleIdentity) reply.related = to.related;
    reply.what = std::move(what);
    gates_[service].hold(to.prefix, std::move(reply), ReplyGate<Reply>::Clock::now());
  }
  template <class Msg>
  void hold(Service service, const ReplyAddress& to, const Msg& msg, std::string what) {
    hold_sample(service, to, encode_reply(msg, to.mapping, to.header), std::move(what));
  }

  // A request that cannot be decoded: logged once per client, never answered (without its
  // goal id there is nothing to answer, as in rcl_action).
  void refuse(const ReplyAddress& from, const char* service, const std::string& problem) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (warned_.size() >= 1000 || !warned_.insert(from.prefix).second) return;
    }
    spdlog::warn("{}: a {} request from participant {} dropped: {} (mapping {})", self_.ros_name_,
                 service, hex(from.prefix), problem, to_string(from.mapping));
  }

  template <class T>
  void on_send_goal(RawSample&& raw, const dds::SampleInfo& info) {
    ReplyAddress from = address_of(info);
    typename T::SendGoalRequest request;
    if (self_.kind_ == ActionKind::kComputePathThroughPoses)
      if (std::string problem = announced_poses_problem(raw, from.mapping); !problem.empty())
        return refuse(from, "send_goal", problem);
    if (std::string problem = decode_request(raw, from.mapping, request, from.header);
        !problem.empty())
      return refuse(from, "send_goal", problem);
    raw = RawSample();  // a ThroughPoses goal may be megabytes: the decoded copy is enough
    ActionGoal goal;
    goal.id = request.goal_id().uuid();
    goal.goals = T::goals(request);
    goal.start = std::move(request.goal().start());
    goal.use_start = request.goal().use_start();
    goal.planner_id = std::move(request.goal().planner_id());
    goal.identity = identity_of(info, wire::SUBJECT_REQUEST);
    const TimeMsg stamp = hooks_.now();
    bool accepted = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      accepted = goals_.accept(goal.id, GoalStamp{stamp.sec(), stamp.nanosec()});
      typename T::SendGoalResponse response;
      response.accepted(accepted);
      response.stamp(stamp);
      hold(kSendGoal, from, response, "the send_goal reply of goal " + uuid_text(goal.id));
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

  template <class T>
  void on_get_result(RawSample&& raw, const dds::SampleInfo& info) {
    ReplyAddress from = address_of(info);
    typename T::GetResultRequest request;
    if (std::string problem = decode_request(raw, from.mapping, request, from.header);
        !problem.empty())
      return refuse(from, "get_result", problem);
    const GoalUuid id = request.goal_id().uuid();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto answer = goals_.result_or_wait(id, from);
      if (!answer) return;  // answered when the goal finishes
      const std::string what = "the result of goal " + uuid_text(id);
      if (answer->result) {
        hold_result(from, answer->result, what);
      } else {  // a goal never seen, or forgotten: UNKNOWN with an empty result
        hold(kGetResult, from, result_response<T>(GoalState::kUnknown, ActionOutcome{}), what);
      }
    }
    cv_.notify_all();
  }

  void on_cancel(RawSample&& raw, const dds::SampleInfo& info) {
    ReplyAddress from = address_of(info);
    CancelRequest request;
    if (std::string problem = decode_request(raw, from.mapping, request, from.header);
        !problem.empty())
      return refuse(from, "cancel_goal", problem);
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
      hold(kCancel, from, response, "a cancel_goal reply");
      status_dirty_ = status_dirty_ || !canceling.empty();
    }
    cv_.notify_all();
    if (!canceling.empty()) hooks_.on_cancel(self_, canceling);
  }

  template <class T>
  typename T::GetResultResponse result_response(GoalState state, const ActionOutcome& outcome) {
    typename T::GetResultResponse response;
    response.status(static_cast<int8_t>(state));
    auto& result = response.result();
    result.path(outcome.path);
    const double seconds = std::max(0.0, outcome.planning_time_s);
    const auto whole = static_cast<int32_t>(std::min(seconds, 2147483647.0));
    result.planning_time().sec(whole);
    result.planning_time().nanosec(
        static_cast<uint32_t>(std::min(999999999.0, std::round((seconds - whole) * 1e9))));
    result.error_code(outcome.error_code);
    result.error_msg(outcome.error_msg);
    return response;
  }
  // The goal's get_result message, encoded once for every requester.
  EncodedResult encode_result(GoalState state, const ActionOutcome& outcome) {
    if (self_.kind_ == ActionKind::kComputePathToPose)
      return encode_message(result_response<ToPoseTypes>(state, outcome));
    return encode_message(result_response<ThroughPosesTypes>(state, outcome));
  }
  void hold_result(const ReplyAddress& to, const EncodedResult& result, std::string what) {
    hold_sample(kGetResult, to, reply_with_message(result, to.mapping, to.header), std::move(what));
  }

  template <class T>
  core::Status create(Participant& participant,
                      std::vector<std::unique_ptr<TakingListener>>& listeners,
                      std::vector<std::pair<TakingListener*, dds::DataReader*>>& inputs) {
    // Writers first, so that every request read can be answered.
    auto reply_writer = [&](auto type, Service service, bool large) -> core::Status {
      matched_[service] = std::make_unique<MatchedReaders>(mutex_, cv_, gates_[service]);
      auto writer = participant.writer_on<RawOf<typename decltype(type)::type>>(
          topic(kServiceNames[service], false), reply_writer_qos(kReplyHistory, large),
          matched_[service].get());
      if (!writer) return writer.error();
      reply_writers_[service] = *writer;
      return core::Status::ok();
    };
    if (auto s = reply_writer(Tag<typename T::SendGoalResponseType>(), kSendGoal, false);
        !s.is_ok())
      return s;
    if (auto s = reply_writer(Tag<typename T::GetResultResponseType>(), kGetResult, true);
        !s.is_ok())
      return s;
    if (auto s = reply_writer(Tag<action_msgs::srv::dds_::CancelGoal_Response_PubSubType>(),
                              kCancel, false);
        !s.is_ok())
      return s;
    auto status = participant.writer_on<action_msgs::msg::dds_::GoalStatusArray_PubSubType>(
        "rt" + self_.ros_name_ + "/_action/status", writer_qos(TopicQos::kLatched, false));
    if (!status) return status.error();
    status_writer_ = *status;
    auto feedback = participant.writer_on<typename T::FeedbackMessageType>(
        "rt" + self_.ros_name_ + "/_action/feedback", writer_qos(TopicQos::kLatest, false));
    if (!feedback) return feedback.error();
    feedback_writer_ = *feedback;

    auto add_reader = [&](auto type, Service service,
                          std::unique_ptr<TakingListener> listener) -> core::Status {
      listeners.push_back(std::move(listener));
      auto reader = participant.reader_on<RawOf<typename decltype(type)::type>>(
          topic(kServiceNames[service], true), reader_qos(TopicQos::kEvents),
          listeners.back().get());
      if (!reader) return reader.error();
      if (service == kSendGoal) inputs.emplace_back(listeners.back().get(), *reader);
      return core::Status::ok();
    };
    // Goals are taken by the node's intake thread, as requests are (bounded by the robot's
    // answers owed); results and cancels are cheap and taken as they come.
    if (auto s = add_reader(Tag<typename T::SendGoalRequestType>(), kSendGoal,
                            make_intake_listener<RawSample>(
                                [this](RawSample&& raw, const dds::SampleInfo& info) {
                                  on_send_goal<T>(std::move(raw), info);
                                },
                                hooks_.may_take, hooks_.wake_intake));
        !s.is_ok())
      return s;
    if (auto s = add_reader(
            Tag<typename T::GetResultRequestType>(), kGetResult,
            make_listener<RawSample>([this](RawSample&& raw, const dds::SampleInfo& info) {
              on_get_result<T>(std::move(raw), info);
            }));
        !s.is_ok())
      return s;
    return add_reader(
        Tag<action_msgs::srv::dds_::CancelGoal_Request_PubSubType>(), kCancel,
        make_listener<RawSample>([this](RawSample&& raw, const dds::SampleInfo& info) {
          on_cancel(std::move(raw), info);
        }));
  }

  template <class U>
  struct Tag {
    using type = U;
  };
};

ActionServer::ActionServer(ActionKind kind, std::string ros_name, const NodeConfig& config,
                           const ParticipantWatch* vendors, std::mutex& reply_mutex,
                           std::condition_variable& reply_cv, Hooks hooks)
    : kind_(kind), ros_name_(std::move(ros_name)) {
  impl_ = std::make_unique<Impl>(*this, config, vendors, reply_mutex, reply_cv, std::move(hooks));
}

ActionServer::~ActionServer() = default;

core::Status ActionServer::create(
    Participant& participant, std::vector<std::unique_ptr<TakingListener>>& listeners,
    std::vector<std::pair<TakingListener*, dds::DataReader*>>& inputs) {
  return kind_ == ActionKind::kComputePathToPose
             ? impl_->create<ToPoseTypes>(participant, listeners, inputs)
             : impl_->create<ThroughPosesTypes>(participant, listeners, inputs);
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
  const auto release_at = all ? ReplyGate<Reply>::Clock::time_point::max() : now;
  while (!impl_->unwritten_.empty()) {
    out.replies.push_back(std::move(impl_->unwritten_.front()));
    impl_->unwritten_.pop_front();
  }
  for (size_t s = 0; s < impl_->gates_.size(); ++s) {
    bool heartbeat = false;
    for (Reply& reply : impl_->gates_[s].release(release_at, nullptr, &heartbeat))
      out.replies.push_back(std::move(reply));
    if (heartbeat && impl_->reply_writers_[s] != nullptr)
      out.heartbeats.push_back(impl_->reply_writers_[s]);
  }
  for (const ReplyFlow& flow : impl_->flows_)
    if (const auto next = flow.next_check(!impl_->unwritten_.empty()); next && now >= *next)
      out.check_flows = true;
  if (impl_->goals_.expire(now) > 0) impl_->status_dirty_ = true;
  // The list holds every goal not finished and the last actions.status_finished_goals that
  // finished: under a burst of goals, one list per kStatusPeriod carries every change since the
  // last.
  if (!impl_->status_dirty_ || (!all && now < impl_->last_status_ + kStatusPeriod)) return;
  impl_->status_dirty_ = false;
  impl_->last_status_ = now;
  GoalStatusArrayMsg msg;
  for (const auto& entry :
       impl_->goals_.statuses(static_cast<size_t>(impl_->cfg_.actions.status_finished_goals))) {
    action_msgs::msg::dds_::GoalStatus_ status;
    status.goal_info().goal_id().uuid(entry.id);
    status.goal_info().stamp().sec(entry.stamp.sec);
    status.goal_info().stamp().nanosec(entry.stamp.nanosec);
    status.status(static_cast<int8_t>(entry.state));
    msg.status_list().push_back(status);
  }
  out.status = std::move(msg);
}

bool ActionServer::write(Due& due, bool stopping, bool give_up) {
  Impl& impl = *impl_;
  const Clock::time_point now = Clock::now();
  // A writer whose readers have acknowledged every reply written opens its window again; one
  // whose window waited reply_ack_timeout names the clients of the replies in it, once.
  for (int s = 0; s < 3; ++s) {
    ReplyFlow& flow = impl.flows_[s];
    dds::DataWriter* writer = impl.reply_writers_[s];
    if (writer == nullptr || flow.unacknowledged_bytes() == 0) continue;
    if (writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0, 0)) ==
        ReturnCode_t::RETCODE_OK) {
      flow.all_acknowledged();
    } else if (const auto clients = flow.stalled(now)) {
      std::string names;
      for (size_t i = 0; i < clients->size() && i < 3; ++i)
        names += (i ? ", " : "") + hex((*clients)[i].first) + " (" +
                 std::to_string((*clients)[i].second) + ")";
      if (clients->size() > 3) names += " and more";
      // DDS does not say which reader lags: every participant with a reader on this topic.
      std::vector<GuidPrefix> readers;
      {
        std::lock_guard<std::mutex> lock(impl.mutex_);
        readers = impl.gates_[s].matched_participants();
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
          ros_name_, Impl::kServiceNames[s],
          static_cast<double>(impl.cfg_.actions.reply_ack_timeout.count()) / 1000.0, names,
          readers_text);
    }
  }
  // A heartbeat that does not count these replies first, as the node does before statuses
  // (replier_loop): Cyclone DDS's volatile reader skips everything up to the last sequence
  // number of the first heartbeat it accepts from a writer, and a client that discovered the
  // reply writer after the node matched its reader missed the earlier heartbeats. An 885 kB
  // result (14 fragments) was lost so in 7 of 15 runs of the Cyclone client's cancel test.
  // Not enough alone when the heartbeat goes to a multicast group and Fast DDS sends the reply's
  // own heartbeat to the client's unicast locator (reply_gate.hpp): the gate's heartbeats
  // (`due.heartbeats`) go out a settle ahead of such a reply.
  std::set<dds::DataWriter*> asserted;
  for (dds::DataWriter* writer : due.heartbeats)
    if (asserted.insert(writer).second) writer->assert_liveliness();
  for (const Reply& reply : due.replies)
    if (reply.writer != nullptr && asserted.insert(reply.writer).second)
      reply.writer->assert_liveliness();
  // In order per service: a reply that must wait keeps every later one of its service waiting.
  std::array<bool, 3> waiting{};
  std::array<std::map<GuidPrefix, size_t>, 3> done;  // replies written or given up, per client
  std::deque<Reply> keep;
  for (Reply& reply : due.replies) {
    const int s = reply.service;
    if (reply.writer == nullptr) {
      ++done[s][reply.client];
      continue;
    }
    ReplyFlow& flow = impl.flows_[s];
    const size_t bytes = reply.sample.size();
    if (!waiting[s] && !stopping) {
      const ReplyFlow::Step step = flow.next(bytes, now);
      if (step == ReplyFlow::Step::kWait) waiting[s] = true;
      if (step == ReplyFlow::Step::kClearHistory) {
        size_t removed = 0;
        reply.writer->clear_history(&removed);
        flow.history_cleared();
        spdlog::warn(
            "{}: {} replies a reader has not acknowledged for actions.reply_ack_timeout "
            "dropped from the writer's history ({} of them)",
            ros_name_, Impl::kServiceNames[s], removed);
      }
    }
    if (!waiting[s]) {
      eprosima::fastrtps::rtps::WriteParams params;
      if (reply.related) params.related_sample_identity(*reply.related);
      if (write_sample(reply.writer, &reply.sample, params)) {
        flow.written(reply.client, bytes, now);
        ++done[s][reply.client];
        continue;
      }
      waiting[s] = true;  // refused: tried again on the next pass
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
    impl.unwritten_.push_front(std::move(keep.back()));
    keep.pop_back();
  }
  if (due.status && impl.status_writer_ != nullptr && !impl.status_writer_->write(&*due.status))
    spdlog::error("{}: could not publish the goal status list", ros_name_);
  {
    std::lock_guard<std::mutex> lock(impl.mutex_);
    for (int s = 0; s < 3; ++s)
      for (const auto& [client, count] : done[s]) {
        auto it = impl.pending_[s].find(client);
        if (it == impl.pending_[s].end()) continue;
        it->second -= std::min(it->second, count);
        if (it->second == 0) impl.pending_[s].erase(it);
      }
  }
  return impl.unwritten_.empty();
}

std::optional<ActionServer::Clock::time_point> ActionServer::next_deadline() const {
  std::optional<Clock::time_point> earliest = impl_->goals_.next_expiry();
  // The flows' next look (the acknowledgements themselves are looked for every few milliseconds
  // by the replier while replies wait).
  for (const ReplyFlow& flow : impl_->flows_)
    if (auto next = flow.next_check(!impl_->unwritten_.empty());
        next && (!earliest || *next < *earliest))
      earliest = next;
  if (impl_->status_dirty_) {
    const Clock::time_point list_due = impl_->last_status_ + kStatusPeriod;
    if (!earliest || list_due < *earliest) earliest = list_due;
  }
  for (const auto& gate : impl_->gates_)
    if (auto next = gate.next_deadline(); next && (!earliest || *next < *earliest)) earliest = next;
  return earliest;
}

std::array<dds::DataWriter*, 3> ActionServer::reply_writers() const {
  return impl_->reply_writers_;
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
