// vnsba_node as a process: it refuses bad configs, naming every bad key, and SIGTERM makes it
// drain and exit 0.
#include <gtest/gtest.h>
#include <signal.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "bus_client.hpp"
#include "child_process.hpp"
#include "temp_dir.hpp"
#include "vnsba/node/process.hpp"

namespace vnsba::test {
namespace {

TEST(NodeProcess, RefusesToStartOnABadConfigNamingEveryKey) {
  const std::string path = write_temp_file("bad.yaml", R"(
domain_id: 999
planner:
  name: dijkstra
  omega: "lots"
map:
  occupied_threshold: 0
requests:
  queue_capacity: -3
topics:
  plan: "bad topic!"
planer:
  eta: 1
)");
  const auto [code, output] = run_to_exit(kNode, {"--config", path});
  EXPECT_EQ(code, 2) << output;
  for (const char* key : {"domain_id", "planner.name", "planner.omega", "map.occupied_threshold",
                          "requests.queue_capacity", "topics.plan", "planer"}) {
    EXPECT_NE(output.find(key), std::string::npos) << key << " not named in:\n" << output;
  }
}

// ROS users' habit (issue 45): ROS_DOMAIN_ID picks the domain, as for every ROS 2 node, over the
// config's domain_id; --domain wins over both; each choice is logged; a bad value is refused
// naming the variable. --print-config shows the domain the node would run on.
TEST(NodeProcess, RosDomainIdPicksTheDomainAndDomainWins) {
  const std::string path = write_temp_file("domain5.yaml", "domain_id: 5\n");
  auto run = [&](const char* env, std::vector<std::string> args) {
    if (env != nullptr)
      setenv("ROS_DOMAIN_ID", env, 1);
    else
      unsetenv("ROS_DOMAIN_ID");
    args.insert(args.begin(), {"--config", path, "--print-config"});
    auto result = run_to_exit(kNode, args);
    unsetenv("ROS_DOMAIN_ID");
    return result;
  };
  {
    const auto [code, output] = run(nullptr, {});
    EXPECT_EQ(code, 0) << output;
    EXPECT_NE(output.find("domain_id: 5\n"), std::string::npos) << output;
  }
  {
    const auto [code, output] = run("128", {});
    EXPECT_EQ(code, 0) << output;
    EXPECT_NE(output.find("domain_id: 128\n"), std::string::npos) << output;
    EXPECT_NE(output.find("DDS domain 128 (ROS_DOMAIN_ID; domain_id 5 of the config is not used)"),
              std::string::npos)
        << output;
  }
  {
    const auto [code, output] = run("128", {"--domain", "42"});
    EXPECT_EQ(code, 0) << output;
    EXPECT_NE(output.find("domain_id: 42\n"), std::string::npos) << output;
    EXPECT_NE(output.find("ROS_DOMAIN_ID=128 in the environment is not used"), std::string::npos)
        << output;
  }
  {
    const auto [code, output] = run("", {});  // empty: as unset (rcl's rule)
    EXPECT_EQ(code, 0) << output;
    EXPECT_NE(output.find("domain_id: 5\n"), std::string::npos) << output;
  }
  for (const char* bad : {"233", "-1", "seven", "12x"}) {
    const auto [code, output] = run(bad, {});
    EXPECT_EQ(code, 2) << bad << ": " << output;
    EXPECT_NE(output.find(std::string("ROS_DOMAIN_ID: found \"") + bad + "\""), std::string::npos)
        << output;
  }
}

TEST(NodeProcess, MissingConfigFileIsNamed) {
  // In an empty directory of its own: nothing can have made it.
  const std::string missing = (FreshTempDir("missing_config") / "no/such/file.yaml").string();
  const auto [code, output] = run_to_exit(kNode, {"--config", missing});
  EXPECT_EQ(code, 2);
  EXPECT_NE(output.find(missing), std::string::npos) << output;
}

// Issue 31: a usage error exits 2 from every executable on the bus, naming the flag (vnsba_node
// and vnsba_slicer exited 109, CLI11's own code for an argument not expected).
TEST(CommandLine, EveryExecutableExitsTwoOnAnUnknownFlagNamingIt) {
  const std::vector<std::vector<std::string>> commands = {
      {kNode, "--no-such-flag"},
      {VNSBA_SLICER_BINARY, "--no-such-flag"},
      {VNSBA_RECORDER_BINARY, "--no-such-flag"},
      {VNSBA_RECORDER_BINARY, "render", "run.json", "--no-such-flag"},
      {VNSBA_SEND_GOAL_BINARY, "--no-such-flag"},
      {VNSBA_MAKE_KEYSTORE, "--no-such-flag"},
  };
  for (const std::vector<std::string>& command : commands) {
    const auto [code, output] =
        run_to_exit(command.front(), std::vector<std::string>(command.begin() + 1, command.end()));
    EXPECT_EQ(code, 2) << command.front() << ":\n" << output;
    EXPECT_NE(output.find("--no-such-flag"), std::string::npos) << command.front() << ":\n"
                                                                << output;
  }
}

// A misspelt flag is reported as unknown, with the flag it was probably meant to be, before any
// other error (the value it was given is not taken for something else).
TEST(CommandLine, AMisspeltFlagIsNamedWithTheNearestKnownOne) {
  struct Case {
    std::vector<std::string> args;
    std::string said;
  };
  for (const Case& c : {
           Case{{"--domian", "3"}, "unknown option --domian (did you mean --domain?)"},
           Case{{"--config-file", "x.yaml"},
                "unknown option --config-file (did you mean --config?)"},
           Case{{"--namesp", "robot7"}, "unknown option --namesp (did you mean --namespace?)"},
           Case{{"extra"}, "unexpected argument extra"},
       }) {
    const auto [code, output] = run_to_exit(kNode, c.args);
    EXPECT_EQ(code, 2) << output;
    EXPECT_NE(output.find(c.said), std::string::npos) << c.said << " not in:\n" << output;
  }
}

TEST(NodeProcess, SigtermDrainsAndExitsZero) {
  const node::NodeConfig cfg = test_config("proc");
  const std::string path = write_temp_file("good.yaml", config_yaml(cfg));
  ChildProcess node_process(kNode, {"--config", path, "--domain", std::to_string(test_domain())});
  ASSERT_TRUE(node_process.wait_for_output("up on domain " + std::to_string(test_domain()), 10s))
      << node_process.output();
  {
    // One plan through the process: every publication must succeed (a writer that failed is
    // logged as "could not publish").
    BusClient client(cfg);
    ASSERT_TRUE(client.wait_for_node());
    core::OccupancyGrid free_room;  // 4 x 3 free cells at 1 m
    free_room.width = 4;
    free_room.height = 3;
    free_room.data.assign(12, core::kOccupancyFree);
    client.publish_slice(free_room);
    std::optional<PlanStatusMsg> status;
    for (int attempt = 0; attempt < 50 && !(status && status->code() == node::wire::OK);
         ++attempt) {
      const std::string id = "proc-" + std::to_string(attempt);
      client.publish_request(id, 0.5, 0.5, 3.5, 2.5);
      status = client.wait_status(id);
      if (status && status->code() == node::wire::NO_MAP) std::this_thread::sleep_for(100ms);
    }
    ASSERT_TRUE(status && status->code() == node::wire::OK) << node_process.output();
  }
  node_process.signal(SIGTERM);
  EXPECT_EQ(node_process.wait(), 0) << node_process.output();
  EXPECT_NE(node_process.output().find("SIGTERM received"), std::string::npos)
      << node_process.output();
  EXPECT_EQ(node_process.output().find("could not publish"), std::string::npos)
      << node_process.output();
}

// A tool that does its work and exits (vnsba_send_goal) must not swallow a Ctrl-C that came while
// DDS was torn down: bash takes a child that exited normally after SIGINT as having handled it
// and runs the script's next command (the demo then waited out every remaining goal). release()
// lets a signal still pending end the process as that signal.
TEST(StopSignals, ASignalStillPendingEndsTheProcessOnRelease) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  for (const int signal : {SIGINT, SIGTERM}) {
    EXPECT_EXIT(
        {
          const node::StopSignals stop;
          ::raise(signal);  // blocked: pending until taken or released
          stop.release();
          std::exit(0);  // reached only if the signal was lost
        },
        testing::KilledBySignal(signal), "")
        << node::StopSignals::name(signal);
  }
}

TEST(StopSignals, ASignalAlreadyTakenDoesNotEndTheProcessOnRelease) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        const node::StopSignals stop;
        ::raise(SIGINT);
        const std::optional<int> taken = stop.wait_for(std::chrono::milliseconds(0));
        stop.release();
        std::exit(taken == SIGINT ? 3 : 4);  // the tool's own exit code stands
      },
      testing::ExitedWithCode(3), "");
}

}  // namespace
}  // namespace vnsba::test
