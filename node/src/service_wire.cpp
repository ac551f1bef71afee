#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

std::string to_string(WireMapping mapping) {
  return mapping == WireMapping::kRequestHeader ? "rmw_cyclonedds (request header)"
                                                : "rmw_fastrtps (sample identity)";
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
