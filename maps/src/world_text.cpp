#include "vnsba/maps/world_text.hpp"

#include <Eigen/Core>
#include <cmath>
#include <cstdio>

namespace vnsba::maps {
namespace {

// Metres to the millimetre, as map bounds are given; %g beyond 1e9 m, so that any magnitude
// fits (a fixed 96-byte buffer once cut 1e300 off mid-number).
std::string metres(double v) {
  char text[64];
  std::snprintf(text, sizeof(text), std::abs(v) < 1e9 ? "%.3f" : "%.6g", v);
  return text;
}

}  // namespace

std::string describe_position(const std::string& which, double x, double y) {
  return which + " (" + metres(x) + ", " + metres(y) + ") m";
}

std::string describe_world_bounds(const core::GridMap& map) {
  const Eigen::Vector2d lo = map.grid_to_world({0, 0});
  const Eigen::Vector2d hi = map.grid_to_world({double(map.width()), double(map.height())});
  return "[" + metres(lo.x()) + ", " + metres(hi.x()) + "] x [" + metres(lo.y()) + ", " +
         metres(hi.y()) + "] m";
}

std::string goal_outside_message(const core::GridMap& map, double x, double y,
                                 double goal_tolerance) {
  std::string message =
      describe_position("goal", x, y) + " is outside the map " + describe_world_bounds(map);
  if (goal_tolerance > 0.0) {
    char tolerance[32];
    std::snprintf(tolerance, sizeof tolerance, "%g", goal_tolerance);  // as a user types it
    message += std::string("; no free cell within goal_tolerance ") + tolerance + " m";
  }
  return message;
}

}  // namespace vnsba::maps
