// A bond (bond.hpp) on the bus, as bondcpp puts it there (ros/bond_core, branch ros2,
// bondcpp/src/bond.cpp): bond/msg/Status written on the topic `bond` with a keep-last-5 writer
// (rclcpp::QoS(rclcpp::KeepLast(5)): reliable, volatile) and read with a keep-last-100 reader
// (rclcpp::QoS(100)); the topic name is relative, so a node in a namespace bonds on
// rt/<namespace>/bond (Nav2 passes "bond": nav2_util's LifecycleNode::createBond and
// nav2_lifecycle_manager's createBondConnection).
//
// The link owns its writer, its reader and one thread that runs the bond's timers; bonds come
// and go on it (start, break_bond) as Nav2 creates a Bond on activate and destroys it on
// deactivate, each with a fresh instance_id. The node (one per managed node) and vnsba_lifecycle
// (the manager's side) both use it.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "vnsba/core/status.hpp"
#include "vnsba/node/bond.hpp"
#include "vnsba/node/dds.hpp"

namespace vnsba::node {

class BondLink {
 public:
  // Called on the link's thread or a DDS thread, never with the link's lock held.
  using OnFormed = std::function<void(const std::string& sister_instance_id)>;
  using OnBroken = std::function<void(BondEnd why)>;

  // The writer and reader of bond/msg/Status on `dds_topic` ("rt/bond", dds_topic_name(config,
  // "bond")). No bond runs until start().
  static core::Expected<std::unique_ptr<BondLink>> create(Participant& participant,
                                                          const std::string& dds_topic);
  ~BondLink();  // close()
  BondLink(const BondLink&) = delete;
  BondLink& operator=(const BondLink&) = delete;

  // A new bond `id` (a fresh instance_id) with `timings`, started now; a bond still running is
  // broken first (break_bond without waiting).
  void start(const std::string& id, const BondTimings& timings, OnFormed on_formed = nullptr,
             OnBroken on_broken = nullptr);
  // Breaks the running bond (active=false to the sister), then waits up to `wait` for it to end
  // (bondcpp's destructor waits 100 ms: the sister's answer ends it at once). No-op without one.
  void break_bond(std::chrono::milliseconds wait = std::chrono::milliseconds(100));

  // The running bond's state (kNotStarted before the first start()).
  BondState state() const;
  // bondcpp's waitUntilFormed: true once the bond left kWaitingForSister (formed, or already
  // dead), false if `timeout` passed first.
  bool wait_until_formed(std::chrono::milliseconds timeout) const;
  // bondcpp's waitUntilBroken: true once the bond is dead.
  bool wait_until_broken(std::chrono::milliseconds timeout) const;
  // The running bond's instance_id ("" before the first start()).
  std::string instance_id() const;
  // Heartbeats written (active or not) since create(): a test's view of the period.
  uint64_t heartbeats_written() const;

  // Ends the thread and deletes the writer and reader (no callback runs after it returns). Call
  // it before the participant is shut down; idempotent. A running bond is not broken: stopping
  // a process is what the manager's watchdog is for.
  void close();

 private:
  class Impl;
  explicit BondLink(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace vnsba::node
