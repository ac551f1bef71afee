#include "vnsba/node/service_client.hpp"

#include <fastdds/rtps/common/WriteParams.h>

#include <cstring>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <random>
#include <thread>

#include "take_listener.hpp"

namespace vnsba::node {

namespace {

int64_t sequence_of(const eprosima::fastrtps::rtps::SampleIdentity& identity) {
  return (static_cast<int64_t>(identity.sequence_number().high) << 32) |
         identity.sequence_number().low;
}

uint64_t random_client_id() {
  std::mt19937_64 engine{std::random_device{}()};
  return engine();
}

}  // namespace

ServiceClient::ServiceClient(std::string name, WireMapping mapping)
    : name_(std::move(name)), mapping_(mapping), client_id_(random_client_id()) {}

// The one take loop of the node's readers (take_listener.hpp).
dds::DataReaderListener* ServiceClient::reply_listener() {
  listener_ = make_listener<RawSample>(
      [this](RawSample&& raw, const dds::SampleInfo& info) { on_reply(std::move(raw), info); });
  return listener_.get();
}

// The endpoints go before the listener: a reader deleted later would call a listener freed.
ServiceClient::~ServiceClient() {
  if (reply_reader_ != nullptr)
    const_cast<dds::Subscriber*>(reply_reader_->get_subscriber())->delete_datareader(reply_reader_);
  if (request_writer_ != nullptr)
    const_cast<dds::Publisher*>(request_writer_->get_publisher())
        ->delete_datawriter(request_writer_);
}

// Keeps the replies that answer this client's requests.
void ServiceClient::on_reply(RawSample&& raw, const dds::SampleInfo& info) {
  using eprosima::fastrtps::rtps::GUID_t;
  int64_t sequence = -1;
  if (mapping_ == WireMapping::kSampleIdentity) {
    const GUID_t ours = reply_reader_->guid();
    if (info.related_sample_identity.writer_guid() == ours)
      sequence = sequence_of(info.related_sample_identity);
  } else if (raw.bytes.size() >= 20) {
    uint64_t id = 0;
    std::memcpy(&id, raw.bytes.data() + 4, sizeof id);  // little-endian, as encoded
    if (id == client_id_) std::memcpy(&sequence, raw.bytes.data() + 12, sizeof sequence);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (sequence >= 0) servers_.insert(info.sample_identity.writer_guid().guidPrefix);
    if (sequence < 0)
      ++unmatched_;
    else if (!answered_.insert(sequence).second)
      ++duplicates_;
    else
      replies_[sequence] = std::move(raw);
  }
  cv_.notify_all();
}

int64_t ServiceClient::next_header(RequestHeader& header) {
  if (mapping_ != WireMapping::kRequestHeader) return 0;
  int64_t sequence = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sequence = ++next_sequence_;
  }
  std::memcpy(header.data(), &client_id_, 8);
  std::memcpy(header.data() + 8, &sequence, 8);
  return sequence;
}

int64_t ServiceClient::write_request(RawSample& sample, int64_t header_sequence) {
  eprosima::fastrtps::rtps::WriteParams params;
  // As rmw_fastrtps: the request names the client's reply reader (rmw_cyclonedds does not).
  if (mapping_ == WireMapping::kSampleIdentity)
    params.related_sample_identity().writer_guid() = reply_reader_->guid();
  if (!write_sample(request_writer_, &sample, params)) return -1;
  return mapping_ == WireMapping::kRequestHeader ? header_sequence
                                                 : sequence_of(params.sample_identity());
}

std::optional<RawSample> ServiceClient::wait_raw(int64_t request, Duration timeout) {
  if (request < 0) return std::nullopt;
  std::unique_lock<std::mutex> lock(mutex_);
  if (!cv_.wait_for(lock, timeout, [&] { return replies_.count(request) > 0; }))
    return std::nullopt;
  RawSample raw = std::move(replies_[request]);
  replies_.erase(request);
  return raw;
}

void ServiceClient::send_raw(const RawSample& payload) {
  RawSample copy = payload;
  write_sample(request_writer_, &copy);
}

size_t ServiceClient::reply_writers_matched() const {
  dds::SubscriptionMatchedStatus matched;
  if (reply_reader_->get_subscription_matched_status(matched) != ReturnCode_t::RETCODE_OK) return 0;
  return static_cast<size_t>(std::max(matched.current_count, 0));
}

bool ServiceClient::server_ready(int servers) const {
  return matched_readers(request_writer_) >= servers &&
         reply_writers_matched() >= static_cast<size_t>(servers);
}

bool ServiceClient::wait_for_server(Duration timeout, int servers) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!server_ready(servers)) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

size_t ServiceClient::unmatched_replies() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return unmatched_;
}

size_t ServiceClient::duplicate_replies() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return duplicates_;
}

std::set<eprosima::fastrtps::rtps::GuidPrefix_t> ServiceClient::servers_replied() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return servers_;
}

}  // namespace vnsba::node
