#include "vnsba/node/bond.hpp"

#include <algorithm>
#include <cstdio>
#include <random>

#include "bond/msg/Constants.h"

namespace vnsba::node {

namespace {

std::chrono::nanoseconds bond_duration(double seconds) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(seconds));
}

float bond_seconds(std::chrono::nanoseconds d) {
  return std::chrono::duration<float>(d).count();
}

}  // namespace

std::string_view bond_state_name(BondState state) {
  switch (state) {
    case BondState::kNotStarted:
      return "not started";
    case BondState::kWaitingForSister:
      return "waiting for sister";
    case BondState::kAlive:
      return "alive";
    case BondState::kAwaitSisterDeath:
      return "awaiting sister death";
    case BondState::kDead:
      return "dead";
  }
  return "?";
}

std::string_view bond_end_name(BondEnd end) {
  switch (end) {
    case BondEnd::kConnectTimeout:
      return "no heartbeat of the sister within the connect timeout";
    case BondEnd::kHeartbeatTimeout:
      return "the sister's heartbeats stopped (heartbeat timeout)";
    case BondEnd::kSisterBroke:
      return "the sister broke the bond (active=false)";
    case BondEnd::kBrokenHere:
      return "broken here before the sister was heard";
    case BondEnd::kDisconnectTimeout:
      return "broken here; the sister did not acknowledge within the disconnect timeout";
    case BondEnd::kSisterAcknowledged:
      return "broken here; the sister acknowledged";
  }
  return "?";
}

BondTimings BondTimings::bondcpp_defaults() {
  namespace k = bond::msg::dds_::Constants_Constants;
  return BondTimings{
      bond_duration(k::DEFAULT_CONNECT_TIMEOUT),    bond_duration(k::DEFAULT_HEARTBEAT_TIMEOUT),
      bond_duration(k::DEFAULT_DISCONNECT_TIMEOUT), bond_duration(k::DEFAULT_HEARTBEAT_PERIOD),
      bond_duration(k::DEAD_PUBLISH_PERIOD),        SisterSilence::kBreaksBond};
}

BondTimings BondTimings::nav2_managed_node(std::chrono::nanoseconds heartbeat_period) {
  // nav2_util/src/lifecycle_node.cpp (Jazzy), createBond(): setHeartbeatPeriod(
  // bond_heartbeat_period), setHeartbeatTimeout(4.0); the constructor sets
  // DISABLE_HEARTBEAT_TIMEOUT_PARAM true, so the timeout never fires on the node's side.
  BondTimings t = bondcpp_defaults();
  t.heartbeat_period = heartbeat_period;
  t.heartbeat_timeout = bond_duration(4.0);
  t.sister_silence = SisterSilence::kIgnored;
  return t;
}

BondTimings BondTimings::nav2_lifecycle_manager(std::chrono::nanoseconds bond_timeout) {
  // nav2_lifecycle_manager/src/lifecycle_manager.cpp, createBondConnection():
  // setHeartbeatTimeout(bond_timeout), setHeartbeatPeriod(0.10).
  BondTimings t = bondcpp_defaults();
  t.heartbeat_timeout = bond_timeout;
  t.heartbeat_period = bond_duration(0.10);
  return t;
}

Bond::Bond(std::string id, std::string instance_id, BondTimings timings)
    : id_(std::move(id)), instance_id_(std::move(instance_id)), timings_(timings) {}

BondHeartbeat Bond::heartbeat(bool active) const {
  return BondHeartbeat{id_, instance_id_, active, bond_seconds(timings_.heartbeat_timeout),
                       bond_seconds(timings_.heartbeat_period)};
}

BondStep Bond::start(TimePoint now) {
  BondStep step;
  if (state_ != BondState::kNotStarted) return step;
  state_ = BondState::kWaitingForSister;
  connect_due_ = now + timings_.connect_timeout;
  publish_due_ = now + timings_.heartbeat_period;
  return step;
}

// BondSM's Death(): every timer but the publishing ones stops; the publishing timer stops at its
// next tick (bondcpp's doPublishing in state Dead), so nothing more is published.
void Bond::die(BondEnd why, BondStep& step) {
  state_ = BondState::kDead;
  connect_due_.reset();
  heartbeat_timeout_due_.reset();
  disconnect_due_.reset();
  publish_due_.reset();
  dead_publish_due_.reset();
  step.ended = why;
}

BondStep Bond::on_status(const BondHeartbeat& status, TimePoint now) {
  BondStep step;
  if (state_ == BondState::kNotStarted) return step;
  // bondcpp's bondStatusCB: other bonds' messages and our own (the topic brings them back) are
  // not the sister's.
  if (status.id != id_ || status.instance_id == instance_id_) return step;
  if (sister_instance_id_.empty()) sister_instance_id_ = status.instance_id;
  if (status.active) {
    switch (state_) {
      case BondState::kWaitingForSister:  // Connected()
        state_ = BondState::kAlive;
        connect_due_.reset();
        step.formed = true;
        // bondcpp arms the heartbeat timer only from the second heartbeat on (BondSM runs
        // Heartbeat() on Alive -> Alive, not on the first SisterAlive): a sister heard once and
        // then never again would keep the bond alive for ever. Armed from the first here, so
        // silence always breaks an enforced bond after heartbeat_timeout.
        [[fallthrough]];
      case BondState::kAlive:  // Heartbeat()
        if (timings_.sister_silence == SisterSilence::kBreaksBond)
          heartbeat_timeout_due_ = now + timings_.heartbeat_timeout;
        break;
      default:  // awaiting the sister's death, or dead: ignored
        break;
    }
    return step;
  }
  // active=false: SisterDead.
  switch (state_) {
    case BondState::kWaitingForSister:  // Connected(); SisterDied(); Death()
    case BondState::kAlive:             // SisterDied(); Death()
      sister_died_first_ = true;
      die(BondEnd::kSisterBroke, step);
      break;
    case BondState::kAwaitSisterDeath:  // Death(): she answered ours
      die(BondEnd::kSisterAcknowledged, step);
      break;
    default:
      break;
  }
  // bondcpp: "Immediate ack for sister's death notification", on every active=false heard
  // once she died first.
  if (sister_died_first_) step.publish.push_back(heartbeat(false));
  return step;
}

BondStep Bond::advance(TimePoint now) {
  BondStep step;
  // Timeouts before heartbeats: a bond that timed out at `now` publishes nothing more.
  if (state_ == BondState::kWaitingForSister && connect_due_ && now >= *connect_due_)
    die(BondEnd::kConnectTimeout, step);
  if (state_ == BondState::kAlive && heartbeat_timeout_due_ && now >= *heartbeat_timeout_due_)
    die(BondEnd::kHeartbeatTimeout, step);
  if (state_ == BondState::kAwaitSisterDeath && disconnect_due_ && now >= *disconnect_due_)
    die(BondEnd::kDisconnectTimeout, step);
  // bondcpp's doPublishing, on the heartbeat period and (awaiting death) the dead publish period.
  // A late call publishes once and schedules from now, as a timer that missed ticks does.
  const bool active = state_ == BondState::kWaitingForSister || state_ == BondState::kAlive;
  bool due = false;
  if (publish_due_ && now >= *publish_due_) {
    due = true;
    publish_due_ = std::max(*publish_due_ + timings_.heartbeat_period, now);
  }
  if (dead_publish_due_ && now >= *dead_publish_due_) {
    due = true;
    dead_publish_due_ = std::max(*dead_publish_due_ + timings_.dead_publish_period, now);
  }
  if (due && state_ != BondState::kDead) step.publish.push_back(heartbeat(active));
  return step;
}

BondStep Bond::break_bond(TimePoint now) {
  BondStep step;
  switch (state_) {
    case BondState::kNotStarted:
      // Never started: nothing to tell anyone (bondcpp's destructor returns early).
      state_ = BondState::kDead;
      return step;
    case BondState::kWaitingForSister:  // Die -> Dead: Death()
      die(BondEnd::kBrokenHere, step);
      break;
    case BondState::kAlive:  // Die -> AwaitSisterDeath: StartDying()
      state_ = BondState::kAwaitSisterDeath;
      heartbeat_timeout_due_.reset();
      // BondSM.sm: AwaitSisterDeath ends on SisterDead or DisconnectTimeout. (The ROS 2 port's
      // StartDying() resets the disconnect timer's pointer, which destroys that timer, so its
      // bond stays in AwaitSisterDeath until the sister answers; the state machine's
      // DisconnectTimeout, as ROS 1's bondcpp runs it, is followed here.)
      disconnect_due_ = now + timings_.disconnect_timeout;
      dead_publish_due_ = now + timings_.dead_publish_period;
      break;
    case BondState::kAwaitSisterDeath:
    case BondState::kDead:
      return step;  // bondcpp publishes only when the state was not Dead; Die is a no-op here
  }
  step.publish.push_back(heartbeat(false));
  return step;
}

std::optional<Bond::TimePoint> Bond::next_deadline() const {
  std::optional<TimePoint> next;
  for (const std::optional<TimePoint>& due :
       {connect_due_, heartbeat_timeout_due_, disconnect_due_, publish_due_, dead_publish_due_})
    if (due && (!next || *due < *next)) next = due;
  return next;
}

std::string new_instance_id() {
  std::random_device device;
  std::mt19937_64 random(
      (static_cast<uint64_t>(device()) << 32) ^ device() ^
      static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()));
  unsigned char bytes[16];
  for (int i = 0; i < 16; i += 8) {
    const uint64_t word = random();
    for (int j = 0; j < 8; ++j) bytes[i + j] = static_cast<unsigned char>(word >> (8 * j));
  }
  bytes[6] = static_cast<unsigned char>((bytes[6] & 0x0F) | 0x40);  // version 4
  bytes[8] = static_cast<unsigned char>((bytes[8] & 0x3F) | 0x80);  // RFC 4122 variant
  char text[37];
  std::snprintf(text, sizeof text,
                "%02x%02x%02x%02x-%02x%02x-%02x%02x-%02x%02x-%02x%02x%02x%02x%02x%02x", bytes[0],
                bytes[1], bytes[2], bytes[3], bytes[4], bytes[5], bytes[6], bytes[7], bytes[8],
                bytes[9], bytes[10], bytes[11], bytes[12], bytes[13], bytes[14], bytes[15]);
  return text;
}

}  // namespace vnsba::node
