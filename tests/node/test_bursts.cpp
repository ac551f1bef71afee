// Bursts and shutdowns lose no answer (issue 31, items 2 and 3): several clients flood the node
// with requests over loopback DDS, and every request the node took from the bus is answered on
// the client that sent it, exactly once. The oracle is the node's own count of requests taken
// (PlannerNode::Stats::requests_received, or the count vnsba_node logs when it stops) against
// what the clients received, request id by request id.
//
// Suites: Bursts.* run in the default suite (label node): the 3 x 5,000 with queue
// 100,000, and smaller bursts that still overflow the node's answer backlog with queue 64 (so its
// flow control is exercised) or meet a SIGTERM; StressBursts.* are the other full sizes
// (3 clients x 5,000 with queue 64, SIGTERM 2 s in; label stress, outside the default run):
//   ctest --test-dir build/release -L stress --output-on-failure
#include <gtest/gtest.h>
#include <signal.h>

#include <map>
#include <regex>
#include <set>
#include <thread>

#include "bus_client.hpp"
#include "child_process.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

// A small open room: every plan takes microseconds, so answers come faster than DDS delivers.
core::OccupancyGrid open_room() {
  core::OccupancyGrid g;
  g.width = g.height = 16;
  g.resolution = 0.1;
  g.data.assign(static_cast<size_t>(g.width * g.height), 0);
  for (int x = 3; x < 12; ++x) g.data[static_cast<size_t>(8 * g.width + x)] = 100;  // a wall
  return g;
}

struct BurstResult {
  std::vector<size_t> sent;      // requests each client wrote (write accepted by DDS)
  std::vector<size_t> answered;  // distinct requests of each client with a status
  std::vector<size_t> repeated;  // statuses a client got twice for one request
  std::string first_missing;
};

// Each client writes `per_client` requests as fast as it can, from its own thread; then the
// statuses each received for its own requests (matched by the request's sample identity) are
// counted once `settled()` holds or `timeout` passes.
template <class Settled>
BurstResult burst(std::vector<std::unique_ptr<BusClient>>& clients, size_t per_client,
                  const core::OccupancyGrid& grid, Settled settled,
                  std::chrono::milliseconds timeout, const std::function<void()>& mid_burst = {}) {
  BurstResult result;
  const double ax = 0.15, ay = 0.15;                           // cell (1, 1)
  const double bx = 0.1 * (grid.width - 2) + 0.05, by = 1.45;  // cell (14, 14)
  std::vector<std::vector<node::RequestIdentity>> identities(clients.size());
  std::vector<std::thread> writers;
  for (size_t c = 0; c < clients.size(); ++c) {
    writers.emplace_back([&, c] {
      for (size_t i = 0; i < per_client; ++i) {
        identities[c].push_back(clients[c]->publish_request(
            "c" + std::to_string(c) + "-" + std::to_string(i), ax, ay, bx, by, "jps"));
      }
    });
  }
  if (mid_burst) mid_burst();
  for (std::thread& t : writers) t.join();
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!settled() && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // stragglers: counted as lost
  for (size_t c = 0; c < clients.size(); ++c) {
    std::map<int64_t, int> seen;  // sequence number -> statuses received for it
    node::RequestIdentity mine = identities[c].empty() ? node::RequestIdentity{} : identities[c][0];
    for (const PlanStatusMsg& s : clients[c]->statuses.snapshot())
      if (s.request_writer_guid() == mine.writer_guid) ++seen[s.request_sequence_number()];
    size_t sent = 0, repeated = 0;
    for (const node::RequestIdentity& id : identities[c]) {
      if (id.sequence_number <= 0) continue;  // the write was refused: never sent
      ++sent;
      const auto it = seen.find(id.sequence_number);
      if (it == seen.end()) {
        if (result.first_missing.empty())
          result.first_missing =
              "client " + std::to_string(c) + " request seq " + std::to_string(id.sequence_number);
      } else if (it->second > 1) {
        ++repeated;
      }
    }
    result.sent.push_back(sent);
    result.answered.push_back(seen.size());
    result.repeated.push_back(repeated);
  }
  return result;
}

size_t sum(const std::vector<size_t>& values) {
  size_t total = 0;
  for (size_t v : values) total += v;
  return total;
}

// 3 clients x `per_client`, preempt off, jps (35-55 us a plan): the node answers faster than the
// bus delivers. Every request the node took is answered on its client, once.
void expect_no_status_lost(const std::string& tag, size_t per_client, int queue_capacity,
                           std::chrono::seconds timeout) {
  node::NodeConfig cfg = test_config(tag);
  cfg.preempt = false;
  cfg.queue_capacity = queue_capacity;
  cfg.workers = 1;
  node::PlannerNode planner(cfg);
  ASSERT_TRUE(planner.start().is_ok());
  std::vector<std::unique_ptr<BusClient>> clients;
  for (int c = 0; c < 3; ++c) clients.push_back(std::make_unique<BusClient>(cfg));
  for (auto& client : clients) ASSERT_TRUE(client->wait_for_match(planner));
  const core::OccupancyGrid grid = open_room();
  clients[0]->publish_slice(grid);
  ASSERT_TRUE(planner.wait_for_map(std::chrono::seconds(10)));
  const size_t expected = 3 * per_client;
  const BurstResult r = burst(
      clients, per_client, grid,
      [&] {
        const auto stats = planner.stats();
        if (stats.requests_received < expected) return false;
        for (auto& client : clients)  // every client reads every answer on the topic
          if (client->statuses.snapshot().size() < expected) return false;
        return true;
      },
      timeout);
  const node::PlannerNode::Stats stats = planner.stats();
  const std::string diagnosis =
      "node took " + std::to_string(stats.requests_received) + ", published " +
      std::to_string(stats.statuses_published) + "; clients sent " + std::to_string(sum(r.sent)) +
      ", answered " + std::to_string(sum(r.answered)) + "; first missing: " + r.first_missing;
  EXPECT_EQ(sum(r.sent), expected) << diagnosis;
  EXPECT_EQ(stats.requests_received, sum(r.answered)) << diagnosis;
  EXPECT_EQ(stats.requests_received, expected) << diagnosis;
  for (size_t c = 0; c < clients.size(); ++c) {
    EXPECT_EQ(r.answered[c], r.sent[c]) << "client " << c << ": " << diagnosis;
    EXPECT_EQ(r.repeated[c], 0u) << "client " << c;
  }
}

TEST(Bursts, ThreeClientsWithAQueueOf64LoseNoStatus) {
  expect_no_status_lost("burst64", 1500, 64, std::chrono::seconds(120));
}

// The issue's own burst, in the default run (about 25 s): with the old keep-last status writer it
// lost 1,976 of 15,000 statuses (client 0 from its 2,614th request on); the smaller bursts here
// did not reproduce that loss.
TEST(Bursts, ThreeClientsOf5000WithAQueueOf100000LoseNoStatus) {
  expect_no_status_lost("burst100k", 5000, 100000, std::chrono::seconds(600));
}

TEST(StressBursts, ThreeClientsOf5000WithAQueueOf64LoseNoStatus) {
  expect_no_status_lost("stress64", 5000, 64, std::chrono::seconds(600));
}

// SIGTERM in the middle of a burst: vnsba_node drains (every request it took is answered, those
// not planned yet CANCELED) and waits for the acknowledgements before its writers go, then exits
// 0. Its count of requests taken (its last log line) equals what the clients received.
void expect_drain_loses_nothing(const std::string& tag, size_t per_client,
                                std::chrono::milliseconds term_after) {
  node::NodeConfig cfg = test_config(tag);
  const std::string path = write_temp_file(tag + ".yaml", config_yaml(cfg));
  ChildProcess node_process(VNSBA_NODE_BINARY, {"--config", path});
  std::vector<std::unique_ptr<BusClient>> clients;
  for (int c = 0; c < 3; ++c) clients.push_back(std::make_unique<BusClient>(cfg));
  for (auto& client : clients) ASSERT_TRUE(client->wait_for_node()) << node_process.output();
  const core::OccupancyGrid grid = open_room();
  clients[0]->publish_slice(grid);
  ASSERT_TRUE(node_process.wait_for_output("map accepted", std::chrono::seconds(10)))
      << node_process.output();
  int exit_code = -1;
  const BurstResult r = burst(
      clients, per_client, grid,
      [&] { return node_process.output().find("stopped:") != std::string::npos; },
      std::chrono::seconds(120),
      [&] {
        std::this_thread::sleep_for(term_after);
        node_process.signal(SIGTERM);
      });
  exit_code = node_process.wait();
  const std::string log = node_process.output();
  EXPECT_EQ(exit_code, 0) << log.substr(log.size() > 4000 ? log.size() - 4000 : 0);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex("stopped: (\\d+) requests")))
      << log.substr(log.size() > 4000 ? log.size() - 4000 : 0);
  const size_t taken = std::stoul(m[1]);
  const std::string diagnosis =
      "node took " + std::to_string(taken) + "; clients sent " + std::to_string(sum(r.sent)) +
      ", answered " + std::to_string(sum(r.answered)) + "; first missing: " + r.first_missing;
  EXPECT_GT(taken, 0u) << diagnosis;
  EXPECT_EQ(sum(r.answered), taken) << diagnosis;
  for (size_t c = 0; c < clients.size(); ++c) EXPECT_EQ(r.repeated[c], 0u) << "client " << c;
  EXPECT_EQ(log.find("could not publish"), std::string::npos) << diagnosis;
}

TEST(Bursts, SigtermMidBurstAnswersEveryRequestTaken) {
  expect_drain_loses_nothing("drain", 1500, std::chrono::milliseconds(300));
}

TEST(StressBursts, SigtermTwoSecondsIntoThreeClientsOf5000AnswersEveryRequestTaken) {
  expect_drain_loses_nothing("stressdrain", 5000, std::chrono::seconds(2));
}

}  // namespace
}  // namespace vnsba::test
