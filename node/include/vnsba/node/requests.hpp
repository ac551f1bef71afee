// What happens to a request between the bus and the planner, without DDS: the checks that decide
// whether it would be planned (resolve_request), and the queueing rules (RequestQueue). The node
// calls both under its own locks; the tests call them directly.
//
// Rules (docs/node.md):
// - A request is checked when it arrives. One that would not be planned (malformed, too long, no
//   map yet, start or goal outside the map or blocked) is answered at once and touches nothing
//   else: it preempts nothing and takes no place in the queue.
// - A request with the id of one still waiting or being planned *from the same client* (DDS
//   participant) replaces it: the older is answered CANCELED with "replaced by a newer request
//   with the same id ...". Different clients may use the same id independently.
// - With requests.preempt, an accepted request cancels every older one (waiting or being
//   planned): "preempted by newer request ...". Without it, requests wait in arrival order, at
//   most requests.queue_capacity of them; one more is answered CANCELED "request queue is full".
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/node/action_goals.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"

namespace vnsba::node {

// Longest string fields a request may carry, in bytes; longer ones are refused with
// INVALID_REQUEST naming the field (1,024 requests of 500 kB ids once took the node to 1 GB).
// The planner's and the frame's limits are config.hpp's (the config checks against them too).
constexpr size_t kMaxIdBytes = 256;

// Why a request must not be planned (or stop being planned); set under the queue's lock.
struct Interruption {
  std::atomic<bool> flag{false};  // polled by the search
  std::string reason;             // the CANCELED message
};

class ActionServer;

// A goal of a Nav2 action (action_server.hpp): who answers it, and what the answer needs.
struct ActionJob {
  ActionServer* server = nullptr;
  GoalUuid goal_id{};
  // ComputePathThroughPoses: the poses after the first (Job::goal), planned leg by leg.
  std::vector<PoseStampedMsg> more_goals;
  // Set when the request fails for these reasons: Nav2 has codes of their own for them.
  bool invalid_planner = false;  // planner_id unknown or unusable (INVALID_PLANNER)
  bool tf_problem = false;       // the robot's pose could not be looked up (TF_ERROR)
};

// A request checked against the configuration and (when there is one) the active map.
struct ResolvedRequest {
  WireStatus status;             // OK: the request would be planned
  std::string planner_name;      // set once the planner is known
  core::PlannerOptions options;  // valid when status.ok()
  // Valid when status.ok(): the cells holding the requested positions, and the positions
  // themselves in continuous cell coordinates (start_point, goal_point), so that a tolerance
  // moves a blocked start or goal to the free cell nearest the real point. A goal outside the
  // map (allowed when planner.goal_tolerance > 0 brings a free cell within reach) has the cell
  // floor(goal_point), outside the map.
  core::PlanQuery query;
  // The goal's orientation (radians, core::yaw_from_quaternion) for the last pose of the path;
  // unset when its quaternion is not unit length (then `warning` says so).
  std::optional<double> goal_yaw;
  // Non-fatal remarks for the status message of an OK plan ("warning: ..."), "" when none.
  std::string warning;
  // The request failed because of its planner (unknown, or unusable with the node's settings).
  bool invalid_planner = false;
  // The planner's own part of `warning` (jps on a node with costs), shared by every leg of a
  // request; "" when none.
  std::string planner_warning;
};

struct Job {
  std::string id;
  RequestIdentity identity;
  PoseStampedMsg start;
  PoseStampedMsg goal;
  std::string planner;        // empty: the configured planner
  std::string missing_start;  // set when a goal_pose came before any robot_pose
  std::shared_ptr<Interruption> interruption = std::make_shared<Interruption>();
  // Set for a Nav2 action goal, answered on its action; shared by the legs of a
  // ComputePathThroughPoses goal.
  std::shared_ptr<ActionJob> action;
  // Set when the request is accepted (resolve_request said OK, before it is queued): what was
  // resolved then, and the map its cells are on. The worker plans it as resolved on that map,
  // without checking it again; on a newer map it only locates the same endpoints there
  // (resolve_leg), the planner staying the one chosen on acceptance.
  std::shared_ptr<const ResolvedRequest> resolved;
  std::weak_ptr<const core::GridMap> resolved_on;
};

// The id as a status echoes it: at most kMaxIdBytes of it.
std::string echoed_id(const std::string& id);

// `map` may be null (no map yet: NO_MAP). Checks, first failure wins: the string fields' lengths,
// the id, the planner name, the options the planner would run with (core::validate: e.g. jps with
// corner_policy touch is INVALID_REQUEST naming it; jps on a node with planner.cost_weight > 0
// plans on uniform costs with a warning), the start (a goal_pose without
// robot_pose), both poses (frame, finite), then start and goal against the map: the start inside
// it (START_OUTSIDE_MAP), the goal inside it or, with planner.goal_tolerance > 0, within that
// distance of it (GOAL_OUTSIDE_MAP), then core::check_query (blocked cells, tolerances).
// `map_topic` is the DDS topic the node's slices arrive on, which NO_MAP names (one for every
// robot of a fleet, under the node's namespace, not the robot's); empty: config's own.
ResolvedRequest resolve_request(const Job& job, const NodeConfig& config, const core::GridMap* map,
                                const std::string& map_topic = "");

// One leg of a request resolve_request accepted (`accepted`): `job`'s start and goal, checked and
// located on `map` as resolve_request does from the frames' lengths on, with the planner, its
// options and its warning as chosen on acceptance (the id and the planner are not checked
// again). The request's own endpoints on a newer map than the one it was accepted on, or a
// further leg of a ComputePathThroughPoses goal.
ResolvedRequest resolve_leg(const Job& job, const ResolvedRequest& accepted,
                            const NodeConfig& config, const core::GridMap* map,
                            const std::string& map_topic = "");

// The waiting requests and the one being planned. Not thread-safe: the node holds its lock.
class RequestQueue {
 public:
  RequestQueue(size_t capacity, bool preempt) : capacity_(capacity), preempt_(preempt) {}

  // Admits a request resolve_request accepted. Returns the requests to answer CANCELED now
  // (their interruption's reason says why): replaced or preempted waiting ones, or `job`
  // itself when the queue is full. The one being planned, when replaced or preempted, is only
  // flagged: its planner stops and the worker answers it.
  std::vector<Job> admit(Job job);

  // The oldest waiting request, which becomes the one being planned; nullopt when none waits.
  std::optional<Job> next();
  // The request being planned has been answered.
  void finish_current() { current_.reset(); }
  // Flags the one being planned (shutdown); the waiting ones are answered by the worker.
  void interrupt_current(const std::string& reason);
  // A client canceled request `id` (an action goal): a waiting one is removed and returned, to
  // be answered CANCELED now; the one being planned is flagged with `reason`.
  std::vector<Job> cancel(const std::string& id, const std::string& reason);

  size_t waiting() const { return queue_.size(); }
  // Whether a request is being planned (between next() and finish_current()).
  bool planning() const { return current_.has_value(); }

 private:
  struct Current {
    std::string id;
    RequestIdentity identity;
    std::shared_ptr<Interruption> interruption;
  };
  static void interrupt(Interruption& interruption, const std::string& reason);

  size_t capacity_;
  bool preempt_;
  std::deque<Job> queue_;
  std::optional<Current> current_;
};

}  // namespace vnsba::node
