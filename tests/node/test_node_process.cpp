// vnsba_node as a process: it refuses bad configs, naming every bad key, and SIGTERM makes it
// drain and exit 0.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include "bus_client.hpp"

namespace vnsba::test {
namespace {

struct ProcessResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// Runs the node with `args`, stdout+stderr into a file; optionally SIGTERM after `term_after`.
ProcessResult run_node(const std::vector<std::string>& args,
                       std::chrono::milliseconds term_after = std::chrono::milliseconds(0)) {
  const std::string log = ::testing::TempDir() + "/node_" + std::to_string(getpid()) + ".log";
  const pid_t pid = fork();
  if (pid == 0) {
    FILE* out = std::freopen(log.c_str(), "w", stdout);
    if (out == nullptr || dup2(fileno(stdout), fileno(stderr)) < 0) _exit(127);
    std::vector<char*> argv{const_cast<char*>(VNSBA_NODE_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(VNSBA_NODE_BINARY, argv.data());
    _exit(127);
  }
  ProcessResult result;
  if (term_after.count() > 0) {
    std::this_thread::sleep_for(term_after);
    kill(pid, SIGTERM);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(log);
  result.output.assign(std::istreambuf_iterator<char>(in), {});
  return result;
}

std::string write_config(const std::string& name, const std::string& text) {
  const std::string path =
      ::testing::TempDir() + "/" + name + "_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << text;
  return path;
}

TEST(NodeProcess, RefusesToStartOnABadConfigNamingEveryKey) {
  const std::string path = write_config("bad", R"(
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
  const ProcessResult r = run_node({"--config", path});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  for (const char* key : {"domain_id", "planner.name", "planner.omega", "map.occupied_threshold",
                          "requests.queue_capacity", "topics.plan", "planer"}) {
    EXPECT_NE(r.output.find(key), std::string::npos) << key << " not named in:\n" << r.output;
  }
}

TEST(NodeProcess, MissingConfigFileIsNamed) {
  const ProcessResult r = run_node({"--config", "no/such/file.yaml"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("no/such/file.yaml"), std::string::npos) << r.output;
}

TEST(NodeProcess, SigtermDrainsAndExitsZero) {
  const node::NodeConfig cfg = test_config("proc");
  const std::string path =
      write_config("good", "domain_id: 0\ntopics:\n  plan_request: " + cfg.topics.plan_request +
                               "\n  plan_status: " + cfg.topics.plan_status + "\n");
  const ProcessResult r = run_node({"--config", path, "--domain", std::to_string(test_domain())},
                                   std::chrono::milliseconds(1500));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("SIGTERM received"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("on domain " + std::to_string(test_domain())), std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace vnsba::test
