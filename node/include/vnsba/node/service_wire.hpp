// ROS 2 services on the wire, as the two ROS 2 middlewares put them (the Nav2 actions' send_goal,
// get_result and cancel_goal), without DDS entities: which mapping a client uses, and a request
// or reply as the bytes of a DDS sample.
//
// - rmw_fastrtps: the payload is the message; the reply's related sample identity (an inline
//   parameter) is the request's sample identity, with the writer GUID replaced by the client's
//   reply reader when the request names one in its own related sample identity.
// - rmw_cyclonedds: the payload starts with a 16-byte request header (a client id, a sequence
//   number), copied as it is into the reply, then the message. The header is 16 bytes, so the
//   message after it keeps its CDR alignment (counted from the start of the payload).
// A server that serves both decides per client: the vendor id its participant announced in
// discovery (eProsima: rmw_fastrtps; Eclipse Cyclone: rmw_cyclonedds), a request that carries a
// related sample identity (rmw_fastrtps always sends one) when the vendor is not known, or the
// configuration's actions.reply_mapping.
#pragma once

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vnsba/node/config.hpp"

namespace vnsba::node {

// A serialized DDS sample: the CDR encapsulation (4 bytes) and what follows, `bytes` then
// `shared_tail` when there is one. A reply built from an encoded message (reply_with_message)
// keeps only its encapsulation and request header in `bytes` and shares the message itself with
// every other reply of the same message: a large result is held once however many clients ask.
struct RawSample {
  std::vector<uint8_t> bytes;
  std::shared_ptr<const std::vector<uint8_t>> shared_tail;
  size_t size() const { return bytes.size() + (shared_tail ? shared_tail->size() : 0); }
};

enum class WireMapping {
  kSampleIdentity,  // rmw_fastrtps
  kRequestHeader,   // rmw_cyclonedds
};
std::string to_string(WireMapping mapping);

using RequestHeader = std::array<uint8_t, 16>;
using VendorId = std::array<uint8_t, 2>;
constexpr VendorId kVendorEprosima = {0x01, 0x0F};
constexpr VendorId kVendorCyclone = {0x01, 0x10};
// "Fast DDS", "Cyclone DDS", else "vendor id 01.02" (the RTPS vendor id a participant announces).
std::string vendor_name(const VendorId& vendor);

// "rq/<name>Request" or "rr/<name>Reply": a service's DDS topic (both rmw), for its full ROS 2
// name ("/vnsba_node/get_state", "/compute_path_to_pose/_action/send_goal").
std::string service_topic(const std::string& ros_service_name, bool request);

// The mapping for one client's request.
WireMapping choose_mapping(ReplyMapping configured, const std::optional<VendorId>& vendor,
                           bool request_has_related_identity);

// Decodes `sample` as a T under `mapping` (the header, when there is one, into `header`).
// Returns "" or what is wrong with it (truncated, not CDR, trailing nonsense is allowed as DDS
// pads). Never throws.
template <class T>
std::string decode_request(const RawSample& sample, WireMapping mapping, T& out,
                           RequestHeader& header) {
  if (sample.bytes.size() < 4) return "shorter than a CDR encapsulation";
  if (sample.bytes[0] != 0 || sample.bytes[1] > 1)
    return "not plain CDR (encapsulation " + std::to_string(sample.bytes[0]) + "." +
           std::to_string(sample.bytes[1]) + ")";
  try {
    eprosima::fastcdr::FastBuffer buffer(
        reinterpret_cast<char*>(const_cast<uint8_t*>(sample.bytes.data())), sample.bytes.size());
    eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN,
                               eprosima::fastcdr::Cdr::DDS_CDR);
    cdr.read_encapsulation();
    if (mapping == WireMapping::kRequestHeader) {
      if (sample.bytes.size() < 4 + header.size()) return "shorter than a request header";
      for (uint8_t& b : header) cdr.deserialize(b);
    }
    out.deserialize(cdr);
  } catch (const std::exception& e) {
    return std::string("cannot be decoded as ") +
           (mapping == WireMapping::kRequestHeader ? "an rmw_cyclonedds" : "an rmw_fastrtps") +
           " request: " + e.what();
  }
  return "";
}

// Encodes `msg` as a reply under `mapping` (after `header` for rmw_cyclonedds), little-endian.
template <class T>
RawSample encode_reply(const T& msg, WireMapping mapping, const RequestHeader& header) {
  const size_t extra = mapping == WireMapping::kRequestHeader ? header.size() : 0;
  RawSample out;
  out.bytes.resize(4 + extra + T::getCdrSerializedSize(msg) + 8);
  eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(out.bytes.data()), out.bytes.size());
  eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::LITTLE_ENDIANNESS,
                             eprosima::fastcdr::Cdr::DDS_CDR);
  cdr.serialize_encapsulation();
  if (mapping == WireMapping::kRequestHeader)
    for (uint8_t b : header) cdr.serialize(b);
  msg.serialize(cdr);
  out.bytes.resize(cdr.getSerializedDataLength());
  return out;
}

// `msg` serialized alone (little-endian CDR, aligned from its own first byte), to be sent as
// the message of any number of replies (reply_with_message).
template <class T>
std::shared_ptr<const std::vector<uint8_t>> encode_message(const T& msg) {
  const RawSample whole = encode_reply(msg, WireMapping::kSampleIdentity, RequestHeader{});
  return std::make_shared<const std::vector<uint8_t>>(whole.bytes.begin() + 4, whole.bytes.end());
}

// A reply under `mapping` whose message is `message` (encode_message), shared, not copied: the
// encapsulation and, for rmw_cyclonedds, the 16-byte header in front. The header's 16 bytes keep
// the message's 8-byte CDR alignment, which counts from the end of the encapsulation.
inline RawSample reply_with_message(std::shared_ptr<const std::vector<uint8_t>> message,
                                    WireMapping mapping, const RequestHeader& header) {
  RawSample out;
  out.bytes = {0, 1, 0, 0};  // CDR, little-endian
  if (mapping == WireMapping::kRequestHeader)
    out.bytes.insert(out.bytes.end(), header.begin(), header.end());
  out.shared_tail = std::move(message);
  return out;
}

// The inverse pair, for clients (vnsba_send_goal --action, tests): a request under `mapping`
// and a reply's message and header.
template <class T>
RawSample encode_request(const T& msg, WireMapping mapping, const RequestHeader& header) {
  return encode_reply(msg, mapping, header);
}
template <class T>
std::string decode_reply(const RawSample& sample, WireMapping mapping, T& out,
                         RequestHeader& header) {
  return decode_request(sample, mapping, out, header);
}

}  // namespace vnsba::node
