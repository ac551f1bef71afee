#include "vnsba/node/action_client.hpp"

#include <fastdds/rtps/common/WriteParams.h>

#include <condition_variable>
#include <cstring>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <thread>

#include "action_server.hpp"
#include "action_types.hpp"

namespace vnsba::node {

namespace {

using eprosima::fastrtps::rtps::GUID_t;
using eprosima::fastrtps::rtps::SampleIdentity;

enum Service { kSendGoal = 0, kGetResult = 1, kCancel = 2 };
constexpr const char* kServiceNames[3] = {"send_goal", "get_result", "cancel_goal"};

int64_t sequence_of(const SampleIdentity& identity) {
  return (static_cast<int64_t>(identity.sequence_number().high) << 32) |
         identity.sequence_number().low;
}

}  // namespace

class ActionClient::Impl {
 public:
  ActionKind kind;
  std::string name;
  WireMapping mapping;
  std::array<dds::DataWriter*, 3> request_writers{};
  std::array<dds::DataReader*, 3> reply_readers{};
  dds::DataReader* status_reader = nullptr;
  dds::DataReader* feedback_reader = nullptr;
  std::vector<std::unique_ptr<dds::DataReaderListener>> listeners;
  uint64_t client_id = 0;  // rmw_cyclonedds's header: the client's id
  mutable std::mutex mutex;
  mutable std::condition_variable cv;
  int64_t next_sequence = 0;                            // header mapping, under mutex
  std::array<std::map<int64_t, RawSample>, 3> replies;  // by request sequence, under mutex
  std::map<GoalUuid, GoalState> statuses;               // newest status list, under mutex
  size_t unmatched = 0;                                 // under mutex
  size_t duplicates = 0;                                // under mutex
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t>
      servers;                                // participants that replied, under mutex
  std::array<std::set<int64_t>, 3> answered;  // sequences replied to, under mutex

  // Takes the replies of one service; keeps those that answer this client's requests.
  void on_reply(Service service, RawSample&& raw, const dds::SampleInfo& info) {
    int64_t sequence = -1;
    if (mapping == WireMapping::kSampleIdentity) {
      const GUID_t ours = reply_readers[service]->guid();
      if (info.related_sample_identity.writer_guid() == ours)
        sequence = sequence_of(info.related_sample_identity);
    } else if (raw.bytes.size() >= 20) {
      uint64_t id = 0;
      std::memcpy(&id, raw.bytes.data() + 4, sizeof id);  // little-endian, as encoded
      if (id == client_id) std::memcpy(&sequence, raw.bytes.data() + 12, sizeof sequence);
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (sequence >= 0) servers.insert(info.sample_identity.writer_guid().guidPrefix);
      if (sequence < 0)
        ++unmatched;
      else if (!answered[service].insert(sequence).second)
        ++duplicates;
      else
        replies[service][sequence] = std::move(raw);
    }
    cv.notify_all();
  }

  template <class Msg>
  int64_t request(Service service, const Msg& msg) {
    RequestHeader header{};
    int64_t sequence = 0;
    if (mapping == WireMapping::kRequestHeader) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        sequence = ++next_sequence;
      }
      std::memcpy(header.data(), &client_id, 8);
      std::memcpy(header.data() + 8, &sequence, 8);
    }
    RawSample sample = encode_request(msg, mapping, header);
    eprosima::fastrtps::rtps::WriteParams params;
    // As rmw_fastrtps: the request names the client's reply reader (rmw_cyclonedds does not).
    if (mapping == WireMapping::kSampleIdentity)
      params.related_sample_identity().writer_guid() = reply_readers[service]->guid();
    if (!write_sample(request_writers[service], &sample, params)) return -1;
    return mapping == WireMapping::kRequestHeader ? sequence
                                                  : sequence_of(params.sample_identity());
  }

  // The reply to `request`, decoded as Msg, or nullopt when none came in time.
  template <class Msg>
  std::optional<Msg> wait(Service service, int64_t request, Duration timeout) {
    if (request < 0) return std::nullopt;
    std::unique_lock<std::mutex> lock(mutex);
    if (!cv.wait_for(lock, timeout, [&] { return replies[service].count(request) > 0; }))
      return std::nullopt;
    RawSample raw = std::move(replies[service][request]);
    replies[service].erase(request);
    lock.unlock();
    Msg msg;
    RequestHeader header;
    if (!decode_reply(raw, mapping, msg, header).empty()) return std::nullopt;
    return msg;
  }

  template <class T>
  core::Status create(Participant& participant) {
    auto topic = [&](Service s, bool request) {
      return std::string(request ? "rq" : "rr") + name + "/_action/" + kServiceNames[s] +
             (request ? "Request" : "Reply");
    };
    // Readers first: a request names its reply reader.
    auto add_reply_reader = [&](auto type, Service service) -> core::Status {
      listeners.push_back(
          make_listener<RawSample>([this, service](RawSample&& raw, const dds::SampleInfo& info) {
            on_reply(service, std::move(raw), info);
          }));
      auto reader = participant.reader_on<RawOf<typename decltype(type)::type>>(
          topic(service, false), reader_qos(TopicQos::kStatus), listeners.back().get());
      if (!reader) return reader.error();
      reply_readers[service] = *reader;
      return core::Status::ok();
    };
    if (auto s = add_reply_reader(Tag<typename T::SendGoalResponseType>(), kSendGoal); !s.is_ok())
      return s;
    if (auto s = add_reply_reader(Tag<typename T::GetResultResponseType>(), kGetResult); !s.is_ok())
      return s;
    if (auto s = add_reply_reader(Tag<action_msgs::srv::dds_::CancelGoal_Response_PubSubType>(),
                                  kCancel);
        !s.is_ok())
      return s;
    listeners.push_back(make_listener<GoalStatusArrayMsg>([this](GoalStatusArrayMsg&& msg,
                                                                 const dds::SampleInfo&) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        statuses.clear();
        for (const auto& status : msg.status_list())
          statuses[status.goal_info().goal_id().uuid()] = static_cast<GoalState>(status.status());
      }
      cv.notify_all();
    }));
    auto status = participant.reader_on<action_msgs::msg::dds_::GoalStatusArray_PubSubType>(
        "rt" + name + "/_action/status", reader_qos(TopicQos::kLatched), listeners.back().get());
    if (!status) return status.error();
    status_reader = *status;
    auto feedback = participant.reader_on<typename T::FeedbackMessageType>(
        "rt" + name + "/_action/feedback", reader_qos(TopicQos::kLatest), nullptr);
    if (!feedback) return feedback.error();
    feedback_reader = *feedback;
    auto add_request_writer = [&](auto type, Service service) -> core::Status {
      auto writer = participant.writer_on<RawOf<typename decltype(type)::type>>(
          topic(service, true), writer_qos(TopicQos::kEvents, service == kSendGoal));
      if (!writer) return writer.error();
      request_writers[service] = *writer;
      return core::Status::ok();
    };
    if (auto s = add_request_writer(Tag<typename T::SendGoalRequestType>(), kSendGoal); !s.is_ok())
      return s;
    if (auto s = add_request_writer(Tag<typename T::GetResultRequestType>(), kGetResult);
        !s.is_ok())
      return s;
    return add_request_writer(Tag<action_msgs::srv::dds_::CancelGoal_Request_PubSubType>(),
                              kCancel);
  }

  template <class T>
  int64_t send_goal(const GoalUuid& id, const ActionGoalSpec& spec) {
    typename T::SendGoalRequest request;
    request.goal_id().uuid(id);
    T::set_goals(request, spec.goals);
    request.goal().start(spec.start);
    request.goal().planner_id(spec.planner_id);
    request.goal().use_start(spec.use_start);
    return this->request(kSendGoal, request);
  }
  template <class T>
  std::optional<bool> wait_accepted(int64_t request, Duration timeout) {
    auto reply = wait<typename T::SendGoalResponse>(kSendGoal, request, timeout);
    if (!reply) return std::nullopt;
    return reply->accepted();
  }
  template <class T>
  int64_t request_result(const GoalUuid& id) {
    typename T::GetResultRequest request;
    request.goal_id().uuid(id);
    return this->request(kGetResult, request);
  }
  template <class T>
  std::optional<ActionResultReply> wait_result(int64_t request, Duration timeout) {
    auto reply = wait<typename T::GetResultResponse>(kGetResult, request, timeout);
    if (!reply) return std::nullopt;
    ActionResultReply out;
    out.status = static_cast<GoalState>(reply->status());
    out.path = std::move(reply->result().path());
    out.planning_time_s =
        reply->result().planning_time().sec() + reply->result().planning_time().nanosec() * 1e-9;
    out.error_code = reply->result().error_code();
    out.error_msg = std::move(reply->result().error_msg());
    return out;
  }

  template <class U>
  struct Tag {
    using type = U;
  };
};

ActionClient::ActionClient() : impl_(std::make_unique<Impl>()) {}

// The client's endpoints go before its listeners: the participant outlives the client, and a
// reader deleted later would call a listener already freed.
ActionClient::~ActionClient() {
  for (dds::DataReader* reader : impl_->reply_readers)
    if (reader != nullptr)
      const_cast<dds::Subscriber*>(reader->get_subscriber())->delete_datareader(reader);
  for (dds::DataReader* reader : {impl_->status_reader, impl_->feedback_reader})
    if (reader != nullptr)
      const_cast<dds::Subscriber*>(reader->get_subscriber())->delete_datareader(reader);
  for (dds::DataWriter* writer : impl_->request_writers)
    if (writer != nullptr)
      const_cast<dds::Publisher*>(writer->get_publisher())->delete_datawriter(writer);
}

GoalUuid ActionClient::random_id() {
  static thread_local std::mt19937_64 engine{std::random_device{}()};
  GoalUuid id;
  for (size_t i = 0; i < id.size(); i += 8) {
    const uint64_t r = engine();
    std::memcpy(id.data() + i, &r, 8);
  }
  return id;
}

core::Expected<std::unique_ptr<ActionClient>> ActionClient::create(Participant& participant,
                                                                   const std::string& ros_name,
                                                                   ActionKind kind,
                                                                   WireMapping mapping) {
  std::unique_ptr<ActionClient> client(new ActionClient());
  Impl& impl = *client->impl_;
  impl.kind = kind;
  impl.name = ros_name;
  impl.mapping = mapping;
  std::mt19937_64 engine{std::random_device{}()};
  impl.client_id = engine();
  const core::Status status = kind == ActionKind::kComputePathToPose
                                  ? impl.create<ToPoseTypes>(participant)
                                  : impl.create<ThroughPosesTypes>(participant);
  if (!status.is_ok()) return status;
  return client;
}

bool ActionClient::wait_for_server(Duration timeout, int servers) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  auto ready = [&] {
    for (dds::DataWriter* writer : impl_->request_writers)
      if (matched_readers(writer) < servers) return false;
    for (dds::DataReader* reader : impl_->reply_readers) {
      dds::SubscriptionMatchedStatus matched;
      if (reader->get_subscription_matched_status(matched) != ReturnCode_t::RETCODE_OK ||
          matched.current_count < servers)
        return false;
    }
    for (dds::DataReader* reader : {impl_->status_reader, impl_->feedback_reader}) {
      dds::SubscriptionMatchedStatus matched;
      if (reader->get_subscription_matched_status(matched) != ReturnCode_t::RETCODE_OK ||
          matched.current_count < servers)
        return false;
    }
    return true;
  };
  while (!ready()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

int64_t ActionClient::send_goal(const GoalUuid& id, const ActionGoalSpec& goal) {
  return impl_->kind == ActionKind::kComputePathToPose
             ? impl_->send_goal<ToPoseTypes>(id, goal)
             : impl_->send_goal<ThroughPosesTypes>(id, goal);
}
std::optional<bool> ActionClient::wait_accepted(int64_t request, Duration timeout) {
  return impl_->kind == ActionKind::kComputePathToPose
             ? impl_->wait_accepted<ToPoseTypes>(request, timeout)
             : impl_->wait_accepted<ThroughPosesTypes>(request, timeout);
}
int64_t ActionClient::request_result(const GoalUuid& id) {
  return impl_->kind == ActionKind::kComputePathToPose
             ? impl_->request_result<ToPoseTypes>(id)
             : impl_->request_result<ThroughPosesTypes>(id);
}
std::optional<ActionResultReply> ActionClient::wait_result(int64_t request, Duration timeout) {
  return impl_->kind == ActionKind::kComputePathToPose
             ? impl_->wait_result<ToPoseTypes>(request, timeout)
             : impl_->wait_result<ThroughPosesTypes>(request, timeout);
}
int64_t ActionClient::request_cancel(const GoalUuid& id, const GoalStamp& stamp) {
  action_msgs::srv::dds_::CancelGoal_Request_ request;
  request.goal_info().goal_id().uuid(id);
  request.goal_info().stamp().sec(stamp.sec);
  request.goal_info().stamp().nanosec(stamp.nanosec);
  return impl_->request(kCancel, request);
}
std::optional<CancelReply> ActionClient::wait_cancel(int64_t request, Duration timeout) {
  auto reply = impl_->wait<action_msgs::srv::dds_::CancelGoal_Response_>(kCancel, request, timeout);
  if (!reply) return std::nullopt;
  CancelReply out;
  out.code = static_cast<CancelCode>(reply->return_code());
  for (const auto& info : reply->goals_canceling()) out.canceling.push_back(info.goal_id().uuid());
  return out;
}

std::optional<ActionResultReply> ActionClient::plan(const GoalUuid& id, const ActionGoalSpec& goal,
                                                    Duration timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  auto left = [&] {
    return std::chrono::duration_cast<Duration>(std::max(
        std::chrono::steady_clock::duration::zero(), deadline - std::chrono::steady_clock::now()));
  };
  const auto accepted = wait_accepted(send_goal(id, goal), left());
  if (!accepted) return std::nullopt;
  if (!*accepted) {
    ActionResultReply rejected;
    rejected.error_msg = "rejected";
    return rejected;
  }
  return wait_result(request_result(id), left());
}

GoalState ActionClient::status_of(const GoalUuid& id) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  const auto it = impl_->statuses.find(id);
  return it == impl_->statuses.end() ? GoalState::kUnknown : it->second;
}

size_t ActionClient::status_list_size() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->statuses.size();
}

bool ActionClient::wait_status(const GoalUuid& id, GoalState state, Duration timeout) const {
  std::unique_lock<std::mutex> lock(impl_->mutex);
  return impl_->cv.wait_for(lock, timeout, [&] {
    const auto it = impl_->statuses.find(id);
    return it != impl_->statuses.end() && it->second == state;
  });
}

size_t ActionClient::unmatched_replies() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->unmatched;
}

void ActionClient::send_raw(ActionService service, const RawSample& payload) {
  RawSample copy = payload;
  write_sample(impl_->request_writers[static_cast<size_t>(service)], &copy);
}

size_t ActionClient::duplicate_replies() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->duplicates;
}

size_t ActionClient::servers_seen() const {
  size_t matched = 0;
  dds::SubscriptionMatchedStatus status;
  if (impl_->reply_readers[kSendGoal]->get_subscription_matched_status(status) ==
      ReturnCode_t::RETCODE_OK)
    matched = static_cast<size_t>(std::max(status.current_count, 0));
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return std::max(matched, impl_->servers.size());
}

}  // namespace vnsba::node
