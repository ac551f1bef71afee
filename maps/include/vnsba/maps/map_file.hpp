// Any map file a user has, as an occupancy grid: the one dispatcher that vnsba_plan, vnsba_slicer
// and the tests share, so every tool accepts the same files.
#pragma once

#include <string>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/status.hpp"
#include "vnsba/maps/octomap_slice.hpp"

namespace vnsba::maps {

// What a file holds, from its name: OctoMaps are 3D and sliced; the others are 2D grids read as
// they are (map_server semantics for values).
enum class MapFileKind { kMovingAi, kMapServer, kOctoMap, kUnknown };
MapFileKind map_file_kind(const std::string& path);

// Loads `.map` (Moving AI), `.yaml`/`.yml` (map_server; a `.pgm` with its `.yaml` beside it),
// `.bt`/`.ot` (OctoMap, sliced with `slice`). Errors name the file (kInvalidMap) or, for a slice
// the tree cannot give, the option as `slice.names` calls it (kInvalidRequest).
core::Expected<core::OccupancyGrid> load_map_file(const std::string& path,
                                                  const SliceOptions& slice = {});

}  // namespace vnsba::maps
