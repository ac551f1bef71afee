// TransformTree (robot_pose_source: tf) against an independent oracle: poses in the plane
// composed as (x, y, yaw) triples with trigonometry, never through Eigen's isometries.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "vnsba/node/transforms.hpp"

namespace vnsba::node {
namespace {

// A planar pose: the child's origin and heading in the parent, metres and radians.
struct Pose2 {
  double x = 0.0, y = 0.0, yaw = 0.0;
};

// a then b: b is given in a's frame.
Pose2 compose(const Pose2& a, const Pose2& b) {
  return {a.x + std::cos(a.yaw) * b.x - std::sin(a.yaw) * b.y,
          a.y + std::sin(a.yaw) * b.x + std::cos(a.yaw) * b.y, a.yaw + b.yaw};
}

Pose2 inverse(const Pose2& p) {
  return {-std::cos(p.yaw) * p.x - std::sin(p.yaw) * p.y,
          std::sin(p.yaw) * p.x - std::cos(p.yaw) * p.y, -p.yaw};
}

std::string set(TransformTree& tree, const std::string& parent, const std::string& child,
                const Pose2& p, double stamp = 0.0, bool is_static = true) {
  return tree.set(parent, child, Eigen::Vector3d(p.x, p.y, 0.0),
                  Eigen::Quaterniond(Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ())), stamp,
                  is_static);
}

void expect_pose(const TransformTree::Lookup& found, const Pose2& expected) {
  ASSERT_TRUE(found.ok) << found.problem;
  const Eigen::Vector3d t = found.source_in_target.translation();
  EXPECT_NEAR(t.x(), expected.x, 1e-9);
  EXPECT_NEAR(t.y(), expected.y, 1e-9);
  EXPECT_NEAR(t.z(), 0.0, 1e-9);
  const Eigen::Vector3d x_axis = found.source_in_target.rotation() * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::remainder(std::atan2(x_axis.y(), x_axis.x()) - expected.yaw, 2 * M_PI), 0.0,
              1e-9);
}

bool mentions(const std::string& text, const std::vector<std::string>& parts) {
  for (const std::string& part : parts)
    if (text.find(part) == std::string::npos) return false;
  return true;
}

TEST(TransformTree, TheRobotInTheMapIsTheChainMapOdomBaseLink) {
  TransformTree tree;
  const Pose2 odom_in_map{1.5, -0.4, 0.7}, base_in_odom{2.0, 0.3, -1.2};
  ASSERT_EQ(set(tree, "map", "odom", odom_in_map), "");
  ASSERT_EQ(set(tree, "odom", "base_link", base_in_odom), "");
  expect_pose(tree.lookup("map", "base_link", 0.0, 1.0), compose(odom_in_map, base_in_odom));
  expect_pose(tree.lookup("base_link", "map", 0.0, 1.0),
              inverse(compose(odom_in_map, base_in_odom)));
  expect_pose(tree.lookup("map", "map", 0.0, 1.0), Pose2{});
  // A leading '/' names the same frame, as in tf2.
  expect_pose(tree.lookup("/map", "/base_link", 0.0, 1.0), compose(odom_in_map, base_in_odom));
}

// Random trees: every pair of frames, through their common ancestor.
TEST(TransformTree, EveryPairOfARandomTreeMatchesThePlanarOracle) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-5.0, 5.0), angle(-M_PI, M_PI);
  for (int trial = 0; trial < 20; ++trial) {
    TransformTree tree;
    const int n = 12;
    std::vector<Pose2> in_root(n);  // frame i's pose in frame 0 (the root)
    for (int i = 1; i < n; ++i) {
      const int parent = std::uniform_int_distribution<int>(0, i - 1)(rng);
      const Pose2 local{coord(rng), coord(rng), angle(rng)};
      ASSERT_EQ(set(tree, "f" + std::to_string(parent), "f" + std::to_string(i), local), "");
      in_root[i] = compose(in_root[parent], local);
    }
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        expect_pose(tree.lookup("f" + std::to_string(a), "f" + std::to_string(b), 0.0, 1.0),
                    compose(inverse(in_root[a]), in_root[b]));
  }
}

TEST(TransformTree, AMissingLinkNamesTheFramesOnEachSide) {
  TransformTree tree;
  EXPECT_TRUE(
      mentions(tree.lookup("map", "base_link", 0.0, 1.0).problem, {"'map'", "'base_link'"}));
  ASSERT_EQ(set(tree, "odom", "base_link", {}), "");
  const auto found = tree.lookup("map", "base_link", 0.0, 1.0);
  EXPECT_FALSE(found.ok);
  EXPECT_TRUE(mentions(found.problem, {"'map'", "'base_link'", "'odom'", "none joins"}))
      << found.problem;
  const auto unknown = tree.lookup("odom", "laser", 0.0, 1.0);
  EXPECT_FALSE(unknown.ok);
  EXPECT_TRUE(mentions(unknown.problem, {"'laser'", "no transform with child frame"}))
      << unknown.problem;
}

TEST(TransformTree, AnOldDynamicTransformIsStaleAndAStaticOneNever) {
  TransformTree tree;
  ASSERT_EQ(set(tree, "map", "odom", {1, 0, 0}, /*stamp=*/0.0, /*is_static=*/true), "");
  ASSERT_EQ(set(tree, "odom", "base_link", {1, 0, 0}, /*stamp=*/100.0, /*is_static=*/false), "");
  EXPECT_TRUE(tree.lookup("map", "base_link", 100.4, 0.5).ok);
  const auto stale = tree.lookup("map", "base_link", 100.6, 0.5);
  EXPECT_FALSE(stale.ok);
  EXPECT_TRUE(mentions(stale.problem, {"stale", "'odom' -> 'base_link'", "0.600 s old",
                                       "transform_tolerance 0.500 s"}))
      << stale.problem;
  // The static map -> odom, 1000 s old, is fine; a newer sample of the dynamic one refreshes it.
  ASSERT_EQ(set(tree, "odom", "base_link", {2, 0, 0}, 1000.0, false), "");
  expect_pose(tree.lookup("map", "base_link", 1000.0, 0.5), Pose2{3, 0, 0});
  // A lookup that does not cross the stale transform is unaffected by it.
  EXPECT_TRUE(tree.lookup("map", "odom", 5000.0, 0.5).ok);
}

TEST(TransformTree, BadTransformsAreRefusedNamingTheFramesAndChangeNothing) {
  TransformTree tree;
  ASSERT_EQ(set(tree, "map", "odom", {1, 2, 0}), "");
  ASSERT_EQ(set(tree, "odom", "base_link", {0, 0, 0}), "");
  // A loop: map would become a child of its own descendant.
  EXPECT_TRUE(mentions(set(tree, "base_link", "map", {}), {"'base_link' -> 'map'", "loop"}));
  EXPECT_TRUE(mentions(set(tree, "odom", "odom", {}), {"own parent"}));
  EXPECT_TRUE(mentions(set(tree, "", "odom", {}), {"non-empty"}));
  const double nan = std::nan("");
  EXPECT_TRUE(mentions(set(tree, "map", "odom", {nan, 0, 0}), {"'map' -> 'odom'", "finite"}));
  EXPECT_TRUE(mentions(
      tree.set("map", "odom", Eigen::Vector3d::Zero(), Eigen::Quaterniond(0, 0, 0, 0), 0.0, true),
      {"zero quaternion"}));
  EXPECT_TRUE(mentions(
      tree.set("map", "odom", Eigen::Vector3d::Zero(), Eigen::Quaterniond(1, 0, 0, 0), nan, true),
      {"finite"}));
  expect_pose(tree.lookup("map", "base_link", 0.0, 1.0), Pose2{1, 2, 0});
  // A re-parented frame (tf2 allows it) is looked up through its new parent.
  ASSERT_EQ(set(tree, "map", "base_link", {5, 5, 0}), "");
  expect_pose(tree.lookup("map", "base_link", 0.0, 1.0), Pose2{5, 5, 0});
}

TEST(TransformTree, ANonUnitQuaternionIsNormalised) {
  TransformTree tree;
  const double yaw = 0.9;
  ASSERT_EQ(
      tree.set("map", "base_link", Eigen::Vector3d(1, 1, 0),
               Eigen::Quaterniond(3 * std::cos(yaw / 2), 0, 0, 3 * std::sin(yaw / 2)), 0.0, true),
      "");
  expect_pose(tree.lookup("map", "base_link", 0.0, 1.0), Pose2{1, 1, yaw});
}

TEST(TransformTree, AFloodOfMadeUpFramesIsBounded) {
  TransformTree tree;
  for (size_t i = 0; i < TransformTree::kMaxFrames; ++i)
    ASSERT_EQ(set(tree, "root", "f" + std::to_string(i), {}), "");
  EXPECT_TRUE(mentions(set(tree, "root", "one_more", {}), {"more than"}));
  EXPECT_EQ(tree.frame_count(), TransformTree::kMaxFrames);
  // Known frames still update.
  EXPECT_EQ(set(tree, "root", "f0", {1, 0, 0}), "");
}

}  // namespace
}  // namespace vnsba::node
