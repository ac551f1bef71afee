// An action server's goals, without DDS: the goal state machine of ROS 2 actions (rcl_action) as
// the node keeps it for Nav2's ComputePathToPose and ComputePathThroughPoses.
//
//   accept -> ACCEPTED -> execute -> EXECUTING -> finish -> SUCCEEDED | ABORTED
//                  \______________ cancel ______/-> CANCELING -> finish -> SUCCEEDED | ABORTED
//                                                                          | CANCELED
//
// - Only rcl_action's transitions happen (rcl_action_transition_goal_state): a goal that ends
//   while still ACCEPTED (refused before it was planned, or dropped from the queue) passes
//   through EXECUTING on its way to SUCCEEDED or ABORTED, and through CANCELING on its way to
//   CANCELED, as an rclcpp_action server that calls execute() then abort() would; a goal never
//   goes from ACCEPTED straight to a terminal state.
// - A goal id (UUID) already known (running or finished and still kept) is rejected: rcl_action
//   refuses a goal whose id exists.
// - get_result of a finished goal is answered at once; of a running one, when it finishes (the
//   requester is parked with the goal); of an unknown one (never seen, or forgotten), at once
//   with status UNKNOWN, as rcl_action does.
// - cancel is rcl_action_process_cancel_request: an id and a zero stamp cancels that goal if it
//   is ACCEPTED or EXECUTING (ERROR_NONE), answers ERROR_UNKNOWN_GOAL_ID when the id is not
//   known and ERROR_GOAL_TERMINATED when the goal cannot be canceled (finished, or CANCELING
//   already); otherwise the answer is ERROR_NONE, listing every ACCEPTED or EXECUTING goal
//   accepted at or before the stamp (all of them when id and stamp are both zero) or carrying
//   the id, possibly none.
// - Finished goals are kept for `result_timeout`, at most `max_results` of them, and the node can
//   forget more to keep one byte budget over all its servers (oldest_finished, forget): memory is
//   bounded whatever the rate of goals and whether or not their clients ever ask for the result.
//   The oldest result already delivered goes first, then the oldest of the rest (under a burst a
//   client's get_result can trail its goal's end by many goals). A goal not yet finished is
//   never forgotten.
// Not thread-safe: the node holds its lock.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <utility>
#include <vector>

namespace vnsba::node {

using GoalUuid = std::array<uint8_t, 16>;

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

// A finished goal, and when: goals finish in the order of `order`.
struct FinishedGoal {
  std::chrono::steady_clock::time_point finished_at;
  uint64_t order = 0;
  GoalUuid id{};
};

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
  using Finished = FinishedGoal;

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
  // The goal's end, `state` terminal, its result `bytes` long (what the node's byte budget
  // counts). CANCELED only from CANCELING or, through it, from ACCEPTED or EXECUTING; SUCCEEDED
  // and ABORTED from any state not terminal (through EXECUTING from ACCEPTED). Returns the
  // get_result requesters that waited, to be answered with answer(id). Unknown or already
  // finished: nothing.
  std::vector<Requester> finish(const GoalUuid& id, GoalState state, Result result,
                                Clock::time_point now, size_t bytes = 0) {
    auto it = goals_.find(id);
    if (it == goals_.end() || !is_terminal(state) || is_terminal(it->second.state)) return {};
    Goal& goal = it->second;
    goal.state = state;
    goal.result = std::move(result);
    goal.bytes = bytes;
    goal.finished_at = now;
    goal.order = ++finish_count_;
    goal.delivered = !goal.waiting.empty();
    (goal.delivered ? delivered_ : undelivered_).insert({goal.order, id});
    kept_bytes_ += bytes;
    return std::exchange(goal.waiting, {});
  }
  // get_result: the answer now (finished or unknown goal), or nullopt with `requester` parked
  // until finish().
  std::optional<Answer> result_or_wait(const GoalUuid& id, Requester requester) {
    auto it = goals_.find(id);
    if (it == goals_.end()) return Answer{};
    Goal& goal = it->second;
    if (is_terminal(goal.state)) {
      if (!goal.delivered) {
        undelivered_.erase({goal.order, id});
        delivered_.insert({goal.order, id});
        goal.delivered = true;
      }
      return Answer{goal.state, goal.result};
    }
    goal.waiting.push_back(std::move(requester));
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
    auto cancelable = [](GoalState s) {
      return s == GoalState::kAccepted || s == GoalState::kExecuting;
    };
    auto start_canceling = [&](const GoalUuid& goal_id, Goal& goal) {
      goal.state = GoalState::kCanceling;
      out.canceling.push_back({goal_id, goal.stamp, goal.state});
    };
    if (!is_zero(id) && stamp.zero()) {  // exactly this goal
      auto it = goals_.find(id);
      if (it == goals_.end()) {
        out.code = CancelCode::kUnknownGoalId;
      } else if (!cancelable(it->second.state)) {
        out.code = CancelCode::kGoalTerminated;  // rcl: not cancelable means terminal to it
      } else {
        start_canceling(id, it->second);
      }
      return out;
    }
    const bool all = is_zero(id) && stamp.zero();
    for (auto& [goal_id, goal] : goals_) {
      if (!cancelable(goal.state)) continue;
      if (all || goal.stamp <= stamp || goal_id == id) start_canceling(goal_id, goal);
    }
    return out;  // ERROR_NONE, with or without goals
  }

  GoalState state(const GoalUuid& id) const {
    auto it = goals_.find(id);
    return it == goals_.end() ? GoalState::kUnknown : it->second.state;
  }

  // Forgets finished goals older than result_timeout and the oldest beyond max_results (the
  // oldest delivered first). Returns how many went (the status list changed when > 0).
  size_t expire(Clock::time_point now) {
    size_t forgotten = 0;
    for (auto oldest = oldest_finished(); oldest && now - oldest->finished_at >= result_timeout_;
         oldest = oldest_finished()) {
      forget(oldest->id);
      ++forgotten;
    }
    while (delivered_.size() + undelivered_.size() > max_results_) {
      auto victim = oldest_finished(/*delivered=*/true);
      if (!victim) victim = oldest_finished();
      forget(victim->id);
      ++forgotten;
    }
    return forgotten;
  }
  // The finished goal that finished first: among those already delivered (`delivered` true),
  // or among all (nullopt); none when nothing (of that kind) is kept.
  std::optional<Finished> oldest_finished(std::optional<bool> delivered = std::nullopt) const {
    const auto* from = &delivered_;
    if (delivered == false) from = &undelivered_;
    if (!delivered) {
      if (delivered_.empty())
        from = &undelivered_;
      else if (!undelivered_.empty() && *undelivered_.begin() < *delivered_.begin())
        from = &undelivered_;
    }
    if (from->empty()) return std::nullopt;
    const auto& [order, id] = *from->begin();
    return Finished{goals_.at(id).finished_at, order, id};
  }
  // Forgets a finished goal (its result goes; a get_result then answers UNKNOWN). False when the
  // goal is unknown or not finished.
  bool forget(const GoalUuid& id) {
    auto it = goals_.find(id);
    if (it == goals_.end() || !is_terminal(it->second.state)) return false;
    (it->second.delivered ? delivered_ : undelivered_).erase({it->second.order, id});
    kept_bytes_ -= it->second.bytes;
    goals_.erase(it);
    return true;
  }
  // When the oldest finished goal is due to be forgotten (none: nothing finished).
  std::optional<Clock::time_point> next_expiry() const {
    const auto oldest = oldest_finished();
    if (!oldest) return std::nullopt;
    return oldest->finished_at + result_timeout_;
  }
  // The bytes of every kept result (finish's `bytes`).
  size_t kept_bytes() const { return kept_bytes_; }

  // The status topic's list: every goal not finished, and the `max_finished` goals that
  // finished last; in id order.
  std::vector<StatusEntry> statuses(size_t max_finished) const {
    std::vector<std::pair<uint64_t, GoalUuid>> finished(delivered_.begin(), delivered_.end());
    finished.insert(finished.end(), undelivered_.begin(), undelivered_.end());
    const size_t keep = std::min(max_finished, finished.size());
    std::nth_element(finished.begin(), finished.end() - static_cast<std::ptrdiff_t>(keep),
                     finished.end());
    std::set<GoalUuid> listed_finished;
    for (auto it = finished.end() - static_cast<std::ptrdiff_t>(keep); it != finished.end(); ++it)
      listed_finished.insert(it->second);
    std::vector<StatusEntry> out;
    out.reserve(running() + keep);
    for (const auto& [id, goal] : goals_)
      if (!is_terminal(goal.state) || listed_finished.count(id) > 0)
        out.push_back({id, goal.stamp, goal.state});
    return out;
  }
  size_t size() const { return goals_.size(); }
  size_t running() const { return goals_.size() - delivered_.size() - undelivered_.size(); }

 private:
  struct Goal {
    GoalStamp stamp;
    GoalState state = GoalState::kAccepted;
    Result result{};
    size_t bytes = 0;
    Clock::time_point finished_at{};
    uint64_t order = 0;              // finish_count_ when it finished
    bool delivered = false;          // a get_result has been answered with the result
    std::vector<Requester> waiting;  // get_result requests parked until the goal finishes
  };
  std::chrono::milliseconds result_timeout_;
  size_t max_results_;
  std::map<GoalUuid, Goal> goals_;
  // Finished goals by the order they finished in, split by whether a client has the result.
  std::set<std::pair<uint64_t, GoalUuid>> delivered_, undelivered_;
  uint64_t finish_count_ = 0;
  size_t kept_bytes_ = 0;
};

// One byte budget over the results that several servers keep: forgets finished goals until the
// servers' kept bytes are at most `max_bytes`, the oldest delivered result of any server first,
// then the oldest of any. `Server` has kept_bytes(), oldest_finished(std::optional<bool>
// delivered) and forget(id), as ActionGoals has. Returns how many were forgotten.
template <class Server>
size_t forget_beyond_budget(const std::vector<Server*>& servers, size_t max_bytes) {
  size_t total = 0;
  for (const Server* server : servers) total += server->kept_bytes();
  size_t forgotten = 0;
  while (total > max_bytes) {
    Server* owner = nullptr;
    std::optional<FinishedGoal> victim;
    for (const bool delivered : {true, false}) {
      for (Server* server : servers) {
        const auto oldest = server->oldest_finished(delivered);
        if (oldest &&
            (!victim || oldest->finished_at < victim->finished_at ||
             (oldest->finished_at == victim->finished_at && oldest->order < victim->order))) {
          victim = oldest;
          owner = server;
        }
      }
      if (victim) break;
    }
    if (!victim) break;  // only running goals: nothing to forget
    const size_t before = owner->kept_bytes();
    owner->forget(victim->id);
    total -= before - owner->kept_bytes();
    ++forgotten;
  }
  return forgotten;
}

}  // namespace vnsba::node
