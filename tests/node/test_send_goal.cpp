// vnsba_send_goal as a process against a planner node over real loopback DDS: the one status
// line and the exit codes (0 OK, 1 another status, 2 bad input, 3 no answer in time, 4 DDS
// failure), for a plan_request and for the Nav2 actions (--action). Oracles for the actions: the
// same plan asked through plan_request (the path the node answers there, its poses counted and
// its length summed here), the legs of a through_poses goal asked one by one, and nav2_msgs's
// error code table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "bus_client.hpp"
#include "child_process.hpp"
#include "temp_dir.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

// 4 m x 3 m at 0.1 m, origin (0, 0): a wall at x in [2.0, 2.1) m from y = 0 to 2 m, so paths
// from the left half to the right half go around its top end.
core::OccupancyGrid walled_room() {
  core::OccupancyGrid g;
  g.width = 40;
  g.height = 30;
  g.resolution = 0.1;
  g.data.assign(static_cast<size_t>(g.width) * g.height, 0);
  for (int32_t y = 0; y < 20; ++y) g.data[static_cast<size_t>(y) * g.width + 20] = 100;
  return g;
}

// The fields of the status line "<id> <status> <length_m> <clearance_m> <turns> <time_us>
// [start_used=X,Y start_moved_m=D] [goal_used=X,Y goal_moved_m=D]" for `id`.
struct StatusLine {
  std::string id, status;
  double length_m = -1.0;
  std::string clearance_m;  // "nan" and "inf" are words here
  int turns = -1;
  long long time_us = -1;
  std::vector<std::string> extra;  // the *_used / *_moved_m fields
};
std::optional<StatusLine> find_status_line(const std::string& output, const std::string& id) {
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(id + " ", 0) != 0) continue;
    StatusLine parsed;
    std::istringstream fields(line);
    if (!(fields >> parsed.id >> parsed.status >> parsed.length_m >> parsed.clearance_m >>
          parsed.turns >> parsed.time_us)) {
      continue;
    }
    bool well_formed = true;
    for (std::string rest; fields >> rest;) {
      well_formed = well_formed && (rest.rfind("start_", 0) == 0 || rest.rfind("goal_", 0) == 0) &&
                    rest.find('=') != std::string::npos;
      parsed.extra.push_back(rest);
    }
    if (well_formed) return parsed;
  }
  return std::nullopt;
}

// A planner node in this process, on topics of its own, with the walled room as its map.
class SendGoal : public ::testing::Test {
 protected:
  void start_node(const std::string& tag, bool preempt = true,
                  const std::string& ros_namespace = "") {
    config_ = test_config(tag);
    config_.preempt = preempt;
    config_.ros_namespace = ros_namespace;  // not in the YAML: the tools get --namespace
    config_path_ = write_temp_file(tag + ".yaml", config_yaml(config_));
    run_node(config_);
  }
  // The node with `node_config`, the test client on config_'s topics matched with it both ways
  // before anything is sent (the tests read the node's statuses with this client's volatile
  // reader too; under ctest -j3 the node once answered send_goal before that reader had
  // matched), and the walled room as its map.
  // `with_map` false: the node gets no map (a goal then waits requests.map_wait for one).
  void run_node(const node::NodeConfig& node_config, bool with_map = true) {
    node_ = std::make_unique<node::PlannerNode>(node_config);
    ASSERT_TRUE(node_->start().is_ok());
    client_ = std::make_unique<BusClient>(config_);
    ASSERT_TRUE(client_->wait_for_match(*node_)) << "the node and the test client never matched";
    if (!with_map) return;
    client_->publish_slice(walled_room());
    ASSERT_TRUE(node_->wait_for_map(10s)) << "the node never got the slice";
  }
  std::vector<std::string> args(const std::string& id, double sx, double sy, double gx,
                                double gy) const {
    return {"--config",
            config_path_,
            "--domain",
            std::to_string(test_domain()),
            "--id",
            id,
            "--start",
            std::to_string(sx),
            std::to_string(sy),
            "--goal",
            std::to_string(gx),
            std::to_string(gy),
            "--wait",
            "20"};
  }
  void TearDown() override {
    client_.reset();
    if (node_) node_->stop();
  }

  node::NodeConfig config_ = paper_test_config();  // start_node() sets the test's
  std::string config_path_;
  std::unique_ptr<node::PlannerNode> node_;
  std::unique_ptr<BusClient> client_;
};

TEST_F(SendGoal, OkStatusPrintsOneLineAndExitsZero) {
  start_node("sg_ok");
  const auto [code, output] = run_to_exit(kSendGoal, args("sg-ok", 0.55, 0.55, 3.55, 0.55));
  ASSERT_EQ(code, 0) << output;
  const auto line = find_status_line(output, "sg-ok");
  ASSERT_TRUE(line) << "no status line for sg-ok in:\n" << output;
  EXPECT_EQ(line->status, "OK");
  // Around the wall's top end: well over the 3 m straight line, with at least one turn.
  EXPECT_GT(line->length_m, 3.0);
  EXPECT_LT(line->length_m, 8.0);
  EXPECT_GE(line->turns, 1);
  EXPECT_GT(line->time_us, 0);
  // The line says what the node published.
  const auto status = client_->wait_status("sg-ok", 5s);
  ASSERT_TRUE(status);
  EXPECT_NEAR(line->length_m, status->length_m(), 0.0005);
  ASSERT_TRUE(std::isfinite(status->clearance_m()));
  EXPECT_NEAR(std::stod(line->clearance_m), status->clearance_m(), 0.0005);
  EXPECT_EQ(line->turns, status->turns());
  EXPECT_EQ(line->time_us, status->planning_time_us());
  EXPECT_TRUE(line->extra.empty()) << "nothing was adjusted";
}

// Issue 18: robots on one domain, apart by namespace. The node is in robot7's.
TEST_F(SendGoal, ANamespaceSeparatesRobotsOnOneDomain) {
  start_node("sg_ns", true, "robot7");
  auto with = [&](const std::string& id, const std::string& ns, const std::string& wait) {
    std::vector<std::string> a = args(id, 0.55, 0.55, 3.55, 0.55);
    *(std::find(a.begin(), a.end(), "--wait") + 1) = wait;
    a.insert(a.end(), {"--namespace", ns});
    return a;
  };
  const auto [code, output] = run_to_exit(kSendGoal, with("sg-ns", "/robot7/", "20"));
  ASSERT_EQ(code, 0) << output;
  const auto line = find_status_line(output, "sg-ns");
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->status, "OK");
  // robot8's request reaches no node: exit 3, as with no node at all.
  const auto [other_code, other_output] = run_to_exit(kSendGoal, with("sg-ns8", "robot8", "2"));
  EXPECT_EQ(other_code, 3) << other_output;
  EXPECT_FALSE(client_->wait_status("sg-ns8", 500ms));
  const auto [bad_code, bad_output] = run_to_exit(kSendGoal, with("sg-ns-bad", "robot 7", "2"));
  EXPECT_EQ(bad_code, 2) << bad_output;
  EXPECT_NE(bad_output.find("--namespace"), std::string::npos) << bad_output;
}

// --yaw sets the goal's orientation: the last pose of the plan faces it.
TEST_F(SendGoal, YawSetsTheGoalOrientation) {
  start_node("sg_yaw");
  std::vector<std::string> a = args("sg-yaw", 0.55, 0.55, 3.55, 0.55);
  a.insert(a.end(), {"--yaw", "-1.25"});
  const auto [code, output] = run_to_exit(kSendGoal, a);
  ASSERT_EQ(code, 0) << output;
  const auto status = client_->wait_status("sg-yaw", 5s);
  ASSERT_TRUE(status);
  ASSERT_FALSE(status->path().poses().empty());
  const auto& q = status->path().poses().back().pose().orientation();
  EXPECT_NEAR(2.0 * std::atan2(q.z(), q.w()), -1.25, 1e-9);
  const auto [bad_code, bad_output] = run_to_exit(kSendGoal, [&] {
    std::vector<std::string> b = args("sg-yaw-bad", 0.55, 0.55, 3.55, 0.55);
    b.insert(b.end(), {"--yaw", "nan"});
    return b;
  }());
  EXPECT_EQ(bad_code, 2) << bad_output;
  EXPECT_NE(bad_output.find("--yaw"), std::string::npos) << bad_output;
}

// A goal moved by goal_tolerance: the line carries the goal used and how far it moved.
TEST_F(SendGoal, AnAdjustedGoalIsPrintedWithTheLine) {
  config_ = test_config("sg_moved");
  config_path_ =
      write_temp_file("sg_moved.yaml", config_yaml(config_) + "planner:\n  goal_tolerance: 0.3\n");
  node::NodeConfig cfg = config_;
  cfg.planner.settings.goal_tolerance = 0.3;
  ASSERT_NO_FATAL_FAILURE(run_node(cfg));
  // (2.05, 1.05) m is in the wall (cell (20, 10)); the nearest free centres are 0.1 m away.
  const auto [code, output] = run_to_exit(kSendGoal, args("sg-moved", 0.55, 0.55, 2.05, 1.05));
  ASSERT_EQ(code, 0) << output;
  const auto line = find_status_line(output, "sg-moved");
  ASSERT_TRUE(line) << output;
  ASSERT_EQ(line->extra.size(), 2u) << output;
  EXPECT_EQ(line->extra[0].rfind("goal_used=", 0), 0u) << output;
  EXPECT_EQ(line->extra[1], "goal_moved_m=0.100") << output;
  EXPECT_NE(output.find("goal moved 0.100 m to the nearest free cell"), std::string::npos)
      << output;
  const auto status = client_->wait_status("sg-moved", 5s);
  ASSERT_TRUE(status);
  EXPECT_TRUE(status->goal_adjusted());
  char used[64];
  std::snprintf(used, sizeof used, "goal_used=%.3f,%.3f", status->goal_x(), status->goal_y());
  EXPECT_EQ(line->extra[0], used);
}

TEST_F(SendGoal, PlannerOverrideReachesTheNode) {
  start_node("sg_planner");
  std::vector<std::string> a = args("sg-astar", 0.55, 0.55, 3.55, 0.55);
  a.insert(a.end(), {"--planner", "astar"});
  const auto [code, output] = run_to_exit(kSendGoal, a);
  ASSERT_EQ(code, 0) << output;
  const auto status = client_->wait_status("sg-astar", 5s);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->planner(), "astar");
}

// Issue 31: a plan the node refused exits 1, not 2 as bad input does, so a script tells them
// apart.
TEST_F(SendGoal, GoalInAWallExitsOneWithTheStatus) {
  start_node("sg_occupied");
  const auto [code, output] = run_to_exit(kSendGoal, args("sg-wall", 0.55, 0.55, 2.05, 1.05));
  EXPECT_EQ(code, 1) << output;
  const auto line = find_status_line(output, "sg-wall");
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->status, "GOAL_OCCUPIED");
  EXPECT_EQ(line->length_m, 0.0);
}

// Issue 13: `--id X` twice, the second a goal in a wall, printed the first run's replayed OK
// from the status history and exited 0. It matches the status on its request's sample identity.
TEST_F(SendGoal, AReusedIdPrintsItsOwnAnswerNotTheEarlierOne) {
  start_node("sg_reuse");
  const auto [first_code, first_output] = run_to_exit(kSendGoal, args("X", 0.55, 0.55, 3.55, 0.55));
  ASSERT_EQ(first_code, 0) << first_output;
  ASSERT_TRUE(find_status_line(first_output, "X"));
  EXPECT_EQ(find_status_line(first_output, "X")->status, "OK");
  const auto [code, output] = run_to_exit(kSendGoal, args("X", 0.55, 0.55, 2.05, 1.05));
  EXPECT_EQ(code, 1) << output;
  const auto line = find_status_line(output, "X");
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->status, "GOAL_OCCUPIED") << output;
}

// issue 17, item 2: 100 fresh short-lived clients (vnsba_send_goal processes, 10 at a time) with
// a volatile status reader, ROS 2's default, each sending as soon as its own endpoints are
// matched: every one gets its answer, which the node holds until it has matched that client's
// status reader (requests.reply_wait). Concurrent clients do not preempt each other here.
TEST_F(SendGoal, FreshClientsWithVolatileStatusReadersLoseNoAnswer) {
  start_node("sg_fresh", /*preempt=*/false);
  int ok = 0;
  std::vector<std::string> failures;
  for (int round = 0; round < 10; ++round) {
    std::vector<std::unique_ptr<ChildProcess>> clients;
    std::vector<std::string> ids;
    for (int i = 0; i < 10; ++i) {
      ids.push_back("fresh-" + std::to_string(round) + "-" + std::to_string(i));
      clients.push_back(
          std::make_unique<ChildProcess>(kSendGoal, args(ids.back(), 0.55, 0.55, 3.55, 0.55)));
    }
    for (int i = 0; i < 10; ++i) {
      const int code = clients[i]->wait();  // send_goal gives up by itself after --wait
      const std::string output = clients[i]->output();
      const auto line = find_status_line(output, ids[i]);
      if (code == 0 && line && line->status == "OK")
        ++ok;
      else
        failures.push_back(ids[i] + " exited " + std::to_string(code) + ":\n" + output);
    }
  }
  EXPECT_EQ(ok, 100);
  for (const std::string& f : failures) ADD_FAILURE() << f;
}

// --- --action: the Nav2 actions, called as a ROS 2 action client does ---------------------------

// config_yaml's text plus the action names of `cfg`, which config_yaml leaves to default.yaml's.
// They go at the end of its `topics:` block, which must therefore be the file's last section.
std::string action_config_yaml(const node::NodeConfig& cfg) {
  const std::string yaml = config_yaml(cfg);
  const size_t topics = yaml.rfind("\ntopics:\n");
  EXPECT_NE(topics, std::string::npos) << yaml;
  for (size_t line = yaml.find('\n', topics + 1); line + 1 < yaml.size();
       line = yaml.find('\n', line + 1)) {
    EXPECT_EQ(yaml.compare(line + 1, 2, "  "), 0) << "topics: is not the last section of:\n"
                                                  << yaml;
  }
  return yaml + "  compute_path_to_pose: " + cfg.topics.compute_path_to_pose +
         "\n  compute_path_through_poses: " + cfg.topics.compute_path_through_poses + "\n";
}

// The result line of --action: "<goal_id> <status> <error_code> <error_name> <length_m> <poses>
// <planning_time_us>", the goal id 32 hex digits.
struct ActionLine {
  std::string goal_id, status, error_name;
  int error_code = -1;
  double length_m = -1.0;
  size_t poses = 0;
  long long time_us = -1;
};
std::optional<ActionLine> find_action_line(const std::string& output) {
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    ActionLine parsed;
    std::istringstream fields(line);
    std::string rest;
    if (!(fields >> parsed.goal_id >> parsed.status >> parsed.error_code >> parsed.error_name >>
          parsed.length_m >> parsed.poses >> parsed.time_us) ||
        (fields >> rest) || parsed.goal_id.size() != 32 ||
        !std::all_of(parsed.goal_id.begin(), parsed.goal_id.end(),
                     [](unsigned char c) { return std::isxdigit(c) && !std::isupper(c); })) {
      continue;
    }
    return parsed;
  }
  return std::nullopt;
}

// Metres along a path's poses: the oracle of the line's length_m.
double path_length(const node::PathMsg& path) {
  double length = 0.0;
  for (size_t i = 1; i < path.poses().size(); ++i) {
    const auto& a = path.poses()[i - 1].pose().position();
    const auto& b = path.poses()[i].pose().position();
    length += std::hypot(b.x() - a.x(), b.y() - a.y());
  }
  return length;
}

class SendGoalAction : public SendGoal {
 protected:
  // The node (config_ as `configure` changes it), the walled room as its map unless `with_map` is
  // false, and a config file for the tool with config_'s topics and action names.
  void start_action_node(const std::string& tag,
                         const std::function<void(node::NodeConfig&)>& configure = {},
                         bool with_map = true, const std::string& extra_yaml = "") {
    config_ = test_config(tag);
    config_path_ = write_temp_file(tag + ".yaml", action_config_yaml(config_) + extra_yaml);
    node::NodeConfig cfg = config_;
    if (configure) configure(cfg);
    run_node(cfg, with_map);
  }
  // --action `action` with `goals` (x, y pairs), and a start unless `start` is empty.
  std::vector<std::string> action_args(const std::string& action, std::vector<double> start,
                                       const std::vector<std::pair<double, double>>& goals,
                                       const std::string& wait = "20") const {
    std::vector<std::string> a = {
        "--config", config_path_, "--domain", std::to_string(test_domain()),
        "--action", action,       "--wait",   wait};
    if (!start.empty())
      a.insert(a.end(), {"--start", std::to_string(start[0]), std::to_string(start[1])});
    for (const auto& [x, y] : goals)
      a.insert(a.end(), {"--goal", std::to_string(x), std::to_string(y)});
    return a;
  }
  // The node's path for start -> goal through plan_request: the oracle of an action's result.
  node::PathMsg plan_request_path(const std::string& id, double sx, double sy, double gx,
                                  double gy) {
    client_->publish_request(id, sx, sy, gx, gy);
    const auto status = client_->wait_status(id, 15s);
    EXPECT_TRUE(status) << "no status for " << id;
    if (!status) return {};
    EXPECT_EQ(status->code(), node::wire::OK) << status->message();
    return status->path();
  }
};

TEST_F(SendGoalAction, ToPoseSucceedsWithThePathAPlanRequestGets) {
  ASSERT_NO_FATAL_FAILURE(start_action_node("sga_ok"));
  const auto [code, output] =
      run_to_exit(kSendGoal, action_args("to_pose", {0.55, 0.55}, {{3.55, 0.55}}));
  ASSERT_EQ(code, 0) << output;
  const auto line = find_action_line(output);
  ASSERT_TRUE(line) << "no result line in:\n" << output;
  EXPECT_EQ(line->status, "SUCCEEDED");
  EXPECT_EQ(line->error_code, 0);
  EXPECT_EQ(line->error_name, "NONE");
  EXPECT_GT(line->time_us, 0);
  const node::PathMsg oracle = plan_request_path("sga-oracle", 0.55, 0.55, 3.55, 0.55);
  EXPECT_EQ(line->poses, oracle.poses().size());
  EXPECT_NEAR(line->length_m, path_length(oracle), 0.0005);
  EXPECT_GT(line->length_m, 3.0) << "around the wall, not through it";
}

// Issue 32: a goal the node cannot plan gets Nav2's error code and its name, exit 1 as any other
// refused plan; through_poses adds 100 and names the leg.
TEST_F(SendGoalAction, AGoalInAWallIsAbortedWithNav2sCodeAndExitsOne) {
  ASSERT_NO_FATAL_FAILURE(start_action_node("sga_wall"));
  const auto [code, output] =
      run_to_exit(kSendGoal, action_args("to_pose", {0.55, 0.55}, {{2.05, 1.05}}));
  EXPECT_EQ(code, 1) << output;
  const auto line = find_action_line(output);
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->status, "ABORTED");
  EXPECT_EQ(line->error_code, 206);
  EXPECT_EQ(line->error_name, "GOAL_OCCUPIED");
  EXPECT_EQ(line->poses, 0u);
  EXPECT_NE(output.find("goal (2.050, 1.050) m"), std::string::npos) << "error_msg:\n" << output;

  const auto [leg_code, leg_output] = run_to_exit(
      kSendGoal, action_args("through_poses", {0.55, 0.55}, {{3.55, 0.55}, {2.05, 1.05}}));
  EXPECT_EQ(leg_code, 1) << leg_output;
  const auto leg = find_action_line(leg_output);
  ASSERT_TRUE(leg) << leg_output;
  EXPECT_EQ(leg->status, "ABORTED");
  EXPECT_EQ(leg->error_code, 306);
  EXPECT_EQ(leg->error_name, "GOAL_OCCUPIED");
  EXPECT_NE(leg_output.find("leg 2 of 2"), std::string::npos) << leg_output;
}

// Issue 48: --distro speaks the distribution's types. A Kilted node's through_poses goal (a
// nav_msgs/Goals) succeeds; a Humble node's failed goal is ABORTED with no error code (its result
// has none: the line shows 0).
TEST_F(SendGoalAction, DistroKiltedSendsItsGoalsMessage) {
  ASSERT_NO_FATAL_FAILURE(start_action_node(
      "sga_kilted", [](node::NodeConfig& cfg) { cfg.ros_distro = node::RosDistro::kKilted; }));
  std::vector<std::string> args =
      action_args("through_poses", {0.55, 0.55}, {{3.55, 0.55}, {0.55, 2.55}});
  args.insert(args.end(), {"--distro", "kilted"});
  const auto [code, output] = run_to_exit(kSendGoal, args);
  ASSERT_EQ(code, 0) << output;
  const auto line = find_action_line(output);
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->status, "SUCCEEDED");
  EXPECT_GT(line->poses, 2u);
}
TEST_F(SendGoalAction, DistroHumbleResultsCarryNoErrorCode) {
  ASSERT_NO_FATAL_FAILURE(start_action_node(
      "sga_humble", [](node::NodeConfig& cfg) { cfg.ros_distro = node::RosDistro::kHumble; }));
  std::vector<std::string> args = action_args("to_pose", {0.55, 0.55}, {{2.05, 1.05}});
  args.insert(args.end(), {"--distro", "humble"});
  const auto [code, output] = run_to_exit(kSendGoal, args);
  EXPECT_EQ(code, 1) << output;
  const auto line = find_action_line(output);
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->status, "ABORTED");
  EXPECT_EQ(line->error_code, 0);
  EXPECT_EQ(line->poses, 0u);
  args = action_args("to_pose", {0.55, 0.55}, {{3.55, 0.55}});
  args.insert(args.end(), {"--distro", "humble"});
  const auto [ok_code, ok_output] = run_to_exit(kSendGoal, args);
  EXPECT_EQ(ok_code, 0) << ok_output;
}

// Each leg of a through_poses goal starts where the last ended: the joined path is the legs'
// plan_request paths end to end (the shared pose counted once).
TEST_F(SendGoalAction, ThroughPosesIsItsLegsPlannedOneByOne) {
  ASSERT_NO_FATAL_FAILURE(start_action_node("sga_through"));
  const auto [code, output] = run_to_exit(
      kSendGoal, action_args("through_poses", {0.55, 0.55}, {{3.55, 0.55}, {0.55, 2.55}}));
  ASSERT_EQ(code, 0) << output;
  const auto line = find_action_line(output);
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->status, "SUCCEEDED");
  EXPECT_EQ(line->error_code, 0);
  const node::PathMsg first = plan_request_path("sga-leg1", 0.55, 0.55, 3.55, 0.55);
  const node::PathMsg second = plan_request_path("sga-leg2", 3.55, 0.55, 0.55, 2.55);
  ASSERT_FALSE(first.poses().empty());
  ASSERT_FALSE(second.poses().empty());
  EXPECT_EQ(line->poses, first.poses().size() + second.poses().size() - 1);
  EXPECT_NEAR(line->length_m, path_length(first) + path_length(second), 0.0005);
}

// Without --start the goal has use_start false: the node plans from the robot's pose, and
// answers 200 UNKNOWN (its INVALID_REQUEST) while it has none.
TEST_F(SendGoalAction, WithoutAStartTheNodePlansFromTheRobotsPose) {
  ASSERT_NO_FATAL_FAILURE(start_action_node("sga_robot"));
  const auto [none_code, none_output] =
      run_to_exit(kSendGoal, action_args("to_pose", {}, {{3.55, 0.55}}));
  EXPECT_EQ(none_code, 1) << none_output;
  const auto none = find_action_line(none_output);
  ASSERT_TRUE(none) << none_output;
  EXPECT_EQ(none->error_code, 200);
  EXPECT_EQ(none->error_name, "UNKNOWN");
  EXPECT_NE(none_output.find("robot_pose"), std::string::npos) << none_output;

  // A goal_pose goal plans from the robot's pose too: once it is answered OK, the node has it,
  // and its path is the oracle.
  client_->publish_robot_pose(0.55, 0.55);
  std::this_thread::sleep_for(300ms);  // robot_pose is keep-last: let it land before the goal
  client_->publish_goal(3.55, 0.55);
  const auto goal_status = client_->wait_status("goal-1", 15s);
  ASSERT_TRUE(goal_status);
  ASSERT_EQ(goal_status->code(), node::wire::OK) << goal_status->message();
  const auto [code, output] = run_to_exit(kSendGoal, action_args("to_pose", {}, {{3.55, 0.55}}));
  ASSERT_EQ(code, 0) << output;
  const auto line = find_action_line(output);
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->poses, goal_status->path().poses().size());
  EXPECT_NEAR(line->length_m, path_length(goal_status->path()), 0.0005);
}

// rmw_cyclonedds's mapping (a request header): against a node that answers every client so,
// --mapping cyclonedds plans, and so does a config whose actions.reply_mapping says cyclonedds;
// --mapping fastrtps gets no answer (exit 3) and is told why.
TEST_F(SendGoalAction, TheCycloneDdsMappingNeedsANodeThatAnswersInIt) {
  ASSERT_NO_FATAL_FAILURE(start_action_node("sga_cyclone", [](node::NodeConfig& cfg) {
    cfg.actions.reply_mapping = node::ReplyMapping::kCycloneDds;
  }));
  const auto base = action_args("to_pose", {0.55, 0.55}, {{3.55, 0.55}});
  std::vector<std::string> flagged = base;
  flagged.insert(flagged.end(), {"--mapping", "cyclonedds"});
  const auto [code, output] = run_to_exit(kSendGoal, flagged);
  ASSERT_EQ(code, 0) << output;
  const auto line = find_action_line(output);
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->status, "SUCCEEDED");
  const node::PathMsg oracle = plan_request_path("sga-cyclone-oracle", 0.55, 0.55, 3.55, 0.55);
  EXPECT_EQ(line->poses, oracle.poses().size());

  std::vector<std::string> from_config = base;
  *(std::find(from_config.begin(), from_config.end(), "--config") + 1) =
      write_temp_file("sga_cyclone_cfg.yaml",
                      action_config_yaml(config_) + "actions:\n  reply_mapping: cyclonedds\n");
  const auto [config_code, config_output] = run_to_exit(kSendGoal, from_config);
  EXPECT_EQ(config_code, 0) << config_output;

  std::vector<std::string> wrong = action_args("to_pose", {0.55, 0.55}, {{3.55, 0.55}}, "2");
  wrong.insert(wrong.end(), {"--mapping", "fastrtps"});
  const auto [wrong_code, wrong_output] = run_to_exit(kSendGoal, wrong);
  EXPECT_EQ(wrong_code, 3) << wrong_output;
  EXPECT_NE(wrong_output.find("the server matched but did not answer"), std::string::npos)
      << wrong_output;
  EXPECT_FALSE(find_action_line(wrong_output)) << wrong_output;
}

// --cancel-after: a goal waiting for the node's first map (requests.map_wait 30 s) is canceled
// half a second after its acceptance: CANCELED with error code 0, exit 1, long before the wait.
TEST_F(SendGoalAction, CancelAfterCancelsTheGoal) {
  ASSERT_NO_FATAL_FAILURE(start_action_node(
      "sga_cancel", [](node::NodeConfig& cfg) { cfg.map_wait = 30s; }, /*with_map=*/false));
  std::vector<std::string> a = action_args("to_pose", {0.55, 0.55}, {{3.55, 0.55}});
  a.insert(a.end(), {"--cancel-after", "0.5"});
  const auto began = std::chrono::steady_clock::now();
  const auto [code, output] = run_to_exit(kSendGoal, a);
  const auto took = std::chrono::steady_clock::now() - began;
  EXPECT_EQ(code, 1) << output;
  const auto line = find_action_line(output);
  ASSERT_TRUE(line) << output;
  EXPECT_EQ(line->status, "CANCELED");
  EXPECT_EQ(line->error_code, 0);
  EXPECT_EQ(line->poses, 0u);
  EXPECT_NE(output.find("cancel of goal " + line->goal_id + " after 0.500 s: ERROR_NONE"),
            std::string::npos)
      << output;
  EXPECT_LT(took, 20s) << "ended by the map wait, not by the cancel";
}

// A goal given up on is canceled, as `ros2 action send_goal` cancels its goal on Ctrl-C: SIGTERM
// while it waits for the node's first map gives exit 143 (128 + SIGTERM, what a shell reports for
// a command the signal ended, so that a script running the tool stops too), and the server
// accepts the cancel.
TEST_F(SendGoalAction, AnInterruptedGoalIsCanceledFirst) {
  // The tool logs the acceptance at debug level: interrupted after it, it waits for the result
  // (the node counting the goal is not enough: its acceptance may still be on the way).
  ASSERT_NO_FATAL_FAILURE(start_action_node(
      "sga_interrupt", [](node::NodeConfig& cfg) { cfg.map_wait = 30s; }, /*with_map=*/false,
      "log_level: debug\n"));
  ChildProcess child(kSendGoal, action_args("to_pose", {0.55, 0.55}, {{3.55, 0.55}}));
  ASSERT_TRUE(child.wait_for_output("accepted; asking for its result", 20s))
      << "the goal was never accepted:\n"
      << child.output();
  ASSERT_EQ(node_->stats().action_goals, 1u) << child.output();
  child.signal(SIGTERM);
  EXPECT_EQ(child.wait(), 128 + SIGTERM) << child.output();
  const std::string output = child.output();
  EXPECT_NE(output.find("interrupted before the result of goal"), std::string::npos) << output;
  EXPECT_NE(output.find(": ERROR_NONE"), std::string::npos) << "the cancel was not accepted:\n"
                                                            << output;
  EXPECT_FALSE(find_action_line(output)) << output;
}

// Two nodes serving one action on one domain (issue 45): each hears and plans every goal, the
// client takes the first answer; the tool says that two servers serve it and what to do, never
// a bare status with an empty warning. --min-readers 2 waits for both servers, so that both
// answer. The second node has no map: whichever answers first, the goal ends (SUCCEEDED from the
// first, ABORTED NO_MAP from the second), and the warning names both.
TEST_F(SendGoalAction, TwoServersOnOneDomainAreNamed) {
  ASSERT_NO_FATAL_FAILURE(start_action_node("sga_two"));
  node::NodeConfig second = config_;
  second.map_wait = std::chrono::milliseconds(0);
  node::PlannerNode other(second);
  ASSERT_TRUE(other.start().is_ok());
  std::vector<std::string> args = action_args("to_pose", {0.55, 0.55}, {{3.55, 0.55}});
  args.insert(args.end(), {"--min-readers", "2"});
  const auto [code, output] = run_to_exit(kSendGoal, args);
  other.stop();
  const auto line = find_action_line(output);
  ASSERT_TRUE(line) << "no result line in:\n" << output;
  EXPECT_NE(output.find("2 servers of '"), std::string::npos) << output;
  EXPECT_NE(output.find("more than one node serves this action"), std::string::npos) << output;
  // No warning line without words after its level.
  EXPECT_EQ(output.find("[warning] \n"), std::string::npos) << output;
  EXPECT_TRUE(code == 0 || code == 1) << output;
}

TEST(SendGoalWithoutNode, NoAnswerExitsThreeWithinTheWait) {
  const node::NodeConfig cfg = test_config("sg_nobody");
  const std::string path = write_temp_file("sg_nobody.yaml", config_yaml(cfg));
  const auto began = std::chrono::steady_clock::now();
  const auto [code, output] =
      run_to_exit(kSendGoal, {"--config", path, "--domain", std::to_string(test_domain()),
                              "--start", "0.5", "0.5", "--goal", "1.5", "0.5", "--wait", "1"});
  const auto took = std::chrono::steady_clock::now() - began;
  EXPECT_EQ(code, 3) << output;
  EXPECT_NE(output.find("no planner node"), std::string::npos) << output;
  // One second of waiting, plus process start and DDS teardown.
  EXPECT_LT(took, 6s);
}

TEST(SendGoalWithoutNode, NoActionServerExitsThreeNamingTheAction) {
  node::NodeConfig cfg = test_config("sga_nobody");
  const std::string path = write_temp_file("sga_nobody.yaml", action_config_yaml(cfg));
  const auto [code, output] =
      run_to_exit(kSendGoal, {"--config", path, "--domain", std::to_string(test_domain()),
                              "--action", "through_poses", "--goal", "1.5", "0.5", "--wait", "1"});
  EXPECT_EQ(code, 3) << output;
  EXPECT_NE(output.find("no nav2_msgs/action/ComputePathThroughPoses server"), std::string::npos)
      << output;
  EXPECT_NE(output.find(cfg.topics.compute_path_through_poses), std::string::npos) << output;
}

// Issue 31: a DDS failure exits 4 (it was 1, which now means a plan refused): here the
// participant is refused before it exists, its keystore missing under security's Enforce.
TEST(SendGoalWithoutNode, ADdsFailureExitsFour) {
  const node::NodeConfig cfg = test_config("sg_dds");
  const std::string keystore = (FreshTempDir("sg_dds") / "ks").string();  // never made
  const std::string path = write_temp_file(
      "sg_dds.yaml", config_yaml(cfg) + "security:\n  enable: true\n  keystore: " + keystore +
                         "\n  strategy: Enforce\n");
  const auto [code, output] = run_to_exit(kSendGoal, {"--config", path, "--start", "0.5", "0.5",
                                                      "--goal", "1.5", "0.5", "--wait", "1"});
  EXPECT_EQ(code, 4) << output;
  EXPECT_NE(output.find(keystore), std::string::npos) << output;
}

// The exit codes are in --help, each with its meaning.
TEST(SendGoalArguments, HelpListsTheExitCodes) {
  const auto [code, output] = run_to_exit(kSendGoal, {"--help"});
  EXPECT_EQ(code, 0) << output;
  for (const char* said :
       {"0 the node answered OK", "1 it answered with another status",
        "2 bad command line or config", "3 no answer within --wait", "4 DDS failure",
        "--action: the goal SUCCEEDED", "--action: the goal was rejected, ABORTED or CANCELED"})
    EXPECT_NE(output.find(said), std::string::npos) << said << " not in:\n" << output;
}

// A command line that must exit 2 with a message naming `named`.
struct UsageCase {
  std::vector<std::string> args;
  std::string named;
};
// Runs each case (with --config `config` unless it gives its own) and expects exit 2 and its
// name in the output.
void expect_usage_errors(const std::vector<UsageCase>& cases, const std::string& config) {
  for (const UsageCase& c : cases) {
    std::vector<std::string> a = c.args;
    if (std::find(a.begin(), a.end(), "--config") == a.end())
      a.insert(a.end(), {"--config", config});
    const auto [code, output] = run_to_exit(kSendGoal, a);
    std::string joined;
    for (const auto& s : c.args) joined += s + " ";
    EXPECT_EQ(code, 2) << joined << "\n" << output;
    EXPECT_NE(output.find(c.named), std::string::npos)
        << joined << ": '" << c.named << "' not named in:\n"
        << output;
  }
}

TEST(SendGoalArguments, BadInputExitsTwoNamingTheOption) {
  const node::NodeConfig cfg = test_config("sg_args");
  const std::string path = write_temp_file("sg_args.yaml", config_yaml(cfg));
  const std::string bad_config = write_temp_file("sg_bad.yaml", "planner:\n  name: dijkstra\n");
  const std::string missing = (FreshTempDir("sg_args") / "no/such/file.yaml").string();
  expect_usage_errors(
      {
          {{"--start", "0", "0"}, "--goal"},
          {{"--goal", "1", "1"}, "--start"},
          {{"--start", "nan", "0", "--goal", "1", "1"}, "--start"},
          {{"--start", "0", "0", "--goal", "1", "inf"}, "--goal"},
          {{"--start", "0", "--goal", "1", "1"}, "--start"},
          {{"--start", "0", "zero", "--goal", "1", "1"}, "--start"},
          {{"--start", "0", "0", "--goal", "1", "1", "--planner", "dijkstra"}, "--planner"},
          {{"--start", "0", "0", "--goal", "1", "1", "--wait", "-1"}, "--wait"},
          {{"--start", "0", "0", "--goal", "1", "1", "--domain", "999"}, "--domain"},
          {{"--start", "0", "0", "--goal", "1", "1", "--id", ""}, "--id"},
          {{"--start", "0", "0", "--goal", "1", "1", "--id", std::string(300, 'x')},
           "--id: 300 bytes"},
          {{"--start", "0", "0", "--goal", "1", "1", "--config", missing}, missing},
          {{"--start", "0", "0", "--goal", "1", "1", "--config", bad_config}, "planner.name"},
      },
      path);
}

// The flags of --action, checked before anything is sent: each mistake exits 2 naming the flag.
TEST(SendGoalArguments, BadActionFlagsExitTwoNamingTheFlag) {
  expect_usage_errors(
      {
          {{"--action", "to_the_moon", "--goal", "1", "1"}, "--action"},
          {{"--action", "--mapping", "zenoh", "--goal", "1", "1"}, "--mapping"},
          {{"--mapping", "cyclonedds", "--start", "0", "0", "--goal", "1", "1"}, "--mapping"},
          {{"--cancel-after", "1", "--start", "0", "0", "--goal", "1", "1"}, "--cancel-after"},
          {{"--action", "--cancel-after", "-1", "--goal", "1", "1"}, "--cancel-after"},
          {{"--action", "--cancel-after", "nan", "--goal", "1", "1"}, "--cancel-after"},
          {{"--action", "--id", "x", "--goal", "1", "1"}, "--id"},
          {{"--action", "--min-readers", "0", "--goal", "1", "1"}, "--min-readers"},
          {{"--action", "--goal", "1", "1", "--goal", "2", "2"}, "--goal: 2 goals"},
          {{"--start", "0", "0", "--goal", "1", "1", "--goal", "2", "2"}, "--goal: 2 goals"},
          {{"--action", "through_poses", "--goal", "1", "1", "2"}, "--goal: 3 numbers"},
          {{"--action", "through_poses", "--goal", "1", "1", "--goal", "nan", "2"}, "--goal #2"},
          {{"--action", "--start", "0", "inf", "--goal", "1", "1"}, "--start"},
          {{"--goal", "1", "1"}, "--start is required"},
          {{"--acton", "--goal", "1", "1"}, "unknown option --acton (did you mean --action?)"},
      },
      write_temp_file("sga_args.yaml", config_yaml(test_config("sga_args"))));
}

// Issue 31: `--goal-pose 16 -6.5` was reported as "--goal is required". The unknown flag comes
// first, with the flag it was probably meant to be; nothing is sent (no config is even read).
TEST(SendGoalArguments, AMisspeltFlagIsNamedBeforeAMissingOne) {
  const std::string missing = (FreshTempDir("sg_misspelt") / "no/such/file.yaml").string();
  for (const auto& [misspelt, meant] :
       {std::pair{"--goal-pose", "--goal"}, std::pair{"--gaol", "--goal"},
        std::pair{"--min", "--min-readers"}}) {
    const auto [code, output] =
        run_to_exit(kSendGoal, {misspelt, "16", "-6.5", "--start", "2", "-6", "--config", missing});
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(
        output.find("unknown option " + std::string(misspelt) + " (did you mean " + meant + "?)"),
        std::string::npos)
        << output;
    EXPECT_EQ(output.find("is required"), std::string::npos) << output;
    EXPECT_EQ(output.find(missing), std::string::npos) << output;
  }
}

}  // namespace
}  // namespace vnsba::test
