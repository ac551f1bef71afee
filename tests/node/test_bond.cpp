// The bond's state machine (vnsba/node/bond.hpp) on a clock the test steps: what bondcpp's
// BondSM.sm and bond.cpp do, event by event, checked against the transitions written there.
#include <gtest/gtest.h>

#include <set>

#include "vnsba/node/bond.hpp"
#include "vnsba/node/config.hpp"

namespace vnsba::node {
namespace {

using std::chrono::milliseconds;
using BondTime = Bond::TimePoint;

BondTimings bond_test_timings() {
  BondTimings t = BondTimings::bondcpp_defaults();
  t.connect_timeout = milliseconds(1000);
  t.heartbeat_timeout = milliseconds(400);
  t.disconnect_timeout = milliseconds(200);
  t.heartbeat_period = milliseconds(100);
  t.dead_publish_period = milliseconds(10);
  return t;
}

BondHeartbeat sister_says(bool active, const std::string& id = "planner_server",
                          const std::string& instance = "sister-instance") {
  BondHeartbeat h;
  h.id = id;
  h.instance_id = instance;
  h.active = active;
  return h;
}

// Steps the bond from `from` to `to` in 1 ms ticks (finer than every timing), collecting what it
// published and how it ended.
struct BondRun {
  std::vector<std::pair<BondTime, BondHeartbeat>> published;
  std::optional<BondEnd> ended;
  std::optional<BondTime> ended_at;
};
void bond_step_until(Bond& bond, BondTime from, BondTime to, BondRun& run) {
  for (BondTime t = from; t <= to; t += milliseconds(1)) {
    BondStep step = bond.advance(t);
    for (BondHeartbeat& h : step.publish) run.published.emplace_back(t, std::move(h));
    if (step.ended && !run.ended) {
      run.ended = step.ended;
      run.ended_at = t;
    }
  }
}

TEST(Bond, NothingBeforeStart) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  EXPECT_EQ(bond.state(), BondState::kNotStarted);
  EXPECT_FALSE(bond.on_status(sister_says(true), t0).formed);
  EXPECT_EQ(bond.state(), BondState::kNotStarted);
  EXPECT_FALSE(bond.next_deadline());
  EXPECT_TRUE(bond.advance(t0 + milliseconds(5000)).publish.empty());
}

TEST(Bond, HeartbeatsAtThePeriodWhileWaitingAndAlive) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  BondRun run;
  bond_step_until(bond, t0, t0 + milliseconds(350), run);
  // One period after start, then every period: 100, 200, 300 ms.
  ASSERT_EQ(run.published.size(), 3U);
  for (size_t i = 0; i < run.published.size(); ++i) {
    EXPECT_EQ(run.published[i].first, t0 + milliseconds(100 * (i + 1)));
    const BondHeartbeat& h = run.published[i].second;
    EXPECT_EQ(h.id, "planner_server");
    EXPECT_EQ(h.instance_id, "me");
    EXPECT_TRUE(h.active);
    EXPECT_FLOAT_EQ(h.heartbeat_period_s, 0.1F);
    EXPECT_FLOAT_EQ(h.heartbeat_timeout_s, 0.4F);
  }
  EXPECT_EQ(bond.state(), BondState::kWaitingForSister);
  // Formed: still every period.
  EXPECT_TRUE(bond.on_status(sister_says(true), t0 + milliseconds(350)).formed);
  BondRun alive;
  for (int k = 0; k < 3; ++k) {  // keep the sister heard
    const BondTime at = t0 + milliseconds(351 + 100 * k);
    bond.on_status(sister_says(true), at);
    bond_step_until(bond, at, at + milliseconds(99), alive);
  }
  ASSERT_EQ(alive.published.size(), 3U);
  EXPECT_EQ(alive.published[0].first, t0 + milliseconds(400));
  EXPECT_EQ(alive.published[2].first, t0 + milliseconds(600));
  EXPECT_FALSE(alive.ended);
}

TEST(Bond, FormedWhenTheSistersHeartbeatArrives) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  EXPECT_EQ(bond.state(), BondState::kWaitingForSister);
  const BondStep step = bond.on_status(sister_says(true), t0 + milliseconds(250));
  EXPECT_TRUE(step.formed);
  EXPECT_FALSE(step.ended);
  EXPECT_EQ(bond.state(), BondState::kAlive);
  EXPECT_EQ(bond.sister_instance_id(), "sister-instance");
  // The connect timeout no longer applies: past it, still alive while heard.
  BondRun run;
  for (int ms = 300; ms <= 2000; ms += 100) {
    bond.on_status(sister_says(true), t0 + milliseconds(ms));
    bond_step_until(bond, t0 + milliseconds(ms), t0 + milliseconds(ms + 99), run);
  }
  EXPECT_FALSE(run.ended);
  EXPECT_EQ(bond.state(), BondState::kAlive);
}

TEST(Bond, BrokenAfterHeartbeatTimeoutOfSilence) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  bond.on_status(sister_says(true), t0 + milliseconds(100));
  const BondTime last = t0 + milliseconds(300);
  bond.on_status(sister_says(true), last);
  BondRun run;
  bond_step_until(bond, last, last + milliseconds(1000), run);
  ASSERT_TRUE(run.ended);
  EXPECT_EQ(*run.ended, BondEnd::kHeartbeatTimeout);
  EXPECT_EQ(*run.ended_at, last + milliseconds(400));  // heartbeat_timeout after the last one
  EXPECT_EQ(bond.state(), BondState::kDead);
  // Dead: nothing published after (heartbeats went out until then), no deadline left.
  ASSERT_FALSE(run.published.empty());
  for (const auto& [at, h] : run.published) EXPECT_LT(at, *run.ended_at);
  EXPECT_FALSE(bond.next_deadline());
}

TEST(Bond, OneHeartbeatThenSilenceStillBreaks) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  bond.on_status(sister_says(true), t0 + milliseconds(50));
  BondRun run;
  bond_step_until(bond, t0, t0 + milliseconds(2000), run);
  ASSERT_TRUE(run.ended);
  EXPECT_EQ(*run.ended, BondEnd::kHeartbeatTimeout);
  EXPECT_EQ(*run.ended_at, t0 + milliseconds(450));
}

TEST(Bond, SilenceIgnoredWhereNav2sManagedNodesIgnoreIt) {
  Bond bond("planner_server", "me", BondTimings::nav2_managed_node(milliseconds(100)));
  const BondTime t0{};
  bond.start(t0);
  bond.on_status(sister_says(true), t0 + milliseconds(50));
  BondRun run;
  bond_step_until(bond, t0, t0 + milliseconds(20000), run);  // 5 x the 4 s heartbeat timeout
  EXPECT_FALSE(run.ended);
  EXPECT_EQ(bond.state(), BondState::kAlive);
  EXPECT_EQ(run.published.size(), 200U);  // still heartbeating every 0.1 s
}

TEST(Bond, BrokenAtOnceOnActiveFalseAndAcknowledged) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  bond.on_status(sister_says(true), t0 + milliseconds(100));
  const BondStep step = bond.on_status(sister_says(false), t0 + milliseconds(150));
  ASSERT_TRUE(step.ended);
  EXPECT_EQ(*step.ended, BondEnd::kSisterBroke);
  EXPECT_EQ(bond.state(), BondState::kDead);
  // The immediate acknowledgement: our own active=false.
  ASSERT_EQ(step.publish.size(), 1U);
  EXPECT_FALSE(step.publish[0].active);
  EXPECT_EQ(step.publish[0].instance_id, "me");
  // Dead is final: a later heartbeat of hers does not revive it.
  EXPECT_FALSE(bond.on_status(sister_says(true), t0 + milliseconds(200)).formed);
  EXPECT_EQ(bond.state(), BondState::kDead);
}

TEST(Bond, ActiveFalseWhileWaitingEndsIt) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  const BondStep step = bond.on_status(sister_says(false), t0 + milliseconds(10));
  ASSERT_TRUE(step.ended);
  EXPECT_EQ(*step.ended, BondEnd::kSisterBroke);
}

TEST(Bond, ConnectTimeoutWithoutSister) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  BondRun run;
  bond_step_until(bond, t0, t0 + milliseconds(3000), run);
  ASSERT_TRUE(run.ended);
  EXPECT_EQ(*run.ended, BondEnd::kConnectTimeout);
  EXPECT_EQ(*run.ended_at, t0 + milliseconds(1000));
  EXPECT_EQ(run.published.size(), 9U);  // 100 .. 900 ms; the 1000 ms one is after death
}

TEST(Bond, IgnoresOtherIdsAndItsOwnInstance) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  EXPECT_FALSE(bond.on_status(sister_says(true, "controller_server"), t0).formed);
  EXPECT_FALSE(bond.on_status(sister_says(true, "planner_server", "me"), t0).formed);
  EXPECT_FALSE(bond.on_status(sister_says(false, "controller_server"), t0).ended);
  EXPECT_FALSE(bond.on_status(sister_says(false, "planner_server", "me"), t0).ended);
  EXPECT_EQ(bond.state(), BondState::kWaitingForSister);
  EXPECT_TRUE(bond.sister_instance_id().empty());
  EXPECT_TRUE(bond.on_status(sister_says(true), t0).formed);
}

TEST(Bond, BreakingWhileAliveAwaitsTheSister) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  bond.on_status(sister_says(true), t0 + milliseconds(100));
  const BondTime broke = t0 + milliseconds(150);
  BondStep step = bond.break_bond(broke);
  EXPECT_FALSE(step.ended);
  ASSERT_EQ(step.publish.size(), 1U);
  EXPECT_FALSE(step.publish[0].active);
  EXPECT_EQ(bond.state(), BondState::kAwaitSisterDeath);
  // Publishing active=false every dead publish period (10 ms) while it waits; her heartbeats
  // do not bring it back.
  BondRun run;
  bond.on_status(sister_says(true), broke + milliseconds(5));
  bond_step_until(bond, broke, broke + milliseconds(55), run);
  EXPECT_GE(run.published.size(), 5U);
  for (const auto& [at, h] : run.published) EXPECT_FALSE(h.active);
  EXPECT_EQ(bond.state(), BondState::kAwaitSisterDeath);
  step = bond.on_status(sister_says(false), broke + milliseconds(60));
  ASSERT_TRUE(step.ended);
  EXPECT_EQ(*step.ended, BondEnd::kSisterAcknowledged);
  EXPECT_TRUE(step.publish.empty());  // she did not die first: no acknowledgement of ours
  EXPECT_FALSE(bond.break_bond(broke + milliseconds(70)).ended);  // idempotent
}

TEST(Bond, BreakingWhileAliveEndsAfterDisconnectTimeout) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  bond.on_status(sister_says(true), t0 + milliseconds(100));
  const BondTime broke = t0 + milliseconds(150);
  bond.break_bond(broke);
  BondRun run;
  bond_step_until(bond, broke, broke + milliseconds(1000), run);
  ASSERT_TRUE(run.ended);
  EXPECT_EQ(*run.ended, BondEnd::kDisconnectTimeout);
  EXPECT_EQ(*run.ended_at, broke + milliseconds(200));
}

TEST(Bond, BreakingWhileWaitingEndsAtOnce) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  const BondStep step = bond.break_bond(t0 + milliseconds(10));
  ASSERT_TRUE(step.ended);
  EXPECT_EQ(*step.ended, BondEnd::kBrokenHere);
  ASSERT_EQ(step.publish.size(), 1U);
  EXPECT_FALSE(step.publish[0].active);
  EXPECT_FALSE(bond.next_deadline());
}

TEST(Bond, NextDeadlineIsTheEarliestTimer) {
  Bond bond("planner_server", "me", bond_test_timings());
  const BondTime t0{};
  bond.start(t0);
  EXPECT_EQ(bond.next_deadline(), t0 + milliseconds(100));  // heartbeat before connect timeout
  bond.advance(t0 + milliseconds(100));
  EXPECT_EQ(bond.next_deadline(), t0 + milliseconds(200));
}

TEST(Bond, Nav2Timings) {
  const BondTimings node = BondTimings::nav2_managed_node(milliseconds(100));
  EXPECT_EQ(node.heartbeat_period, milliseconds(100));
  EXPECT_EQ(node.heartbeat_timeout, milliseconds(4000));
  EXPECT_EQ(node.sister_silence, SisterSilence::kIgnored);
  const BondTimings manager = BondTimings::nav2_lifecycle_manager(milliseconds(4000));
  EXPECT_EQ(manager.heartbeat_period, milliseconds(100));
  EXPECT_EQ(manager.heartbeat_timeout, milliseconds(4000));
  EXPECT_EQ(manager.sister_silence, SisterSilence::kBreaksBond);
  const BondTimings defaults = BondTimings::bondcpp_defaults();
  EXPECT_EQ(defaults.connect_timeout, milliseconds(10000));
  EXPECT_EQ(defaults.disconnect_timeout, milliseconds(2000));
}

TEST(Bond, InstanceIdsAreFreshUuids) {
  std::set<std::string> seen;
  for (int i = 0; i < 100; ++i) {
    const std::string id = new_instance_id();
    ASSERT_EQ(id.size(), 36U);
    EXPECT_EQ(id[8], '-');
    EXPECT_EQ(id[14], '4');  // version 4
    seen.insert(id);
  }
  EXPECT_EQ(seen.size(), 100U);
}

// bond.*: Nav2's default period, and every bad value refused naming the key and the unit.
TEST(BondConfig, DefaultsAndRefusals) {
  const ConfigResult defaults = default_config();
  ASSERT_TRUE(defaults.config.has_value());
  EXPECT_EQ(defaults.config->bond.mode, BondMode::kManaged);
  EXPECT_EQ(defaults.config->bond.heartbeat_period, milliseconds(100));  // Nav2 Jazzy's 0.1 s
  const ConfigResult set = parse_config("bond: {mode: always, heartbeat_period: 0.25}\n");
  ASSERT_TRUE(set.config.has_value());
  EXPECT_EQ(set.config->bond.mode, BondMode::kAlways);
  EXPECT_EQ(set.config->bond.heartbeat_period, milliseconds(250));
  for (const char* bad : {"bond: {heartbeat_period: 0}\n", "bond: {heartbeat_period: -1}\n",
                          "bond: {heartbeat_period: 61}\n", "bond: {heartbeat_period: .nan}\n",
                          "bond: {heartbeat_period: fast}\n"}) {
    const ConfigResult r = parse_config(bad);
    EXPECT_FALSE(r.config.has_value()) << bad;
    ASSERT_EQ(r.errors.size(), 1U) << bad;
    EXPECT_EQ(r.errors[0].rfind("bond.heartbeat_period: ", 0), 0U) << r.errors[0];
    EXPECT_NE(r.errors[0].find("seconds in [0.01, 60]"), std::string::npos) << r.errors[0];
  }
  const ConfigResult mode = parse_config("bond: {mode: sometimes}\n");
  ASSERT_EQ(mode.errors.size(), 1U);
  EXPECT_EQ(mode.errors[0].rfind("bond.mode: ", 0), 0U) << mode.errors[0];
  for (const char* name : {"managed", "always", "off"})
    EXPECT_NE(mode.errors[0].find(name), std::string::npos) << mode.errors[0];
}

}  // namespace
}  // namespace vnsba::node
