#include "service_server.hpp"

#include <fastdds/rtps/common/WriteParams.h>
#include <spdlog/spdlog.h>

#include <algorithm>

namespace vnsba::node {

using eprosima::fastrtps::rtps::GUID_t;

ReplyAddress reply_address(const dds::SampleInfo& info, ReplyMapping configured,
                           const ParticipantWatch* vendors) {
  ReplyAddress address;
  const GUID_t& writer = info.sample_identity.writer_guid();
  std::copy(std::begin(writer.guidPrefix.value), std::end(writer.guidPrefix.value),
            address.prefix.begin());
  const bool has_related = info.related_sample_identity.writer_guid() != GUID_t::unknown();
  std::optional<VendorId> vendor;
  if (vendors != nullptr) vendor = vendors->vendor_of(writer.guidPrefix);
  address.mapping = choose_mapping(configured, vendor, has_related);
  // As rmw_fastrtps's server: the request's identity, with the client's reply reader as the
  // writer GUID when the request names it.
  address.related = info.sample_identity;
  if (has_related) address.related.writer_guid() = info.related_sample_identity.writer_guid();
  return address;
}

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

// A request that cannot be decoded is never answered: without its content (a goal id, a
// transition) there is nothing to answer, as in rcl and rcl_action.
void RefusedRequests::refuse(const std::string& owner, const std::string& service,
                             const ReplyAddress& from, const std::string& problem) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (warned_.size() >= 1000 || !warned_.insert(from.prefix).second) return;
  }
  spdlog::warn("{}: a {} request from participant {} dropped: {} (mapping {})", owner, service,
               hex_text(from.prefix), problem, to_string(from.mapping));
}

// Feeds a reply writer's gate with its matched readers (per remote participant).
class ServiceReplies::MatchedReaders : public dds::DataWriterListener {
 public:
  explicit MatchedReaders(ServiceReplies& replies) : replies_(replies) {}
  void on_publication_matched(dds::DataWriter*,
                              const dds::PublicationMatchedStatus& status) override {
    if (status.current_count_change == 0) return;
    GuidPrefix prefix;  // an endpoint's instance handle is its GUID
    for (size_t i = 0; i < prefix.size(); ++i) prefix[i] = status.last_subscription_handle.value[i];
    {
      std::lock_guard<std::mutex> lock(replies_.mutex_);
      replies_.gate_.reader_matched(prefix, status.current_count_change);
    }
    replies_.cv_.notify_all();
  }

 private:
  ServiceReplies& replies_;
};

ServiceReplies::ServiceReplies(std::string owner, std::string service, const NodeConfig& config,
                               std::mutex& mutex, std::condition_variable& cv)
    : owner_(std::move(owner)),
      service_(std::move(service)),
      cfg_(config),
      mutex_(mutex),
      cv_(cv),
      gate_(config.reply_wait, kReaderSettle),
      flow_(static_cast<size_t>(config.actions.replies_in_flight_mb) << 20,
            config.actions.reply_ack_timeout) {}

ServiceReplies::~ServiceReplies() = default;

dds::DataWriterListener* ServiceReplies::matched_listener() {
  matched_ = std::make_unique<MatchedReaders>(*this);
  return matched_.get();
}

// Holds a reply for the replier thread, unless the client has max_pending_replies held by this
// service already (then it is dropped with a warning, at most one a second per client).
void ServiceReplies::hold(const ReplyAddress& to, RawSample sample, std::string what) {
  size_t& pending = pending_[to.prefix];
  if (pending >= static_cast<size_t>(cfg_.actions.max_pending_replies)) {
    warn_dropped(to.prefix, pending, what);
    return;
  }
  ++pending;
  ServiceReply reply;
  reply.writer = writer_;
  reply.client = to.prefix;
  reply.sample = std::move(sample);
  if (to.mapping == WireMapping::kSampleIdentity) reply.related = to.related;
  reply.what = std::move(what);
  gate_.hold(to.prefix, std::move(reply), ReplyGate<ServiceReply>::Clock::now());
}

void ServiceReplies::warn_dropped(const GuidPrefix& client, size_t pending,
                                  const std::string& what) {
  const Clock::time_point now = Clock::now();
  auto [warned, first] = drop_warned_.try_emplace(client, now);
  if (!first && now - warned->second < std::chrono::seconds(1)) return;
  warned->second = now;
  spdlog::warn(
      "{}: {} to participant {} dropped: {} {} replies to it wait already "
      "(actions.max_pending_replies; its reply reader is not matched or not taking them)",
      owner_, what, hex_text(client), pending, service_);
}

void ServiceReplies::take_due(Clock::time_point now, bool all, Due& out) {
  const auto release_at = all ? ReplyGate<ServiceReply>::Clock::time_point::max() : now;
  while (!unwritten_.empty()) {
    out.replies.push_back(std::move(unwritten_.front()));
    unwritten_.pop_front();
  }
  bool heartbeat = false;
  for (ServiceReply& reply : gate_.release(release_at, nullptr, &heartbeat))
    out.replies.push_back(std::move(reply));
  if (heartbeat && writer_ != nullptr) out.heartbeat = true;
  if (const auto next = flow_.next_check(!unwritten_.empty()); next && now >= *next)
    out.check_flows = true;
}

// A heartbeat that does not count these replies goes first, as the node does before statuses
// (Replier::loop): Cyclone DDS's volatile reader skips everything up to the last sequence
// number of the first heartbeat it accepts from a writer, and a client that discovered the
// reply writer after the node matched its reader missed the earlier heartbeats. An 885 kB
// result (14 fragments) was lost so in 7 of 15 runs of the Cyclone client's cancel test.
// Not enough alone when the heartbeat goes to a multicast group and Fast DDS sends the reply's
// own heartbeat to the client's unicast locator (reply_gate.hpp): the gate's heartbeats
// (`due.heartbeat`) go out a settle ahead of such a reply.
ServiceReplies::Done ServiceReplies::write(Due& due, bool stopping, bool give_up) {
  const Clock::time_point now = Clock::now();
  check_acknowledgements(now);
  if (writer_ != nullptr && (due.heartbeat || !due.replies.empty())) writer_->assert_liveliness();
  // In order: a reply that must wait keeps every later one waiting.
  bool waiting = false;
  Done done;
  std::deque<ServiceReply> keep;
  for (ServiceReply& reply : due.replies) {
    if (reply.writer == nullptr || write_now(reply, now, stopping, waiting)) {
      ++done[reply.client];
      continue;
    }
    if (give_up) {
      spdlog::error("{}: could not write {}: the shutdown's drain ran out of time", owner_,
                    reply.what);
      ++done[reply.client];
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
void ServiceReplies::check_acknowledgements(Clock::time_point now) {
  if (writer_ == nullptr || flow_.unacknowledged_bytes() == 0) return;
  if (writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0, 0)) ==
      ReturnCode_t::RETCODE_OK) {
    flow_.all_acknowledged();
  } else if (const auto clients = flow_.stalled(now)) {
    warn_stalled(*clients);
  }
}

void ServiceReplies::warn_stalled(const std::vector<std::pair<GuidPrefix, size_t>>& clients) {
  std::string names;
  for (size_t i = 0; i < clients.size() && i < 3; ++i)
    names += (i ? ", " : "") + hex_text(clients[i].first) + " (" +
             std::to_string(clients[i].second) + ")";
  if (clients.size() > 3) names += " and more";
  // DDS does not say which reader lags: every participant with a reader on this topic.
  std::vector<GuidPrefix> readers;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    readers = gate_.matched_participants();
  }
  std::string readers_text;
  for (const GuidPrefix& participant : readers)
    readers_text += (readers_text.empty() ? "" : ", ") + hex_text(participant);
  spdlog::warn(
      "{}: {} replies not acknowledged by every reader within actions.reply_ack_timeout "
      "({:g} s): a reader does not take its replies (a stopped or overloaded client). "
      "Replies waiting in it by client participant: {}; participants with a reader of it: "
      "{}. The others' replies go on without waiting for it, and what only it lacks is "
      "dropped",
      owner_, service_, static_cast<double>(cfg_.actions.reply_ack_timeout.count()) / 1000.0, names,
      readers_text);
}

// Writes `reply` now if the service is not `waiting` and its flow allows (`stopping`: the flow
// is not asked); true when written. A reply that must wait, or that the writer refuses, sets
// `waiting` for the rest of this pass.
bool ServiceReplies::write_now(ServiceReply& reply, Clock::time_point now, bool stopping,
                               bool& waiting) {
  const size_t bytes = reply.sample.size();
  if (!waiting && !stopping) {
    const ReplyFlow::Step step = flow_.next(bytes, now);
    if (step == ReplyFlow::Step::kWait) waiting = true;
    if (step == ReplyFlow::Step::kClearHistory) {
      size_t removed = 0;
      reply.writer->clear_history(&removed);
      flow_.history_cleared();
      spdlog::warn(
          "{}: {} replies a reader has not acknowledged for actions.reply_ack_timeout "
          "dropped from the writer's history ({} of them)",
          owner_, service_, removed);
    }
  }
  if (waiting) return false;
  eprosima::fastrtps::rtps::WriteParams params;
  if (reply.related) params.related_sample_identity(*reply.related);
  if (write_sample(reply.writer, &reply.sample, params)) {
    flow_.written(reply.client, bytes, now);
    return true;
  }
  waiting = true;  // refused: tried again on the next pass
  return false;
}

void ServiceReplies::release_pending(const Done& done) {
  for (const auto& [client, count] : done) {
    auto it = pending_.find(client);
    if (it == pending_.end()) continue;
    it->second -= std::min(it->second, count);
    if (it->second == 0) pending_.erase(it);
  }
}

// The flow's next look (the acknowledgements themselves are looked for every few milliseconds
// by the replier while replies wait) and the gate's next deadline.
void ServiceReplies::next_deadline(std::optional<Clock::time_point>& earliest) const {
  if (auto next = flow_.next_check(!unwritten_.empty()); next && (!earliest || *next < *earliest))
    earliest = next;
  if (auto next = gate_.next_deadline(); next && (!earliest || *next < *earliest)) earliest = next;
}

ServiceServerBase::ServiceServerBase(std::string ros_name, const NodeConfig& config,
                                     const ParticipantWatch* vendors, std::mutex& mutex,
                                     std::condition_variable& cv)
    : ros_name_(std::move(ros_name)),
      cfg_(config),
      vendors_(vendors),
      mutex_(mutex),
      cv_(cv),
      replies_(owner_of(ros_name_), short_name_of(ros_name_), config, mutex, cv) {}

std::string ServiceServerBase::owner_of(const std::string& ros_name) {
  const size_t slash = ros_name.rfind('/');
  return slash == std::string::npos || slash == 0 ? ros_name : ros_name.substr(0, slash);
}

std::string ServiceServerBase::short_name_of(const std::string& ros_name) {
  const size_t slash = ros_name.rfind('/');
  return slash == std::string::npos ? ros_name : ros_name.substr(slash + 1);
}

bool ServiceServerBase::write(Due& due, bool stopping, bool give_up) {
  const ServiceReplies::Done done = replies_.write(due, stopping, give_up);
  std::lock_guard<std::mutex> lock(mutex_);
  replies_.release_pending(done);
  return replies_.all_written();
}

std::optional<ServiceServerBase::Clock::time_point> ServiceServerBase::next_deadline() const {
  std::optional<Clock::time_point> earliest;
  replies_.next_deadline(earliest);
  return earliest;
}

}  // namespace vnsba::node
