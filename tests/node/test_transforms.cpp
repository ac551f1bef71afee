// TransformTree (robot_pose_source: tf) against an independent oracle: poses in the plane
// composed as (x, y, yaw) triples with trigonometry, never through Eigen's isometries.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bus_client.hpp"
#include "log_capture.hpp"
#include "rosgraph_msgs/msg/ClockPubSubTypes.h"
#include "tf2_msgs/msg/TFMessagePubSubTypes.h"
#include "vnsba/node/time_source.hpp"
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

// What set() said: "" when taken, else the problem.
std::string set(TransformTree& tree, const std::string& parent, const std::string& child,
                const Pose2& p, double stamp = 0.0, bool is_static = true) {
  return tree
      .set(parent, child, Eigen::Vector3d(p.x, p.y, 0.0),
           Eigen::Quaterniond(Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ())), stamp, is_static)
      .problem;
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
      tree.set("map", "odom", Eigen::Vector3d::Zero(), Eigen::Quaterniond(0, 0, 0, 0), 0.0, true)
          .problem,
      {"zero quaternion"}));
  EXPECT_TRUE(mentions(
      tree.set("map", "odom", Eigen::Vector3d::Zero(), Eigen::Quaterniond(1, 0, 0, 0), nan, true)
          .problem,
      {"finite"}));
  expect_pose(tree.lookup("map", "base_link", 0.0, 1.0), Pose2{1, 2, 0});
  // A re-parented frame (tf2 allows it) is looked up through its new parent.
  ASSERT_EQ(set(tree, "map", "base_link", {5, 5, 0}), "");
  expect_pose(tree.lookup("map", "base_link", 0.0, 1.0), Pose2{5, 5, 0});
}

TEST(TransformTree, ANonUnitQuaternionIsNormalised) {
  TransformTree tree;
  const double yaw = 0.9;
  ASSERT_TRUE(tree.set("map", "base_link", Eigen::Vector3d(1, 1, 0),
                       Eigen::Quaterniond(3 * std::cos(yaw / 2), 0, 0, 3 * std::sin(yaw / 2)), 0.0,
                       true)
                  .taken());
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

// Issue 31 item 7: each transform walks its parent's chain (for loops), so the chain's depth is
// bounded: 20,000 chained frames took 12 s a message under the lock a goal needs.
TEST(TransformTree, AChainDeeperThanTheLimitIsRefusedNamingTheLimit) {
  TransformTree tree;
  std::string last = "map";
  for (size_t i = 0; i < TransformTree::kMaxDepth; ++i) {
    const std::string child = "f" + std::to_string(i);
    ASSERT_EQ(set(tree, last, child, {1, 0, 0}), "") << i;
    last = child;
  }
  // kMaxDepth steps of 1 m: the deepest frame is kMaxDepth metres along x.
  expect_pose(tree.lookup("map", last, 0.0, 1.0), Pose2{double(TransformTree::kMaxDepth), 0, 0});
  const TransformTree::SetResult deeper =
      tree.set(last, "one_more", Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity(), 0, true);
  EXPECT_EQ(deeper.refusal, TransformTree::Refusal::kTooDeep);
  EXPECT_TRUE(mentions(deeper.problem, {"'" + last + "' -> 'one_more'", "more than 100"}))
      << deeper.problem;
  EXPECT_EQ(tree.frame_count(), TransformTree::kMaxDepth);

  // A subtree given a new parent deep in the chain makes a deeper chain: lookups through it stop
  // at the limit and say so; the frames above the limit still resolve.
  std::string sub = "b_root";
  for (int i = 0; i < 60; ++i) {
    ASSERT_EQ(set(tree, sub, "b" + std::to_string(i), {0, 1, 0}), "");
    sub = "b" + std::to_string(i);
  }
  ASSERT_EQ(set(tree, "f59", "b_root", {}), "");  // b_root 61 deep, b59 121
  expect_pose(tree.lookup("map", "b20", 0.0, 1.0), Pose2{60, 21, 0});
  const TransformTree::Lookup too_deep = tree.lookup("map", "b59", 0.0, 1.0);
  EXPECT_FALSE(too_deep.ok);
  EXPECT_TRUE(mentions(too_deep.problem, {"'b59'", "more than 100 transforms"}))
      << too_deep.problem;
  EXPECT_FALSE(tree.lookup("b59", "map", 0.0, 1.0).ok);
}

// tf2_msgs/TFMessage of `count` frames chained from "map": flood_0 in map, flood_1 in flood_0...
TFMessageMsg chained_frames(size_t count, const TimeMsg& stamp) {
  TFMessageMsg msg;
  msg.transforms().resize(count);
  for (size_t i = 0; i < count; ++i) {
    auto& t = msg.transforms()[i];
    t.header().frame_id(i == 0 ? "map" : "flood_" + std::to_string(i - 1));
    t.header().stamp(stamp);
    t.child_frame_id("flood_" + std::to_string(i));
    t.transform().rotation().w(1.0);
  }
  return msg;
}

TEST(TransformTree, AFloodOfChainedFramesIsOneLinePerLimitAndKeepsTheLimits) {
  TransformTree tree;
  const TFMessageMsg flood = chained_frames(20000, to_time_msg(int64_t{0}));
  for (int message = 0; message < 3; ++message) {
    const std::vector<std::string> problems = add_transforms(flood, false, tree);
    ASSERT_GE(problems.size(), 1u);
    EXPECT_LE(problems.size(), 2u) << "one line per limit reached";
    for (const std::string& problem : problems)
      EXPECT_TRUE(mentions(problem, {"more transforms of this message"})) << problem;
    EXPECT_LE(tree.frame_count(), TransformTree::kMaxFrames);
  }
}

TEST(TransformTree, ATransformStampedAfterTheClockIsRefusedAtLookup) {
  TransformTree tree;
  const double now = 1000.0;                      // seconds, the node's clock
  const double years_56 = 56 * 365.25 * 86400.0;  // seconds
  ASSERT_EQ(set(tree, "map", "odom", {}, now, true), "");
  ASSERT_EQ(set(tree, "odom", "base_link", {1, 2, 0}, now + years_56, false), "");
  const TransformTree::Lookup future = tree.lookup("map", "base_link", now, 0.5);
  EXPECT_FALSE(future.ok);
  EXPECT_TRUE(mentions(future.problem, {"in the future", "'odom' -> 'base_link'",
                                        "1767225600.000 s after the node's clock (1000.000 s"}))
      << future.problem;
  // Clock skew of less than kMaxAheadS is taken, more is not.
  ASSERT_EQ(set(tree, "odom", "base_link", {1, 2, 0}, now + 0.4, false), "");
  expect_pose(tree.lookup("map", "base_link", now, 0.5), Pose2{1, 2, 0});
  ASSERT_EQ(set(tree, "odom", "base_link", {1, 2, 0}, now + 0.6, false), "");
  EXPECT_FALSE(tree.lookup("map", "base_link", now, 0.5).ok);
  // A static transform has no time.
  ASSERT_EQ(set(tree, "odom", "base_link", {1, 2, 0}, now + years_56, true), "");
  expect_pose(tree.lookup("map", "base_link", now, 0.5), Pose2{1, 2, 0});
}

TEST(TransformTree, ClearingDynamicTransformsKeepsTheStaticOnes) {
  TransformTree tree;
  ASSERT_EQ(set(tree, "map", "odom", {1, 0, 0}, 5.0, true), "");
  ASSERT_EQ(set(tree, "odom", "base_link", {2, 0, 0}, 5.0, false), "");
  ASSERT_EQ(set(tree, "base_link", "laser", {0, 1, 0}, 5.0, true), "");
  EXPECT_EQ(tree.clear_dynamic(), 1u);
  EXPECT_EQ(tree.frame_count(), 2u);
  expect_pose(tree.lookup("map", "odom", 5.0, 1.0), Pose2{1, 0, 0});
  expect_pose(tree.lookup("base_link", "laser", 5.0, 1.0), Pose2{0, 1, 0});
  EXPECT_FALSE(tree.lookup("map", "base_link", 5.0, 1.0).ok);
}

TimeMsg at(int32_t sec, uint32_t nanosec = 0) {
  TimeMsg t;
  t.sec(sec);
  t.nanosec(nanosec);
  return t;
}

TEST(TimeSource, ASimulatedClockFollowsAJumpBackAndRefusesNegativeTimesSayingSoOnce) {
  const test::LogCapture log;
  TimeSource clock(true);
  EXPECT_EQ(clock.now_seconds(), 0.0);  // until the first Clock
  EXPECT_EQ(clock.set_sim_time(at(1000, 250'000'000)), ClockUpdate::kFollowed);
  EXPECT_EQ(clock.set_sim_time(at(1000, 250'000'000)), ClockUpdate::kFollowed);  // paused
  EXPECT_EQ(clock.set_sim_time(at(10)), ClockUpdate::kJumpedBack);
  EXPECT_EQ(clock.now_seconds(), 10.0);
  EXPECT_EQ(log.matching({"[warning]", "went back from 1000.250000000 s to 10.000000000 s"}).size(),
            1u);
  for (int repeat = 0; repeat < 3; ++repeat)
    EXPECT_EQ(clock.set_sim_time(at(-5)), ClockUpdate::kRefusedNegative);
  EXPECT_EQ(clock.now_seconds(), 10.0);
  EXPECT_EQ(log.matching({"[warning]", "refused a clock of -5.000000000 s"}).size(), 1u);
  // Once a valid time came, a negative one is news again.
  EXPECT_EQ(clock.set_sim_time(at(11)), ClockUpdate::kFollowed);
  EXPECT_EQ(clock.set_sim_time(at(-1, 500'000'000)), ClockUpdate::kRefusedNegative);
  EXPECT_EQ(log.matching({"refused a clock of -0.500000000 s", "stays at 11.000000000 s"}).size(),
            1u);
  EXPECT_EQ(log.matching({"went back"}).size(), 1u);

  TimeSource wall(false);
  EXPECT_EQ(wall.set_sim_time(at(5)), ClockUpdate::kIgnored);
  EXPECT_GT(wall.now_seconds(), 1.6e9);  // the system clock: after 2020
}

}  // namespace
}  // namespace vnsba::node

// --- On the bus: the node's tf readers, clock and goals together. ---

namespace vnsba::test {
namespace {

using node::wire::INVALID_REQUEST;
using node::wire::OK;

// The node (robot_pose_source tf) on an open 2 m x 2 m map, and a tf broadcaster beside it.
struct TfNode {
  explicit TfNode(const std::string& tag, bool use_sim_time = false)
      : config(make_config(tag, use_sim_time)), node(config), client(config) {}
  static node::NodeConfig make_config(const std::string& tag, bool use_sim_time) {
    node::NodeConfig cfg = test_config(tag);
    cfg.robot_pose_source = node::RobotPoseSource::kTf;
    cfg.use_sim_time = use_sim_time;
    return cfg;
  }
  bool start() {
    const core::Status s = node.start();
    EXPECT_TRUE(s.is_ok()) << s.message;
    if (!s.is_ok() || !client.wait_for_match(node)) return false;
    core::OccupancyGrid grid;
    grid.width = grid.height = 20;
    grid.resolution = 0.1;
    grid.data.assign(400, 0);
    client.publish_slice(grid);
    return node.wait_for_map(10s);
  }
  // A writer of `topic` on a participant of its own, once the node reads it.
  template <class PubSubType>
  node::dds::DataWriter* writer(const std::string& topic) {
    auto* w = broadcaster
                  ->writer_on<PubSubType>(node::dds_topic_name(config, topic),
                                          node::writer_qos(node::TopicQos::kLatest, true))
                  .value();
    const auto end = std::chrono::steady_clock::now() + 10s;
    while (node::matched_readers(w) == 0 && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(10ms);
    EXPECT_GT(node::matched_readers(w), 0) << topic;
    return w;
  }
  // Writes `msg` a few times (the node reads tf and clock best effort: one sample alone may be
  // lost, a stream is not), then leaves the node a moment to take it.
  template <class Msg>
  bool broadcast(node::dds::DataWriter* writer, Msg msg) {
    for (int i = 0; i < 3; ++i) {
      if (!writer->write(&msg)) return false;
      std::this_thread::sleep_for(20ms);
    }
    std::this_thread::sleep_for(200ms);
    return true;
  }
  // A goal at (1.55, 1.55) m, and its status.
  std::optional<PlanStatusMsg> goal(const std::string& id) {
    client.publish_goal(1.55, 1.55);
    return client.wait_status(id);
  }
  ~TfNode() {
    broadcaster->shutdown();
    node.stop();
  }

  node::NodeConfig config;
  node::PlannerNode node;
  BusClient client;
  std::unique_ptr<node::Participant> broadcaster =
      node::Participant::create(config.domain_id, "tf_broadcaster").value();
};

node::TFMessageMsg base_link_at(double x, double y, const node::TimeMsg& stamp) {
  geometry_msgs::msg::dds_::TransformStamped_ t;
  t.header().frame_id("map");
  t.header().stamp(stamp);
  t.child_frame_id("base_link");
  t.transform().translation().x(x);
  t.transform().translation().y(y);
  t.transform().rotation().w(1.0);
  node::TFMessageMsg msg;
  msg.transforms().push_back(t);
  return msg;
}

// Issue 31 item 7: after 20 /tf messages of 20,000 chained frames each, the next goal_pose got
// no status at all (each message held the transforms' lock for 12 s). Now it gets its status at
// once, planned from the robot's transform, and the flood is one warning per limit it reached.
TEST(TfOnTheBus, AGoalAfterAFloodOfChainedFramesGetsItsStatus) {
  const LogCapture log;
  TfNode run("tfflood");
  ASSERT_TRUE(run.start());
  auto* tf = run.writer<tf2_msgs::msg::dds_::TFMessage_PubSubType>(run.config.topics.tf);
  // The robot broadcasts its transform from its start, at 20 Hz, as robots do: the node's tf
  // reader is best effort (one sample may be lost), and the node may still be working through
  // the flood when the goal comes (seconds under the sanitizers), where a single transform would
  // be older than transform_tolerance (0.5 s) by then.
  struct Broadcaster {
    std::atomic<bool> stop{false};
    std::atomic<bool> moved{false};  // (0.15, 0.15) before the flood, (0.25, 0.35) after it
    std::thread thread;
    ~Broadcaster() {
      stop = true;
      if (thread.joinable()) thread.join();
    }
  } robot;
  robot.thread = std::thread([&] {
    while (!robot.stop) {
      node::TFMessageMsg msg = robot.moved ? base_link_at(0.25, 0.35, node::now_msg())
                                           : base_link_at(0.15, 0.15, node::now_msg());
      tf->write(&msg);
      std::this_thread::sleep_for(50ms);
    }
  });
  // The node knows the robot's frame before the flood: a goal is planned from it.
  std::this_thread::sleep_for(200ms);
  const auto before = run.goal("goal-1");
  ASSERT_TRUE(before && before->code() == OK) << (before ? before->message() : "no status");
  const node::TFMessageMsg flood = node::chained_frames(20000, node::now_msg());
  for (int message = 0; message < 20; ++message) {
    node::TFMessageMsg copy = flood;
    ASSERT_TRUE(tf->write(&copy));
    std::this_thread::sleep_for(20ms);  // best effort on the node's side: room to take each
  }
  const std::string tf_topic = node::dds_topic_name(run.config, run.config.topics.tf);
  ASSERT_TRUE(log.wait_for({"'" + tf_topic + "': refused"}, 20s)) << "the flood never arrived";
  robot.moved = true;
  std::this_thread::sleep_for(200ms);
  // Every goal gets its status at once. While the node still works through the flood (seconds
  // under the sanitizers: the robot's newer broadcasts wait behind it in the tf reader) the
  // honest answer is a stale transform; once it is through, the goal plans from the new pose.
  std::optional<PlanStatusMsg> status;
  const auto give_up = std::chrono::steady_clock::now() + 30s;
  for (int goal = 2; std::chrono::steady_clock::now() < give_up; ++goal) {
    const auto start = std::chrono::steady_clock::now();
    status = run.goal("goal-" + std::to_string(goal));
    ASSERT_TRUE(status) << "no status for goal-" << goal << " after the flood";
    EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
    if (status->code() == OK) break;
    ASSERT_NE(status->message().find("stale"), std::string::npos) << status->message();
    std::this_thread::sleep_for(250ms);
  }
  ASSERT_EQ(status->code(), OK) << status->message();
  EXPECT_NEAR(status->path().poses().front().pose().position().x(), 0.25, 1e-9);
  EXPECT_NEAR(status->path().poses().front().pose().position().y(), 0.35, 1e-9);
  // One line per limit a message reached, each once: the first flood reaches both limits, the
  // next nineteen repeat one line (the node logs a repeated line once). The old code logged
  // one line per refused transform, up to its cap of 100.
  EXPECT_LE(log.matching({"'" + tf_topic + "': refused"}).size(), 3u);
}

// With use_sim_time a transform 56 years ahead of /clock is no start (it counted as fresh), nor
// are transforms from before the clock went back (a simulation reset).
TEST(TfOnTheBus, WithSimulatedTimeAFutureTransformOrAClockGoneBackIsNoStart) {
  const LogCapture log;
  TfNode run("tffuture", /*use_sim_time=*/true);
  ASSERT_TRUE(run.start());
  auto* clock = run.writer<rosgraph_msgs::msg::dds_::Clock_PubSubType>(run.config.topics.clock);
  auto* tf = run.writer<tf2_msgs::msg::dds_::TFMessage_PubSubType>(run.config.topics.tf);
  auto tick = [&](int32_t sec) {
    node::ClockMsg msg;
    msg.clock(node::at(sec));
    return run.broadcast(clock, msg);
  };
  ASSERT_TRUE(tick(600));
  ASSERT_TRUE(run.broadcast(tf, base_link_at(0.25, 0.35, node::at(600 + 56 * 31'557'600))));
  const auto future = run.goal("goal-1");
  ASSERT_TRUE(future);
  EXPECT_EQ(future->code(), INVALID_REQUEST);
  EXPECT_NE(future->message().find("in the future: 'map' -> 'base_link'"), std::string::npos)
      << future->message();

  ASSERT_TRUE(run.broadcast(tf, base_link_at(0.25, 0.35, node::at(600))));
  const auto planned = run.goal("goal-2");
  ASSERT_TRUE(planned);
  EXPECT_EQ(planned->code(), OK) << planned->message();

  ASSERT_TRUE(tick(30));  // the simulation restarts
  ASSERT_TRUE(log.wait_for({"[warning]", "went back from 600.000000000 s to 30.000000000 s"}, 5s));
  const auto reset = run.goal("goal-3");
  ASSERT_TRUE(reset);
  EXPECT_EQ(reset->code(), INVALID_REQUEST) << "a transform from before the reset was used";
  EXPECT_NE(reset->message().find("'base_link'"), std::string::npos) << reset->message();

  ASSERT_TRUE(tick(-7));
  ASSERT_TRUE(log.wait_for({"[warning]", "refused a clock of -7.000000000 s"}, 5s));
}

}  // namespace
}  // namespace vnsba::test
