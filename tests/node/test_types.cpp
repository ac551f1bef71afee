// The registered DDS type names equal ROS 2's, so ROS 2 nodes match ours by name.
#include <gtest/gtest.h>

#include "builtin_interfaces/msg/TimePubSubTypes.h"
#include "geometry_msgs/msg/PointPubSubTypes.h"
#include "geometry_msgs/msg/PosePubSubTypes.h"
#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "geometry_msgs/msg/QuaternionPubSubTypes.h"
#include "nav_msgs/msg/MapMetaDataPubSubTypes.h"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "octomap_msgs/msg/OctomapPubSubTypes.h"
#include "std_msgs/msg/HeaderPubSubTypes.h"
#include "vnsba/node/dds.hpp"
#include "vnsba_msgs/msg/GridCellPubSubTypes.h"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"
#include "vnsba_msgs/msg/PlanStatusPubSubTypes.h"
#include "vnsba_msgs/msg/PlannerDebugPubSubTypes.h"

namespace vnsba::test {
namespace {

template <class PubSubType>
void expect_registered_as(node::Participant& participant, const std::string& ros_name) {
  PubSubType type;
  EXPECT_EQ(std::string(type.getName()), ros_name);
  auto topic =
      participant.topic<PubSubType>("types_test_" + std::to_string(getpid()) + "_" + ros_name);
  ASSERT_TRUE(topic) << topic.error().message;
  EXPECT_EQ((*topic)->get_type_name(), ros_name);
  EXPECT_FALSE(participant.get()->find_type(ros_name).empty());
}

TEST(Types, RegisteredNamesAreRos2Names) {
  auto participant = node::Participant::create(1 + getpid() % 200, "types_test");
  ASSERT_TRUE(participant) << participant.error().message;
  auto& p = **participant;
  expect_registered_as<builtin_interfaces::msg::dds_::Time_PubSubType>(
      p, "builtin_interfaces::msg::dds_::Time_");
  expect_registered_as<std_msgs::msg::dds_::Header_PubSubType>(p, "std_msgs::msg::dds_::Header_");
  expect_registered_as<geometry_msgs::msg::dds_::Point_PubSubType>(
      p, "geometry_msgs::msg::dds_::Point_");
  expect_registered_as<geometry_msgs::msg::dds_::Quaternion_PubSubType>(
      p, "geometry_msgs::msg::dds_::Quaternion_");
  expect_registered_as<geometry_msgs::msg::dds_::Pose_PubSubType>(
      p, "geometry_msgs::msg::dds_::Pose_");
  expect_registered_as<geometry_msgs::msg::dds_::PoseStamped_PubSubType>(
      p, "geometry_msgs::msg::dds_::PoseStamped_");
  expect_registered_as<nav_msgs::msg::dds_::MapMetaData_PubSubType>(
      p, "nav_msgs::msg::dds_::MapMetaData_");
  expect_registered_as<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(
      p, "nav_msgs::msg::dds_::OccupancyGrid_");
  expect_registered_as<nav_msgs::msg::dds_::Path_PubSubType>(p, "nav_msgs::msg::dds_::Path_");
  expect_registered_as<octomap_msgs::msg::dds_::Octomap_PubSubType>(
      p, "octomap_msgs::msg::dds_::Octomap_");
  expect_registered_as<vnsba_msgs::msg::dds_::GridCell_PubSubType>(
      p, "vnsba_msgs::msg::dds_::GridCell_");
  expect_registered_as<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(
      p, "vnsba_msgs::msg::dds_::PlanRequest_");
  expect_registered_as<vnsba_msgs::msg::dds_::PlanStatus_PubSubType>(
      p, "vnsba_msgs::msg::dds_::PlanStatus_");
  expect_registered_as<vnsba_msgs::msg::dds_::PlannerDebug_PubSubType>(
      p, "vnsba_msgs::msg::dds_::PlannerDebug_");
}

// No type information goes on the wire (Cyclone DDS drops matches that carry Fast DDS 2.9's).
TEST(Types, TypeInformationIsOff) {
  auto participant = node::Participant::create(1 + getpid() % 200, "types_test");
  ASSERT_TRUE(participant);
  auto topic =
      (*participant)
          ->topic<nav_msgs::msg::dds_::Path_PubSubType>("types_info_" + std::to_string(getpid()));
  ASSERT_TRUE(topic);
  const node::dds::TypeSupport type =
      (*participant)->get()->find_type("nav_msgs::msg::dds_::Path_");
  ASSERT_FALSE(type.empty());
  EXPECT_FALSE(type->auto_fill_type_information());
  EXPECT_FALSE(type->auto_fill_type_object());
}

}  // namespace
}  // namespace vnsba::test
