// Soaks of vnsba_node as a process (label `soak`, outside tools/test.sh's runs; see
// tests/CMakeLists.txt): a slice every 2 s, alternating between two maps, and a request every
// 50 ms (one robot) or from each of ten robots every 100 ms (a `robots` node), for
// VNSBA_SOAK_SECONDS (default 600) each. Checks that every request is answered and that
// the node's resident memory levels off: over the last third of the run it grows by at most
// 4 MB (issue 13 saw 42.6 -> 60.5 MB over 10 minutes, still growing by 1 MB/min at the end).
// Prints the RSS series, one line per 10 s, for the record.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "node/bus_client.hpp"
#include "node/child_process.hpp"

namespace vnsba::test {
namespace {

// Resident set size of process `pid`, megabytes (VmRSS of /proc/<pid>/status); -1 if unknown.
double rss_mb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) {
      std::istringstream fields(line.substr(6));
      double kb = -1;
      fields >> kb;
      return kb / 1024.0;
    }
  }
  return -1.0;
}

// An office-like map: rooms of 40 cells with doors, `shift` moving the doors.
core::OccupancyGrid office(int size, int shift) {
  core::OccupancyGrid g;
  g.width = g.height = size;
  g.resolution = 0.05;
  g.data.assign(static_cast<size_t>(size) * size, 0);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const bool wall =
          (x % 40 == 0 && (y + shift) % 40 > 6) || (y % 40 == 0 && (x + shift) % 40 > 6);
      if (wall) g.data[static_cast<size_t>(y) * size + x] = 100;
    }
  return g;
}

int soak_seconds() {
  const char* env = std::getenv("VNSBA_SOAK_SECONDS");
  return env ? std::max(30, std::atoi(env)) : 600;
}

// Runs the soak against `node_process`: `map_client` publishes a slice every 2 s (alternating
// two maps); every `period` each client of `robots` sends a request. Then checks that every
// request got exactly one status on its own client's topic, that the node still runs, and that
// its memory levelled off (the last third's peak at most 4 MB above the middle third's).
void soak(ChildProcess& node_process, BusClient& map_client, const std::vector<BusClient*>& robots,
          std::chrono::milliseconds period) {
  const int seconds = soak_seconds();
  const core::OccupancyGrid maps[2] = {office(300, 0), office(300, 17)};
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> coord(0.1, 14.9);
  const auto begin = std::chrono::steady_clock::now();
  const auto end = begin + std::chrono::seconds(seconds);
  std::vector<double> series;  // MB, every 10 s
  int requests = 0, slices = 0;
  auto next_slice = begin, next_sample = begin, next_round = begin;
  // Request statuses among `all` (slice reports excluded).
  auto answers_in = [](const std::vector<node::PlanStatusMsg>& all) {
    size_t answers = 0;
    for (const auto& s : all) answers += s.subject() != node::wire::SUBJECT_MAP;
    return answers;
  };
  auto answered = [&](BusClient& client) { return answers_in(client.statuses.snapshot()); };
  while (std::chrono::steady_clock::now() < end) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_slice) {
      map_client.publish_slice(maps[slices++ % 2]);
      next_slice += 2s;
    }
    if (now >= next_sample) {
      series.push_back(rss_mb(node_process.pid()));
      size_t statuses = 0;
      for (BusClient* robot : robots) statuses += answered(*robot);
      std::printf("soak t=%4llds rss=%.1f MB requests=%d statuses=%zu\n",
                  static_cast<long long>(
                      std::chrono::duration_cast<std::chrono::seconds>(now - begin).count()),
                  series.back(), requests, statuses);
      std::fflush(stdout);
      next_sample += 10s;
    }
    for (size_t r = 0; r < robots.size(); ++r) {
      const int index = requests++;
      robots[r]->publish_request("soak-" + std::to_string(index), coord(rng), coord(rng),
                                 coord(rng), coord(rng), index % 3 == 0 ? "astar" : "");
    }
    next_round += period;
    std::this_thread::sleep_until(next_round);
  }
  // Every request exactly once, on its own robot's topic (request ids are unique over the run).
  std::set<std::string> seen;
  size_t answers = 0;
  for (BusClient* robot : robots) {
    ASSERT_TRUE(robot->statuses.wait(
        [&](const auto& all) {
          return answers_in(all) * robots.size() >= static_cast<size_t>(requests);
        },
        60s))
        << "every request gets its status: " << answered(*robot) << " on one robot";
  }
  std::this_thread::sleep_for(500ms);  // anything extra would arrive now
  for (BusClient* robot : robots)
    for (const auto& s : robot->statuses.snapshot())
      if (s.subject() != node::wire::SUBJECT_MAP) {
        ++answers;
        EXPECT_TRUE(seen.insert(s.request_id()).second) << "two statuses for " << s.request_id();
      }
  EXPECT_EQ(answers, static_cast<size_t>(requests)) << "statuses lost or repeated";
  ASSERT_TRUE(node_process.running()) << node_process.output();
  ASSERT_GE(series.size(), 3u);
  const size_t third = series.size() / 3;
  const double middle_peak = *std::max_element(series.begin() + third, series.begin() + 2 * third);
  const double last_peak = *std::max_element(series.begin() + 2 * third, series.end());
  std::printf(
      "soak: %d requests from %zu robot(s), %d slices; RSS start %.1f, middle-third peak %.1f, "
      "last-third peak %.1f MB\n",
      requests, robots.size(), slices, series.front(), middle_peak, last_peak);
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer keeps freed memory in quarantine, so resident size means nothing here;
  // LeakSanitizer checks for leaks at the node's exit instead (its findings fail the run below).
  std::printf("soak: resident memory not judged under AddressSanitizer\n");
#else
  EXPECT_LE(last_peak - middle_peak, 4.0) << "resident memory still grows";
#endif
  node_process.signal(SIGTERM);
  EXPECT_EQ(node_process.wait(), 0) << node_process.output();
  // In the sanitizer build the node reports any finding on its output (and exits non-zero).
  for (const char* finding : {"Sanitizer", "runtime error:"})
    EXPECT_EQ(node_process.output().find(finding), std::string::npos) << node_process.output();
}

TEST(Soak, TheNodeServesForMinutesAndItsMemoryLevelsOff) {
  const node::NodeConfig cfg = test_config("soak");
  const std::string config_path =
      write_temp_file("soak.yaml", config_yaml(cfg) + "log_level: warn\n");
  ChildProcess node_process(kNode, {"--config", config_path});
  BusClient client(cfg);
  ASSERT_TRUE(client.wait_for_node(20s)) << node_process.output();
  soak(node_process, client, {&client}, 50ms);
}

// Issue 18: one node for ten robots (`robots`), each requesting every 100 ms on its own topics,
// the shared map republished every 2 s.
TEST(Soak, AFleetNodeServesTenRobotsForMinutes) {
  const node::NodeConfig cfg = test_config("soak_fleet");
  std::string robots = "robots: [";
  node::NodeConfig fleet = cfg;
  for (int r = 1; r <= 10; ++r) {
    fleet.robots.push_back("robot" + std::to_string(r));
    robots += (r > 1 ? ", " : "") + fleet.robots.back();
  }
  const std::string config_path =
      write_temp_file("soak_fleet.yaml", config_yaml(cfg) + robots + "]\nlog_level: warn\n");
  ChildProcess node_process(kNode, {"--config", config_path});
  std::vector<std::unique_ptr<BusClient>> clients;
  std::vector<BusClient*> robot_clients;
  for (const std::string& robot : fleet.robots) {
    clients.push_back(std::make_unique<BusClient>(node::robot_view(fleet, robot)));
    robot_clients.push_back(clients.back().get());
    ASSERT_TRUE(clients.back()->wait_for_node(20s)) << robot << node_process.output();
  }
  BusClient map_client(cfg);  // the node's own namespace: the shared map
  soak(node_process, map_client, robot_clients, 100ms);
}

}  // namespace
}  // namespace vnsba::test
