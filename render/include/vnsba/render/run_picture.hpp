// Pictures of planning runs, like the paper's figures: the map, what each search expanded, the
// paths, start and goal, with a legend, a scale bar in metres and a caption with the metrics.
//
//   RunPicture picture = picture_of(map_picture(grid, &planning_map), query, result);
//   std::string svg = render_svg(picture);
//
// All geometry is in continuous cell coordinates (see core/geometry.hpp); the renderer flips y
// so that row 0 is at the bottom, as in the world. Consecutive cells of a layer in a row are
// merged into one run, so a 1000 x 1000 map with 200,000 expansions stays a few MB.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/metrics.hpp"
#include "vnsba/core/planner.hpp"

namespace vnsba::render {

// A cell as the picture shows it: core's classification (free, occupied, unknown, inflated).
using CellState = core::CellLayer;

// The map as the picture shows it: one state per cell, row-major, row 0 at the origin.
struct MapPicture {
  int32_t width = 0;        // cells
  int32_t height = 0;       // cells
  double resolution = 1.0;  // metres per cell
  double origin_x = 0.0;    // metres
  double origin_y = 0.0;    // metres
  std::vector<CellState> cells;
  // The planning map's cell costs (ALGORITHM.md section 8) of free cells, in kCostLevels equal
  // bands: 0 = no cost, k = cost in ((k - 1) / kCostLevels, k / kCostLevels]. Empty when the map
  // has no costs (drawn as a tint that deepens toward obstacles).
  static constexpr int kCostLevels = 4;
  std::vector<uint8_t> cost_levels;
  CellState at(int32_t x, int32_t y) const { return cells[static_cast<size_t>(y) * width + x]; }
  uint8_t cost_level(int32_t x, int32_t y) const {
    return cost_levels.empty() ? 0 : cost_levels[static_cast<size_t>(y) * width + x];
  }
};

// From an occupancy grid: values >= occupied_threshold are occupied, -1 unknown. When the
// planning map built from that grid is given (same size), cells it blocks that the grid does not
// are drawn as inflated, and its cell costs as cost levels.
MapPicture map_picture(const core::OccupancyGrid& grid, int occupied_threshold = 65,
                       const core::GridMap* planning_map = nullptr);
// From a planning map alone (blocked cells are occupied; no unknown; its costs as cost levels).
MapPicture map_picture(const core::GridMap& map);

// One planning run. Everything but the map is optional: a run without debug data still gets a
// picture of its path, a failed run a picture of its start and goal.
struct RunPicture {
  std::shared_ptr<const MapPicture> map;
  std::optional<core::Point2> start;  // cell coordinates
  std::optional<core::Point2> goal;
  std::vector<core::Cell> expanded_forward;
  std::vector<core::Cell> expanded_backward;
  std::optional<core::Cell> meeting_cell;
  std::vector<core::Cell> raw_path;      // the grid path (thin black)
  std::vector<core::Point2> waypoints;   // the pruned polyline (black)
  std::vector<core::Point2> path;        // the final path; where it leaves the pruned polyline
                                         // it is drawn red (the smoothed corners)
  std::string title;                     // e.g. the request id or "map A"
  std::string planner;                   // e.g. "vns_bastar"
  std::string status = "OK";             // status code name
  std::string message;                   // status message (shown for failures)
  std::optional<core::Metrics> metrics;  // shown in the caption when present
};

// A run from an offline plan: start and goal at the query's requested points (start_point,
// goal_point) or, without them, its cells' centres, every layer from the result (expansions only
// when it recorded them). The caption shows the metrics of a successful run: length, clearance
// (omitted when NaN), turns, turn angle, expansions, time and the length ratio.
RunPicture picture_of(std::shared_ptr<const MapPicture> map, const core::PlanQuery& query,
                      const core::PlanResult& result);

struct RenderOptions {
  double pixels_per_cell = 0.0;  // 0 = choose so the longer side is about 1000 px
  bool legend = true;
  bool caption = true;
};

// The SVG document. Group ids, fixed for tools and tests: "map-occupied", "map-unknown",
// "map-inflated", "expanded-forward", "expanded-backward", "raw-path", "pruned-path",
// "smoothed-corners", "meeting-cell", "start", "goal", "legend", "scale-bar", "caption".
// Each layer group carries data-count (cells, or points for paths).
std::string render_svg(const RunPicture& run, const RenderOptions& options = {});

}  // namespace vnsba::render
