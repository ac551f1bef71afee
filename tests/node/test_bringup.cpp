// Nav2's bringup against a real vnsba_node process (issue 48, "Bringup"): the node started as
// `vnsba_node --name planner_server` with `lifecycle: managed`, and this test playing
// nav2_lifecycle_manager's calls (node::LifecycleManagerClient: lifecycle_manager.cpp's
// changeStateForNode, createBondConnection, shutdownAllNodes) over loopback, in both rmw
// mappings: configure, activate, the bond formed, a ComputePathToPose goal that succeeds,
// deactivate, cleanup, shutdown; and the watchdog: the node frozen (SIGSTOP), the manager's bond
// breaks after bond_timeout of silence. vnsba_lifecycle, the tool that plays the manager, is run
// the same way. Oracles: the lifecycle's states as get_state reports them, the bond's state on
// the manager's side, the clock, and the path's ends against the goal.
#include <gtest/gtest.h>
#include <signal.h>

#include "bus_client.hpp"
#include "child_process.hpp"
#include "vnsba/node/action_client.hpp"
#include "vnsba/node/lifecycle_manager.hpp"

namespace vnsba::test {
namespace {

using node::BondState;
using node::LifecycleState;
using node::LifecycleTransition;
using node::ManagerStep;
using node::WireMapping;

#ifdef VNSBA_LIFECYCLE_BINARY
const std::string kLifecycleTool = VNSBA_LIFECYCLE_BINARY;
#endif

// The node as a process named planner_server, managed, in a namespace of this test's own, and
// the manager's side on a participant of the test.
struct Bringup {
  Bringup(const std::string& tag, WireMapping mapping,
          std::chrono::milliseconds bond_timeout = 4000ms)
      : cfg(configure(tag)),
        config_path(write_temp_file(
            "planner_server.yaml",
            config_yaml(cfg) + "namespace: " + cfg.ros_namespace +
                "\nlifecycle: managed\nbond:\n  mode: managed\n  heartbeat_period: 0.1\n"
                "actions:\n  reply_mapping: " +
                (mapping == WireMapping::kRequestHeader ? "cyclonedds" : "auto") +
                "\nmap:\n  robot_radius: 0\n  inflation_radius: 0\n"
                // A goal that comes before the latched map is installed waits for it.
                "requests:\n  map_wait: 20\n")),
        node(kNode, {"--config", config_path, "--name", "planner_server"}),
        bus(cfg) {
    participant = node::Participant::create(cfg.domain_id, "nav2_lifecycle_manager").value();
    node::LifecycleManagerOptions options;
    options.node_full_name = "/" + cfg.ros_namespace + "/planner_server";
    options.bond_id = "planner_server";
    options.bond_topic = node::dds_topic_name(cfg, "bond");
    options.mapping = mapping;
    options.bond_timeout = bond_timeout;
    options.service_wait = 20s;
    options.reply_wait = 20s;
    manager = node::LifecycleManagerClient::create(*participant, options).value();
    action = node::ActionClient::create(*participant,
                                        node::ros_topic_name(cfg, cfg.topics.compute_path_to_pose),
                                        node::ActionKind::kComputePathToPose, mapping)
                 .value();
  }
  ~Bringup() {
    if (node.running()) {
      node.signal(SIGCONT);
      node.signal(SIGTERM);
      node.wait();
    }
    manager.reset();
    action.reset();
    participant->shutdown();
  }
  static node::NodeConfig configure(const std::string& tag) {
    node::NodeConfig cfg = test_config(tag);
    cfg.ros_namespace = "t" + std::to_string(getpid()) + "_" + tag;
    // config_yaml() leaves the actions' names out: the node's default, in the test's namespace.
    cfg.topics.compute_path_to_pose = "compute_path_to_pose";
    return cfg;
  }
  // The node's exit after SIGTERM, its log on failure.
  void expect_clean_exit() {
    node.signal(SIGTERM);
    EXPECT_EQ(node.wait(), 0) << node.output();
  }

  node::NodeConfig cfg;
  std::string config_path;
  ChildProcess node;
  BusClient bus;
  std::unique_ptr<node::Participant> participant;
  std::unique_ptr<node::LifecycleManagerClient> manager;
  std::unique_ptr<node::ActionClient> action;
};

class BringupMappings : public ::testing::TestWithParam<WireMapping> {};

std::string bringup_mapping_name(const ::testing::TestParamInfo<WireMapping>& info) {
  return info.param == WireMapping::kRequestHeader ? "CycloneDds" : "FastRtps";
}

TEST_P(BringupMappings, LifecycleManagersCallsBondAndAGoal) {
  Bringup run(GetParam() == WireMapping::kRequestHeader ? "bring_c" : "bring_f", GetParam());
  ASSERT_TRUE(run.manager->wait_for_services(20s)) << run.node.output();
  EXPECT_EQ(run.manager->get_state(), LifecycleState::kUnconfigured);
  run.bus.publish_slice(free_room(30, 20, 0.1));  // latched: the node reads it once configured

  // startup(): configure, activate (the bond formed within bond_timeout / 2).
  ASSERT_EQ(run.manager->change_state(LifecycleTransition::kConfigure), ManagerStep::kDone)
      << run.node.output();
  EXPECT_EQ(run.manager->bond_state(), BondState::kNotStarted);  // no bond while inactive
  ASSERT_EQ(run.manager->change_state(LifecycleTransition::kActivate), ManagerStep::kDone)
      << run.node.output();
  EXPECT_EQ(run.manager->bond_state(), BondState::kAlive);
  EXPECT_TRUE(run.node.wait_for_output("Creating bond (planner_server)", 5s));

  // A ComputePathToPose goal: SUCCEEDED, the path from the start to the goal.
  ASSERT_TRUE(run.action->wait_for_server(20s));
  node::ActionGoalSpec goal;
  goal.start = node::to_pose_msg(0.25, 0.25, 0.0, "map", node::now_msg());
  goal.goals = {node::to_pose_msg(2.65, 1.75, 0.0, "map", node::now_msg())};
  goal.use_start = true;
  const std::optional<node::ActionResultReply> result =
      run.action->plan(node::ActionClient::random_id(), goal, 30s);
  ASSERT_TRUE(result.has_value()) << run.node.output();
  EXPECT_EQ(result->status, node::GoalState::kSucceeded) << result->error_msg;
  ASSERT_GE(result->path.poses().size(), 2U);
  EXPECT_NEAR(result->path.poses().back().pose().position().x(), 2.65, 1e-6);
  EXPECT_NEAR(result->path.poses().back().pose().position().y(), 1.75, 1e-6);

  // The bond stays formed while active.
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(run.manager->bond_state(), BondState::kAlive);

  // shutdown(): deactivate (the node breaks its bond), cleanup, shutdown.
  ASSERT_EQ(run.manager->change_state(LifecycleTransition::kDeactivate), ManagerStep::kDone);
  EXPECT_EQ(run.manager->bond_state(), BondState::kDead);
  EXPECT_TRUE(run.node.wait_for_output("Destroying bond (planner_server)", 5s));
  EXPECT_EQ(run.manager->change_state(LifecycleTransition::kCleanup), ManagerStep::kDone);
  EXPECT_EQ(run.manager->change_state(LifecycleTransition::kUnconfiguredShutdown),
            ManagerStep::kDone);
  EXPECT_EQ(run.manager->get_state(), LifecycleState::kFinalized);
  run.expect_clean_exit();
}

// The watchdog: the node frozen, the manager's bond breaks after bond_timeout of silence, not
// before; the node continued, the manager's reset takes it back to unconfigured.
TEST_P(BringupMappings, FrozenNodeBreaksTheManagersBondWithinBondTimeout) {
  // Nav2's default bond_timeout: the manager waits half of it for the first heartbeat, which
  // comes from endpoints the node created at configure, on a participant discovered then.
  const auto bond_timeout = 4000ms;
  Bringup run(GetParam() == WireMapping::kRequestHeader ? "watch_c" : "watch_f", GetParam(),
              bond_timeout);
  ASSERT_TRUE(run.manager->wait_for_services(20s)) << run.node.output();
  ASSERT_EQ(run.manager->startup(), ManagerStep::kDone) << run.node.output();
  ASSERT_EQ(run.manager->bond_state(), BondState::kAlive);
  std::this_thread::sleep_for(300ms);
  ASSERT_EQ(run.manager->bond_state(), BondState::kAlive);
  const auto stopped = std::chrono::steady_clock::now();
  run.node.signal(SIGSTOP);
  const bool broke = run.manager->wait_bond_broken(bond_timeout + 3s);
  const auto took = std::chrono::steady_clock::now() - stopped;
  run.node.signal(SIGCONT);
  ASSERT_TRUE(broke) << "the bond did not break within bond_timeout + 3 s of SIGSTOP";
  // The last heartbeat came at most one period (0.1 s) before the stop.
  EXPECT_GE(took, bond_timeout - 150ms);
  EXPECT_LE(took, bond_timeout + 500ms);
  // checkBondConnections' reset(true): deactivate, cleanup.
  EXPECT_EQ(run.manager->reset(), ManagerStep::kDone) << run.node.output();
  EXPECT_EQ(run.manager->get_state(), LifecycleState::kUnconfigured);
  run.expect_clean_exit();
}

INSTANTIATE_TEST_SUITE_P(Bringup, BringupMappings,
                         ::testing::Values(WireMapping::kSampleIdentity,
                                           WireMapping::kRequestHeader),
                         bringup_mapping_name);

#ifdef VNSBA_LIFECYCLE_BINARY
// vnsba_lifecycle as the manager: get, startup --watch (the bond breaks when the node freezes:
// exit 5 after the reset), set, shutdown.
TEST(LifecycleTool, GetStartupWatchSetShutdown) {
  Bringup run("tool", WireMapping::kSampleIdentity);
  const std::vector<std::string> common = {"--config",       run.config_path, "--node",
                                           "planner_server", "--wait",        "20"};
  auto tool = [&](std::vector<std::string> args) {
    std::vector<std::string> all = common;
    all.insert(all.end(), args.begin(), args.end());
    return all;
  };
  auto [code, out] = run_to_exit(kLifecycleTool, tool({"get"}));
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("unconfigured 1"), std::string::npos) << out;

  ChildProcess watch(kLifecycleTool, tool({"--bond-timeout", "4", "startup", "--watch"}));
  ASSERT_TRUE(watch.wait_for_output("bond formed with planner_server", 30s))
      << watch.output() << run.node.output();
  EXPECT_NE(watch.output().find("configure: done"), std::string::npos);
  EXPECT_NE(watch.output().find("activate: done"), std::string::npos);
  run.node.signal(SIGSTOP);
  const bool broke = watch.wait_for_output("bond broken: server planner_server is down", 8s);
  run.node.signal(SIGCONT);
  ASSERT_TRUE(broke) << watch.output();
  EXPECT_EQ(watch.wait(), 5) << watch.output();
  EXPECT_NE(watch.output().find("cleanup: done"), std::string::npos) << watch.output();

  std::tie(code, out) = run_to_exit(kLifecycleTool, tool({"set", "configure"}));
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("configure succeeded: inactive 2"), std::string::npos) << out;
  std::tie(code, out) = run_to_exit(kLifecycleTool, tool({"set", "activate"}));
  EXPECT_EQ(code, 0) << out;
  std::tie(code, out) = run_to_exit(kLifecycleTool, tool({"set", "configure"}));
  EXPECT_EQ(code, 1) << out;  // not a transition of active
  EXPECT_NE(out.find("configure failed: active 3"), std::string::npos) << out;
  std::tie(code, out) = run_to_exit(kLifecycleTool, tool({"shutdown"}));
  EXPECT_EQ(code, 0) << out;
  for (const char* step : {"deactivate: done", "cleanup: done", "shutdown: done"})
    EXPECT_NE(out.find(step), std::string::npos) << out;
  std::tie(code, out) = run_to_exit(kLifecycleTool, tool({"get"}));
  EXPECT_NE(out.find("finalized 4"), std::string::npos) << out;
  run.expect_clean_exit();
}
#endif

}  // namespace
}  // namespace vnsba::test
