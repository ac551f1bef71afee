#include "vnsba/maps/world_text.hpp"

#include <Eigen/Core>
#include <cmath>
#include <cstdio>

namespace vnsba::maps {

// A fixed 96-byte buffer once cut 1e300 off mid-number: %g beyond 1e9 m.
std::string metres_text(double metres) {
  char text[64];
  std::snprintf(text, sizeof(text), std::abs(metres) < 1e9 ? "%.3f" : "%.6g", metres);
  return text;
}

std::string short_number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

std::string describe_position(const std::string& which, double x, double y) {
  return which + " (" + metres_text(x) + ", " + metres_text(y) + ") m";
}

std::string describe_world_bounds(const core::GridMap& map) {
  const Eigen::Vector2d lo = map.grid_to_world({0, 0});
  const Eigen::Vector2d hi = map.grid_to_world({double(map.width()), double(map.height())});
  return "[" + metres_text(lo.x()) + ", " + metres_text(hi.x()) + "] x [" + metres_text(lo.y()) +
         ", " + metres_text(hi.y()) + "] m";
}

std::string outside_map_message(const std::string& which, const core::GridMap& map, double x,
                                double y) {
  return describe_position(which, x, y) + " is outside the map " + describe_world_bounds(map);
}

std::string goal_outside_message(const core::GridMap& map, double x, double y,
                                 double goal_tolerance) {
  std::string message = outside_map_message("goal", map, x, y);
  if (goal_tolerance > 0.0)
    message += "; no free cell within goal_tolerance " + short_number(goal_tolerance) + " m";
  return message;
}

}  // namespace vnsba::maps
