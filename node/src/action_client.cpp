#include "vnsba/node/action_client.hpp"

#include <condition_variable>
#include <cstring>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <thread>

#include "action_traits.hpp"
#include "take_listener.hpp"
#include "vnsba/node/service_client.hpp"

namespace vnsba::node {

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
  // The three services, by ActionService (service_client.hpp: requests, replies, the mapping).
  std::array<std::unique_ptr<ServiceClient>, kActionServices> services;
  dds::DataReader* status_reader = nullptr;
  dds::DataReader* feedback_reader = nullptr;
  std::vector<std::unique_ptr<dds::DataReaderListener>> listeners;
  mutable std::mutex mutex;
  mutable std::condition_variable cv;
  std::map<GoalUuid, GoalState> statuses;  // newest status list, under mutex

  ServiceClient& service(ActionService which) { return *services[static_cast<size_t>(which)]; }

  template <class Msg>
  int64_t request(ActionService which, const Msg& msg) {
    return service(which).request(msg);
  }
  // The reply to `request`, decoded as Msg, or nullopt when none came in time.
  template <class Msg>
  std::optional<Msg> wait(ActionService which, int64_t request, Duration timeout) {
    return service(which).wait<Msg>(request, timeout);
  }

  // The service's client, of RequestType's and ReplyType's DDS types.
  template <class RequestType, class ReplyType>
  core::Status add_service(Participant& participant, ActionService which) {
    auto client = ServiceClient::create<RequestType, ReplyType>(
        participant, name + "/_action/" + service_name(which), mapping,
        which == ActionService::kSendGoal);
    if (!client) return client.error();
    services[static_cast<size_t>(which)] = std::move(client).value();
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
  core::Status create(Participant& participant) override {
    if (auto s =
            add_service<typename Wire::SendGoalRequestType, typename Wire::SendGoalResponseType>(
                participant, ActionService::kSendGoal);
        !s.is_ok())
      return s;
    if (auto s =
            add_service<typename Wire::GetResultRequestType, typename Wire::GetResultResponseType>(
                participant, ActionService::kGetResult);
        !s.is_ok())
      return s;
    if (auto s = add_service<CancelRequestType, CancelResponseType>(participant,
                                                                    ActionService::kCancelGoal);
        !s.is_ok())
      return s;
    return add_topic_readers<typename Wire::FeedbackMessageType>(participant);
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
};

ActionClient::ActionClient(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

// The client's endpoints go before its listeners: the participant outlives the client, and a
// reader deleted later would call a listener already freed.
ActionClient::~ActionClient() {
  for (auto& service : impl_->services) service.reset();
  for (dds::DataReader* reader : {impl_->status_reader, impl_->feedback_reader})
    if (reader != nullptr)
      const_cast<dds::Subscriber*>(reader->get_subscriber())->delete_datareader(reader);
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
        return with_wire<Traits>(distro, [](auto wire) -> std::unique_ptr<Impl> {
          return std::make_unique<ImplOf<Traits, decltype(wire)>>();
        });
      })));
  Impl& impl = *client->impl_;
  impl.name = ros_name;
  impl.mapping = mapping;
  const core::Status status = impl.create(participant);
  if (!status.is_ok()) return status;
  return client;
}

bool ActionClient::wait_for_server(Duration timeout, int servers) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  auto ready = [&] {
    for (const auto& service : impl_->services)
      if (!service->server_ready(servers)) return false;
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
  size_t unmatched = 0;
  for (const auto& service : impl_->services) unmatched += service->unmatched_replies();
  return unmatched;
}

void ActionClient::send_raw(ActionService service, const RawSample& payload) {
  impl_->service(service).send_raw(payload);
}

size_t ActionClient::duplicate_replies() const {
  size_t duplicates = 0;
  for (const auto& service : impl_->services) duplicates += service->duplicate_replies();
  return duplicates;
}

size_t ActionClient::servers_seen() const {
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t> servers;
  for (const auto& service : impl_->services) {
    const auto replied = service->servers_replied();
    servers.insert(replied.begin(), replied.end());
  }
  return std::max(impl_->service(ActionService::kSendGoal).reply_writers_matched(), servers.size());
}

}  // namespace vnsba::node
