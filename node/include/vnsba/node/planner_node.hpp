// vnsba_node's runtime: one participant, a map thread, an intake thread, the planning workers
// and a replier thread. Each role is a class of its own under node/src/ (map_input, robot_poses,
// request_intake, request_admission, work_queues, planning_workers, answers, replier,
// debug_publisher, fleet_router); PlannerNode composes them.
//
//   slice --listener--> newest-slice slot --map thread--> validate, convert, build (threshold,
//                                                          inflation, density table, the map's
//                                                          core::Planner), swap in
//   plan_request / goal_pose / action goal --intake--> checked once, bounded queue --worker-->
//                                      the map's core::Planner --> plan, planner_debug, and
//                                      plan_status or the action's result (--replier--> DDS)
//
// Listeners never plan and never convert maps. A new map is swapped in atomically, with its
// planner's search arrays already allocated (so the first plan on it is as fast, and as quick to
// cancel, as the next); a plan in flight finishes on the map and planner it started with; a
// newer slice stops the conversion of an older one. Every request gets exactly one PlanStatus
// carrying its sample identity: planned, rejected (checked on arrival, see requests.hpp),
// replaced or preempted (CANCELED), refused because the queue is full (CANCELED), or drained at
// shutdown (CANCELED). A rejected or superseded map gets a PlanStatus with subject SUBJECT_MAP.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>

#include "vnsba/core/status.hpp"
#include "vnsba/node/config.hpp"

namespace vnsba::node {

class PlannerNode {
 public:
  explicit PlannerNode(NodeConfig config);
  ~PlannerNode();  // stop()
  PlannerNode(const PlannerNode&) = delete;
  PlannerNode& operator=(const PlannerNode&) = delete;

  // Creates the participant, topics, writers, then readers (so nothing arrives before the node
  // can answer), and starts the threads. Each DDS step is checked; a failure is returned with
  // what failed, and nothing is left running.
  core::Status start();

  // Stops input (readers first), cancels the plan in progress, answers every queued request
  // with CANCELED, joins the threads and deletes every entity. Idempotent.
  void stop();

  struct Stats {
    uint64_t requests_received = 0;   // plan_request samples and goal_pose goals
    uint64_t statuses_published = 0;  // request statuses (not map reports)
    uint64_t maps_accepted = 0;
    uint64_t maps_rejected = 0;
    uint64_t maps_superseded = 0;  // a newer slice arrived while this one was being converted
    uint64_t plans_ok = 0;
    size_t queue_peak = 0;  // most requests ever waiting at once
    // Other participants seen writing plan_status (another node on the same domain and topics).
    size_t other_status_writers = 0;
    // Readers matched by the `plan` writer. `plan` is volatile: a path written before a reader
    // is matched never reaches it, so a client that needs the path waits for this.
    size_t plan_readers = 0;
    // Readers matched by the `plan_status` writer(s): volatile too, so a bystander that reads
    // other clients' answers (a dashboard, a test) waits for this as well.
    size_t status_readers = 0;
    // Remote endpoints whose QoS can never match one of the node's (each is logged once).
    size_t incompatible_qos = 0;
    // Goals the action servers know: running, or finished and kept for a late get_result
    // (actions.result_timeout, actions.max_results).
    size_t action_goals = 0;
  };
  Stats stats() const;

  // Whether it plans (lifecycle: active; true unless set otherwise): while not, plan_request and
  // goal_pose goals are answered NODE_INACTIVE and action goals rejected; what was accepted
  // before goes on and is answered. Any thread, before or after start().
  void set_accepting(bool accepting);

  // True once a slice has been accepted; waits up to `timeout` for one.
  bool wait_for_map(std::chrono::milliseconds timeout) const;

  const NodeConfig& config() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vnsba::node
