#include "vnsba/node/service_wire.hpp"

#include <cstdio>

namespace vnsba::node {

std::string to_string(WireMapping mapping) {
  return mapping == WireMapping::kRequestHeader ? "rmw_cyclonedds (request header)"
                                                : "rmw_fastrtps (sample identity)";
}

std::string vendor_name(const VendorId& vendor) {
  if (vendor == kVendorEprosima) return "Fast DDS";
  if (vendor == kVendorCyclone) return "Cyclone DDS";
  char text[24];
  std::snprintf(text, sizeof text, "vendor id %02x.%02x", vendor[0], vendor[1]);
  return text;
}

std::string service_topic(const std::string& ros_service_name, bool request) {
  return std::string(request ? "rq" : "rr") + ros_service_name + (request ? "Request" : "Reply");
}

WireMapping choose_mapping(ReplyMapping configured, const std::optional<VendorId>& vendor,
                           bool request_has_related_identity) {
  switch (configured) {
    case ReplyMapping::kFastRtps:
      return WireMapping::kSampleIdentity;
    case ReplyMapping::kCycloneDds:
      return WireMapping::kRequestHeader;
    case ReplyMapping::kAuto:
      break;
  }
  if (vendor)
    return *vendor == kVendorCyclone ? WireMapping::kRequestHeader : WireMapping::kSampleIdentity;
  // Discovery has not told the vendor (it always does before a request can arrive; this is a
  // fallback): rmw_fastrtps names its reply reader in every request, rmw_cyclonedds never.
  return request_has_related_identity ? WireMapping::kSampleIdentity : WireMapping::kRequestHeader;
}

}  // namespace vnsba::node
