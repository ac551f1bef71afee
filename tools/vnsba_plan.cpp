// vnsba_plan: plan offline on a map file and draw the run, for users without a DDS system.
//
//   vnsba_plan MAP --start X Y --goal X Y [--planner NAME] [--svg out.svg] [--cells]
//              [--z-min A --z-max B] [--resolution R] [--bounds XMIN,YMIN,XMAX,YMAX]
//                                                       (OctoMap files)
//              [--allow-unknown] [--robot-radius M] [--occupied-threshold T]
//              [--neighborhood 8|8-11-13] [--corner-policy never|touch|always]
//              [--prune|--no-prune] [--smooth|--no-smooth] [--omega W] [--eta W]
//              [--inflation-radius M] [--cost-scaling-factor PER_M] [--cost-weight W]
//              [--goal-tolerance M] [--start-tolerance M]
//              [--poses FILE [--path-spacing M] [--goal-yaw RAD]]
//
// MAP is a Moving AI `.map` (1 m cells, origin (0, 0), row 0 at the bottom), a map_server
// `.yaml` (with its `.pgm`), or an OctoMap `.bt`/`.ot` sliced at the height band given, over the
// tree's extent or the --bounds given (metres, as vnsba_slicer takes them).
// Start and goal are world coordinates in metres in the map's frame; with --cells they are cell
// indices (column, row counted from the bottom). The requested points are what start_tolerance
// and goal_tolerance measure from (ALGORITHM.md section 8); a goal outside the map is planned
// only with --goal-tolerance, to the nearest free cell within it. Prints one line: planner,
// status, length in metres, clearance in metres (`inf` on a map without obstacles, `nan` without
// a path), turns, turn angle, expansions, time, the length ratio to optimal A* (a second search,
// which the time does not include), and start_moved_m / goal_moved_m when a tolerance moved the
// start or the goal.
//
// --inflation-radius and --cost-scaling-factor add the cost gradient to the map as it is built
// (GridBuildOptions), --cost-weight plans with it. --poses FILE writes the poses the node would
// publish for the path (core::path_poses: at most --path-spacing metres apart, default the map's
// resolution; the last with --goal-yaw when given), one `x y yaw` per line in metres and
// radians; an empty file when no path was found.
//
// The planner options are core::make_options(--planner, the option flags given): a flag left out
// follows the chosen planner's paper configuration, exactly as a config key left out does in
// vnsba_node.
//
// Exit codes: 0 a path was found, 1 the planner answered another status (printed), 2 bad
// arguments or map file.
#include <CLI/CLI.hpp>
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
#include "vnsba/maps/map_file.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/render/run_picture.hpp"
#include "vnsba/render/svg.hpp"
#include "vnsba/render/text_format.hpp"

namespace {

using namespace vnsba;

constexpr int kPlanFailed = 1;
constexpr int kBadInput = 2;
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
    char bounds[160];
    std::snprintf(bounds, sizeof bounds, "[%g, %g] x [%g, %g] m", map.origin_x(),
                  map.origin_x() + map.width() * map.resolution(), map.origin_y(),
                  map.origin_y() + map.height() * map.resolution());
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               option + " is outside the map " + bounds +
                                   (option == "--goal" && !outside_ok
                                        ? " (with --goal-tolerance, the plan goes to the nearest "
                                          "free cell within it)"
                                        : ""));
  }
  return Endpoint{core::Cell{static_cast<int32_t>(std::floor(point.x())),
                             static_cast<int32_t>(std::floor(point.y()))},
                  point};
}

std::string metres(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vnsba_plan: plan on a map file offline and draw the run as SVG"};
  std::string map_path;
  std::vector<double> start, goal;
  std::string planner_name = "vns_bastar";
  std::string svg_path;
  bool cells = false;
  maps::SliceOptions slice;
  slice.names = {"--z-min", "--z-max", "--resolution", "--bounds", "vnsba_plan's limit"};
  std::vector<double> bounds;
  core::GridBuildOptions build;
  app.add_option("map", map_path, "map file: .map, .yaml/.pgm (map_server), .bt/.ot (OctoMap)")
      ->required();
  app.add_option("--start", start, "start X Y (metres; cell indices with --cells)")
      ->expected(2)
      ->required();
  app.add_option("--goal", goal, "goal X Y (metres; cell indices with --cells)")
      ->expected(2)
      ->required();
  app.add_option("--planner", planner_name,
                 "vns_bastar, astar, weighted_astar, bidirectional_astar, "
                 "alternating_bidirectional_astar, jps");
  app.add_option("--svg", svg_path, "write a picture of the run here");
  app.add_flag("--cells", cells, "start and goal are cell indices (column, row from the bottom)");
  const std::vector<CLI::Option*> octomap_options = {
      app.add_option("--z-min", slice.z_min, "OctoMap: bottom of the height band, metres"),
      app.add_option("--z-max", slice.z_max, "OctoMap: top of the height band, metres"),
      app.add_option("--resolution", slice.resolution,
                     "OctoMap: metres per cell, a whole multiple of the leaf size (0 = leaf size)"),
      app.add_option("--bounds", bounds,
                     "OctoMap: the area to slice, x_min,y_min,x_max,y_max in metres (default: "
                     "the tree's extent)")
          ->expected(4)
          ->delimiter(',')};
  app.add_option("--occupied-threshold", build.occupied_threshold,
                 "occupancy percent at or above which a cell is blocked (1..100)");
  app.add_flag("--allow-unknown", build.allow_unknown, "plan through unknown cells");
  auto* robot_radius_flag =
      app.add_option("--robot-radius", build.robot_radius, "inflate obstacles by this, metres");
  auto* inflation_radius_flag = app.add_option(
      "--inflation-radius", build.inflation_radius,
      "cost gradient around obstacles out to this, metres: 0 (none, the default) or >= "
      "--robot-radius");
  auto* cost_scaling_flag = app.add_option(
      "--cost-scaling-factor", build.cost_scaling_factor,
      "decay of the cost gradient, per metre, >= 0 (default 3): cost 0.99 * exp(-factor * (d - "
      "robot radius))");
  // Costs, tolerances and poses (ALGORITHM.md section 8).
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
  std::string poses_path;
  double path_spacing = 0.0, goal_yaw = 0.0;
  app.add_option("--poses", poses_path,
                 "write the path's poses here, one `x y yaw` per line (metres, radians)");
  auto* path_spacing_flag = app.add_option(
      "--path-spacing", path_spacing,
      "--poses: poses at most this far apart, metres > 0 (default: the map's resolution)");
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kBadInput;
  }

  const auto kind = core::planner_kind_from_string(planner_name);
  if (!kind) {
    std::fprintf(stderr, "--planner: unknown planner '%s'\n", planner_name.c_str());
    return kBadInput;
  }
  core::PlannerSettings settings;
  if (*neighborhood_flag) settings.neighborhood = core::neighborhood_from_string(neighborhood);
  if (*corner_policy_flag) settings.corner_policy = core::corner_policy_from_string(corner_policy);
  if (*prune_flag) settings.prune = prune;
  if (*smooth_flag) settings.smooth = smooth;
  if (*omega_flag) settings.omega = omega;
  if (*eta_flag) settings.eta = eta;
  if (*cost_weight_flag) settings.cost_weight = cost_weight;
  if (*goal_tolerance_flag) settings.goal_tolerance = goal_tolerance;
  if (*start_tolerance_flag) settings.start_tolerance = start_tolerance;
  settings.record_expansions = !svg_path.empty();
  settings.compute_length_ratio = true;
  // Every new option named with its unit when its value is refused (before any map is read).
  const bool values_ok =
      check_range(cost_weight_flag, "--cost-weight", cost_weight, core::kCostWeightRange) &&
      check_range(goal_tolerance_flag, "--goal-tolerance", goal_tolerance, core::kToleranceRange) &&
      check_range(start_tolerance_flag, "--start-tolerance", start_tolerance,
                  core::kToleranceRange) &&
      (robot_radius_flag->count() == 0 ||
       (std::isfinite(build.robot_radius) && build.robot_radius >= 0.0) ||
       refuse("--robot-radius", "a finite number of metres >= 0", build.robot_radius)) &&
      (inflation_radius_flag->count() == 0 ||
       (std::isfinite(build.inflation_radius) && build.inflation_radius >= 0.0) ||
       refuse("--inflation-radius", "a finite number of metres >= 0", build.inflation_radius)) &&
      (inflation_radius_flag->count() == 0 || build.inflation_radius == 0.0 ||
       build.inflation_radius >= build.robot_radius ||
       refuse("--inflation-radius",
              "0 (no cost gradient) or at least --robot-radius (" + metres(build.robot_radius) +
                  " metres)",
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
    if (option->count() > 0 && poses_path.empty()) {
      std::fprintf(stderr, "%s: only with --poses FILE\n", option->get_name().c_str());
      return kBadInput;
    }
  const core::PlannerOptions options = core::make_options(*kind, settings);
  if (const core::Status valid = core::validate(options); !valid.is_ok()) {
    std::fprintf(stderr, "%s\n", valid.message.c_str());  // names the option at fault
    return kBadInput;
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
  core::Planner planner(map);
  const core::PlanResult result = planner.plan(query, options);
  const core::Metrics& m = result.metrics;
  std::printf(
      "%s %s length_m=%.3f clearance_m=%s turns=%d turn_angle_deg=%.1f expanded=%lld "
      "time_us=%lld",
      std::string(core::to_string(result.planner)).c_str(),
      std::string(core::to_string(result.status.code)).c_str(), m.length_m,
      render::format_metres(m.clearance_m).c_str(), m.turns, m.turn_angle_deg,
      static_cast<long long>(m.expanded), static_cast<long long>(m.planning_time_us));
  if (std::isfinite(m.length_ratio)) std::printf(" length_ratio=%.4f", m.length_ratio);
  if (result.endpoints.start_adjusted)
    std::printf(" start_moved_m=%.3f", result.endpoints.start_moved_m);
  if (result.endpoints.goal_adjusted)
    std::printf(" goal_moved_m=%.3f", result.endpoints.goal_moved_m);
  std::printf("\n");
  if (!result.status.is_ok()) std::fprintf(stderr, "%s\n", result.status.message.c_str());

  if (!poses_path.empty()) {
    const double spacing = path_spacing_flag->count() > 0 ? path_spacing : map->resolution();
    if (const core::Status valid = core::validate_path_spacing(result.world_path, spacing);
        !valid.is_ok()) {
      std::fprintf(stderr, "--path-spacing: %s\n", valid.message.c_str());
      return kBadInput;
    }
    double pose_count = 1.0;
    for (size_t i = 1; i < result.world_path.size(); ++i)
      pose_count += std::ceil((result.world_path[i] - result.world_path[i - 1]).norm() / spacing);
    if (pose_count > kMaxPoses) {
      std::fprintf(stderr,
                   "--path-spacing %g metres gives about %.0f poses for this %.3f m path, more "
                   "than the %.0f --poses writes\n",
                   spacing, pose_count, m.length_m, kMaxPoses);
      return kBadInput;
    }
    const std::optional<double> yaw =
        goal_yaw_flag->count() > 0 ? std::optional<double>(goal_yaw) : std::nullopt;
    const core::Status written =
        write_poses(poses_path, core::path_poses(result.world_path, spacing, yaw));
    if (!written.is_ok()) {
      std::fprintf(stderr, "%s\n", written.message.c_str());
      return kBadInput;
    }
    std::fprintf(stderr, "wrote %s\n", poses_path.c_str());
  }

  if (!svg_path.empty()) {
    auto picture = std::make_shared<const render::MapPicture>(
        render::map_picture(*grid, build.occupied_threshold, map.get()));
    render::RunPicture run = render::picture_of(picture, query, result);
    run.title = std::filesystem::path(map_path).filename().string();
    const core::Status written = render::write_text_file(svg_path, render::render_svg(run));
    if (!written.is_ok()) {
      std::fprintf(stderr, "--svg: %s\n", written.message.c_str());
      return kBadInput;
    }
    std::fprintf(stderr, "wrote %s\n", svg_path.c_str());
  }
  return result.status.is_ok() ? 0 : kPlanFailed;
}
