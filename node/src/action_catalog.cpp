#include "vnsba/node/action_catalog.hpp"

#include "action_traits.hpp"
#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

namespace {

constexpr const char* kServiceNames[kActionServices] = {"send_goal", "get_result", "cancel_goal"};

// The name Nav2's planner actions give a plan's failure, for the wire codes they have a code of
// their own for; "UNKNOWN" for the others.
const char* nav2_failure_name(uint8_t wire_code) {
  switch (wire_code) {
    case wire::FRAME_MISMATCH:
      return "TF_ERROR";
    case wire::START_OUTSIDE_MAP:
      return "START_OUTSIDE_MAP";
    case wire::GOAL_OUTSIDE_MAP:
      return "GOAL_OUTSIDE_MAP";
    case wire::START_OCCUPIED:
      return "START_OCCUPIED";
    case wire::GOAL_OCCUPIED:
      return "GOAL_OCCUPIED";
    case wire::TIMEOUT:
      return "TIMEOUT";
    case wire::NO_VALID_PATH:
      return "NO_VALID_PATH";
    default:
      return "UNKNOWN";  // NO_MAP, INVALID_MAP, INVALID_REQUEST, CANCELED, INTERNAL_ERROR,
                         // NODE_INACTIVE (a goal is rejected then, never planned)
  }
}

template <class Traits>
Nav2ActionInfo describe_action() {
  Nav2ActionInfo info;
  info.kind = action_kind<Traits>();
  info.type_name = Traits::kTypeName;
  info.id_name = Traits::kIdName;
  info.option_name = Traits::kOptionName;
  info.topic = Traits::kTopic;
  info.several_goals = Traits::kSeveralGoals;
  info.errors = Traits::kErrors;
  return info;
}

}  // namespace

const char* service_name(ActionService service) {
  return kServiceNames[static_cast<size_t>(service)];
}

std::string service_topic(const std::string& ros_name, ActionService service, bool request) {
  return service_topic(ros_name + "/_action/" + service_name(service), request);
}

std::string action_topic(const std::string& ros_name, const char* topic) {
  return "rt" + ros_name + "/_action/" + topic;
}

std::string ActionErrorCodes::name(uint16_t code) const {
  if (code == 0) return "NONE";
  if (code >= base && static_cast<size_t>(code - base) < count) return names[code - base];
  return "NOT_A_NAV2_CODE";
}

const std::vector<Nav2ActionInfo>& nav2_actions() {
  static const std::vector<Nav2ActionInfo> actions = [] {
    std::vector<Nav2ActionInfo> all;
    for_each_action([&all](auto traits) { all.push_back(describe_action<decltype(traits)>()); });
    return all;
  }();
  return actions;
}

const Nav2ActionInfo& nav2_action(ActionKind kind) {
  return nav2_actions().at(static_cast<size_t>(kind));
}

uint16_t nav2_error_code(ActionKind kind, uint8_t wire_code, bool invalid_planner) {
  if (wire_code == wire::OK) return 0;
  return nav2_action(kind).errors.code(invalid_planner ? "INVALID_PLANNER"
                                                       : nav2_failure_name(wire_code));
}

}  // namespace vnsba::node
