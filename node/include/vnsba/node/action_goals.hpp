// An action server's goals, without DDS: the goal state machine of ROS 2 actions (rcl_action) as
// the node keeps it for Nav2's ComputePathToPose and ComputePathThroughPoses.
//
//   accept -> ACCEPTED -> execute -> EXECUTING -> finish -> SUCCEEDED | ABORTED | CANCELED
//                  \______________ cancel ______/-> CANCELING -> finish -> CANCELED
//
// - A goal id (UUID) already known (running or finished and still kept) is rejected: rcl_action
//   refuses a goal whose id exists.
// - get_result of a finished goal is answered at once; of a running one, when it finishes (the
//   requester is parked with the goal); of an unknown one (never seen, or forgotten), at once
//   with status UNKNOWN, as rcl_action does.
// - cancel follows rcl_action_process_cancel_request: a zero id and zero stamp cancels every
//   goal; a zero id and a stamp, every goal accepted at or before it; an id and a zero stamp,
//   that goal; both, that goal and every goal at or before the stamp. Only goals not yet
//   finished can be canceled; return codes 0 (none: some goals are canceling), 2 (unknown goal
//   id), 3 (that goal has already finished).
// - Finished goals are kept for `result_timeout`, at most `max_results` of them, so memory is
//   bounded whatever the rate of goals and whether or not their clients ever ask for the result.
//   Over the cap, the oldest result already delivered goes first, then the oldest of the rest
//   (under a burst a client's get_result can trail its goal's end by many goals). A goal not yet
//   finished is never forgotten.
// Not thread-safe: the node holds its lock.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <utility>
#include <vector>

namespace vnsba::node {

using GoalUuid = std::array<uint8_t, 16>;

// Nav2's two planner actions (nav2_msgs/action, ROS 2 Jazzy).
enum class ActionKind { kComputePathToPose, kComputePathThroughPoses };

// action_msgs/GoalStatus values.
enum class GoalState : int8_t {
  kUnknown = 0,
  kAccepted = 1,
  kExecuting = 2,
  kCanceling = 3,
  kSucceeded = 4,
  kCanceled = 5,
  kAborted = 6,
};
constexpr bool is_terminal(GoalState s) {
  return s == GoalState::kSucceeded || s == GoalState::kCanceled || s == GoalState::kAborted;
}

// action_msgs/CancelGoal response return codes.
enum class CancelCode : int8_t {
  kNone = 0,
  kRejected = 1,
  kUnknownGoalId = 2,
  kGoalTerminated = 3,
};

// builtin_interfaces/Time as the goal's acceptance stamp.
struct GoalStamp {
  int32_t sec = 0;
  uint32_t nanosec = 0;
  bool zero() const { return sec == 0 && nanosec == 0; }
  friend bool operator<=(const GoalStamp& a, const GoalStamp& b) {
    return a.sec < b.sec || (a.sec == b.sec && a.nanosec <= b.nanosec);
  }
};

inline bool is_zero(const GoalUuid& id) {
  for (uint8_t b : id)
    if (b != 0) return false;
  return true;
}

template <class Result, class Requester>
class ActionGoals {
 public:
  using Clock = std::chrono::steady_clock;

  ActionGoals(std::chrono::milliseconds result_timeout, size_t max_results)
      : result_timeout_(result_timeout), max_results_(max_results) {}

  struct StatusEntry {
    GoalUuid id;
    GoalStamp stamp;
    GoalState state;
  };
  struct CancelOutcome {
    CancelCode code = CancelCode::kNone;
    std::vector<StatusEntry> canceling;  // goals that moved to CANCELING
  };
  // What to answer a get_result with.
  struct Answer {
    GoalState state = GoalState::kUnknown;
    Result result{};
  };

  // False when the id is already known (the goal is rejected).
  bool accept(const GoalUuid& id, const GoalStamp& stamp) {
    if (goals_.count(id) > 0) return false;
    Goal goal;
    goal.stamp = stamp;
    goals_.emplace(id, std::move(goal));
    return true;
  }
  // ACCEPTED -> EXECUTING (a worker took it). False when the goal is not ACCEPTED.
  bool execute(const GoalUuid& id) {
    auto it = goals_.find(id);
    if (it == goals_.end() || it->second.state != GoalState::kAccepted) return false;
    it->second.state = GoalState::kExecuting;
    return true;
  }
  // The goal's end. `state` must be terminal; a goal that was CANCELING ends CANCELED whatever
  // the plan's outcome was unless it succeeded (rcl_action lets a canceling goal succeed or
  // abort, but the node's canceled plan never succeeds). Returns the get_result requesters that
  // waited, to be answered with answer(id). Unknown or already finished: nothing.
  std::vector<Requester> finish(const GoalUuid& id, GoalState state, Result result,
                                Clock::time_point now) {
    auto it = goals_.find(id);
    if (it == goals_.end() || is_terminal(it->second.state)) return {};
    it->second.state = state;
    it->second.result = std::move(result);
    it->second.finished_at = now;
    finished_.push_back(id);
    it->second.delivered = !it->second.waiting.empty();
    return std::exchange(it->second.waiting, {});
  }
  // get_result: the answer now (finished or unknown goal), or nullopt with `requester` parked
  // until finish().
  std::optional<Answer> result_or_wait(const GoalUuid& id, Requester requester) {
    auto it = goals_.find(id);
    if (it == goals_.end()) return Answer{};
    if (is_terminal(it->second.state)) {
      it->second.delivered = true;
      return Answer{it->second.state, it->second.result};
    }
    it->second.waiting.push_back(std::move(requester));
    return std::nullopt;
  }
  // The answer of a finished goal (what finish() stored).
  Answer answer(const GoalUuid& id) const {
    auto it = goals_.find(id);
    if (it == goals_.end()) return Answer{};
    return Answer{it->second.state, it->second.result};
  }

  CancelOutcome cancel(const GoalUuid& id, const GoalStamp& stamp) {
    CancelOutcome out;
    const bool by_id = !is_zero(id);
    if (by_id) {
      auto it = goals_.find(id);
      if (it == goals_.end()) {
        out.code = CancelCode::kUnknownGoalId;
        if (stamp.zero()) return out;
      } else if (is_terminal(it->second.state)) {
        out.code = CancelCode::kGoalTerminated;
        if (stamp.zero()) return out;
      }
    }
    for (auto& [goal_id, goal] : goals_) {
      const bool selected = (!by_id && stamp.zero()) || (by_id && goal_id == id) ||
                            (!stamp.zero() && goal.stamp <= stamp);
      if (!selected) continue;
      if (goal.state == GoalState::kAccepted || goal.state == GoalState::kExecuting) {
        goal.state = GoalState::kCanceling;
        out.canceling.push_back({goal_id, goal.stamp, goal.state});
      } else if (goal.state == GoalState::kCanceling) {
        out.canceling.push_back({goal_id, goal.stamp, goal.state});  // asked again: still so
      }
    }
    if (!out.canceling.empty()) out.code = CancelCode::kNone;
    return out;
  }

  GoalState state(const GoalUuid& id) const {
    auto it = goals_.find(id);
    return it == goals_.end() ? GoalState::kUnknown : it->second.state;
  }

  // Forgets finished goals older than result_timeout and the oldest beyond max_results. Returns
  // how many went (the status list changed when > 0).
  size_t expire(Clock::time_point now) {
    size_t forgotten = 0;
    // By age: finished_ is in order of finishing.
    while (!finished_.empty()) {
      auto it = goals_.find(finished_.front());
      if (now - it->second.finished_at < result_timeout_) break;
      goals_.erase(it);
      finished_.pop_front();
      ++forgotten;
    }
    // By number: the oldest delivered result first, else the oldest.
    while (finished_.size() > max_results_) {
      auto victim = std::find_if(finished_.begin(), finished_.end(),
                                 [&](const GoalUuid& id) { return goals_.at(id).delivered; });
      if (victim == finished_.end()) victim = finished_.begin();
      goals_.erase(*victim);
      finished_.erase(victim);
      ++forgotten;
    }
    return forgotten;
  }
  // When the oldest finished goal is due to be forgotten (none: nothing finished).
  std::optional<Clock::time_point> next_expiry() const {
    if (finished_.empty()) return std::nullopt;
    return goals_.at(finished_.front()).finished_at + result_timeout_;
  }

  // Every goal known, in id order (the status topic's list).
  std::vector<StatusEntry> statuses() const {
    std::vector<StatusEntry> out;
    out.reserve(goals_.size());
    for (const auto& [id, goal] : goals_) out.push_back({id, goal.stamp, goal.state});
    return out;
  }
  size_t size() const { return goals_.size(); }
  size_t running() const { return goals_.size() - finished_.size(); }

 private:
  struct Goal {
    GoalStamp stamp;
    GoalState state = GoalState::kAccepted;
    Result result{};
    Clock::time_point finished_at{};
    bool delivered = false;          // a get_result has been answered with the result
    std::vector<Requester> waiting;  // get_result requests parked until the goal finishes
  };
  std::chrono::milliseconds result_timeout_;
  size_t max_results_;
  std::map<GoalUuid, Goal> goals_;
  std::deque<GoalUuid> finished_;  // finished goals, oldest first
};

}  // namespace vnsba::node
