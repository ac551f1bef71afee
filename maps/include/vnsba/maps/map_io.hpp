// Map files: Moving AI benchmark maps and scenarios, ROS map_server maps (.pgm + .yaml).
//
// Every loader returns the map as a core::OccupancyGrid (row 0 at the bottom, as in the world) or a
// Status of kInvalidMap whose message names the file, the line and the problem.
#pragma once

#include <string>
#include <vector>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/status.hpp"

namespace vnsba::maps {

// Moving AI `.map` ("type octile / height H / width W / map" then H rows). '.', 'G' and 'S' are
// free (0), '@', 'O', 'T', 'W' blocked (100); anything else is an error. The file's top line
// becomes row H-1. Resolution 1 m, origin (0, 0).
core::Expected<core::OccupancyGrid> load_movingai_map(const std::string& path);

struct MovingAiScenario {
  int bucket = 0;
  std::string map_name;
  int map_width = 0;
  int map_height = 0;
  core::Cell start;  // converted to our rows: y = height - 1 - file_y
  core::Cell goal;
  double optimal_length = 0.0;  // octile, no corner cutting, as printed in the file
  // One unit of the last printed digit of optimal_length (the files print 2 to 8 decimals, and
  // round or truncate to that): compare path costs to the optimum within this.
  double optimal_resolution = 1e-8;
  int line = 0;  // 1-based line in the .scen file
};

// Moving AI `.scen` ("version 1" tab-separated or "version 1.0" space-separated).
core::Expected<std::vector<MovingAiScenario>> load_movingai_scenarios(const std::string& path);

// ROS map_server map: the YAML file names the image (PGM, P2 or P5, 8 or 16 bit; a relative
// name is relative to the YAML's folder) and gives resolution, origin [x, y, yaw], negate,
// occupied_thresh, free_thresh and mode (trinary, scale or raw). Only yaw = 0 is supported (the
// grid must be axis-aligned); a non-zero yaw is an error. The YAML is read with yaml-cpp (quoted
// values, comments, flow or block lists, anchors); it must be one document holding a map, without
// repeated keys; keys map_server does not know are ignored.
core::Expected<core::OccupancyGrid> load_map_server(const std::string& yaml_path);

// Writes `<stem>.pgm` (P5) and `<stem>.yaml` in trinary mode as map_saver does: occupied
// (>= occupied_threshold) black 0, free (0..25) white 254, unknown 205. Returns
// the YAML path.
core::Expected<std::string> save_map_server(const core::OccupancyGrid& grid,
                                            const std::string& stem, int occupied_threshold = 65);

}  // namespace vnsba::maps
