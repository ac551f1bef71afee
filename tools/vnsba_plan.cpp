// vnsba_plan: plan offline on a map file and draw the run, for users without a DDS system.
//
//   vnsba_plan MAP --start X Y --goal X Y [--planner NAME] [--svg out.svg] [--cells]
//              [--config FILE] [--repeat N] [--json run.json] [--png out.png]
//              [--z-min A --z-max B] [--resolution R] [--bounds XMIN,YMIN,XMAX,YMAX]
//                                                       (OctoMap files)
//              [--allow-unknown] [--inflate-unknown] [--robot-radius M] [--occupied-threshold T]
//              [--neighborhood 8|8-11-13] [--corner-policy never|touch|always]
//              [--prune|--no-prune] [--smooth|--no-smooth] [--omega W] [--eta W]
//              [--inflation-radius M] [--cost-scaling-factor PER_M] [--cost-weight W]
//              [--goal-tolerance M] [--start-tolerance M]
//              [--smoother none|relax] [--smoother-smoothness W] [--smoother-closeness W]
//              [--smoother-cost W] [--smoother-iterations N]
//              [--poses FILE [--path-spacing M] [--goal-yaw RAD]]
//   vnsba_plan [MAP] --scen FILE.scen [--scen-index N] [--progress] [other options as above]
//
// MAP is a Moving AI `.map` (1 m cells, origin (0, 0), row 0 at the bottom), a map_server
// `.yaml` (with its `.pgm`), or an OctoMap `.bt`/`.ot` sliced at the height band given, over the
// tree's extent or the --bounds given (metres, as vnsba_slicer takes them).
// Start and goal are world coordinates in metres in the map's frame; with --cells they are cell
// indices (column, row counted from the bottom). The requested points are what start_tolerance
// and goal_tolerance measure from (docs/algorithm.md section 8); a goal outside the map is planned
// only with --goal-tolerance, to the nearest free cell within it. Prints one line: planner,
// status, length in metres, clearance in metres (`inf` on a map without obstacles, `nan` without
// a path), turns, turn angle, expansions, time, the length ratio to optimal A* (a second search,
// which the time does not include), and start_moved_m / goal_moved_m when a tolerance moved the
// start or the goal. With --repeat N the query is planned N times on one Planner (its search
// state allocated once): time_us is the first plan's, and `repeats=N first_time_us=
// median_time_us=` follow (the first includes one-off allocation, the median does not).
//
// --config FILE reads the node's config (node::load_config, no DDS): its planner section (name,
// options, costs, tolerances, path_spacing), its map section (thresholds, robot_radius, cost
// gradient, max_cells) and, for OctoMaps, its slicer band are the defaults; every flag given
// overrides its key. A bad file is refused with every error the loader reports. Without --config
// the tool reads default.yaml where the node finds it (node::find_default_config), so the
// shortest command plans for the same robot as the node and every other tool. --paper asks for
// the paper's setting instead: a binary grid (no robot radius, inflation or cost gradient), the
// exact start and goal, vns_bastar and each planner's options as the paper gives them.
//
// --scen FILE runs Moving AI scenario lines as the file writes them (its rows count from the
// top; the loader turns them into ours), on MAP or, without MAP, on the map the first line names,
// beside the .scen file. One line per scenario, then a summary: with an exact planner (astar or
// jps on the Moving AI graph: 8-neighbourhood, corners never cut, no cost weight) how many grid
// path costs match the line's optimum within its printed precision, otherwise the mean and
// largest ratio of the final length to the optimum. --scen-index N runs the N-th line alone
// (0-based); only then may --svg, --png, --json and --poses draw it. Progress on stderr (at
// most once a second) when stderr is a terminal or with --progress.
//
// --inflation-radius and --cost-scaling-factor add the cost gradient to the map as it is built
// (GridBuildOptions), --cost-weight plans with it. --poses FILE writes the poses the node would
// publish for the path (core::path_poses: at most --path-spacing metres apart, default the map's
// resolution; the last with --goal-yaw when given), one `x y yaw` per line in metres and
// radians; an empty file when no path was found.
//
// --json FILE writes the run record as vnsba_recorder writes it (records::to_json), with the map
// saved beside it as FILE's stem + "_map.yaml"/".pgm" (map_server), so that
// `vnsba_recorder render FILE` redraws it. --png FILE writes the picture as PNG (librsvg,
// in-process).
//
// With --paper the planner options are core::make_options(--planner, the option flags given): a
// flag left out follows the chosen planner's paper configuration.
//
// Exit codes: 0 a path was found (with --scen: every line planned, and matched its optimum where
// the planner is exact), 1 the planner answered another status (printed) or missed an optimum,
// 2 bad arguments, config, map or output file.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vnsba/core/path_poses.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/core/planner_options.hpp"
#include "vnsba/core/planner_registry.hpp"
#include "vnsba/maps/map_file.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/maps/world_text.hpp"
#include "vnsba/node/command_line.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/status_codes.hpp"
#include "vnsba/records/run_record.hpp"
#include "vnsba/render/png.hpp"
#include "vnsba/render/progress.hpp"
#include "vnsba/render/run_picture.hpp"
#include "vnsba/render/svg.hpp"
#include "vnsba/render/text_format.hpp"

namespace {

using namespace vnsba;

constexpr int kPlanFailed = 1;
constexpr int kBadInput = node::kExitUsage;
// --poses writes at most this many poses (a path of 10 km at 1 mm spacing): a tiny
// --path-spacing is refused rather than filling the disk.
constexpr double kMaxPoses = 1e7;

// A start or goal given on the command line: its cell and the requested point in continuous cell
// coordinates (unset with --cells: the cell's centre). `outside_ok` (a goal with goal_tolerance)
// lets a point outside the map through, as the cell that contains it, for core to resolve. The
// error names the option.
struct Endpoint {
  core::Cell cell;
  std::optional<core::Point2> point;
};
core::Expected<Endpoint> to_endpoint(const core::GridMap& map, const std::vector<double>& xy,
                                     bool cells, bool outside_ok, const std::string& option) {
  if (!std::isfinite(xy[0]) || !std::isfinite(xy[1]))
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               option + " must be two finite numbers");
  // Beyond this a cell index leaves int32 (and no tolerance of at most 100 m reaches the map).
  constexpr double kFarCells = 1e9;
  if (cells) {
    if (xy[0] != std::floor(xy[0]) || xy[1] != std::floor(xy[1]))
      return core::Status::error(core::StatusCode::kInvalidRequest,
                                 option + " with --cells must be whole cell indices");
    const bool far = std::abs(xy[0]) > kFarCells || std::abs(xy[1]) > kFarCells;
    const core::Cell c{far ? 0 : static_cast<int32_t>(xy[0]),
                       far ? 0 : static_cast<int32_t>(xy[1])};
    if (far || (!map.in_bounds(c) && !outside_ok))
      return core::Status::error(core::StatusCode::kInvalidRequest,
                                 option + " is outside the map (" + std::to_string(map.width()) +
                                     " x " + std::to_string(map.height()) + " cells)");
    return Endpoint{c, std::nullopt};
  }
  const core::Point2 point = map.world_to_grid(xy[0], xy[1]);
  if (const auto cell = map.world_to_cell(xy[0], xy[1])) return Endpoint{*cell, point};
  const bool far = !(std::abs(point.x()) <= kFarCells && std::abs(point.y()) <= kFarCells);
  if (!outside_ok || far) {
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               maps::outside_map_message(option, map, xy[0], xy[1]) +
                                   (option == "--goal" && !outside_ok
                                        ? " (with --goal-tolerance, the plan goes to the nearest "
                                          "free cell within it)"
                                        : ""));
  }
  return Endpoint{core::Cell{static_cast<int32_t>(std::floor(point.x())),
                             static_cast<int32_t>(std::floor(point.y()))},
                  point};
}

// Prints why a value given for `flag` is refused and returns false.
bool refuse(const char* flag, const std::string& expected, double got) {
  std::fprintf(stderr, "%s must be %s (got %g)\n", flag, expected.c_str(), got);
  return false;
}

// A planner setting against its core range (kCostWeightRange, kToleranceRange): the message names
// the flag and the range with its unit.
bool check_range(const CLI::Option* option, const char* flag, double value,
                 const core::OptionRange& range) {
  return option->count() == 0 || range.contains(value) || refuse(flag, range.describe(), value);
}

// Writes the poses, one `x y yaw` per line (metres, radians); the error names --poses.
core::Status write_poses(const std::string& path, const std::vector<core::Pose2>& poses) {
  std::string text;
  text.reserve(poses.size() * 36);
  char line[128];
  for (const core::Pose2& p : poses) {
    std::snprintf(line, sizeof line, "%.6f %.6f %.6f\n", p.x, p.y, p.yaw);
    text += line;
  }
  const core::Status written = render::write_text_file(path, text);
  if (written.is_ok()) return written;
  return core::Status::error(written.code, "--poses: " + written.message);
}

// The run as vnsba_recorder records it from the bus (request, status, path, debug, map): the
// same JSON, so `vnsba_recorder render` and records::run_record_from_json read it. `map_file` is
// the saved map_server file relative to the record's folder.
records::RunRecord run_record(const std::string& request_id, const core::GridMap& map,
                              const core::PlanQuery& query, const core::PlanResult& result,
                              const core::GridBuildOptions& build, const std::string& frame_id,
                              const std::string& map_file) {
  records::RunRecord record;
  record.request_id = request_id;
  auto requested = [&](const core::Cell& cell, const std::optional<core::Point2>& point) {
    return point ? map.grid_to_world(*point) : map.cell_centre_world(cell);
  };
  records::RequestRecord request;
  request.source = "vnsba_plan";
  request.planner = std::string(core::to_string(result.planner));
  request.start = requested(query.start, query.start_point);
  request.goal = requested(query.goal, query.goal_point);
  record.request = request;
  records::StatusRecord status;
  status.code = node::plan_status_code(result.status.code);
  status.code_name = std::string(core::to_string(result.status.code));
  status.message = result.status.message;
  status.planner = std::string(core::to_string(result.planner));
  status.metrics = result.metrics;
  record.status = status;
  record.path = result.world_path;
  core::SearchTrace trace;
  trace.planner = status.planner;
  trace.width = map.width();
  trace.height = map.height();
  trace.resolution = map.resolution();
  trace.origin_x = map.origin_x();
  trace.origin_y = map.origin_y();
  trace.expanded_forward = result.expanded_forward;
  trace.expanded_backward = result.expanded_backward;
  trace.meeting_cell = result.meeting_cell;
  trace.raw_path = result.raw_path;
  for (const core::Point2& w : result.waypoints)
    trace.pruned_waypoints.push_back(map.grid_to_world(w));
  record.debug = std::move(trace);
  records::MapReference ref;
  ref.file = map_file;
  ref.frame_id = frame_id;
  ref.width = map.width();
  ref.height = map.height();
  ref.resolution = map.resolution();
  ref.origin_x = map.origin_x();
  ref.origin_y = map.origin_y();
  ref.set_build_options(build);
  record.map = ref;
  return record;
}

// What a run writes besides its line: poses, SVG, PNG, run record. Empty paths are skipped.
struct Outputs {
  std::string poses, svg, png, json;
  std::optional<double> path_spacing;  // metres; unset = the map's resolution
  std::optional<double> goal_yaw;      // radians
  std::string frame_id = "map";
  render::PathOptions options;            // the planner options the picture's caption names
  records::OptionsRecord record_options;  // the same, as the run record keeps them
  bool any_picture() const { return !svg.empty() || !png.empty() || !json.empty(); }
};

// Writes the outputs of one run; false (with the message printed, naming the option or file)
// when one cannot be written.
bool write_outputs(const Outputs& out, const std::string& map_path, const core::OccupancyGrid& grid,
                   const core::GridBuildOptions& build,
                   const std::shared_ptr<const core::GridMap>& map, const core::PlanQuery& query,
                   const core::PlanResult& result) {
  if (!out.poses.empty()) {
    const double spacing = out.path_spacing.value_or(map->resolution());
    if (const core::Status valid = core::validate_path_spacing(result.world_path, spacing);
        !valid.is_ok()) {
      std::fprintf(stderr, "--path-spacing: %s\n", valid.message.c_str());
      return false;
    }
    double pose_count = 1.0;
    for (size_t i = 1; i < result.world_path.size(); ++i)
      pose_count += std::ceil((result.world_path[i] - result.world_path[i - 1]).norm() / spacing);
    if (pose_count > kMaxPoses) {
      std::fprintf(stderr,
                   "--path-spacing %g metres gives about %.0f poses for this %.3f m path, more "
                   "than the %.0f --poses writes\n",
                   spacing, pose_count, result.metrics.length_m, kMaxPoses);
      return false;
    }
    const core::Status written =
        write_poses(out.poses, core::path_poses(result.world_path, spacing, out.goal_yaw));
    if (!written.is_ok()) {
      std::fprintf(stderr, "%s\n", written.message.c_str());
      return false;
    }
    std::fprintf(stderr, "wrote %s\n", out.poses.c_str());
  }
  if (!out.svg.empty() || !out.png.empty()) {
    auto picture = std::make_shared<const render::MapPicture>(
        render::map_picture(grid, build.occupied_threshold, map.get()));
    render::RunPicture run = render::picture_of(picture, query, result);
    run.options = out.options;
    run.title = std::filesystem::path(map_path).filename().string();
    const std::string svg = render::render_svg(run);
    if (!out.svg.empty()) {
      const core::Status written = render::write_text_file(out.svg, svg);
      if (!written.is_ok()) {
        std::fprintf(stderr, "--svg: %s\n", written.message.c_str());
        return false;
      }
      std::fprintf(stderr, "wrote %s\n", out.svg.c_str());
    }
    if (!out.png.empty()) {
      const core::Status written = render::write_png_file(out.png, svg);
      if (!written.is_ok()) {
        std::fprintf(stderr, "--png: %s\n", written.message.c_str());
        return false;
      }
      std::fprintf(stderr, "wrote %s\n", out.png.c_str());
    }
  }
  if (!out.json.empty()) {
    // The map beside the record, as the recorder saves slices: map_server, trinary.
    const std::filesystem::path json_path(out.json);
    const std::filesystem::path stem =
        json_path.parent_path() / (json_path.stem().string() + "_map");
    auto saved = maps::save_map_server(grid, stem.string(), build.occupied_threshold);
    if (!saved) {
      std::fprintf(stderr, "--json: the map beside it: %s\n", saved.error().message.c_str());
      return false;
    }
    const std::string request_id = "vnsba_plan-" + std::filesystem::path(map_path).stem().string();
    records::RunRecord record = run_record(request_id, *map, query, result, build, out.frame_id,
                                           std::filesystem::path(*saved).filename().string());
    record.options = out.record_options;
    const core::Status written = records::write_json_file(out.json, record);
    if (!written.is_ok()) {
      std::fprintf(stderr, "--json: %s\n", written.message.c_str());
      return false;
    }
    std::fprintf(stderr, "wrote %s and %s\n", out.json.c_str(), saved->c_str());
  }
  return true;
}

// Whether `options` find the optimum of a Moving AI scenario: an optimal search (A*, JPS) on the
// graph the files measure (8-neighbourhood, no corner cutting, uniform costs).
bool exact_on_movingai_graph(const core::PlannerOptions& options) {
  return options.planner.descriptor() != nullptr &&
         options.planner.descriptor()->can.optimal_on_baseline &&
         options.neighborhood == core::Neighborhood::kEight &&
         options.corner_policy == core::CornerPolicy::kNever && options.cost_weight == 0.0;
}

// The result line of a single run (scripts and tests parse it); `times_us` holds every plan's
// time when --repeat was given.
void print_result_line(const core::PlanResult& result, const std::vector<int64_t>& times_us,
                       bool repeated) {
  const core::Metrics& m = result.metrics;
  std::printf(
      "%s %s length_m=%.3f clearance_m=%s turns=%d turn_angle_deg=%.1f expanded=%lld "
      "time_us=%lld",
      std::string(core::to_string(result.planner)).c_str(),
      std::string(core::to_string(result.status.code)).c_str(), m.length_m,
      render::format_metres(m.clearance_m).c_str(), m.turns, m.turn_angle_deg,
      static_cast<long long>(m.expanded),
      static_cast<long long>(times_us.empty() ? m.planning_time_us : times_us.front()));
  if (std::isfinite(m.length_ratio)) std::printf(" length_ratio=%.4f", m.length_ratio);
  if (result.endpoints.start_adjusted)
    std::printf(" start_moved_m=%.3f", result.endpoints.start_moved_m);
  if (result.endpoints.goal_adjusted)
    std::printf(" goal_moved_m=%.3f", result.endpoints.goal_moved_m);
  if (repeated && !times_us.empty()) {
    std::vector<int64_t> sorted = times_us;
    std::sort(sorted.begin(), sorted.end());
    const size_t n = sorted.size();
    // Microseconds; the mean of the two middle plans for an even count.
    const double median = n % 2 == 1 ? static_cast<double>(sorted[n / 2])
                                     : 0.5 * static_cast<double>(sorted[n / 2 - 1] + sorted[n / 2]);
    std::printf(" repeats=%zu first_time_us=%lld median_time_us=%lld", n,
                static_cast<long long>(times_us.front()),
                static_cast<long long>(std::llround(median)));
  }
  std::printf("\n");
  std::fflush(stdout);  // the line before its message, also when both go to one pipe
  if (!result.status.is_ok()) std::fprintf(stderr, "%s\n", result.status.message.c_str());
}

// --list-planners: each registered planner with what it searches with, as its descriptor says.
void print_planners() {
  for (const core::PlannerDescriptor* planner : core::registered_planners()) {
    const core::PlannerCapabilities& can = planner->can;
    const std::string heading = std::string(planner->name) + " (" +
                                std::string(planner->paper_name) +
                                "): " + std::string(planner->summary);
    std::printf("%s\n", heading.c_str());
    std::printf("  neighborhood: %s; corner_policy: %s; cost_weight: %s%s\n",
                can.long_moves ? "8 or 8-11-13" : "8", can.corner_cutting ? "any" : "never",
                can.costs ? "any" : "0",
                can.optimal_on_baseline ? "; exact: the shortest grid path" : "");
    std::string own;
    for (size_t i = 0; i < planner->own_option_count; ++i)
      own += (own.empty() ? "" : ", ") + std::string(planner->own_options[i].range->key);
    if (!own.empty()) std::printf("  its own options: %s\n", own.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vnsba_plan: plan on a map file offline and draw the run as SVG"};
  std::string map_path;
  std::vector<double> start, goal;
  std::string planner_name = "vns_bastar";
  std::string config_path, scen_path;
  int scen_index = -1;
  int repeat = 1;
  bool progress_flag = false;
  Outputs out;
  bool cells = false;
  maps::SliceOptions slice;
  slice.names.bounds = "--bounds";
  slice.names.max_cells = "vnsba_plan's limit";
  std::vector<double> bounds;
  // Flags parse into `cli`; the build options are the config's map section (or core's
  // defaults) with every flag given on top.
  core::GridBuildOptions cli;
  app.add_option("map", map_path,
                 "map file: .map, .yaml/.pgm (map_server), .bt/.ot (OctoMap); with --scen, "
                 "default: the map the .scen file names, beside it");
  auto* start_flag =
      app.add_option("--start", start, "start X Y (metres; cell indices with --cells)")
          ->expected(2);
  auto* goal_flag =
      app.add_option("--goal", goal, "goal X Y (metres; cell indices with --cells)")->expected(2);
  auto* planner_flag = app.add_option("--planner", planner_name,
                                      core::accepted_planner_names() +
                                          " (auto: jps with pruning and smoothing where costs are "
                                          "off, else the cost-aware choice; default: the config's "
                                          "planner.name, vns_bastar with --paper)");
  auto* config_flag = app.add_option(
      "--config", config_path,
      "the node's YAML config: its planner and map sections (and, for OctoMaps, its slicer band) "
      "are the defaults of the options below; a flag given overrides its key (default: "
      "default.yaml, as the node)");
  bool list_planners = false;
  app.add_flag("--list-planners", list_planners,
               "list the planners --planner accepts, what each searches with, and exit");
  bool paper = false;
  app.add_flag("--paper", paper,
               "no config: the paper's setting (a binary grid without robot radius, inflation or "
               "costs; the exact start and goal; vns_bastar and each planner's paper options)")
      ->excludes(config_flag);
  app.add_option("--svg", out.svg, "write a picture of the run here");
  app.add_option("--png", out.png, "write the picture as PNG here (rendered in-process)");
  app.add_option("--json", out.json,
                 "write the run record here as vnsba_recorder does (JSON), and the map beside it "
                 "as <stem>_map.yaml/.pgm");
  auto* repeat_flag =
      app.add_option("--repeat", repeat,
                     "plan the query N times on one planner (search state allocated once) and "
                     "print first_time_us= and median_time_us= (1..100000)")
          ->check(CLI::Range(1, 100000));
  auto* scen_flag =
      app.add_option("--scen", scen_path,
                     "run the lines of a Moving AI .scen file as written (rows from the top), "
                     "one result line each and a summary against their optima");
  auto* scen_index_flag =
      app.add_option("--scen-index", scen_index,
                     "with --scen: run only this line (0 = the first scenario of the file)");
  app.add_flag("--progress", progress_flag,
               "with --scen: progress on stderr even when it is not a terminal");
  auto* cells_flag = app.add_flag(
      "--cells", cells,
      "start and goal are cell indices (column, row counted from the bottom; a .scen file counts "
      "rows from the top: run its lines as written with --scen)");
  auto* z_min_flag =
      app.add_option("--z-min", slice.z_min,
                     "OctoMap: bottom of the height band, metres (default: the config's "
                     "slicer.z_min, else 0.1)");
  auto* z_max_flag = app.add_option("--z-max", slice.z_max,
                                    "OctoMap: top of the height band, metres (default: the "
                                    "config's slicer.z_max, else 1.5)");
  auto* resolution_flag =
      app.add_option("--resolution", slice.resolution,
                     "OctoMap: metres per cell, a whole multiple of the leaf size (0 = leaf size)");
  const std::vector<CLI::Option*> octomap_options = {
      z_min_flag, z_max_flag, resolution_flag,
      app.add_option("--bounds", bounds,
                     "OctoMap: the area to slice, x_min,y_min,x_max,y_max in metres (default: "
                     "the tree's extent)")
          ->expected(4)
          ->delimiter(',')};
  auto* occupied_threshold_flag =
      app.add_option("--occupied-threshold", cli.occupied_threshold,
                     "occupancy percent at or above which a cell is blocked (1..100)");
  auto* allow_unknown_flag =
      app.add_flag("--allow-unknown", cli.allow_unknown, "plan through unknown cells");
  auto* inflate_unknown_flag = app.add_flag(
      "--inflate-unknown", cli.inflate_unknown,
      "inflate and cost unknown cells like obstacles (map.inflate_unknown; default: they are "
      "blocked, or free with --allow-unknown, but no inflation source, as in Nav2)");
  auto* robot_radius_flag =
      app.add_option("--robot-radius", cli.robot_radius, "inflate obstacles by this, metres");
  auto* inflation_radius_flag = app.add_option(
      "--inflation-radius", cli.inflation_radius,
      "cost gradient around obstacles out to this, metres: 0 (none, the default) or >= "
      "--robot-radius");
  auto* cost_scaling_flag = app.add_option(
      "--cost-scaling-factor", cli.cost_scaling_factor,
      "decay of the cost gradient, per metre, >= 0 (default 3): cost 0.99 * exp(-factor * (d - "
      "robot radius))");
  // Costs, tolerances and poses (docs/algorithm.md section 8).
  double cost_weight = 0.0, goal_tolerance = 0.0, start_tolerance = 0.0;
  auto* cost_weight_flag = app.add_option("--cost-weight", cost_weight,
                                          "move cost = length * (1 + W * cell cost), " +
                                              core::kCostWeightRange.describe() +
                                              " (default 0: the paper's binary grid)");
  auto* goal_tolerance_flag =
      app.add_option("--goal-tolerance", goal_tolerance,
                     "plan to the nearest free cell within this of a blocked or outside goal, " +
                         core::kToleranceRange.describe() + " (default 0)");
  auto* start_tolerance_flag =
      app.add_option("--start-tolerance", start_tolerance,
                     "move a start blocked by inflation to the nearest free cell within this, " +
                         core::kToleranceRange.describe() + " (default 0)");
  double path_spacing = 0.0, goal_yaw = 0.0;
  app.add_option("--poses", out.poses,
                 "write the path's poses here, one `x y yaw` per line (metres, radians)");
  auto* path_spacing_flag =
      app.add_option("--path-spacing", path_spacing,
                     "--poses: poses at most this far apart, metres > 0 (default: the config's "
                     "planner.path_spacing, else the map's resolution)");
  auto* goal_yaw_flag = app.add_option("--goal-yaw", goal_yaw,
                                       "--poses: yaw of the last pose, radians (default: "
                                       "the path's tangent)");
  // Planner options: each flag left out follows the planner's paper configuration.
  std::string neighborhood, corner_policy;
  bool prune = false, smooth = false;
  double omega = 0.0, eta = 0.0;
  auto* neighborhood_flag =
      app.add_option("--neighborhood", neighborhood,
                     "8 or 8-11-13 (default: 8-11-13 for vns_bastar, 8 for the others)")
          ->check(CLI::IsMember({"8", "8-11-13"}));
  auto* corner_policy_flag =
      app.add_option("--corner-policy", corner_policy,
                     "diagonal moves past blocked cells: never (both side cells free, the "
                     "default), touch (one free), always")
          ->check(CLI::IsMember({"never", "touch", "always"}));
  auto* prune_flag = app.add_flag("--prune,!--no-prune", prune,
                                  "prune the grid path to its turning points (default: on for "
                                  "vns_bastar, off for the others)");
  auto* smooth_flag = app.add_flag("--smooth,!--no-smooth", smooth,
                                   "smooth the path's corners with cubic splines (default: on for "
                                   "vns_bastar, off for the others)");
  auto* omega_flag = app.add_option("--omega", omega,
                                    "vns_bastar: weight of the distance to the other search's "
                                    "current node, 0..1e6 (default 0.5)")
                         ->check(CLI::Range(0.0, 1e6));
  auto* eta_flag = app.add_option("--eta", eta,
                                  "vns_bastar: weight of the distance to the other search's "
                                  "start, 0..1e6 (default 0.5)")
                       ->check(CLI::Range(0.0, 1e6));
  std::string smoother;
  double smoother_smoothness = 0.0, smoother_closeness = 0.0, smoother_cost = 0.0;
  int smoother_iterations = 0;
  auto* smoother_flag =
      app.add_option("--smoother", smoother,
                     "relax (an elastic band after pruning and smoothing: straightens a "
                     "cost-aware path's staircase, never lowers its clearance) or none (default: "
                     "the config's planner.smoother, else none)")
          ->check(CLI::IsMember({"none", "relax"}));
  auto* smoother_smoothness_flag =
      app.add_option("--smoother-smoothness", smoother_smoothness,
                     "relax: pull toward the neighbours' middle per iteration, " +
                         core::kSmootherSmoothnessRange.describe() + " (default 0.9)");
  auto* smoother_closeness_flag =
      app.add_option("--smoother-closeness", smoother_closeness,
                     "relax: pull back toward the planned path per iteration, " +
                         core::kSmootherClosenessRange.describe() + " (default 0)");
  auto* smoother_cost_flag =
      app.add_option("--smoother-cost", smoother_cost,
                     "relax: push down the cost gradient per iteration, times the cost weight, " +
                         core::kSmootherCostRange.describe() + " (default 0.1)");
  auto* smoother_iterations_flag =
      app.add_option("--smoother-iterations", smoother_iterations,
                     "relax: iterations at most, an integer in 1..10000 (default 10)");
  if (const auto exit_code = node::parse_command_line(app, argc, argv)) return *exit_code;
  if (list_planners) {
    print_planners();
    return 0;
  }

  // The config's sections are the defaults of every flag below.
  std::optional<node::NodeConfig> config;
  if (config_path.empty() && !paper) {
    const core::Expected<std::string> found = node::find_default_config();
    if (!found) {
      std::fprintf(stderr, "%s: give --config FILE, or --paper for the paper's setting\n",
                   found.error().message.c_str());
      return kBadInput;
    }
    config_path = *found;
  }
  if (!config_path.empty()) {
    node::ConfigResult loaded = node::load_config(config_path);
    if (!loaded.config) {
      std::fprintf(stderr, "--config %s: %zu error(s)\n", config_path.c_str(),
                   loaded.errors.size());
      for (const std::string& error : loaded.errors) std::fprintf(stderr, "%s\n", error.c_str());
      return kBadInput;
    }
    config = std::move(loaded.config);
  }

  // auto (--planner auto, or the config's planner.name: auto): chosen below from the options.
  const bool auto_kind = planner_flag->count() > 0 ? planner_name == core::kAutoPlannerName
                                                   : config && config->planner.auto_kind;
  std::optional<core::PlannerKind> kind = auto_kind ? std::optional(core::kCostAwareChoice)
                                          : config && planner_flag->count() == 0
                                              ? std::optional(config->planner.kind)
                                              : core::planner_kind_from_string(planner_name);
  if (!kind) {
    std::fprintf(stderr, "--planner: unknown planner '%s' (known: %s)\n", planner_name.c_str(),
                 core::accepted_planner_names().c_str());
    return kBadInput;
  }
  core::PlannerSettings settings = config ? config->planner.settings : core::PlannerSettings{};
  if (*neighborhood_flag) settings.neighborhood = core::neighborhood_from_string(neighborhood);
  if (*corner_policy_flag) settings.corner_policy = core::corner_policy_from_string(corner_policy);
  if (*prune_flag) settings.prune = prune;
  if (*smooth_flag) settings.smooth = smooth;
  if (*omega_flag) settings.omega = omega;
  if (*eta_flag) settings.eta = eta;
  if (*cost_weight_flag) settings.cost_weight = cost_weight;
  if (*goal_tolerance_flag) settings.goal_tolerance = goal_tolerance;
  if (*start_tolerance_flag) settings.start_tolerance = start_tolerance;
  if (*smoother_flag) settings.smoother = core::path_smoother_from_string(smoother);
  if (*smoother_smoothness_flag) settings.smoother_smoothness = smoother_smoothness;
  if (*smoother_closeness_flag) settings.smoother_closeness = smoother_closeness;
  if (*smoother_cost_flag) settings.smoother_cost = smoother_cost;
  if (*smoother_iterations_flag) settings.smoother_iterations = smoother_iterations;
  if (auto_kind) {
    // As the node's planner.name: auto does.
    settings = core::with_auto_defaults(settings);
    kind = core::make_auto_options(settings).planner;
  }
  const bool scen_mode = scen_flag->count() > 0;
  settings.record_expansions = out.any_picture();
  // The scenario files give the optimum; a second A* per line would double the run.
  settings.compute_length_ratio = !scen_mode;
  core::GridBuildOptions build =
      config ? node::planning_grid_options(*config) : core::GridBuildOptions{};
  if (*occupied_threshold_flag) build.occupied_threshold = cli.occupied_threshold;
  if (*allow_unknown_flag) build.allow_unknown = cli.allow_unknown;
  if (*inflate_unknown_flag) build.inflate_unknown = cli.inflate_unknown;
  if (*robot_radius_flag) build.robot_radius = cli.robot_radius;
  if (*inflation_radius_flag) build.inflation_radius = cli.inflation_radius;
  if (*cost_scaling_flag) build.cost_scaling_factor = cli.cost_scaling_factor;
  if (config) {
    if (!*z_min_flag) slice.z_min = config->slicer.z_min;
    if (!*z_max_flag) slice.z_max = config->slicer.z_max;
    if (!*resolution_flag) slice.resolution = config->slicer.resolution;
    slice.remove_speckles = config->slicer.remove_speckles;
    out.frame_id = config->frame_id;
    out.path_spacing = config->planner.path_spacing;
  }
  // A slicing error names the flag given, else the config key the value came from.
  const std::string slice_config = config ? config_path : "";
  slice.names.z_min =
      node::value_source(z_min_flag->count() > 0, "--z-min", "slicer.z_min", slice_config);
  slice.names.z_max =
      node::value_source(z_max_flag->count() > 0, "--z-max", "slicer.z_max", slice_config);
  slice.names.resolution = node::value_source(resolution_flag->count() > 0, "--resolution",
                                              "slicer.resolution", slice_config);
  if (*path_spacing_flag) out.path_spacing = path_spacing;
  if (*goal_yaw_flag) out.goal_yaw = goal_yaw;

  // Every new option named with its unit when its value is refused (before any map is read).
  const bool values_ok =
      check_range(cost_weight_flag, "--cost-weight", cost_weight, core::kCostWeightRange) &&
      check_range(goal_tolerance_flag, "--goal-tolerance", goal_tolerance, core::kToleranceRange) &&
      check_range(start_tolerance_flag, "--start-tolerance", start_tolerance,
                  core::kToleranceRange) &&
      check_range(smoother_smoothness_flag, "--smoother-smoothness", smoother_smoothness,
                  core::kSmootherSmoothnessRange) &&
      check_range(smoother_closeness_flag, "--smoother-closeness", smoother_closeness,
                  core::kSmootherClosenessRange) &&
      check_range(smoother_cost_flag, "--smoother-cost", smoother_cost, core::kSmootherCostRange) &&
      check_range(smoother_iterations_flag, "--smoother-iterations", smoother_iterations,
                  core::kSmootherIterationsRange) &&
      (robot_radius_flag->count() == 0 ||
       (std::isfinite(build.robot_radius) && build.robot_radius >= 0.0) ||
       refuse("--robot-radius", "a finite number of metres >= 0", build.robot_radius)) &&
      (inflation_radius_flag->count() == 0 ||
       (std::isfinite(build.inflation_radius) && build.inflation_radius >= 0.0) ||
       refuse("--inflation-radius", "a finite number of metres >= 0", build.inflation_radius)) &&
      ((inflation_radius_flag->count() == 0 && robot_radius_flag->count() == 0) ||
       build.inflation_radius == 0.0 || build.inflation_radius >= build.robot_radius ||
       refuse("--inflation-radius",
              "0 (no cost gradient) or at least --robot-radius (" +
                  maps::short_number(build.robot_radius) + " metres)",
              build.inflation_radius)) &&
      (cost_scaling_flag->count() == 0 ||
       (std::isfinite(build.cost_scaling_factor) && build.cost_scaling_factor >= 0.0) ||
       refuse("--cost-scaling-factor", "a finite number per metre >= 0",
              build.cost_scaling_factor)) &&
      (path_spacing_flag->count() == 0 || (std::isfinite(path_spacing) && path_spacing > 0.0) ||
       refuse("--path-spacing", "a finite number of metres > 0", path_spacing)) &&
      (goal_yaw_flag->count() == 0 || std::isfinite(goal_yaw) ||
       refuse("--goal-yaw", "a finite number of radians", goal_yaw));
  if (!values_ok) return kBadInput;
  for (const CLI::Option* option : {path_spacing_flag, goal_yaw_flag})
    if (option->count() > 0 && out.poses.empty()) {
      std::fprintf(stderr, "%s: only with --poses FILE\n", option->get_name().c_str());
      return kBadInput;
    }
  core::PlannerOptions options = core::make_options(*kind, settings);
  // A cost weight the config gives every planner, on one that plans on uniform costs (jps):
  // dropped with a warning, as the node does; given as a flag it is refused below.
  if (config && cost_weight_flag->count() == 0) {
    const double configured = options.cost_weight;
    if (core::drop_unsupported_costs(options))
      std::fprintf(stderr,
                   "warning: %s plans on uniform cell costs: the config's planner.cost_weight %g "
                   "not applied\n",
                   std::string(core::to_string(*kind)).c_str(), configured);
  }
  if (const core::Status valid = core::validate(options); !valid.is_ok()) {
    std::fprintf(stderr, "%s\n", valid.message.c_str());  // names the option at fault
    return kBadInput;
  }
  out.options = render::path_options(options, &build);
  out.record_options = records::options_record(options);

  // What the run plans: start and goal from the command line, or the lines of a .scen file.
  std::vector<maps::MovingAiScenario> scenarios;
  if (scen_mode) {
    for (const CLI::Option* option : {start_flag, goal_flag, cells_flag, repeat_flag})
      if (option->count() > 0) {
        std::fprintf(stderr, "%s: not with --scen (its lines give start and goal)\n",
                     option->get_name().c_str());
        return kBadInput;
      }
    auto loaded = maps::load_movingai_scenarios(scen_path);
    if (!loaded) {
      std::fprintf(stderr, "--scen: %s\n", loaded.error().message.c_str());
      return kBadInput;
    }
    scenarios = std::move(loaded).value();
    if (scenarios.empty()) {
      std::fprintf(stderr, "--scen: %s holds no scenario lines\n", scen_path.c_str());
      return kBadInput;
    }
    if (scen_index_flag->count() > 0) {
      if (scen_index < 0 || static_cast<size_t>(scen_index) >= scenarios.size()) {
        std::fprintf(stderr, "--scen-index %d: %s has %zu scenarios (0..%zu)\n", scen_index,
                     scen_path.c_str(), scenarios.size(), scenarios.size() - 1);
        return kBadInput;
      }
      scenarios = {scenarios[static_cast<size_t>(scen_index)]};
    } else {
      for (const std::string* path : {&out.svg, &out.png, &out.json, &out.poses})
        if (!path->empty()) {
          const char* name = path == &out.svg    ? "--svg"
                             : path == &out.png  ? "--png"
                             : path == &out.json ? "--json"
                                                 : "--poses";
          std::fprintf(stderr, "%s: with --scen only for one line (--scen-index N)\n", name);
          return kBadInput;
        }
    }
    // Without MAP: the map the (first run) line names, in the .scen file's folder.
    if (map_path.empty())
      map_path =
          (std::filesystem::path(scen_path).parent_path() / scenarios.front().map_name).string();
  } else {
    if (scen_index_flag->count() > 0) {
      std::fprintf(stderr, "--scen-index: only with --scen FILE\n");
      return kBadInput;
    }
    if (map_path.empty()) {
      std::fprintf(stderr, "map: a map file is required (or --scen FILE, whose lines name it)\n");
      return kBadInput;
    }
    for (const CLI::Option* option : {start_flag, goal_flag})
      if (option->count() == 0) {
        std::fprintf(stderr, "%s X Y is required (or --scen FILE)\n", option->get_name().c_str());
        return kBadInput;
      }
  }

  const bool octomap = maps::map_file_kind(map_path) == maps::MapFileKind::kOctoMap;
  for (const CLI::Option* option : octomap_options)
    if (option->count() > 0 && !octomap) {
      std::fprintf(stderr, "%s: only for OctoMap files (.bt, .ot), not %s\n",
                   option->get_name().c_str(), map_path.c_str());
      return kBadInput;
    }
  if (!bounds.empty()) slice.bounds = maps::SliceBounds{bounds[0], bounds[1], bounds[2], bounds[3]};
  auto grid = maps::load_map_file(map_path, slice);
  if (!grid) {
    std::fprintf(stderr, "%s\n", grid.error().message.c_str());
    return kBadInput;
  }
  auto built = core::GridMap::build(*grid, build);
  if (!built) {
    std::fprintf(stderr, "%s: %s\n", map_path.c_str(), built.error().message.c_str());
    return kBadInput;
  }
  auto map = std::make_shared<const core::GridMap>(std::move(built).value());
  core::Planner planner(map);

  if (scen_mode) {
    for (const maps::MovingAiScenario& s : scenarios)
      if (s.map_width != map->width() || s.map_height != map->height()) {
        std::fprintf(stderr,
                     "--scen: %s line %d is for a %d x %d map (%s), not %s (%d x %d cells)\n",
                     scen_path.c_str(), s.line, s.map_width, s.map_height, s.map_name.c_str(),
                     map_path.c_str(), map->width(), map->height());
        return kBadInput;
      }
    const bool exact = exact_on_movingai_graph(options);
    render::Progress progress("vnsba_plan --scen", static_cast<int64_t>(scenarios.size()),
                              render::progress_wanted(progress_flag));
    size_t ok = 0, with_optimum = 0, matched = 0;
    double ratio_sum = 0.0, ratio_max = 0.0;
    core::PlanQuery last_query;
    core::PlanResult last;
    for (size_t i = 0; i < scenarios.size(); ++i) {
      const maps::MovingAiScenario& s = scenarios[i];
      last_query = core::PlanQuery{s.start, s.goal};
      last = planner.plan(last_query, options);
      const core::Metrics& m = last.metrics;
      // The cells as the file writes them (rows from the top), to find the line again.
      std::printf(
          "line=%d bucket=%d scen_start=%d,%d scen_goal=%d,%d %s %s length_m=%.3f "
          "cost_cells=%.8f optimal=%.8f expanded=%lld time_us=%lld",
          s.line, s.bucket, s.start.x, map->height() - 1 - s.start.y, s.goal.x,
          map->height() - 1 - s.goal.y, std::string(core::to_string(last.planner)).c_str(),
          std::string(core::to_string(last.status.code)).c_str(), m.length_m, m.raw_cost_cells,
          s.optimal_length, static_cast<long long>(m.expanded),
          static_cast<long long>(m.planning_time_us));
      if (last.status.is_ok()) {
        ++ok;
        if (s.optimal_length > 0.0) {
          ++with_optimum;
          if (exact) {
            // Relative 1e-6, or the precision the file prints (as vnsba_bench optimality).
            const bool match = std::abs(m.raw_cost_cells - s.optimal_length) <=
                               std::max(1e-6 * s.optimal_length, s.optimal_resolution);
            matched += match ? 1 : 0;
            std::printf(" optimum=%s", match ? "matched" : "missed");
          } else {
            const double ratio = m.length_cells / s.optimal_length;
            ratio_sum += ratio;
            ratio_max = std::max(ratio_max, ratio);
            std::printf(" length_ratio=%.4f", ratio);
          }
        }
      } else if (scenarios.size() == 1) {
        std::fprintf(stderr, "%s\n", last.status.message.c_str());
      }
      std::printf("\n");
      progress.update(static_cast<int64_t>(i + 1));
    }
    progress.finish(static_cast<int64_t>(scenarios.size()));
    std::printf("summary scenarios=%zu ok=%zu with_optimum=%zu", scenarios.size(), ok,
                with_optimum);
    if (exact)
      std::printf(" matched_optimum=%zu\n", matched);
    else if (with_optimum > 0)
      std::printf(" mean_length_ratio=%.4f max_length_ratio=%.4f\n",
                  ratio_sum / static_cast<double>(with_optimum), ratio_max);
    else
      std::printf("\n");
    std::fflush(stdout);
    // The files' optima are the bare grid's: a robot's config (costs, radius) plans another
    // problem, which is what the ratios above measure.
    if (!exact && with_optimum > 0 && !paper)
      std::fprintf(stderr,
                   "note: the optima are the bare grid's shortest paths; %s plans for the robot "
                   "of %s (give --paper, and --planner astar or jps, to match them exactly)\n",
                   std::string(core::to_string(options.planner)).c_str(), config_path.c_str());
    if (scenarios.size() == 1 && !write_outputs(out, map_path, *grid, build, map, last_query, last))
      return kBadInput;
    return ok == scenarios.size() && (!exact || matched == with_optimum) ? 0 : kPlanFailed;
  }

  // A start outside the map is refused here (start_tolerance only moves a start out of
  // inflation); a goal outside it goes to core when goal_tolerance may bring it in.
  const auto start_at = to_endpoint(*map, start, cells, false, "--start");
  const auto goal_at = to_endpoint(*map, goal, cells, options.goal_tolerance > 0.0, "--goal");
  for (const auto* c : {&start_at, &goal_at})
    if (!*c) {
      std::fprintf(stderr, "%s\n", c->error().message.c_str());
      return kBadInput;
    }

  const core::PlanQuery query{start_at->cell, goal_at->cell, start_at->point, goal_at->point};
  // --repeat: the same query on the same Planner; only the first plan pays for growing the
  // heaps (the per-cell arrays came with the Planner).
  std::vector<int64_t> times_us;
  core::PlanResult result;
  for (int r = 0; r < repeat; ++r) {
    result = planner.plan(query, options);
    times_us.push_back(result.metrics.planning_time_us);
  }
  // Core names the goal's cell; given in metres, the message gives the point and the map in
  // metres, as the node's does.
  if (result.status.code == core::StatusCode::kGoalOutsideMap && !cells)
    result.status.message =
        maps::goal_outside_message(*map, goal[0], goal[1], options.goal_tolerance);
  print_result_line(result, times_us, repeat_flag->count() > 0);
  std::fflush(stdout);
  if (!write_outputs(out, map_path, *grid, build, map, query, result)) return kBadInput;
  return result.status.is_ok() ? 0 : kPlanFailed;
}
