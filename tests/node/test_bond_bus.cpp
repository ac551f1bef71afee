// The bond on a real bus (loopback UDP, two participants): BondLink against BondLink, and the
// node's heartbeat against a manager-side link, as nav2_lifecycle_manager bonds with a server.
// Oracles: the state machine's own rules (bond.hpp) and the clock: a silent sister is noticed
// within heartbeat_timeout, a heartbeat period is counted on the wire.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>

#include "bond/msg/StatusPubSubTypes.h"
#include "bus_client.hpp"
#include "vnsba/node/bond_link.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

using node::BondEnd;
using node::BondLink;
using node::BondState;
using node::BondTimings;

// Both sides of a bond with short timings, on this process's test domain and a topic of its own.
struct BondPair {
  explicit BondPair(const std::string& tag)
      : topic("rt/t" + std::to_string(getpid()) + "_" + tag + "/bond"),
        manager_participant(node::Participant::create(test_domain(), "bond_manager").value()),
        node_participant(node::Participant::create(test_domain(), "bond_node").value()),
        manager(BondLink::create(*manager_participant, topic).value()),
        node(BondLink::create(*node_participant, topic).value()) {}
  ~BondPair() {
    manager->close();
    node->close();
    manager_participant->shutdown();
    node_participant->shutdown();
  }
  const std::string topic;
  std::unique_ptr<node::Participant> manager_participant;
  std::unique_ptr<node::Participant> node_participant;
  std::unique_ptr<BondLink> manager;
  std::unique_ptr<BondLink> node;
};

BondTimings manager_timings(std::chrono::milliseconds bond_timeout) {
  return BondTimings::nav2_lifecycle_manager(bond_timeout);
}

TEST(BondBus, FormsBothWaysAndBreaksOnActiveFalse) {
  BondPair pair("forms");
  std::atomic<int> manager_formed{0};
  std::atomic<int> manager_broken{0};
  std::atomic<int> broken_why{-1};
  pair.manager->start(
      "planner_server", manager_timings(4000ms), [&](const std::string&) { ++manager_formed; },
      [&](BondEnd why) {
        ++manager_broken;
        broken_why = static_cast<int>(why);
      });
  pair.node->start("planner_server", BondTimings::nav2_managed_node(100ms));
  ASSERT_TRUE(pair.manager->wait_until_formed(5s));
  ASSERT_TRUE(pair.node->wait_until_formed(5s));
  EXPECT_EQ(pair.manager->state(), BondState::kAlive);
  EXPECT_EQ(pair.node->state(), BondState::kAlive);
  // The callback runs on the thread that saw the heartbeat, right after the state changed.
  for (int i = 0; i < 100 && manager_formed.load() == 0; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(manager_formed.load(), 1);
  EXPECT_NE(pair.manager->instance_id(), pair.node->instance_id());
  // The node's deactivate: active=false; the manager's side ends at once (no timeout).
  const auto broke = std::chrono::steady_clock::now();
  pair.node->break_bond(1000ms);
  ASSERT_TRUE(pair.manager->wait_until_broken(1000ms));
  EXPECT_LT(std::chrono::steady_clock::now() - broke, 1000ms);
  for (int i = 0; i < 100 && manager_broken.load() == 0; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(manager_broken.load(), 1);
  EXPECT_EQ(broken_why.load(), static_cast<int>(BondEnd::kSisterBroke));
  // The manager acknowledged: the node's side ended on that answer, not on its disconnect
  // timeout.
  EXPECT_EQ(pair.node->state(), BondState::kDead);
}

TEST(BondBus, SilentSisterBreaksWithinTheTimeout) {
  BondPair pair("silent");
  pair.manager->start("planner_server", manager_timings(600ms));
  pair.node->start("planner_server", BondTimings::nav2_managed_node(100ms));
  ASSERT_TRUE(pair.manager->wait_until_formed(5s));
  // The node's side goes silent without a word (a stopped process): close() does not break.
  const auto silent = std::chrono::steady_clock::now();
  pair.node->close();
  ASSERT_TRUE(pair.manager->wait_until_broken(5s));
  const auto took = std::chrono::steady_clock::now() - silent;
  // At most the timeout after the last heartbeat heard, which came at most one period before.
  EXPECT_LT(took, 600ms + 300ms);
  EXPECT_GT(took, 600ms - 150ms);
}

TEST(BondBus, OtherIdsDoNotForm) {
  BondPair pair("ids");
  pair.manager->start("planner_server", manager_timings(4000ms));
  pair.node->start("controller_server", BondTimings::nav2_managed_node(100ms));
  EXPECT_FALSE(pair.manager->wait_until_formed(1000ms));
  EXPECT_EQ(pair.manager->state(), BondState::kWaitingForSister);
}

// Every heartbeat on the topic, as a third participant sees it.
struct BondListener : public node::dds::DataReaderListener {
  void on_data_available(node::dds::DataReader* reader) override {
    bond::msg::dds_::Status_ msg;
    node::dds::SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) {
        std::lock_guard<std::mutex> lock(mutex);
        heard.push_back({std::chrono::steady_clock::now(), msg});
      }
  }
  std::mutex mutex;
  std::vector<std::pair<std::chrono::steady_clock::time_point, bond::msg::dds_::Status_>> heard;
};

// The node with bond.mode always: its heartbeat on rt/<namespace>/bond at the configured period,
// id the node's, a manager-side link forms with it; at stop the node breaks the bond.
TEST(BondBus, NodeHeartbeatsUnderItsNamespace) {
  node::NodeConfig cfg = test_config("bondnode");
  cfg.ros_namespace = "t" + std::to_string(getpid()) + "_bondns";
  cfg.bond.mode = node::BondMode::kAlways;
  cfg.bond.heartbeat_period = 50ms;
  const std::string topic = "rt/" + cfg.ros_namespace + "/bond";
  ASSERT_EQ(node::dds_topic_name(cfg, "bond"), topic);
  BondListener listener;  // outlives the participant's reader
  auto participant = node::Participant::create(cfg.domain_id, "bond_watch").value();
  node::dds::DataReaderQos rqos = node::reader_qos(node::TopicQos::kLatest);
  rqos.history().depth = 100;
  ASSERT_TRUE(participant->reader_on<bond::msg::dds_::Status_PubSubType>(topic, rqos, &listener)
                  .has_value());
  auto manager = BondLink::create(*participant, topic).value();
  std::atomic<int> why{-1};
  manager->start("vnsba_node", manager_timings(4000ms), nullptr,
                 [&](BondEnd end) { why = static_cast<int>(end); });
  {
    node::PlannerNode planner(cfg);
    ASSERT_TRUE(planner.start().is_ok());
    ASSERT_TRUE(manager->wait_until_formed(5s));
    std::this_thread::sleep_for(1000ms);
    planner.stop();
    ASSERT_TRUE(manager->wait_until_broken(2s));
    for (int i = 0; i < 100 && why.load() < 0; ++i) std::this_thread::sleep_for(10ms);
    EXPECT_EQ(why.load(), static_cast<int>(BondEnd::kSisterBroke));
  }
  manager->close();
  participant->shutdown();
  std::vector<std::pair<std::chrono::steady_clock::time_point, bond::msg::dds_::Status_>>
      node_heard;
  const std::string manager_instance = manager->instance_id();
  for (const auto& [at, msg] : listener.heard)
    if (msg.instance_id() != manager_instance) node_heard.push_back({at, msg});
  ASSERT_GE(node_heard.size(), 10U);
  for (const auto& [at, msg] : node_heard) {
    EXPECT_EQ(msg.id(), "vnsba_node");
    EXPECT_FLOAT_EQ(msg.heartbeat_period(), 0.05F);
  }
  EXPECT_FALSE(node_heard.back().second.active());  // the last word: the bond broken at stop
  // The period, from the spacing of the active heartbeats (loopback adds little).
  std::vector<double> gaps_ms;
  for (size_t i = 1; i < node_heard.size(); ++i)
    if (node_heard[i].second.active() && node_heard[i - 1].second.active())
      gaps_ms.push_back(
          std::chrono::duration<double, std::milli>(node_heard[i].first - node_heard[i - 1].first)
              .count());
  ASSERT_GE(gaps_ms.size(), 5U);
  std::sort(gaps_ms.begin(), gaps_ms.end());
  EXPECT_NEAR(gaps_ms[gaps_ms.size() / 2], 50.0, 20.0);  // the median
}

}  // namespace
}  // namespace vnsba::test
