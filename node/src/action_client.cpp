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

#include "action_raw_type.hpp"
#include "action_traits.hpp"
#include "take_listener.hpp"

namespace vnsba::node {

namespace {

using eprosima::fastrtps::rtps::GUID_t;
using eprosima::fastrtps::rtps::SampleIdentity;

int64_t sequence_of(const SampleIdentity& identity) {
  return (static_cast<int64_t>(identity.sequence_number().high) << 32) |
         identity.sequence_number().low;
}

}  // namespace

class ActionClient::Impl {
 public:
  virtual ~Impl() = default;

  // The action's own part (ImplOf): its endpoints, its goal and its result.
  virtual core::Status create(Participant& participant) = 0;
  virtual int64_t send_goal(const GoalUuid& id, const ActionGoalSpec& spec) = 0;
  virtual std::optional<bool> wait_accepted(int64_t request, Duration timeout) = 0;
  virtual int64_t request_result(const GoalUuid& id) = 0;
  virtual std::optional<ActionResultReply> wait_result(int64_t request, Duration timeout) = 0;

  std::string name;
  WireMapping mapping = WireMapping::kSampleIdentity;
  std::array<dds::DataWriter*, kActionServices> request_writers{};
  std::array<dds::DataReader*, kActionServices> reply_readers{};
  dds::DataReader* status_reader = nullptr;
  dds::DataReader* feedback_reader = nullptr;
  std::vector<std::unique_ptr<dds::DataReaderListener>> listeners;
  uint64_t client_id = 0;  // rmw_cyclonedds's header: the client's id
  mutable std::mutex mutex;
  mutable std::condition_variable cv;
  int64_t next_sequence = 0;  // header mapping, under mutex
  // By request sequence, under mutex.
  std::array<std::map<int64_t, RawSample>, kActionServices> replies;
  std::map<GoalUuid, GoalState> statuses;  // newest status list, under mutex
  size_t unmatched = 0;                    // under mutex
  size_t duplicates = 0;                   // under mutex
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t>
      servers;  // participants that replied, under mutex
  std::array<std::set<int64_t>, kActionServices> answered;  // sequences replied to, under mutex

  // Takes the replies of one service; keeps those that answer this client's requests.
  void on_reply(ActionService service, RawSample&& raw, const dds::SampleInfo& info) {
    const size_t s = static_cast<size_t>(service);
    int64_t sequence = -1;
    if (mapping == WireMapping::kSampleIdentity) {
      const GUID_t ours = reply_readers[s]->guid();
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
      else if (!answered[s].insert(sequence).second)
        ++duplicates;
      else
        replies[s][sequence] = std::move(raw);
    }
    cv.notify_all();
  }

  template <class Msg>
  int64_t request(ActionService service, const Msg& msg) {
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
    const size_t s = static_cast<size_t>(service);
    // As rmw_fastrtps: the request names the client's reply reader (rmw_cyclonedds does not).
    if (mapping == WireMapping::kSampleIdentity)
      params.related_sample_identity().writer_guid() = reply_readers[s]->guid();
    if (!write_sample(request_writers[s], &sample, params)) return -1;
    return mapping == WireMapping::kRequestHeader ? sequence
                                                  : sequence_of(params.sample_identity());
  }

  // The reply to `request`, decoded as Msg, or nullopt when none came in time.
  template <class Msg>
  std::optional<Msg> wait(ActionService service, int64_t request, Duration timeout) {
    if (request < 0) return std::nullopt;
    const size_t s = static_cast<size_t>(service);
    std::unique_lock<std::mutex> lock(mutex);
    if (!cv.wait_for(lock, timeout, [&] { return replies[s].count(request) > 0; }))
      return std::nullopt;
    RawSample raw = std::move(replies[s][request]);
    replies[s].erase(request);
    lock.unlock();
    Msg msg;
    RequestHeader header;
    if (!decode_reply(raw, mapping, msg, header).empty()) return std::nullopt;
    return msg;
  }

  // The service's reply reader, of ReplyType's DDS type.
  template <class ReplyType>
  core::Status add_reply_reader(Participant& participant, ActionService service) {
    listeners.push_back(
        make_listener<RawSample>([this, service](RawSample&& raw, const dds::SampleInfo& info) {
          on_reply(service, std::move(raw), info);
        }));
    auto reader = participant.reader_on<RawOf<ReplyType>>(
        service_topic(name, service, false), reader_qos(TopicQos::kStatus), listeners.back().get());
    if (!reader) return reader.error();
    reply_readers[static_cast<size_t>(service)] = *reader;
    return core::Status::ok();
  }

  // The service's request writer, of RequestType's DDS type.
  template <class RequestType>
  core::Status add_request_writer(Participant& participant, ActionService service) {
    auto writer = participant.writer_on<RawOf<RequestType>>(
        service_topic(name, service, true),
        writer_qos(TopicQos::kEvents, service == ActionService::kSendGoal));
    if (!writer) return writer.error();
    request_writers[static_cast<size_t>(service)] = *writer;
    return core::Status::ok();
  }

  // The status reader (the newest list kept) and the feedback reader, of FeedbackType.
  template <class FeedbackType>
  core::Status add_topic_readers(Participant& participant) {
    listeners.push_back(make_listener<GoalStatusArrayMsg>(
        [this](GoalStatusArrayMsg&& msg, const dds::SampleInfo&) { on_status(msg); }));
    auto status = participant.reader_on<GoalStatusArrayType>(
        action_topic(name, "status"), reader_qos(TopicQos::kLatched), listeners.back().get());
    if (!status) return status.error();
    status_reader = *status;
    auto feedback = participant.reader_on<FeedbackType>(action_topic(name, "feedback"),
                                                        reader_qos(TopicQos::kLatest), nullptr);
    if (!feedback) return feedback.error();
    feedback_reader = *feedback;
    return core::Status::ok();
  }

  void on_status(const GoalStatusArrayMsg& msg) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      statuses.clear();
      for (const auto& status : msg.status_list())
        statuses[status.goal_info().goal_id().uuid()] = static_cast<GoalState>(status.status());
    }
    cv.notify_all();
  }
};

template <class Traits, class Wire>
class ActionClient::ImplOf final : public ActionClient::Impl {
 public:
  // Readers first: a request names its reply reader.
  core::Status create(Participant& participant) override {
    if (auto s = add_reply_readers(participant); !s.is_ok()) return s;
    if (auto s = add_topic_readers<typename Wire::FeedbackMessageType>(participant); !s.is_ok())
      return s;
    if (auto s = add_request_writer<typename Wire::SendGoalRequestType>(participant,
                                                                        ActionService::kSendGoal);
        !s.is_ok())
      return s;
    if (auto s = add_request_writer<typename Wire::GetResultRequestType>(participant,
                                                                         ActionService::kGetResult);
        !s.is_ok())
      return s;
    return add_request_writer<CancelRequestType>(participant, ActionService::kCancelGoal);
  }

  int64_t send_goal(const GoalUuid& id, const ActionGoalSpec& spec) override {
    typename Wire::SendGoalRequest request;
    request.goal_id().uuid(id);
    Traits::write_goal(spec, request.goal());
    return this->request(ActionService::kSendGoal, request);
  }
  std::optional<bool> wait_accepted(int64_t request, Duration timeout) override {
    auto reply = wait<typename Wire::SendGoalResponse>(ActionService::kSendGoal, request, timeout);
    if (!reply) return std::nullopt;
    return reply->accepted();
  }
  int64_t request_result(const GoalUuid& id) override {
    typename Wire::GetResultRequest request;
    request.goal_id().uuid(id);
    return this->request(ActionService::kGetResult, request);
  }
  std::optional<ActionResultReply> wait_result(int64_t request, Duration timeout) override {
    auto reply =
        wait<typename Wire::GetResultResponse>(ActionService::kGetResult, request, timeout);
    if (!reply) return std::nullopt;
    ActionResultReply out;
    out.status = static_cast<GoalState>(reply->status());
    Traits::read_result(std::move(reply->result()), out);
    return out;
  }

 private:
  core::Status add_reply_readers(Participant& participant) {
    if (auto s = add_reply_reader<typename Wire::SendGoalResponseType>(participant,
                                                                       ActionService::kSendGoal);
        !s.is_ok())
      return s;
    if (auto s = add_reply_reader<typename Wire::GetResultResponseType>(participant,
                                                                        ActionService::kGetResult);
        !s.is_ok())
      return s;
    return add_reply_reader<CancelResponseType>(participant, ActionService::kCancelGoal);
  }
};

ActionClient::ActionClient(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

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
                                                                   WireMapping mapping,
                                                                   RosDistro distro) {
  std::unique_ptr<ActionClient> client(
      new ActionClient(with_action_traits(kind, [&](auto traits) -> std::unique_ptr<Impl> {
        using Traits = decltype(traits);
        return with_action_wire<Traits>(distro, [](auto wire) -> std::unique_ptr<Impl> {
          return std::make_unique<ImplOf<Traits, decltype(wire)>>();
        });
      })));
  Impl& impl = *client->impl_;
  impl.name = ros_name;
  impl.mapping = mapping;
  std::mt19937_64 engine{std::random_device{}()};
  impl.client_id = engine();
  const core::Status status = impl.create(participant);
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
  return impl_->send_goal(id, goal);
}
std::optional<bool> ActionClient::wait_accepted(int64_t request, Duration timeout) {
  return impl_->wait_accepted(request, timeout);
}
int64_t ActionClient::request_result(const GoalUuid& id) {
  return impl_->request_result(id);
}
std::optional<ActionResultReply> ActionClient::wait_result(int64_t request, Duration timeout) {
  return impl_->wait_result(request, timeout);
}
int64_t ActionClient::request_cancel(const GoalUuid& id, const GoalStamp& stamp) {
  CancelRequest request;
  request.goal_info().goal_id().uuid(id);
  request.goal_info().stamp().sec(stamp.sec);
  request.goal_info().stamp().nanosec(stamp.nanosec);
  return impl_->request(ActionService::kCancelGoal, request);
}
std::optional<CancelReply> ActionClient::wait_cancel(int64_t request, Duration timeout) {
  auto reply = impl_->wait<CancelResponse>(ActionService::kCancelGoal, request, timeout);
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
  if (impl_->reply_readers[static_cast<size_t>(ActionService::kSendGoal)]
          ->get_subscription_matched_status(status) == ReturnCode_t::RETCODE_OK)
    matched = static_cast<size_t>(std::max(status.current_count, 0));
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return std::max(matched, impl_->servers.size());
}

}  // namespace vnsba::node
