// RawOf, a DDS type whose samples stay serialized bytes: the service servers and clients (and so
// the action servers and clients) put the requests and replies of ROS 2 services on the wire as
// service_wire.hpp encodes them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <functional>
#include <vector>

#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::InstanceHandle_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

// A type whose samples are their serialized bytes (RawSample), under the DDS type name of
// `Generated` (a fastddsgen PubSubType): the server decodes a request only once it knows its
// client's mapping, and writes a reply with or without rmw_cyclonedds's header.
template <class Generated>
class RawOf : public dds::TopicDataType {
 public:
  RawOf() {
    Generated generated;
    setName(generated.getName());
    m_typeSize = 1024;  // a first allocation; PREALLOCATED_WITH_REALLOC grows it per sample
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, SerializedPayload_t* payload) override {
    const RawSample& sample = *static_cast<RawSample*>(data);
    const auto& bytes = sample.bytes;
    if (bytes.size() < 4 || sample.size() > payload->max_size) return false;
    uint8_t* end = std::copy(bytes.begin(), bytes.end(), payload->data);
    if (sample.shared_tail) std::copy(sample.shared_tail->begin(), sample.shared_tail->end(), end);
    payload->length = static_cast<uint32_t>(sample.size());
    payload->encapsulation = bytes[1] == 0 ? CDR_BE : CDR_LE;
    return true;
  }
  bool deserialize(SerializedPayload_t* payload, void* data) override {
    RawSample& sample = *static_cast<RawSample*>(data);
    sample.bytes.assign(payload->data, payload->data + payload->length);
    sample.shared_tail.reset();
    return true;
  }
  std::function<uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<uint32_t>(static_cast<RawSample*>(data)->size()); };
  }
  void* createData() override { return new RawSample(); }
  void deleteData(void* data) override { delete static_cast<RawSample*>(data); }
  bool getKey(void*, InstanceHandle_t*, bool) override { return false; }
};

}  // namespace vnsba::node
