// How messages give a point or a map's rectangle in the world: metres, to the millimetre. The
// node's request checks and vnsba_plan word a start or goal outside the map alike.
#pragma once

#include <string>

#include "vnsba/core/grid_map.hpp"

namespace vnsba::maps {

// Metres to the millimetre ("0.412"); %g beyond 1e9 m, so that any magnitude fits.
std::string metres_text(double metres);

// A setting as a user types it: 0.3, 100 (not 0.300).
std::string short_number(double value);

// "which (x, y) m": "goal (20.000, 9.000) m".
std::string describe_position(const std::string& which, double x, double y);

// The map's rectangle: "[x_min, x_max] x [y_min, y_max] m".
std::string describe_world_bounds(const core::GridMap& map);

// "which (x, y) m is outside the map [x_min, x_max] x [y_min, y_max] m".
std::string outside_map_message(const std::string& which, const core::GridMap& map, double x,
                                double y);

// Why a goal at (x, y) metres has no cell to plan to: outside the map and, with a goal_tolerance
// (metres) > 0, no free cell within it.
std::string goal_outside_message(const core::GridMap& map, double x, double y,
                                 double goal_tolerance);

}  // namespace vnsba::maps
