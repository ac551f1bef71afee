// The time and cancel budget of one plan: search, pruning and smoothing all poll the same one,
// so max_planning_time bounds everything Planner::plan() does, not only the search.
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

  // Reads the flag and the clock now (between stages, where a call is rare anyway).
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
