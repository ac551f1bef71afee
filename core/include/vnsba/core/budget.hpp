// The time and cancel budget of one Planner::plan() call: PlannerOptions::max_planning_time (the
// node's planner.max_planning_time) and the caller's cancel flag. Exactly what it bounds:
//
// Its clock starts when plan() is entered. These stages poll it and stop with kTimeout or
// kCanceled when it has run out (the status message names the stage):
//   - the floods that choose a start within start_tolerance and a goal within goal_tolerance
//     (resolve_endpoints: once per cell expanded);
//   - the search (once per expansion; jps also once per cell a diagonal walk visits);
//   - pruning (prune_path: once per line-of-sight check);
//   - corner smoothing (smooth_path: once per corner attempt);
//   - the relax smoother (relax_path: once per iteration and per point it visits).
// The steps between them run inside the clock without polling it, each to its end: joining the
// exact start and goal (join_exact_ends), the turn counts, the path's clearance before and after
// relaxing (the relax smoother's floor and its check), the world coordinates. Their time grows
// with the path's length (the clearance's also with the width of the band it scans), not with
// the map's area. A stage reads the clock only every kPollInterval polls and these steps not at
// all, so a plan can succeed with planning_time_us somewhat above max_planning_time: by what ran
// after the last reading of the clock.
//
// Not bounded: after plan()'s clock has stopped (not in planning_time_us), the clearance metric of
// a path the relax smoother did not measure, and the optimal A* reference run that
// compute_length_ratio adds (no time limit; it honours the cancel flag only, a canceled one
// leaving length_ratio NaN). Outside plan(): building the GridMap from a slice (inflation, the
// distance transform) and, in the node, the queue and the path's poses and messages. Each call is
// one budget: the node plans each leg of a ComputePathThroughPoses goal with a budget of its own.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

#include "vnsba/core/status.hpp"

namespace vnsba::core {

class PlanningBudget {
 public:
  using Clock = std::chrono::steady_clock;

  // `budget` of zero or less is unlimited; `cancel` (may be null) is the caller's flag.
  PlanningBudget(Clock::time_point start, std::chrono::microseconds budget,
                 const std::atomic<bool>* cancel)
      : cancel_(cancel), has_budget_(budget.count() > 0), end_(start + budget) {}

  // kOk to go on, else kTimeout or kCanceled; once expired it stays expired. Reads the cancel
  // flag and the clock every kPollInterval calls only: cheap enough to call once per expansion or
  // per line-of-sight check, frequent enough (a few hundred microseconds at most) for preemption.
  StatusCode poll() {
    if (state_ != StatusCode::kOk) return state_;
    if (++count_ % kPollInterval != 0) return StatusCode::kOk;
    return check_now();
  }

  // Reads the flag and the clock now (poll() does so every kPollInterval calls). Between stages
  // plan() reads only expired(), the state the last poll left.
  StatusCode check_now() {
    if (state_ != StatusCode::kOk) return state_;
    if (cancel_ != nullptr && cancel_->load(std::memory_order_relaxed)) {
      state_ = StatusCode::kCanceled;
    } else if (has_budget_ && Clock::now() >= end_) {
      state_ = StatusCode::kTimeout;
    }
    return state_;
  }

  StatusCode state() const { return state_; }
  bool expired() const { return state_ != StatusCode::kOk; }

 private:
  static constexpr uint32_t kPollInterval = 256;
  const std::atomic<bool>* cancel_;
  bool has_budget_;
  Clock::time_point end_;
  uint32_t count_ = kPollInterval - 1;  // the first call polls: a pre-raised flag stops at once
  StatusCode state_ = StatusCode::kOk;
};

}  // namespace vnsba::core
