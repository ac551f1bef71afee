// Typed outcome of every core operation that can fail.
//
// Modelled on OMPL's PlannerStatus and Nav2's planner error codes: a planner never reports
// failure as a boolean or a magic integer, and every failure carries a message that names the
// field or input at fault. The DDS node adds its own codes (NO_MAP, FRAME_MISMATCH) on top of
// these; core never produces them because it knows nothing about frames or subscriptions.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace vnsba::core {

enum class StatusCode {
  kOk = 0,
  kInvalidMap,      // empty, inconsistent or unreadable map (size, resolution, data)
  kInvalidRequest,  // malformed query or options (NaN, out of range, unknown planner name)
  kStartOutsideMap,
  kGoalOutsideMap,
  kStartOccupied,
  kGoalOccupied,
  kNoValidPath,    // start and goal are in different free components
  kTimeout,        // max_planning_time elapsed before a path was found
  kCanceled,       // the caller's cancel flag was raised
  kInternalError,  // a bug: an invariant of the search did not hold
};

// Upper-case name as used on the wire and in logs, e.g. "START_OCCUPIED".
std::string_view to_string(StatusCode code);

struct Status {
  StatusCode code = StatusCode::kOk;
  std::string message;

  static Status ok() { return {}; }
  static Status error(StatusCode code, std::string message) { return {code, std::move(message)}; }
  bool is_ok() const { return code == StatusCode::kOk; }
};

// A value or the Status explaining why there is none (C++17 stand-in for std::expected).
template <class T>
class Expected {
 public:
  Expected(T value) : state_(std::move(value)) {}       // NOLINT(google-explicit-constructor)
  Expected(Status error) : state_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool has_value() const { return std::holds_alternative<T>(state_); }
  explicit operator bool() const { return has_value(); }
  T& value() & { return std::get<T>(state_); }
  const T& value() const& { return std::get<T>(state_); }
  T&& value() && { return std::get<T>(std::move(state_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  // The failure; only meaningful when !has_value().
  const Status& error() const { return std::get<Status>(state_); }

 private:
  std::variant<T, Status> state_;
};

}  // namespace vnsba::core
