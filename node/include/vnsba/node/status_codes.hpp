// PlanStatus.idl's code numbers for core's statuses, without DDS: the node writes them on the bus
// (node::to_wire_code, which checks them against the generated IDL constants at compile time) and
// vnsba_plan, which links no DDS, writes them into run records.
#pragma once

#include <cstdint>

#include "vnsba/core/status.hpp"

namespace vnsba::node {

constexpr uint8_t plan_status_code(core::StatusCode code) {
  switch (code) {
    case core::StatusCode::kOk:
      return 0;
    case core::StatusCode::kInvalidMap:
      return 2;
    case core::StatusCode::kInvalidRequest:
      return 3;
    case core::StatusCode::kStartOutsideMap:
      return 5;
    case core::StatusCode::kGoalOutsideMap:
      return 6;
    case core::StatusCode::kStartOccupied:
      return 7;
    case core::StatusCode::kGoalOccupied:
      return 8;
    case core::StatusCode::kNoValidPath:
      return 9;
    case core::StatusCode::kTimeout:
      return 10;
    case core::StatusCode::kCanceled:
      return 11;
    case core::StatusCode::kInternalError:
      return 12;
  }
  return 12;  // kInternalError
}

}  // namespace vnsba::node
