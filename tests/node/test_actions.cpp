// Nav2's planner actions over loopback, with real participants: the node's action servers and
// ActionClient (the rcl_action protocol in rmw_fastrtps's mapping, and in rmw_cyclonedds's with
// the node told to use it; the Cyclone DDS client itself is in tests/interop). Oracles: the same
// plan asked through plan_request (one conversion, one planner: the paths must be equal), a
// brute-force walk of every path segment over the map's cells, and Nav2's error code table.
#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <mutex>
#include <random>
#include <thread>

#include "action_run.hpp"
#include "bus_client.hpp"
#include "log_capture.hpp"
#include "nav2_msgs/action/ComputePathToPosePubSubTypes.h"
#include "vnsba/node/action_client.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

using node::ActionClient;
using node::ActionGoalSpec;
using node::ActionKind;
using node::GoalState;
using node::WireMapping;

// 40 x 30 cells of 0.1 m, origin (0, 0): a wall at x = 20 with a door (y 12..17), a closed box
// around (5..9, 22..27) with a free inside, and an occupied block at (30..33, 5..8).
core::OccupancyGrid office() {
  core::OccupancyGrid g;
  g.width = 40;
  g.height = 30;
  g.resolution = 0.1;
  g.data.assign(static_cast<size_t>(g.width * g.height), core::kOccupancyFree);
  auto set = [&](int x, int y) { g.data[static_cast<size_t>(y * g.width + x)] = 100; };
  for (int y = 0; y < g.height; ++y)
    if (y < 12 || y > 17) set(20, y);
  for (int x = 5; x <= 9; ++x) {
    set(x, 22);
    set(x, 27);
  }
  for (int y = 22; y <= 27; ++y) {
    set(5, y);
    set(9, y);
  }
  for (int x = 30; x <= 33; ++x)
    for (int y = 5; y <= 8; ++y) set(x, y);
  return g;
}

node::PoseStampedMsg pose(double x, double y, const std::string& frame = "map") {
  return node::to_pose_msg(x, y, 0.0, frame, node::now_msg());
}

ActionGoalSpec to_pose(double sx, double sy, double gx, double gy,
                       const std::string& planner = "") {
  ActionGoalSpec spec;
  spec.goals = {pose(gx, gy)};
  spec.start = pose(sx, sy);
  spec.planner_id = planner;
  spec.use_start = true;
  return spec;
}

class BothMappings : public ::testing::TestWithParam<WireMapping> {};

std::string mapping_name(const ::testing::TestParamInfo<WireMapping>& info) {
  return info.param == WireMapping::kRequestHeader ? "RequestHeader" : "SampleIdentity";
}

TEST_P(BothMappings, ComputePathToPoseGivesThePlanRequestsPathEndingAtTheGoal) {
  ActionRun run("act_ok", GetParam());
  const core::OccupancyGrid grid = office();
  ASSERT_TRUE(run.start(grid));
  for (const std::string planner : {"", "astar", "jps"}) {
    SCOPED_TRACE("planner '" + planner + "'");
    const auto id = ActionClient::random_id();
    const auto result = run.to_pose->plan(id, to_pose(0.55, 0.45, 3.73, 2.61, planner), 15s);
    ASSERT_TRUE(result.has_value()) << "no result";
    EXPECT_EQ(result->status, GoalState::kSucceeded) << result->error_msg;
    EXPECT_EQ(result->error_code, 0);
    ASSERT_GE(result->path.poses().size(), 2u);
    const auto& first = result->path.poses().front().pose().position();
    const auto& last = result->path.poses().back().pose().position();
    EXPECT_NEAR(first.x(), 0.55, 1e-9);
    EXPECT_NEAR(first.y(), 0.45, 1e-9);
    EXPECT_NEAR(last.x(), 3.73, 1e-9);
    EXPECT_NEAR(last.y(), 2.61, 1e-9);
    EXPECT_TRUE(path_free(grid, result->path));
    EXPECT_GT(result->planning_time_s, 0.0);
    EXPECT_LT(result->planning_time_s, 10.0);
    EXPECT_TRUE(run.to_pose->wait_status(id, GoalState::kSucceeded, 5s))
        << "the status topic shows the goal succeeded";
    // The same plan through plan_request: the same path.
    run.client.publish_request("same_" + planner, 0.55, 0.45, 3.73, 2.61, planner);
    const auto status = run.client.wait_status("same_" + planner);
    ASSERT_TRUE(status.has_value());
    ASSERT_EQ(status->path().poses().size(), result->path.poses().size());
    for (size_t i = 0; i < result->path.poses().size(); ++i) {
      EXPECT_DOUBLE_EQ(status->path().poses()[i].pose().position().x(),
                       result->path.poses()[i].pose().position().x());
      EXPECT_DOUBLE_EQ(status->path().poses()[i].pose().position().y(),
                       result->path.poses()[i].pose().position().y());
    }
  }
  EXPECT_EQ(run.to_pose->duplicate_replies(), 0u);
}

TEST_P(BothMappings, ComputePathThroughPosesPassesThroughEveryPoseInOrder) {
  ActionRun run("act_through", GetParam());
  const core::OccupancyGrid grid = office();
  ASSERT_TRUE(run.start(grid));
  ActionGoalSpec spec;
  spec.start = pose(0.55, 0.45);
  spec.goals = {pose(1.05, 2.55), pose(3.55, 2.05), pose(3.65, 0.35)};
  const auto result = run.through->plan(ActionClient::random_id(), spec, 15s);
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->status, GoalState::kSucceeded) << result->error_msg;
  EXPECT_EQ(result->error_code, 0);
  EXPECT_TRUE(path_free(grid, result->path));
  // Each pose is on the path, in order.
  size_t from = 0;
  for (const auto& goal : spec.goals) {
    bool found = false;
    for (; from < result->path.poses().size() && !found; ++from) {
      const auto& p = result->path.poses()[from].pose().position();
      found =
          std::hypot(p.x() - goal.pose().position().x(), p.y() - goal.pose().position().y()) < 1e-9;
    }
    EXPECT_TRUE(found) << "goal (" << goal.pose().position().x() << ", "
                       << goal.pose().position().y() << ") not on the path after the previous one";
  }
  // An empty list: NO_VIAPOINTS_GIVEN.
  ActionGoalSpec empty;
  empty.start = pose(0.55, 0.45);
  const auto none = run.through->plan(ActionClient::random_id(), empty, 15s);
  ASSERT_TRUE(none.has_value());
  EXPECT_EQ(none->status, GoalState::kAborted);
  EXPECT_EQ(none->error_code, 309);
  // A leg that fails: its code, plus 100, and which leg.
  spec.goals[1] = pose(3.15, 0.65);  // in the occupied block
  const auto blocked = run.through->plan(ActionClient::random_id(), spec, 15s);
  ASSERT_TRUE(blocked.has_value());
  EXPECT_EQ(blocked->status, GoalState::kAborted);
  EXPECT_EQ(blocked->error_code, 306) << blocked->error_msg;
  EXPECT_NE(blocked->error_msg.find("leg 2 of 3"), std::string::npos) << blocked->error_msg;
}

INSTANTIATE_TEST_SUITE_P(NavActions, BothMappings,
                         ::testing::Values(WireMapping::kSampleIdentity,
                                           WireMapping::kRequestHeader),
                         mapping_name);

// Every failure the node can produce, with Nav2's code (ROS 2 Jazzy nav2_msgs).
TEST(NavActions, EachFailureGetsNav2sErrorCodeAndAMessageNamingTheProblem) {
  node::NodeConfig base = paper_test_config();
  base.planner.settings.max_planning_time = std::chrono::seconds(10);
  ActionRun run("act_codes", WireMapping::kSampleIdentity, base);
  ASSERT_TRUE(run.start(office()));
  struct Case {
    const char* what;
    ActionGoalSpec spec;
    uint16_t code;
    const char* in_message;
  };
  ActionGoalSpec nan_goal = to_pose(0.55, 0.45, 1.0, 1.0);
  nan_goal.goals[0].pose().position().x(std::nan(""));
  ActionGoalSpec empty_frame = to_pose(0.55, 0.45, 1.0, 1.0);
  empty_frame.goals[0].header().frame_id("");
  ActionGoalSpec other_frame = to_pose(0.55, 0.45, 1.0, 1.0);
  other_frame.goals[0].header().frame_id("odom");
  const std::vector<Case> cases = {
      {"start outside", to_pose(-1.0, 0.45, 1.0, 1.0), 203, "start"},
      {"goal outside", to_pose(0.55, 0.45, 9.0, 1.0), 204, "goal"},
      {"start occupied", to_pose(2.05, 0.45, 1.0, 1.0), 205, "start"},
      {"goal occupied", to_pose(0.55, 0.45, 3.15, 0.65), 206, "goal"},
      {"no valid path", to_pose(0.55, 0.45, 0.75, 2.45), 208, ""},
      {"unknown planner", to_pose(0.55, 0.45, 1.0, 1.0, "dstar"), 201, "astar"},
      {"NaN goal", nan_goal, 200, "goal.pose.position.x"},
      {"another frame", other_frame, 202, "odom"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const auto result = run.to_pose->plan(ActionClient::random_id(), c.spec, 15s);
    ASSERT_TRUE(result.has_value()) << "no result";
    EXPECT_EQ(result->status, GoalState::kAborted);
    EXPECT_EQ(result->error_code, c.code) << result->error_msg;
    EXPECT_NE(result->error_msg.find(c.in_message), std::string::npos) << result->error_msg;
    EXPECT_TRUE(result->path.poses().empty());
  }
  // The node keeps serving; an empty frame_id means the map's frame, as for plan_request.
  const auto ok = run.to_pose->plan(ActionClient::random_id(), empty_frame, 15s);
  ASSERT_TRUE(ok.has_value());
  EXPECT_EQ(ok->status, GoalState::kSucceeded) << ok->error_msg;
}

TEST(NavActions, TooManyPosesAndAReusedIdAreRefusedAndTheNodeKeepsServing) {
  ActionRun run("act_bad", WireMapping::kSampleIdentity);
  ASSERT_TRUE(run.start(office()));
  ActionGoalSpec many;
  many.start = pose(0.55, 0.45);
  many.goals.assign(100000, pose(1.0, 1.0));
  const auto too_many = run.through->plan(ActionClient::random_id(), many, 30s);
  ASSERT_TRUE(too_many.has_value());
  EXPECT_EQ(too_many->status, GoalState::kAborted);
  EXPECT_EQ(too_many->error_code, 300);
  EXPECT_NE(too_many->error_msg.find("goals: found 100000 poses"), std::string::npos)
      << too_many->error_msg;
  // A reused id while its goal is kept: rejected; the first keeps its result.
  const auto id = ActionClient::random_id();
  const auto first = run.to_pose->plan(id, to_pose(0.55, 0.45, 1.0, 1.0), 15s);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->status, GoalState::kSucceeded);
  const auto again =
      run.to_pose->wait_accepted(run.to_pose->send_goal(id, to_pose(0.55, 0.45, 2.0, 1.0)), 15s);
  ASSERT_TRUE(again.has_value());
  EXPECT_FALSE(*again);
  const auto kept = run.to_pose->wait_result(run.to_pose->request_result(id), 15s);
  ASSERT_TRUE(kept.has_value());
  EXPECT_EQ(kept->status, GoalState::kSucceeded);
  EXPECT_NEAR(kept->path.poses().back().pose().position().x(), 1.0, 1e-9) << "the first goal's";
}

// A map whose plan takes long: 1600 x 1600 cells with walls every 40 rows, each open at
// alternate ends, so A* from one corner to the far corner walks the whole serpentine.
core::OccupancyGrid serpentine() {
  core::OccupancyGrid g;
  g.width = 1600;
  g.height = 1600;
  g.resolution = 0.05;
  g.data.assign(static_cast<size_t>(g.width) * g.height, core::kOccupancyFree);
  for (int y = 40, k = 0; y < g.height; y += 40, ++k)
    for (int x = 0; x < g.width; ++x)
      if ((k % 2 == 0) ? x < g.width - 3 : x >= 3)
        g.data[static_cast<size_t>(y) * g.width + x] = 100;
  return g;
}
// The centre of the serpentine's far corner cell, metres (x and y).
constexpr double kFar = 1600 * 0.05 - 0.025;

// A goal across the serpentine with astar (a plan of seconds), sent by `client`: its id once the
// node accepted it, nullopt otherwise.
std::optional<node::GoalUuid> long_goal_accepted(ActionClient& client, double goal_y = kFar) {
  const auto id = ActionClient::random_id();
  const auto accepted =
      client.wait_accepted(client.send_goal(id, to_pose(0.025, 0.025, kFar, goal_y, "astar")), 15s);
  if (!accepted.value_or(false)) return std::nullopt;
  return id;
}

// A ComputePathToPose client on a participant of its own; the client goes first (its endpoints
// before the participant).
struct OwnClient {
  OwnClient(const node::NodeConfig& cfg, const char* name)
      : participant(node::Participant::create(cfg.domain_id, name).value()),
        client(ActionClient::create(*participant,
                                    node::ros_topic_name(cfg, cfg.topics.compute_path_to_pose),
                                    ActionKind::kComputePathToPose, WireMapping::kSampleIdentity)
                   .value()) {}
  ~OwnClient() {
    client.reset();
    participant->shutdown();
  }
  std::unique_ptr<node::Participant> participant;
  std::unique_ptr<ActionClient> client;
};

// Sends `goals` at once, then asks for each result once its goal is accepted, as rclcpp_action
// does (a get_result before the acceptance would find no goal: UNKNOWN); the results received,
// each within `timeout`, in the goals' order.
std::vector<std::optional<node::ActionResultReply>> burst_of_goals(
    ActionClient& client, const std::vector<ActionGoalSpec>& goals,
    std::chrono::milliseconds timeout) {
  std::vector<std::pair<node::GoalUuid, int64_t>> sent;
  for (const ActionGoalSpec& goal : goals) {
    const auto id = ActionClient::random_id();
    sent.emplace_back(id, client.send_goal(id, goal));
  }
  for (auto& [id, request] : sent) {
    const auto accepted = client.wait_accepted(request, timeout);
    request = accepted.value_or(false) ? client.request_result(id) : -1;
  }
  std::vector<std::optional<node::ActionResultReply>> results;
  for (const auto& [id, request] : sent) results.push_back(client.wait_result(request, timeout));
  return results;
}

TEST(NavActions, ACancelStopsARunningGoalAndAGetResultSentEarlyGetsTheEnd) {
  node::NodeConfig base = paper_test_config();
  base.preempt = false;
  // The serpentine's path is 3.1 km long: 91,691 poses at 5 cm, past the default's 50,000.
  base.actions.max_result_poses = 200000;
  ActionRun run("act_cancel", WireMapping::kSampleIdentity, base);
  const core::OccupancyGrid grid = serpentine();
  ASSERT_TRUE(run.start(grid));
  // get_result right after acceptance, while the plan runs: answered when it ends.
  const auto accepted_early = long_goal_accepted(*run.to_pose);
  ASSERT_TRUE(accepted_early.has_value());
  const node::GoalUuid early = *accepted_early;
  const int64_t result_request = run.to_pose->request_result(early);
  EXPECT_TRUE(run.to_pose->wait_status(early, GoalState::kExecuting, 10s))
      << "the status topic never showed the goal executing";
  const auto done = run.to_pose->wait_result(result_request, 60s);
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->status, GoalState::kSucceeded) << done->error_msg;
  EXPECT_TRUE(path_free(grid, done->path));
  EXPECT_GT(done->planning_time_s, 0.05) << "too quick to test a cancel on";

  // Cancel while it runs.
  const auto accepted = long_goal_accepted(*run.to_pose);
  ASSERT_TRUE(accepted.has_value());
  const node::GoalUuid id = *accepted;
  const int64_t pending = run.to_pose->request_result(id);
  ASSERT_TRUE(run.to_pose->wait_status(id, GoalState::kExecuting, 10s));
  const auto cancel = run.to_pose->wait_cancel(run.to_pose->request_cancel(id), 15s);
  ASSERT_TRUE(cancel.has_value());
  EXPECT_EQ(cancel->code, node::CancelCode::kNone);
  EXPECT_EQ(cancel->canceling, std::vector<node::GoalUuid>{id});
  const auto canceled = run.to_pose->wait_result(pending, 15s);
  ASSERT_TRUE(canceled.has_value());
  EXPECT_EQ(canceled->status, GoalState::kCanceled) << canceled->error_msg;
  EXPECT_TRUE(canceled->path.poses().empty());
  EXPECT_TRUE(run.to_pose->wait_status(id, GoalState::kCanceled, 5s));
  // Canceling a finished goal: GOAL_TERMINATED; an unknown one: UNKNOWN_GOAL_ID.
  const auto late = run.to_pose->wait_cancel(run.to_pose->request_cancel(id), 15s);
  ASSERT_TRUE(late.has_value());
  EXPECT_EQ(late->code, node::CancelCode::kGoalTerminated);
  const auto unknown =
      run.to_pose->wait_cancel(run.to_pose->request_cancel(ActionClient::random_id()), 15s);
  ASSERT_TRUE(unknown.has_value());
  EXPECT_EQ(unknown->code, node::CancelCode::kUnknownGoalId);
}

TEST(NavActions, ARunOutPlanningBudgetIsNav2sTimeoutOnBothActions) {
  node::NodeConfig base = paper_test_config();
  base.planner.settings.max_planning_time = std::chrono::milliseconds(1);
  ActionRun run("act_timeout", WireMapping::kSampleIdentity, base);
  ASSERT_TRUE(run.start(serpentine()));
  const auto to_pose_result =
      run.to_pose->plan(ActionClient::random_id(), to_pose(0.025, 0.025, kFar, kFar, "astar"), 30s);
  ASSERT_TRUE(to_pose_result.has_value());
  EXPECT_EQ(to_pose_result->status, GoalState::kAborted);
  EXPECT_EQ(to_pose_result->error_code, 207) << to_pose_result->error_msg;
  ActionGoalSpec through;
  through.start = pose(0.025, 0.025);
  through.goals = {pose(0.5, 0.5), pose(kFar, kFar)};
  const auto through_result = run.through->plan(ActionClient::random_id(), through, 30s);
  ASSERT_TRUE(through_result.has_value());
  EXPECT_EQ(through_result->status, GoalState::kAborted);
  EXPECT_EQ(through_result->error_code, 307) << through_result->error_msg;
  EXPECT_NE(through_result->error_msg.find("leg 2 of 2"), std::string::npos)
      << through_result->error_msg;
}

// A shutdown with goals running and waiting: each gets its result (ABORTED, the node shutting
// down) before the node's writers go.
TEST(NavActions, AShutdownAnswersEveryAcceptedGoal) {
  node::NodeConfig base = paper_test_config();
  base.preempt = false;
  ActionRun run("act_stop", WireMapping::kSampleIdentity, base);
  ASSERT_TRUE(run.start(serpentine()));
  std::vector<int64_t> pending;
  std::vector<node::GoalUuid> ids;
  for (int g = 0; g < 3; ++g) {
    const auto id = long_goal_accepted(*run.to_pose, kFar - g);
    ASSERT_TRUE(id.has_value());
    pending.push_back(run.to_pose->request_result(*id));
    ids.push_back(*id);
  }
  ASSERT_TRUE(run.to_pose->wait_status(ids[0], GoalState::kExecuting, 10s));
  run.node.stop();  // returns once every reply is acknowledged (or the drain's 10 s passed)
  for (int64_t request : pending) {
    const auto result = run.to_pose->wait_result(request, 0ms);
    ASSERT_TRUE(result.has_value()) << "a goal without a result after the shutdown";
    EXPECT_EQ(result->status, GoalState::kAborted);
    EXPECT_EQ(result->error_code, 200);
    EXPECT_NE(result->error_msg.find("shutting down"), std::string::npos) << result->error_msg;
  }
}

TEST(NavActions, TwentyConcurrentGoalsFromFiveClientsGetOneResultEach) {
  node::NodeConfig base = paper_test_config();
  base.preempt = false;
  ActionRun run("act_many", WireMapping::kSampleIdentity, base);
  const core::OccupancyGrid grid = office();
  ASSERT_TRUE(run.start(grid));
  constexpr int kClients = 5, kGoals = 4;
  std::vector<std::thread> threads;
  std::atomic<int> succeeded{0}, failed{0};
  std::atomic<size_t> duplicates{0};
  for (int c = 0; c < kClients; ++c) {
    threads.emplace_back([&, c] {
      OwnClient own(run.cfg, "client");
      if (!own.client->wait_for_server(15s)) {
        failed += kGoals;
        return;
      }
      std::vector<ActionGoalSpec> goals;
      for (int g = 0; g < kGoals; ++g)
        goals.push_back(to_pose(0.55, 0.45, 3.55 + 0.01 * g, 0.35 + 0.1 * c));
      for (const auto& result : burst_of_goals(*own.client, goals, 30s)) {
        if (result && result->status == GoalState::kSucceeded && path_free(grid, result->path))
          ++succeeded;
        else
          ++failed;
      }
      std::this_thread::sleep_for(300ms);  // a duplicate would arrive by now
      duplicates += own.client->duplicate_replies();
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(succeeded, kClients * kGoals);
  EXPECT_EQ(failed, 0);
  EXPECT_EQ(duplicates, 0u);
}

TEST(NavActions, AClientThatVanishesMidGoalLeavesNothingBehindAfterTheResultTimeout) {
  node::NodeConfig base = paper_test_config();
  base.actions.result_timeout = std::chrono::milliseconds(500);
  ActionRun run("act_vanish", WireMapping::kSampleIdentity, base);
  ASSERT_TRUE(run.start(serpentine()));
  {
    OwnClient vanishing(run.cfg, "vanishing");
    ASSERT_TRUE(vanishing.client->wait_for_server(15s));
    const auto id = long_goal_accepted(*vanishing.client);
    ASSERT_TRUE(id.has_value());
    vanishing.client->request_result(*id);
  }  // gone mid-goal
  EXPECT_GE(run.node.stats().action_goals, 1u);
  const auto end = std::chrono::steady_clock::now() + 60s;
  while (run.node.stats().action_goals > 0 && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(50ms);
  EXPECT_EQ(run.node.stats().action_goals, 0u) << "the finished goal was never forgotten";
  // The node still serves.
  const auto ok =
      run.to_pose->plan(ActionClient::random_id(), to_pose(0.025, 0.025, 1.0, 1.0), 15s);
  ASSERT_TRUE(ok.has_value());
  EXPECT_EQ(ok->status, GoalState::kSucceeded);
}

}  // namespace
}  // namespace vnsba::test

namespace vnsba::test {
namespace {

// 10 clients x 1,000 goals each, all sent at once, results requested as each goal is accepted:
// every goal gets exactly one result (label stress: about a minute on two cores).
TEST(StressBursts, TenThousandActionGoalsFromTenClientsEachGetOneResult) {
  node::NodeConfig base = paper_test_config();
  base.preempt = false;
  base.queue_capacity = 100000;
  base.planner.kind = core::PlannerKind::kJps;
  ActionRun run("act_stress", WireMapping::kSampleIdentity, base);
  const core::OccupancyGrid grid = office();
  ASSERT_TRUE(run.start(grid));
  constexpr int kClients = 10, kGoals = 1000;
  std::atomic<int> results{0}, succeeded{0};
  std::atomic<size_t> duplicates{0};
  std::vector<std::thread> threads;
  const auto t0 = std::chrono::steady_clock::now();
  for (int c = 0; c < kClients; ++c) {
    threads.emplace_back([&, c] {
      OwnClient own(run.cfg, "stress_client");
      if (!own.client->wait_for_server(15s)) return;
      const std::vector<ActionGoalSpec> goals(kGoals, to_pose(0.55, 0.45, 3.55, 0.35 + 0.02 * c));
      for (const auto& result : burst_of_goals(*own.client, goals, 120s)) {
        if (!result) continue;
        ++results;
        if (result->status == GoalState::kSucceeded) ++succeeded;
      }
      std::this_thread::sleep_for(500ms);
      duplicates += own.client->duplicate_replies();
    });
  }
  for (auto& t : threads) t.join();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%d goals from %d clients: %d results, %d succeeded, %zu duplicates, %.1f s\n",
              kClients * kGoals, kClients, results.load(), succeeded.load(), duplicates.load(),
              seconds);
  EXPECT_EQ(results, kClients * kGoals) << "goals without a result";
  EXPECT_EQ(succeeded, kClients * kGoals);
  EXPECT_EQ(duplicates, 0u);
}

}  // namespace
}  // namespace vnsba::test

namespace vnsba::test {
namespace {

// Bytes that are no request: garbage, truncated requests, another encapsulation, a sequence
// count far beyond the sample. Each is dropped with a log line (nothing to answer without a goal
// id); the node keeps serving and answers a valid goal afterwards.
TEST(NavActions, MalformedRequestBytesAreDroppedAndTheNodeKeepsServing) {
  ActionRun run("act_garbage", WireMapping::kSampleIdentity);
  ASSERT_TRUE(run.start(office()));
  std::mt19937 rng(5);
  using Service = node::ActionService;
  for (ActionClient* client : {run.to_pose.get(), run.through.get()}) {
    for (Service service : {Service::kSendGoal, Service::kGetResult, Service::kCancelGoal}) {
      for (int i = 0; i < 40; ++i) {
        node::RawSample garbage;
        garbage.bytes.resize(rng() % 120);
        for (uint8_t& b : garbage.bytes) b = static_cast<uint8_t>(rng());
        if (i % 2 == 0 && garbage.bytes.size() >= 2) {  // plain CDR, so decoding is attempted
          garbage.bytes[0] = 0;
          garbage.bytes[1] = 1;
        }
        client->send_raw(service, garbage);
      }
    }
  }
  // ThroughPoses announcing 2^31 - 1 poses in 44 bytes.
  node::RawSample huge;
  huge.bytes = {0, 1, 0, 0};
  huge.bytes.resize(4 + 16, 7);
  for (uint8_t b : {0xff, 0xff, 0xff, 0x7f}) huge.bytes.push_back(b);
  huge.bytes.resize(44, 0);
  run.through->send_raw(Service::kSendGoal, huge);
  // A valid request cut short.
  node::RawSample cut;
  cut.bytes = {0, 1, 0, 0};
  cut.bytes.resize(30, 1);
  run.to_pose->send_raw(Service::kSendGoal, cut);
  std::this_thread::sleep_for(300ms);
  EXPECT_EQ(run.node.stats().action_goals, 0u) << "no goal came of the garbage";
  const auto ok = run.to_pose->plan(ActionClient::random_id(), to_pose(0.55, 0.45, 1.0, 1.0), 15s);
  ASSERT_TRUE(ok.has_value());
  EXPECT_EQ(ok->status, GoalState::kSucceeded);
  ActionGoalSpec through;
  through.start = pose(0.55, 0.45);
  through.goals = {pose(1.0, 1.0), pose(1.5, 0.5)};
  const auto ok2 = run.through->plan(ActionClient::random_id(), through, 15s);
  ASSERT_TRUE(ok2.has_value());
  EXPECT_EQ(ok2->status, GoalState::kSucceeded);
}

}  // namespace
}  // namespace vnsba::test

// Issue 44: limits that no client can push the node past, each named when it refuses.
namespace vnsba::test {
namespace {

// 200 x 200 cells of 0.05 m, open but for a wall across the middle with a door at its left end.
core::OccupancyGrid open_room() {
  core::OccupancyGrid g;
  g.width = 200;
  g.height = 200;
  g.resolution = 0.05;
  g.data.assign(static_cast<size_t>(g.width * g.height), core::kOccupancyFree);
  for (int x = 20; x < g.width; ++x) g.data[static_cast<size_t>(100 * g.width + x)] = 100;
  return g;
}

// Nav2's default behaviour trees ask for planner "GridBased": planner.aliases maps it to the
// configured planner by default, and a configured alias to the planner it names. An unknown id
// is INVALID_PLANNER (201) naming the aliases too, and so is a 100 kB id (which once got 200),
// whose message does not echo it.
TEST(NavActions, GridBasedAndConfiguredAliasesNameAPlanner) {
  node::NodeConfig base = paper_test_config();
  base.planner.kind = core::PlannerKind::kAStar;
  base.planner.aliases = {{"GridBased", node::kDefaultPlannerAlias}, {"Fast", "jps"}};
  ActionRun run("act_alias", WireMapping::kSampleIdentity, base);
  LogCapture log;
  ASSERT_TRUE(run.start(office()));
  for (const auto& [id, planner] : {std::pair{"GridBased", "astar"}, std::pair{"Fast", "jps"}}) {
    SCOPED_TRACE(id);
    const auto goal_id = ActionClient::random_id();
    const auto result = run.to_pose->plan(goal_id, to_pose(0.55, 0.45, 3.55, 0.35, id), 15s);
    ASSERT_TRUE(result.has_value());
    EXPECT_EQ(result->status, GoalState::kSucceeded) << result->error_msg;
    EXPECT_TRUE(path_free(office(), result->path));
    std::string hex;
    for (uint8_t b : goal_id) {
      char text[3];
      std::snprintf(text, sizeof text, "%02x", b);
      hex += text;
    }
    EXPECT_TRUE(log.wait_for({hex, std::string(" ") + planner + " OK"}, 5s))
        << "the plan's log line does not name " << planner;
  }
  const auto unknown =
      run.to_pose->plan(ActionClient::random_id(), to_pose(0.55, 0.45, 1.0, 1.0, "Smac"), 15s);
  ASSERT_TRUE(unknown.has_value());
  EXPECT_EQ(unknown->error_code, 201);
  EXPECT_NE(unknown->error_msg.find("GridBased"), std::string::npos) << unknown->error_msg;
  const std::string huge(100000, 'p');
  const auto long_id =
      run.to_pose->plan(ActionClient::random_id(), to_pose(0.55, 0.45, 1.0, 1.0, huge), 15s);
  ASSERT_TRUE(long_id.has_value());
  EXPECT_EQ(long_id->status, GoalState::kAborted);
  EXPECT_EQ(long_id->error_code, 201) << long_id->error_msg;
  EXPECT_LT(long_id->error_msg.size(), 200u) << "the id is echoed";
}

// actions.max_result_poses: a goal whose straight lines need more poses is refused before any
// planning, one whose path turns out longer after it, each naming the key; actions.max_goal_poses
// likewise for the goals of a ComputePathThroughPoses goal. A SUCCEEDED result carries no
// error_msg (Nav2's planner server's do not), even when the goal was moved.
TEST(NavActions, ResultsAndGoalListsOverTheirLimitsAreRefusedNamingTheKey) {
  node::NodeConfig base = paper_test_config();
  base.actions.max_result_poses = 60;  // 3 m at 5 cm
  base.actions.max_goal_poses = 3;
  base.planner.settings.goal_tolerance = 0.2;
  ActionRun run("act_limits", WireMapping::kSampleIdentity, base);
  LogCapture log;
  ASSERT_TRUE(run.start(open_room()));
  // Straight: 8.5 m, 171 poses at least.
  const auto far = run.to_pose->plan(ActionClient::random_id(), to_pose(0.5, 0.5, 9.0, 0.5), 15s);
  ASSERT_TRUE(far.has_value());
  EXPECT_EQ(far->status, GoalState::kAborted);
  EXPECT_EQ(far->error_code, 200);
  EXPECT_NE(far->error_msg.find("actions.max_result_poses (60)"), std::string::npos)
      << far->error_msg;
  EXPECT_NE(far->error_msg.find("straight lines"), std::string::npos) << far->error_msg;
  EXPECT_TRUE(log.matching({"plan '", "actions.max_result_poses"}).empty())
      << "it was planned first";
  // 1 m apart across the wall (2 lines of 21 poses), but the path goes round through the door.
  const auto round = run.to_pose->plan(ActionClient::random_id(), to_pose(5.0, 4.5, 5.0, 5.5), 15s);
  ASSERT_TRUE(round.has_value());
  EXPECT_EQ(round->status, GoalState::kAborted);
  EXPECT_EQ(round->error_code, 200);
  EXPECT_NE(round->error_msg.find("the path has"), std::string::npos) << round->error_msg;
  EXPECT_NE(round->error_msg.find("actions.max_result_poses (60)"), std::string::npos);
  EXPECT_TRUE(round->path.poses().empty());
  ActionGoalSpec four;
  four.start = pose(0.5, 0.5);
  four.goals = {pose(0.6, 0.5), pose(0.7, 0.5), pose(0.8, 0.5), pose(0.9, 0.5)};
  const auto too_many = run.through->plan(ActionClient::random_id(), four, 15s);
  ASSERT_TRUE(too_many.has_value());
  EXPECT_EQ(too_many->error_code, 300);
  EXPECT_NE(too_many->error_msg.find("actions.max_goal_poses"), std::string::npos)
      << too_many->error_msg;
  // Within the limits, with a goal in the wall that goal_tolerance moves: SUCCEEDED, the move in
  // the log only.
  const auto moved =
      run.to_pose->plan(ActionClient::random_id(), to_pose(2.0, 4.0, 2.0, 5.02), 15s);
  ASSERT_TRUE(moved.has_value());
  EXPECT_EQ(moved->status, GoalState::kSucceeded) << moved->error_msg;
  EXPECT_EQ(moved->error_msg, "");
  EXPECT_TRUE(log.wait_for({"goal_tolerance"}, 5s)) << "the move is not in the log";
}

// Many get_result requests of one goal each get the whole result, the same; results kept past
// actions.kept_results_mb are forgotten over both action servers, the oldest delivered first
// (a later get_result answers UNKNOWN); the status list holds the goals not finished and the last
// actions.status_finished_goals that did.
TEST(NavActions, KeptResultsShareOneByteBudgetAndTheStatusListIsBounded) {
  node::NodeConfig base = paper_test_config();
  base.actions.kept_results_mb = 1;
  base.actions.status_finished_goals = 4;
  base.preempt = false;
  ActionRun run("act_budget", WireMapping::kSampleIdentity, base);
  ASSERT_TRUE(run.start(open_room()));
  // One goal's result asked 30 times: 30 equal results.
  const auto first = ActionClient::random_id();
  const auto result = run.to_pose->plan(first, to_pose(0.5, 0.5, 9.5, 9.5), 15s);
  ASSERT_TRUE(result.has_value());
  ASSERT_EQ(result->status, GoalState::kSucceeded) << result->error_msg;
  std::vector<int64_t> asked;
  for (int i = 0; i < 30; ++i) asked.push_back(run.to_pose->request_result(first));
  for (int64_t request : asked) {
    const auto again = run.to_pose->wait_result(request, 15s);
    ASSERT_TRUE(again.has_value());
    ASSERT_EQ(again->path.poses().size(), result->path.poses().size());
    EXPECT_EQ(again->path.poses().back().pose().position().x(),
              result->path.poses().back().pose().position().x());
  }
  // Each long result is 300-600 poses of 72 bytes: 40 of them, on both actions, exceed 1 MiB.
  std::vector<node::GoalUuid> ids;
  for (int i = 0; i < 20; ++i) {
    ids.push_back(ActionClient::random_id());
    const auto r = run.to_pose->plan(ids.back(), to_pose(0.5, 0.5, 9.5, 9.5 - 0.01 * i), 15s);
    ASSERT_TRUE(r.has_value() && r->status == GoalState::kSucceeded);
  }
  for (int i = 0; i < 20; ++i) {
    ActionGoalSpec spec;
    spec.start = pose(0.5, 0.5);
    spec.goals = {pose(9.5, 9.5 - 0.01 * i), pose(0.5, 9.5)};
    const auto r = run.through->plan(ActionClient::random_id(), spec, 15s);
    ASSERT_TRUE(r.has_value() && r->status == GoalState::kSucceeded) << (r ? r->error_msg : "");
  }
  const auto end = std::chrono::steady_clock::now() + 10s;
  std::optional<node::ActionResultReply> oldest;
  do {
    oldest = run.to_pose->wait_result(run.to_pose->request_result(first), 15s);
    ASSERT_TRUE(oldest.has_value());
  } while (oldest->status != GoalState::kUnknown && std::chrono::steady_clock::now() < end);
  EXPECT_EQ(oldest->status, GoalState::kUnknown) << "the oldest result was never forgotten";
  const auto newest = run.to_pose->wait_result(run.to_pose->request_result(ids.back()), 15s);
  ASSERT_TRUE(newest.has_value());
  EXPECT_EQ(newest->status, GoalState::kSucceeded) << "the newest result was forgotten";
  EXPECT_TRUE(run.to_pose->wait_status(ids.back(), GoalState::kSucceeded, 5s));
  EXPECT_LE(run.to_pose->status_list_size(), 4u);
  EXPECT_EQ(run.to_pose->status_of(ids.front()), GoalState::kUnknown) << "an old goal is listed";
}

// A reader of get_result replies whose process stops acknowledging (here its participant's
// receiving thread is stuck in the reader's listener, as in a stopped or overloaded process)
// held every other client's results once 1,024 were unacknowledged. With it matched, 1,100
// goals of another client get their results, and the node names the readers' participants.
class StuckListener : public eprosima::fastdds::dds::DataReaderListener {
 public:
  void on_data_available(eprosima::fastdds::dds::DataReader*) override {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [&] { return released_; });
  }
  void release() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      released_ = true;
    }
    cv_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool released_ = false;
};

TEST(NavActions, AReaderThatNeverTakesItsRepliesStallsNoOtherClient) {
  node::NodeConfig base = paper_test_config();
  base.preempt = false;
  base.queue_capacity = 2000;
  base.actions.reply_ack_timeout = std::chrono::milliseconds(300);
  ActionRun run("act_stall", WireMapping::kSampleIdentity, base);
  LogCapture log;
  ASSERT_TRUE(run.start(office()));
  // The stalled reader, on a participant of its own.
  auto stalled = node::Participant::create(run.cfg.domain_id, "stalled_reader").value();
  StuckListener stuck;
  const eprosima::fastdds::dds::DataReaderQos qos = node::reader_qos(node::TopicQos::kEvents);
  const std::string topic = "rr" +
                            node::ros_topic_name(run.cfg, run.cfg.topics.compute_path_to_pose) +
                            "/_action/get_resultReply";
  auto reader =
      stalled->reader_on<nav2_msgs::action::dds_::ComputePathToPose_GetResult_Response_PubSubType>(
          topic, qos, &stuck);
  ASSERT_TRUE(reader.has_value()) << reader.error().message;
  {  // matched with the node's writer
    eprosima::fastdds::dds::SubscriptionMatchedStatus matched;
    const auto end = std::chrono::steady_clock::now() + 10s;
    while ((*reader)->get_subscription_matched_status(matched) == ReturnCode_t::RETCODE_OK &&
           matched.current_count == 0 && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(20ms);
    ASSERT_GT(matched.current_count, 0) << "the stalled reader never matched the node's writer";
  }
  // Goals answered at once (the goal is off the map): the replies come faster than acks.
  const std::vector<ActionGoalSpec> goals(1100, to_pose(0.55, 0.45, 9.0, 1.0));
  const auto t0 = std::chrono::steady_clock::now();
  size_t answered = 0;
  for (const auto& r : burst_of_goals(*run.to_pose, goals, 60s))
    if (r && r->error_code == 204) ++answered;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(answered, goals.size()) << "results held back by a reader that never takes";
  EXPECT_LT(seconds, 30.0);
  const std::string prefix = [&] {
    const auto guid = stalled->get()->guid();
    char text[32] = {0};
    for (int i = 0; i < 12; ++i) std::snprintf(text + 2 * i, 3, "%02x", guid.guidPrefix.value[i]);
    return std::string(text);
  }();
  EXPECT_TRUE(log.wait_for(
      {"get_result replies not acknowledged", "actions.reply_ack_timeout", prefix}, 5s))
      << "no warning naming the stalled reader's participant " << prefix;
  stuck.release();
  stalled->shutdown();
}

}  // namespace
}  // namespace vnsba::test
