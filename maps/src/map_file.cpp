#include "vnsba/maps/map_file.hpp"

#include <filesystem>

#include "vnsba/maps/map_io.hpp"

namespace vnsba::maps {
namespace {

bool has_suffix(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

MapFileKind map_file_kind(const std::string& path) {
  if (has_suffix(path, ".map")) return MapFileKind::kMovingAi;
  if (has_suffix(path, ".yaml") || has_suffix(path, ".yml") || has_suffix(path, ".pgm"))
    return MapFileKind::kMapServer;
  if (has_suffix(path, ".bt") || has_suffix(path, ".ot")) return MapFileKind::kOctoMap;
  return MapFileKind::kUnknown;
}

core::Expected<core::OccupancyGrid> load_map_file(const std::string& path,
                                                  const SliceOptions& slice) {
  switch (map_file_kind(path)) {
    case MapFileKind::kMovingAi:
      return load_movingai_map(path);
    case MapFileKind::kMapServer: {
      if (!has_suffix(path, ".pgm")) return load_map_server(path);
      // The map_server convention: the metadata lives in a YAML file beside the image.
      const std::string yaml = path.substr(0, path.size() - 4) + ".yaml";
      if (!std::filesystem::exists(yaml)) {
        return core::Status::error(
            core::StatusCode::kInvalidMap,
            path + ": a .pgm needs its map_server .yaml beside it (" + yaml + " is missing)");
      }
      return load_map_server(yaml);
    }
    case MapFileKind::kOctoMap: {
      auto tree = load_octree(path);
      if (!tree) return tree.error();
      auto grid = slice_octree(**tree, slice);
      if (!grid) return core::Status::error(grid.error().code, path + ": " + grid.error().message);
      return grid;
    }
    case MapFileKind::kUnknown:
      break;
  }
  return core::Status::error(core::StatusCode::kInvalidMap,
                             path + ": unknown map format (expected .map, .yaml, .pgm, .bt, .ot)");
}

}  // namespace vnsba::maps
