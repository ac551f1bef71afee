// A fastddsgen PubSubType registered under its ROS 2 type name, whatever ROS 2 distribution it is
// from: the types in which a distribution differs from Jazzy's live in their own IDL module
// (idl/nav2_msgs_humble, idl/nav2_msgs_kilted), and on the wire that module's suffix goes
// ("nav2_msgs_humble::action::dds_::X" is "nav2_msgs::action::dds_::X", the name rmw_fastrtps
// and rmw_cyclonedds give it). Jazzy's own types keep their name.
#pragma once

#include <string>

#include "vnsba/node/config.hpp"

namespace vnsba::node {

inline std::string ros_type_name(const std::string& generated_name) {
  for (const RosDistro distro : kRosDistros) {
    const std::string module = std::string("nav2_msgs_") + distro_name(distro) + "::";
    if (generated_name.rfind(module, 0) == 0)
      return "nav2_msgs::" + generated_name.substr(module.size());
  }
  return generated_name;
}

template <class Generated>
struct RosNamed : Generated {
  RosNamed() { this->setName(ros_type_name(this->getName()).c_str()); }
};

}  // namespace vnsba::node
