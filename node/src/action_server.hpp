// Nav2's actions on the bus (issue 32): one ActionServer per action and robot, speaking
// rcl_action's protocol on the DDS topics ROS 2 derives from the action's name:
//
//   rq/<name>/_action/send_goalRequest   -> rr/<name>/_action/send_goalReply
//   rq/<name>/_action/get_resultRequest  -> rr/<name>/_action/get_resultReply
//   rq/<name>/_action/cancel_goalRequest -> rr/<name>/_action/cancel_goalReply
//   rt/<name>/_action/status (action_msgs/GoalStatusArray, transient local)
//   rt/<name>/_action/feedback (written never: Nav2's planner feedback is empty, but a ROS 2
//   client waits for the server's feedback and status writers before it sends a goal)
//
// The server's code is the same for every action: what is an action's own (its DDS types, how a
// goal is read and a result written) comes from its traits type (action_traits.hpp), chosen by
// the ActionKind it is made with.
//
// The server only carries bytes and keeps the goals (action_goals.hpp); a goal it accepts is
// handed to the node, which plans it like a plan_request (same queue, preemption, budgets) and
// calls finish(). Replies go out on the node's replier thread, each once a reply reader of the
// client's participant is matched (at most requests.reply_wait), as plan_status does; the
// mapping of a reply to its request is chosen per client (service_wire.hpp).
//
// Memory is bounded by bytes (issue 44): a goal's result is encoded once, when it finishes, and
// every get_result reply of it shares that encoding (no copy per requester); the results all
// servers keep share one budget (actions.kept_results_mb, forget_beyond_budget); a service holds
// at most actions.max_pending_replies replies per client; the reply writers keep their last
// replies only (reply_writer_qos), never blocking, and the writes are paced (reply_flow.hpp) so
// that each writer holds at most actions.replies_in_flight_mb of replies not yet acknowledged,
// and a client that does not acknowledge delays the others by at most about twice
// actions.reply_ack_timeout and loses only its own replies.
#pragma once

#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "action_traits.hpp"
#include "service_server.hpp"
#include "take_listener.hpp"
#include "vnsba/node/action_catalog.hpp"
#include "vnsba/node/action_goals.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/reply_gate.hpp"
#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

// ComputePathThroughPoses's NO_VIAPOINTS_GIVEN (an empty goals list).
constexpr uint16_t kNoViapointsGiven = ComputePathThroughPoses::kErrors.code("NO_VIAPOINTS_GIVEN");
// The longest error_msg a result carries, in bytes (a message that echoes input is cut there).
constexpr size_t kMaxErrorMessageBytes = 1024;
// The status list is published at most this often (every change in between is in the next one).
constexpr std::chrono::milliseconds kStatusPeriod{50};

// The goal's id as text, for ids and logs: 32 hex digits.
std::string uuid_text(const GoalUuid& id);

class ActionServer {
 public:
  using Clock = std::chrono::steady_clock;
  struct Hooks {
    // An accepted goal (the intake thread); the node plans it and calls finish().
    std::function<void(ActionServer&, ActionGoal&&)> on_goal;
    // Goals a client asked to cancel (a DDS thread); the node interrupts their plans.
    std::function<void(ActionServer&, const std::vector<GoalUuid>&)> on_cancel;
    // Whether the intake may take another goal now, and the intake's wake-up.
    std::function<bool()> may_take;
    std::function<void()> wake_intake;
    // The node's clock, for the acceptance stamps.
    std::function<TimeMsg()> now;
    // Whether the node takes goals now (lifecycle: active); a goal sent while it does not is
    // rejected (accepted false), as Nav2's SimpleActionServer rejects goals while inactive.
    std::function<bool()> accepting;
  };

  // `kind`: the action served (nav2_actions()). `ros_name`: the action's full ROS 2 name
  // ("/compute_path_to_pose", "/robot3/..."). The
  // reply gates and goals are guarded by `reply_mutex`, and `reply_cv` wakes the node's replier.
  ActionServer(ActionKind kind, std::string ros_name, const NodeConfig& config,
               const ParticipantWatch* vendors, std::mutex& reply_mutex,
               std::condition_variable& reply_cv, Hooks hooks);
  ~ActionServer();

  // Writers (replies, status, feedback), then readers; each step checked. The readers'
  // listeners go to `listeners` (the node deletes them after the participant); the send_goal
  // reader is the intake's (`inputs`).
  core::Status create(Participant& participant,
                      std::vector<std::unique_ptr<TakingListener>>& listeners,
                      std::vector<std::pair<TakingListener*, dds::DataReader*>>& inputs);

  // A worker took the goal: ACCEPTED -> EXECUTING.
  void execute(const GoalUuid& id);
  // The goal's end: its result is kept and sent to every get_result that waits for it.
  void finish(const GoalUuid& id, ActionOutcome outcome);
  // Whether the goal was asked to cancel (its plan ends CANCELED rather than ABORTED).
  bool canceling(const GoalUuid& id) const;

  // The replier thread, under reply_mutex: moves what may be written at `now` (replies whose
  // client is matched, and in step with the writer (reply_gate.hpp), or whose reply_wait has
  // passed; a status array when goals changed) out of the server. With `all`, everything held
  // (shutdown).
  struct Due;
  void take_due(Clock::time_point now, bool all, Due& out);
  // Writes them (the replier thread, without the lock), as each reply writer's flow allows
  // (reply_flow.hpp; `stopping`: all at once). A reply that must wait, or that the writer
  // refuses, is kept with the later ones of its service, in order, for the next pass; false when
  // any was kept. With `give_up` (a shutdown out of time) nothing is kept.
  bool write(Due& due, bool stopping = false, bool give_up = false);
  // When something held next falls due (reply_wait, a result's expiry, a reply waiting for
  // acknowledgements); under reply_mutex.
  std::optional<Clock::time_point> next_deadline() const;

  // The results kept, for the node's one budget over all servers (forget_beyond_budget); under
  // reply_mutex.
  size_t kept_bytes() const;
  std::optional<FinishedGoal> oldest_finished(std::optional<bool> delivered = std::nullopt) const;
  bool forget(const GoalUuid& id);

  ActionKind kind() const { return kind_; }
  const std::string& name() const { return ros_name_; }
  // Goals known (running and kept), under reply_mutex.
  size_t goals() const;
  // The three services' reply writers (null before create), for the shutdown's drain.
  std::array<dds::DataWriter*, kActionServices> reply_writers() const;

  struct Due {
    // Per service (ActionService): its replies due, its flow's look, its heartbeat.
    std::array<ServiceReplies::Due, kActionServices> services;
    std::optional<GoalStatusArrayMsg> status;
    bool empty() const {
      for (const auto& service : services)
        if (!service.empty()) return false;
      return !status;
    }
  };

 private:
  // What every action's server does (the goals, the status list, cancel_goal, the replies' way
  // out), and the part of it that is one action's own (ImplOf<Traits>: its endpoints' types,
  // send_goal and get_result).
  class Impl;
  template <class Traits, class Wire>
  class ImplOf;
  std::unique_ptr<Impl> impl_;
  ActionKind kind_;
  std::string ros_name_;
};

}  // namespace vnsba::node
