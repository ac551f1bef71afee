// A client of one ROS 2 service, as rcl's client puts it on the wire in either middleware's
// mapping (service_wire.hpp):
//
//   request writer on rq/<name>Request, reply reader on rr/<name>Reply
//
// - rmw_fastrtps: a request names the client's reply reader in its related sample identity; the
//   reply is the one whose related sample identity is that request's (writer GUID = our reply
//   reader, sequence = the request's).
// - rmw_cyclonedds: a request starts with a 16-byte header (the client's id, a sequence number
//   counted from 1), and the reply carries it back.
// Every reply reaches every client's reply reader; each client keeps its own, as the rmw do.
// The action client (action_client.hpp) calls its three services with it; the lifecycle tools
// and tests call lifecycle_msgs's. It creates its endpoints on a Participant the caller owns (the
// participant outlives the client) and is thread-safe.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>

#include "vnsba/core/status.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/raw_type.hpp"
#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

class ServiceClient {
 public:
  using Duration = std::chrono::milliseconds;

  // `ros_service_name`: the service's full ROS 2 name ("/vnsba_node/get_state");
  // RequestType and ReplyType: its fastddsgen PubSubTypes. `large_requests`: requests may be
  // megabytes (a goal of many poses). The reply reader first: a request names it.
  template <class RequestType, class ReplyType>
  static core::Expected<std::unique_ptr<ServiceClient>> create(Participant& participant,
                                                               const std::string& ros_service_name,
                                                               WireMapping mapping,
                                                               bool large_requests = false) {
    std::unique_ptr<ServiceClient> client(new ServiceClient(ros_service_name, mapping));
    auto reader = participant.reader_on<RawOf<ReplyType>>(service_topic(ros_service_name, false),
                                                          reader_qos(TopicQos::kStatus),
                                                          client->reply_listener());
    if (!reader) return reader.error();
    client->reply_reader_ = *reader;
    auto writer = participant.writer_on<RawOf<RequestType>>(
        service_topic(ros_service_name, true), writer_qos(TopicQos::kEvents, large_requests));
    if (!writer) return writer.error();
    client->request_writer_ = *writer;
    return client;
  }
  // Deletes its reader and writer (the listener after them).
  ~ServiceClient();
  ServiceClient(const ServiceClient&) = delete;
  ServiceClient& operator=(const ServiceClient&) = delete;

  // Sends `msg`; returns the request's sequence number (-1 when the writer refused it).
  template <class Msg>
  int64_t request(const Msg& msg) {
    RequestHeader header{};
    const int64_t sequence = next_header(header);
    RawSample sample = encode_request(msg, mapping_, header);
    return write_request(sample, sequence);
  }
  // The reply to `request` decoded as Msg, or nullopt when none came within `timeout` (or it
  // cannot be decoded).
  template <class Msg>
  std::optional<Msg> wait(int64_t request, Duration timeout) {
    std::optional<RawSample> raw = wait_raw(request, timeout);
    if (!raw) return std::nullopt;
    Msg msg;
    RequestHeader header;
    if (!decode_reply(*raw, mapping_, msg, header).empty()) return std::nullopt;
    return msg;
  }
  // request, then wait: one call.
  template <class Reply, class Msg>
  std::optional<Reply> call(const Msg& msg, Duration timeout) {
    return wait<Reply>(request(msg), timeout);
  }

  // Sends `payload` as it is (the encapsulation and what follows): for tests of malformed
  // requests.
  void send_raw(const RawSample& payload);

  // Whether `servers` servers' request readers and reply writers are matched (what rcl's
  // service_is_ready checks), and a wait for it.
  bool server_ready(int servers = 1) const;
  bool wait_for_server(Duration timeout, int servers = 1) const;

  // Replies received that answer none of this client's requests, replies to a request answered
  // already (never, from a correct server), and the participants that replied.
  size_t unmatched_replies() const;
  size_t duplicate_replies() const;
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t> servers_replied() const;
  // Reply writers matched by the reply reader now.
  size_t reply_writers_matched() const;
  WireMapping mapping() const { return mapping_; }
  const std::string& name() const { return name_; }

 private:
  ServiceClient(std::string name, WireMapping mapping);
  dds::DataReaderListener* reply_listener();
  void on_reply(RawSample&& raw, const dds::SampleInfo& info);
  // rmw_cyclonedds's header for the next request (its sequence number returned); 0 otherwise.
  int64_t next_header(RequestHeader& header);
  int64_t write_request(RawSample& sample, int64_t header_sequence);
  std::optional<RawSample> wait_raw(int64_t request, Duration timeout);

  const std::string name_;
  const WireMapping mapping_;
  const uint64_t client_id_;  // rmw_cyclonedds's header: the client's id
  dds::DataWriter* request_writer_ = nullptr;
  dds::DataReader* reply_reader_ = nullptr;
  std::unique_ptr<dds::DataReaderListener> listener_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  int64_t next_sequence_ = 0;                                 // header mapping, under mutex_
  std::map<int64_t, RawSample> replies_;                      // by request sequence, under mutex_
  std::set<int64_t> answered_;                                // sequences replied to, under mutex_
  size_t unmatched_ = 0;                                      // under mutex_
  size_t duplicates_ = 0;                                     // under mutex_
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t> servers_;  // under mutex_
};

}  // namespace vnsba::node
