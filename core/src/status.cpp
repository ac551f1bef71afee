#include "vnsba/core/status.hpp"

namespace vnsba::core {

std::string_view to_string(StatusCode code) {
  switch (code) {
    case StatusCode::kOk:
      return "OK";
    case StatusCode::kInvalidMap:
      return "INVALID_MAP";
    case StatusCode::kInvalidRequest:
      return "INVALID_REQUEST";
    case StatusCode::kStartOutsideMap:
      return "START_OUTSIDE_MAP";
    case StatusCode::kGoalOutsideMap:
      return "GOAL_OUTSIDE_MAP";
    case StatusCode::kStartOccupied:
      return "START_OCCUPIED";
    case StatusCode::kGoalOccupied:
      return "GOAL_OCCUPIED";
    case StatusCode::kNoValidPath:
      return "NO_VALID_PATH";
    case StatusCode::kTimeout:
      return "TIMEOUT";
    case StatusCode::kCanceled:
      return "CANCELED";
    case StatusCode::kInternalError:
      return "INTERNAL_ERROR";
  }
  return "INTERNAL_ERROR";
}

}  // namespace vnsba::core
