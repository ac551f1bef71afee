// Pictures of planning runs, like the paper's figures: the map, what each search expanded, the
// paths, start and goal, with axis ticks and a scale bar in metres, a legend of the layers drawn
// and a caption with the planner options and the metrics.
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
#include "vnsba/core/planner_options.hpp"

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
  // The planning map's cell costs (docs/algorithm.md section 8) of free cells, in kCostLevels equal
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

// The options that shape a path, as the caption names them. Unset means "not recorded" (an older
// run record, a caller that did not say): the caption then says nothing about it rather than
// guessing.
struct PathOptions {
  std::optional<core::Neighborhood> neighborhood;
  std::optional<bool> prune;
  std::optional<bool> smooth;
  std::optional<core::PathSmoother> smoother;  // relax: the final path is the relaxed one
  std::optional<double> cost_weight;           // 0 = the paper's binary grid
  // How the planning map was built (GridBuildOptions): named only when positive.
  std::optional<double> robot_radius;      // metres: obstacles inflated by it
  std::optional<double> inflation_radius;  // metres: reach of the cost gradient
};

// The options of a plan run with `planner` on a map built with `build` (when given).
PathOptions path_options(const core::PlannerOptions& planner,
                         const core::GridBuildOptions* build = nullptr);

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
  PathOptions options;                   // shown in the caption where set
};

// A run from an offline plan: start and goal at the query's requested points (start_point,
// goal_point) or, without them, its cells' centres, every layer from the result (expansions only
// when it recorded them). The caption shows the metrics of a successful run: length, clearance
// (omitted when NaN), turns, turn angle, expansions, time and the length ratio. The options are
// left unset: callers that know them set `options` (path_options).
RunPicture picture_of(std::shared_ptr<const MapPicture> map, const core::PlanQuery& query,
                      const core::PlanResult& result);

struct RenderOptions {
  double pixels_per_cell = 0.0;  // 0 = choose so the longer side is about 1000 px
  bool legend = true;
  bool caption = true;
  bool axes = true;
};

// The SVG document. The user unit is one cell: the map covers x in [0, width], y in [0, height]
// (SVG y down, so map row r is at SVG y = height - r - 1 .. height - r); the axes, legend and
// caption lie around it, inside the viewBox (which starts left of and above the map's corner).
// Group ids, fixed for tools and tests: "map-occupied", "map-unknown", "map-inflated",
// "map-cost-1".."map-cost-4", "expanded-forward", "expanded-backward", "raw-path",
// "pruned-path", "smoothed-corners", "meeting-cell", "start", "goal", "axis-x", "axis-y",
// "legend", "scale-bar", "caption". Each layer group carries data-count (cells, or points for
// paths) and is present even when empty; the legend ("legend": a "legend-box" rect, then per
// entry a swatch and a <text> with data-layer naming its layer group, "map-cost" for the cost
// levels) lists only the layers with something drawn. Axis groups hold one <line> and one <text>
// per tick, the tick's world coordinate in metres in data-value, the step in data-step.
// Text never runs outside the document: caption lines wrap to its width, which is at least
// kMinTextWidthPx so that the caption of a 40 x 800 map is as readable as that of a square one.
std::string render_svg(const RunPicture& run, const RenderOptions& options = {});
inline constexpr double kMinTextWidthPx = 640;
// The width, in units of the font size, the layout assumes for one character of its sans-serif
// text: DejaVu Sans averages about 0.55 em over lowercase letters, digits and spaces (its digits
// alone 0.636 em).
inline constexpr double kCharWidthEm = 0.6;

}  // namespace vnsba::render
