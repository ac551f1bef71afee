// ros.distro over loopback, with real participants: a node serving Humble's or Kilted's
// nav2_msgs types and ActionClients of the same distribution, in both rmw mappings. Oracles:
// a brute-force walk of the path over the map's cells, the goals on the path in order, and the
// fields the distribution's result has (Humble's carries no error_code: it reads 0).
#include <gtest/gtest.h>

#include <cmath>

#include "action_run.hpp"
#include "bus_client.hpp"
#include "vnsba/node/action_client.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

using node::ActionClient;
using node::ActionGoalSpec;
using node::ActionKind;
using node::GoalState;
using node::RosDistro;
using node::WireMapping;

// 30 x 20 cells of 0.1 m: a wall at x = 15 with a gap at y 8..11, a block at (22..25, 3..6).
core::OccupancyGrid distro_map() {
  core::OccupancyGrid g;
  g.width = 30;
  g.height = 20;
  g.resolution = 0.1;
  g.data.assign(static_cast<size_t>(g.width * g.height), core::kOccupancyFree);
  auto set = [&](int x, int y) { g.data[static_cast<size_t>(y * g.width + x)] = 100; };
  for (int y = 0; y < g.height; ++y)
    if (y < 8 || y > 11) set(15, y);
  for (int x = 22; x <= 25; ++x)
    for (int y = 3; y <= 6; ++y) set(x, y);
  return g;
}

node::PoseStampedMsg map_pose(double x, double y) {
  return node::to_pose_msg(x, y, 0.0, "map", node::now_msg());
}

struct DistroParam {
  RosDistro distro;
  WireMapping mapping;
};

class Distros : public ::testing::TestWithParam<DistroParam> {};

std::string distro_param_name(const ::testing::TestParamInfo<DistroParam>& info) {
  return std::string(node::distro_name(info.param.distro)) +
         (info.param.mapping == WireMapping::kRequestHeader ? "RequestHeader" : "SampleIdentity");
}

TEST_P(Distros, BothActionsPlanAndFailWithTheFieldsOfTheDistribution) {
  const DistroParam param = GetParam();
  node::NodeConfig base = paper_test_config();
  base.ros_distro = param.distro;
  ActionRun run(std::string("distro_") + node::distro_name(param.distro), param.mapping, base);
  const core::OccupancyGrid grid = distro_map();
  ASSERT_TRUE(run.start(grid));
  const bool has_error_code = param.distro != RosDistro::kHumble;

  ActionGoalSpec spec;
  spec.start = map_pose(0.55, 0.45);
  spec.use_start = true;
  spec.goals = {map_pose(2.75, 1.45)};
  const auto ok = run.to_pose->plan(ActionClient::random_id(), spec, 15s);
  ASSERT_TRUE(ok.has_value()) << "no result";
  EXPECT_EQ(ok->status, GoalState::kSucceeded) << ok->error_msg;
  EXPECT_TRUE(path_free(grid, ok->path));
  ASSERT_GE(ok->path.poses().size(), 2u);
  EXPECT_NEAR(ok->path.poses().back().pose().position().x(), 2.75, 1e-9);
  EXPECT_NEAR(ok->path.poses().back().pose().position().y(), 1.45, 1e-9);

  // A goal in the block: ABORTED; GOAL_OCCUPIED (206) where the result has the field.
  spec.goals = {map_pose(2.35, 0.45)};
  const auto occupied = run.to_pose->plan(ActionClient::random_id(), spec, 15s);
  ASSERT_TRUE(occupied.has_value());
  EXPECT_EQ(occupied->status, GoalState::kAborted);
  EXPECT_EQ(occupied->error_code, has_error_code ? 206 : 0);
  EXPECT_EQ(occupied->error_msg.empty(), !has_error_code);
  EXPECT_TRUE(occupied->path.poses().empty());

  // Through poses (Kilted's goal is a nav_msgs/Goals): every goal on the path, in order.
  ActionGoalSpec through;
  through.start = map_pose(0.55, 0.45);
  through.use_start = true;
  through.goals = {map_pose(1.05, 1.55), map_pose(2.05, 1.65), map_pose(2.85, 0.35)};
  const auto legs = run.through->plan(ActionClient::random_id(), through, 15s);
  ASSERT_TRUE(legs.has_value());
  EXPECT_EQ(legs->status, GoalState::kSucceeded) << legs->error_msg;
  EXPECT_TRUE(path_free(grid, legs->path));
  size_t from = 0;
  for (const auto& goal : through.goals) {
    bool found = false;
    for (; from < legs->path.poses().size() && !found; ++from) {
      const auto& p = legs->path.poses()[from].pose().position();
      found =
          std::hypot(p.x() - goal.pose().position().x(), p.y() - goal.pose().position().y()) < 1e-9;
    }
    EXPECT_TRUE(found) << "goal (" << goal.pose().position().x() << ", "
                       << goal.pose().position().y() << ") not on the path after the previous one";
  }
  // No goal: NO_VIAPOINTS_GIVEN (309) where the result has the field.
  through.goals.clear();
  const auto none = run.through->plan(ActionClient::random_id(), through, 15s);
  ASSERT_TRUE(none.has_value());
  EXPECT_EQ(none->status, GoalState::kAborted);
  EXPECT_EQ(none->error_code, has_error_code ? 309 : 0);
}

INSTANTIATE_TEST_SUITE_P(
    RosDistros, Distros,
    ::testing::Values(DistroParam{RosDistro::kHumble, WireMapping::kSampleIdentity},
                      DistroParam{RosDistro::kHumble, WireMapping::kRequestHeader},
                      DistroParam{RosDistro::kKilted, WireMapping::kSampleIdentity},
                      DistroParam{RosDistro::kKilted, WireMapping::kRequestHeader},
                      DistroParam{RosDistro::kJazzy, WireMapping::kSampleIdentity}),
    distro_param_name);

}  // namespace
}  // namespace vnsba::test
