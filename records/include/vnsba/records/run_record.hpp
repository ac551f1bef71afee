// Run records: one planning run as the recorder heard it on the bus (request, status, path,
// debug, map reference), written as JSON beside its picture and read back to redraw it later.
//
// No DDS here: the recorder converts messages to these plain types (through node/convert.hpp),
// and `vnsba_recorder render RUN.json` and the tests work from files alone.
//
// Units: world positions in metres (map frame); debug cells are grid indices of the map the
// debug message describes.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/metrics.hpp"
#include "vnsba/core/planner_options.hpp"
#include "vnsba/core/search_trace.hpp"
#include "vnsba/core/status.hpp"
#include "vnsba/render/run_picture.hpp"

namespace vnsba::records {

// Where the map of a run lies and how it was turned into a planning grid.
struct MapReference {
  std::string file;  // map_server .yaml relative to the record's folder; empty if not saved
  std::string frame_id;
  int64_t stamp_sec = 0;  // header stamp of the slice (PlanStatus.map_stamp refers to it)
  uint32_t stamp_nanosec = 0;
  int32_t width = 0;  // cells
  int32_t height = 0;
  double resolution = 0.0;  // metres per cell
  double origin_x = 0.0;    // metres
  double origin_y = 0.0;
  // The recorder's config (expected to match the node's): redraws inflated cells and the cost
  // gradient (records written before the gradient existed have none).
  int occupied_threshold = 65;
  bool allow_unknown = false;
  // Unknown cells inflated like obstacles (map.inflate_unknown); records from before the key were
  // built so and read back as true.
  bool inflate_unknown = false;
  double robot_radius = 0.0;         // metres
  double inflation_radius = 0.0;     // metres, 0 = no gradient
  double cost_scaling_factor = 3.0;  // per metre

  // How the node built its planning map from the slice (the one conversion of these fields,
  // both ways).
  core::GridBuildOptions build_options() const {
    core::GridBuildOptions options;
    options.occupied_threshold = occupied_threshold;
    options.allow_unknown = allow_unknown;
    options.inflate_unknown = inflate_unknown;
    options.robot_radius = robot_radius;
    options.inflation_radius = inflation_radius;
    options.cost_scaling_factor = cost_scaling_factor;
    return options;
  }
  void set_build_options(const core::GridBuildOptions& options) {
    occupied_threshold = options.occupied_threshold;
    allow_unknown = options.allow_unknown;
    inflate_unknown = options.inflate_unknown;
    robot_radius = options.robot_radius;
    inflation_radius = options.inflation_radius;
    cost_scaling_factor = options.cost_scaling_factor;
  }
};

struct RequestRecord {
  std::string source;                    // "plan_request" or "goal_pose"
  std::string planner;                   // as requested (empty = the node's configured planner)
  std::optional<Eigen::Vector2d> start;  // metres; absent when not finite or not known
  std::optional<Eigen::Vector2d> goal;
};

struct StatusRecord {
  int code = 0;           // PlanStatus_Constants
  std::string code_name;  // "OK", "NO_VALID_PATH", ...
  std::string message;
  std::string planner;
  core::Metrics metrics;
  int64_t map_stamp_sec = 0;
  uint32_t map_stamp_nanosec = 0;
};

// The debug data of a run: the node's PlannerDebug in core types.
using DebugRecord = core::SearchTrace;

// The options that shape a run's path: the recorder's config (expected to match the node's)
// for the planner the run used, since a request names its planner only. Each field is absent in
// records written before it existed (not recorded: the caption then says nothing about it).
struct OptionsRecord {
  std::optional<core::Neighborhood> neighborhood;
  std::optional<bool> prune;
  std::optional<bool> smooth;
  std::optional<core::PathSmoother> smoother;  // none or relax (after pruning and smoothing)
  std::optional<double> cost_weight;           // 0 = the paper's binary grid
};

// The record of a plan run with these options.
OptionsRecord options_record(const core::PlannerOptions& options);

struct RunRecord {
  std::string request_id;
  std::optional<RequestRecord> request;
  std::optional<StatusRecord> status;  // absent when none came before the recorder stopped
  std::vector<Eigen::Vector2d> path;   // the final path, metres
  std::optional<DebugRecord> debug;
  std::optional<MapReference> map;
  std::optional<OptionsRecord> options;
};

// JSON with the keys "request_id", "request", "status", "path", "debug", "map", "options" (null
// when absent; in "options", "neighborhood" is "8" or "8-11-13" and unrecorded fields are left
// out). Non-finite numbers are written as null, except status.clearance_m: metres, "inf" on a
// map without obstacles, null when NaN (no path); a record without it (older ones) reads NaN.
nlohmann::json to_json(const RunRecord& record);
// The same document as text, as to_json(record).dump(1) but with the lists that grow with the
// run (path, debug cells and waypoints) 16 elements to a line, written element by element: no
// JSON tree of them is built (about 100 bytes a cell, against the 8 a cell takes in the record),
// and the text takes about 1.5 times the bytes of the cells and points it writes (a cell
// `[1234,567],` 11 bytes for the 8 it holds; at most 2.6 with 8-digit coordinates).
void write_json(std::ostream& out, const RunRecord& record);
// write_json into the file `path`; the error names it.
core::Status write_json_file(const std::string& path, const RunRecord& record);
// The inverse; errors (kInvalidRequest) name the key at fault ("status.metrics.turns"). A null
// geometry value (map.resolution, map.origin[0], map.robot_radius, map.inflation_radius,
// map.cost_scaling_factor, debug.resolution, debug.origin[1], ...: what to_json wrote for a value
// that was not finite) reads as NaN, so that the record reads back as it was written; with
// `null_geometry`, their paths are listed there, in the order read.
core::Expected<RunRecord> run_record_from_json(const nlohmann::json& json,
                                               std::vector<std::string>* null_geometry = nullptr);

// A file name for a request id: letters, digits, '-', '_' and '.' kept, anything else '_',
// never empty, never "." or "..", at most 120 characters (then a hash suffix keeps it unique).
std::string safe_file_stem(const std::string& request_id);

// Checks the geometry a record carries before it is drawn, with core::validate: the map
// reference's (map.width, map.height, map.resolution, map.origin, map.occupied_threshold,
// map.robot_radius, map.inflation_radius, map.cost_scaling_factor; with `grid`, the map file's
// cells in that geometry) and the debug data's (debug.width, ...), whose cells
// (debug.expanded_forward[i], ...) must lie in its grid. At most `max_cells` cells per grid. The
// error (kInvalidMap) names the JSON field.
core::Status check_record(const RunRecord& record, const core::OccupancyGrid* grid,
                          int64_t max_cells = core::GridBuildOptions{}.max_cells);

// The picture of a run. `grid` is the run's map when it is known (it must match the geometry
// the record carries); otherwise the geometry of the debug data or, failing that, a frame around
// the run's points is drawn without obstacles. The caption names the recorded options and the
// map reference's robot and inflation radii where positive.
render::RunPicture picture_of(const RunRecord& record, const core::OccupancyGrid* grid);

// Reads RUN.json (and the map file it references, relative to the record's folder) and returns
// the SVG. Errors name the file and the key at fault; a record with a null geometry value
// ("map.resolution is null") or one that check_record refuses is not drawn. The map is built for
// planning as the node builds it (GridMap::build with the record's occupied_threshold,
// allow_unknown, robot_radius and cost gradient), so inflated cells and cell costs are drawn as the
// node saw them.
core::Expected<std::string> render_record_file(const std::string& json_path);

}  // namespace vnsba::records
