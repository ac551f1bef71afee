#include "action_server.hpp"

#include <fastdds/rtps/common/WriteParams.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>
#include <set>

#include "action_traits.hpp"
#include "vnsba/node/raw_type.hpp"

namespace vnsba::node {

namespace {

// A finished goal's get_result reply message (status and result), encoded once.
using EncodedResult = std::shared_ptr<const std::vector<uint8_t>>;

// The replies of an action's three services on their way to the clients, one ServiceReplies
// each (service_server.hpp: the reply gate, the per-client cap, the flow), by ActionService.
class ActionReplies {
 public:
  using Clock = ActionServer::Clock;
  using Done = std::array<ServiceReplies::Done, kActionServices>;

  ActionReplies(const std::string& ros_name, const NodeConfig& config, std::mutex& mutex,
                std::condition_variable& cv)
      : ros_name_(ros_name),
        services_{
            ServiceReplies(ros_name, service_name(ActionService::kSendGoal), config, mutex, cv),
            ServiceReplies(ros_name, service_name(ActionService::kGetResult), config, mutex, cv),
            ServiceReplies(ros_name, service_name(ActionService::kCancelGoal), config, mutex, cv)} {
  }

  // The service's reply writer on `participant`, of ReplyType's DDS type (`large`: results).
  template <class ReplyType>
  core::Status create_writer(Participant& participant, ActionService service, bool large) {
    return at(service).create_writer<ReplyType>(participant,
                                                service_topic(ros_name_, service, false), large);
  }
  void hold(ActionService service, const ReplyAddress& to, RawSample sample, std::string what) {
    at(service).hold(to, std::move(sample), std::move(what));
  }
  void take_due(Clock::time_point now, bool all, ActionServer::Due& out) {
    for (size_t s = 0; s < kActionServices; ++s) services_[s].take_due(now, all, out.services[s]);
  }
  Done write_replies(ActionServer::Due& due, bool stopping, bool give_up) {
    Done done;
    for (size_t s = 0; s < kActionServices; ++s)
      done[s] = services_[s].write(due.services[s], stopping, give_up);
    return done;
  }
  void release_pending(const Done& done) {
    for (size_t s = 0; s < kActionServices; ++s) services_[s].release_pending(done[s]);
  }
  bool all_written() const {
    return std::all_of(services_.begin(), services_.end(),
                       [](const ServiceReplies& service) { return service.all_written(); });
  }
  void next_deadline(std::optional<Clock::time_point>& earliest) const {
    for (const ServiceReplies& service : services_) service.next_deadline(earliest);
  }
  std::array<dds::DataWriter*, kActionServices> writers() const {
    std::array<dds::DataWriter*, kActionServices> out{};
    for (size_t s = 0; s < kActionServices; ++s) out[s] = services_[s].writer();
    return out;
  }

 private:
  ServiceReplies& at(ActionService service) { return services_[static_cast<size_t>(service)]; }

  const std::string& ros_name_;
  std::array<ServiceReplies, kActionServices> services_;
};

}  // namespace

std::string announced_poses_problem(const RawSample& raw, WireMapping mapping, bool after_a_header,
                                    size_t leading_bytes, const char* list) {
  // Offsets in bytes from the sample's start: the 4-byte encapsulation, the request header,
  // the leading bytes (a goal id); CDR aligns from the end of the encapsulation.
  size_t at = 4 + (mapping == WireMapping::kRequestHeader ? 16 : 0) + leading_bytes;
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
  return std::string(list) + ": announces " + std::to_string(count) + " poses in " +
         std::to_string(raw.bytes.size()) + " bytes (at most " + std::to_string(room) + " fit)";
}

std::string uuid_text(const GoalUuid& id) {
  return hex_text(id);
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
  RefusedRequests refused_;          // undecodable requests, logged once per client

  ReplyAddress address_of(const dds::SampleInfo& info) const {
    return reply_address(info, cfg_.actions.reply_mapping, vendors_);
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
    refused_.refuse(self_.ros_name_, service_name(service), from, problem);
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
    const bool inactive = hooks_.accepting && !hooks_.accepting();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      accepted = !inactive && goals_.accept(goal.id, GoalStamp{stamp.sec(), stamp.nanosec()});
      typename Wire::SendGoalResponse response;
      response.accepted(accepted);
      response.stamp(stamp);
      hold(ActionService::kSendGoal, from, response,
           "the send_goal reply of goal " + uuid_text(goal.id));
      status_dirty_ = status_dirty_ || accepted;
    }
    cv_.notify_all();
    if (!accepted) {
      spdlog::warn("{}: goal {} rejected: {}", self_.ros_name_, uuid_text(goal.id),
                   inactive ? "the node is inactive (lifecycle: activate it with change_state)"
                            : "a goal with this id is running or its result is kept");
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
    return with_wire<Traits>(config.ros_distro, [&](auto wire) -> std::unique_ptr<Impl> {
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
  const ActionReplies::Done done = impl_->replies_.write_replies(due, stopping, give_up);
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
