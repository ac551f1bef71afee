// A bond: two processes ("sisters") that each publish a heartbeat (bond/msg/Status) on one topic
// and watch the other's, as bondcpp does (ros/bond_core, branch ros2: bondcpp/src/bond.cpp and
// its state machine bond/BondSM.sm). Nav2's lifecycle manager bonds with each node it activates
// and resets the whole stack when one bond breaks (nav2_lifecycle_manager, lifecycle_manager.cpp,
// createBondConnection / checkBondConnections); each managed node bonds back while active
// (nav2_util's LifecycleNode, createBond / destroyBond).
//
// This is the state machine and its timers only: no DDS and no clock of its own. The caller
// passes the time of every event (a steady clock: the node's bus thread, or a test stepping
// time), publishes the heartbeats each call returns, and calls advance() again at
// next_deadline() at the latest. bond_link.hpp carries it on the bus.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vnsba::node {

// BondSM's states (bond/BondSM.sm).
enum class BondState {
  kNotStarted,        // made, start() not called yet: hears nothing, publishes nothing
  kWaitingForSister,  // started, no heartbeat of the sister yet (connect timeout runs)
  kAlive,             // formed: the sister's heartbeats arrive (heartbeat timeout runs)
  kAwaitSisterDeath,  // we broke it while alive: publishing active=false, waiting for the
                      // sister's active=false (disconnect timeout runs)
  kDead,              // broken, for good: nothing is published any more
};
std::string_view bond_state_name(BondState state);

// What ends a bond, for logs and for the caller's reaction.
enum class BondEnd {
  kConnectTimeout,      // no heartbeat of the sister within connect_timeout of start()
  kHeartbeatTimeout,    // the sister fell silent for heartbeat_timeout
  kSisterBroke,         // the sister said active=false
  kBrokenHere,          // break_bond() before the sister was ever heard
  kDisconnectTimeout,   // break_bond() when alive, and the sister never answered active=false
  kSisterAcknowledged,  // break_bond() when alive, and the sister answered active=false
};
std::string_view bond_end_name(BondEnd end);

// Whether the sister's silence breaks the bond. Nav2's managed nodes ignore it ("server side
// never times out from lifecycle manager": nav2_util's LifecycleNode sets bondcpp's
// /bond_disable_heartbeat_timeout parameter); the lifecycle manager enforces it (bond_timeout).
enum class SisterSilence { kBreaksBond, kIgnored };

// bondcpp's timings. Durations in nanoseconds of the caller's steady clock.
struct BondTimings {
  std::chrono::nanoseconds connect_timeout;
  std::chrono::nanoseconds heartbeat_timeout;
  std::chrono::nanoseconds disconnect_timeout;
  std::chrono::nanoseconds heartbeat_period;
  // The period of the active=false heartbeats while awaiting the sister's death (bondcpp's
  // dead_publish_period).
  std::chrono::nanoseconds dead_publish_period;
  SisterSilence sister_silence = SisterSilence::kBreaksBond;

  // bondcpp's defaults (bond/msg/Constants.msg: connect 10 s, heartbeat timeout 4 s, disconnect
  // 2 s, period 1 s, dead publish period 0.05 s).
  static BondTimings bondcpp_defaults();
  // What a Nav2 managed node's createBond() sets: heartbeat_period as its bond_heartbeat_period
  // parameter, heartbeat timeout 4 s but ignored (SisterSilence::kIgnored).
  static BondTimings nav2_managed_node(std::chrono::nanoseconds heartbeat_period);
  // What nav2_lifecycle_manager's createBondConnection() sets: heartbeat timeout = its
  // bond_timeout parameter, period 0.1 s, enforced.
  static BondTimings nav2_lifecycle_manager(std::chrono::nanoseconds bond_timeout);
};

// One bond/msg/Status, without DDS: what is published and what is heard.
struct BondHeartbeat {
  std::string id;           // the bond's id: the same on both sides (Nav2: the node's name)
  std::string instance_id;  // the sender's own id, unique per Bond object (a UUID)
  bool active = true;       // the message's field; false: the sender is breaking the bond
  float heartbeat_timeout_s = 0.0F;  // the sender's timings, seconds, for debugging mismatches
  float heartbeat_period_s = 0.0F;
};

// What one call did: heartbeats to publish now (in order), and whether it formed or ended.
struct BondStep {
  std::vector<BondHeartbeat> publish;
  bool formed = false;           // this call moved the bond from waiting to alive
  std::optional<BondEnd> ended;  // this call moved the bond to dead, and why
};

class Bond {
 public:
  using Clock = std::chrono::steady_clock;
  using TimePoint = Clock::time_point;

  // `id`: the bond's id both sides use; `instance_id`: this side's own (new_instance_id()).
  Bond(std::string id, std::string instance_id, BondTimings timings);

  // bondcpp's start(): the connect timeout and the heartbeat period start now. The first
  // heartbeat goes out one period from now, as a wall timer's first tick does.
  BondStep start(TimePoint now);
  // A bond/msg/Status heard on the topic. Ignored before start(), and unless its id is ours and
  // its instance_id is not (our own heartbeats come back through the topic).
  BondStep on_status(const BondHeartbeat& status, TimePoint now);
  // Fires every timer due at `now`: heartbeats, connect / heartbeat / disconnect timeouts.
  BondStep advance(TimePoint now);
  // bondcpp's breakBond(): tells the sister (active=false) and ends the bond, at once when it was
  // not alive, else when the sister answers or disconnect_timeout passes. Idempotent.
  BondStep break_bond(TimePoint now);

  // When advance() must be called next (nullopt: never again, the bond is dead or not started).
  std::optional<TimePoint> next_deadline() const;

  BondState state() const { return state_; }
  const std::string& id() const { return id_; }
  const std::string& instance_id() const { return instance_id_; }
  // The first sister instance heard (empty until then), for logs.
  const std::string& sister_instance_id() const { return sister_instance_id_; }
  const BondTimings& timings() const { return timings_; }

 private:
  BondHeartbeat heartbeat(bool active) const;
  void die(BondEnd why, BondStep& step);

  const std::string id_;
  const std::string instance_id_;
  const BondTimings timings_;
  BondState state_ = BondState::kNotStarted;
  // bondcpp's sisterDiedFirst_: the sister broke first, so our active=false answers hers at once.
  bool sister_died_first_ = false;
  std::string sister_instance_id_;
  // The timers, as due times (unset: not running).
  std::optional<TimePoint> connect_due_;
  std::optional<TimePoint> heartbeat_timeout_due_;
  std::optional<TimePoint> disconnect_due_;
  std::optional<TimePoint> publish_due_;       // every heartbeat_period
  std::optional<TimePoint> dead_publish_due_;  // every dead_publish_period while awaiting death
};

// A fresh instance id: a random (version 4) UUID in its text form, as bondcpp's makeUUID gives.
std::string new_instance_id();

}  // namespace vnsba::node
