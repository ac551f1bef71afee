// vnsba_node as a process: it refuses bad configs, naming every bad key, and SIGTERM makes it
// drain and exit 0.
#include <gtest/gtest.h>
#include <signal.h>

#include <string>

#include "bus_client.hpp"
#include "child_process.hpp"

namespace vnsba::test {
namespace {

const std::string kNode = VNSBA_NODE_BINARY;

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

TEST(NodeProcess, MissingConfigFileIsNamed) {
  const auto [code, output] = run_to_exit(kNode, {"--config", "no/such/file.yaml"});
  EXPECT_EQ(code, 2);
  EXPECT_NE(output.find("no/such/file.yaml"), std::string::npos) << output;
}

TEST(NodeProcess, SigtermDrainsAndExitsZero) {
  const node::NodeConfig cfg = test_config("proc");
  const std::string path = write_temp_file("good.yaml", config_yaml(cfg));
  ChildProcess node_process(kNode, {"--config", path, "--domain", std::to_string(test_domain())});
  ASSERT_TRUE(node_process.wait_for_output("up on domain " + std::to_string(test_domain()), 10s))
      << node_process.output();
  node_process.signal(SIGTERM);
  EXPECT_EQ(node_process.wait(), 0) << node_process.output();
  EXPECT_NE(node_process.output().find("SIGTERM received"), std::string::npos)
      << node_process.output();
}

}  // namespace
}  // namespace vnsba::test
