// nav2_msgs/srv/IsPathValid, the service Nav2's planner_server serves beside its actions
// ("is_path_valid", relative to the node's name: planner_server.cpp creates it so), per ROS 2
// distribution, and its answer: the check (path_validity.hpp) of the request's path on the
// node's map, from the robot's pose.
//
// Humble and Jazzy: request path; Kilted adds max_cost and consider_unknown_as_obstacle
// (idl/nav2_msgs/srv, idl/nav2_msgs_kilted/srv). The response is is_valid and
// invalid_pose_indices in all three.
#pragma once

#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "nav2_msgs/srv/IsPathValidPubSubTypes.h"
#include "nav2_msgs_kilted/srv/IsPathValidPubSubTypes.h"
#include "ros_named.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/path_validity.hpp"

namespace vnsba::node {

struct IsPathValid {
  static constexpr const char* kTypeName = "nav2_msgs/srv/IsPathValid";

  // The request and response types of each distribution (Humble's are Jazzy's).
  template <RosDistro>
  struct Wire {
    using Request = nav2_msgs::srv::dds_::IsPathValid_Request_;
    using RequestType = RosNamed<nav2_msgs::srv::dds_::IsPathValid_Request_PubSubType>;
    using Response = nav2_msgs::srv::dds_::IsPathValid_Response_;
    using ResponseType = RosNamed<nav2_msgs::srv::dds_::IsPathValid_Response_PubSubType>;
  };

  // Whether a request has Kilted's fields.
  template <class Request, class = void>
  struct HasMaxCost : std::false_type {};
  template <class Request>
  struct HasMaxCost<Request, std::void_t<decltype(std::declval<const Request&>().max_cost())>>
      : std::true_type {};

  // What the request asks beside its path: Kilted's fields, or Humble's and Jazzy's rules.
  template <class Request>
  static PathCheckRules rules_of(const Request& request) {
    PathCheckRules rules;
    if constexpr (HasMaxCost<Request>::value) {
      rules.max_cost = request.max_cost();
      rules.unknown_is_obstacle = request.consider_unknown_as_obstacle();
    }
    return rules;
  }
};
template <>
struct IsPathValid::Wire<RosDistro::kKilted> {
  using Request = nav2_msgs_kilted::srv::dds_::IsPathValid_Request_;
  using RequestType = RosNamed<nav2_msgs_kilted::srv::dds_::IsPathValid_Request_PubSubType>;
  using Response = nav2_msgs_kilted::srv::dds_::IsPathValid_Response_;
  using ResponseType = RosNamed<nav2_msgs_kilted::srv::dds_::IsPathValid_Response_PubSubType>;
};

// The reply to `request`, with `map` the node's current map (null: none accepted yet) and
// `robot` the robot's position in the map's frame (nullopt: unknown). A path that cannot be
// checked (no map, a wrong frame, more poses than actions.max_result_poses) is invalid with no
// index; the returned text says why ("" when checked), for the log.
template <class Request, class Response>
std::string answer_is_path_valid(const Request& request, const core::GridMap* map,
                                 const std::optional<Eigen::Vector2d>& robot,
                                 const NodeConfig& config, Response& response) {
  response.is_valid(false);
  response.invalid_pose_indices().clear();
  std::string problem;
  const std::vector<Eigen::Vector2d> positions =
      path_positions(request.path(), config.frame_id,
                     static_cast<size_t>(config.actions.max_result_poses), problem);
  if (!problem.empty()) return problem;
  if (map == nullptr) return "no map has been accepted yet";
  PathValidity validity = check_path(*map, positions, robot, IsPathValid::rules_of(request));
  response.is_valid(validity.is_valid);
  response.invalid_pose_indices(std::move(validity.invalid_pose_indices));
  return "";
}

}  // namespace vnsba::node
