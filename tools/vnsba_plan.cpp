// vnsba_plan: plan offline on a map file and draw the run, for users without a DDS system.
//
//   vnsba_plan MAP --start X Y --goal X Y [--planner NAME] [--svg out.svg] [--cells]
//              [--z-min A --z-max B] [--resolution R] [--bounds XMIN,YMIN,XMAX,YMAX]
//                                                       (OctoMap files)
//              [--allow-unknown] [--robot-radius M] [--occupied-threshold T]
//              [--neighborhood 8|8-11-13] [--corner-policy never|touch|always]
//              [--prune|--no-prune] [--smooth|--no-smooth] [--omega W] [--eta W]
//
// MAP is a Moving AI `.map` (1 m cells, origin (0, 0), row 0 at the bottom), a map_server
// `.yaml` (with its `.pgm`), or an OctoMap `.bt`/`.ot` sliced at the height band given, over the
// tree's extent or the --bounds given (metres, as vnsba_slicer takes them).
// Start and goal are world coordinates in metres in the map's frame; with --cells they are cell
// indices (column, row counted from the bottom). Prints one line: planner, status, length in
// metres, turns, turn angle, expansions, time, and the length ratio to optimal A* (a second
// search, which the time does not include).
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
#include <string>
#include <vector>

#include "vnsba/core/map_io.hpp"
#include "vnsba/core/octomap_slice.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/render/run_picture.hpp"
#include "vnsba/render/svg.hpp"

namespace {

using namespace vnsba;

constexpr int kPlanFailed = 1;
constexpr int kBadInput = 2;

bool has_suffix(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Loads any supported map file as an occupancy grid; the error names the file.
core::Expected<core::OccupancyGrid> load_map(const std::string& path,
                                             const core::SliceOptions& slice) {
  if (has_suffix(path, ".map")) return core::load_movingai_map(path);
  if (has_suffix(path, ".yaml") || has_suffix(path, ".yml")) return core::load_map_server(path);
  if (has_suffix(path, ".pgm")) {
    // The map_server convention: the metadata lives in a YAML file beside the image.
    const std::string yaml = path.substr(0, path.size() - 4) + ".yaml";
    if (!std::filesystem::exists(yaml))
      return core::Status::error(
          core::StatusCode::kInvalidMap,
          path + ": a .pgm needs its map_server .yaml beside it (" + yaml + " is missing)");
    return core::load_map_server(yaml);
  }
  if (has_suffix(path, ".bt") || has_suffix(path, ".ot")) {
    auto tree = core::load_octree(path);
    if (!tree) return tree.error();
    auto grid = core::slice_octree(**tree, slice);
    if (!grid) return core::Status::error(grid.error().code, path + ": " + grid.error().message);
    return grid;
  }
  return core::Status::error(core::StatusCode::kInvalidMap,
                             path + ": unknown map format (expected .map, .yaml, .pgm, .bt, .ot)");
}

// A start or goal given on the command line -> cell; the error names the option.
core::Expected<core::Cell> to_cell(const core::GridMap& map, const std::vector<double>& xy,
                                   bool cells, const std::string& option) {
  if (!std::isfinite(xy[0]) || !std::isfinite(xy[1]))
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               option + " must be two finite numbers");
  if (cells) {
    if (xy[0] != std::floor(xy[0]) || xy[1] != std::floor(xy[1]))
      return core::Status::error(core::StatusCode::kInvalidRequest,
                                 option + " with --cells must be whole cell indices");
    if (std::abs(xy[0]) > 1e9 || std::abs(xy[1]) > 1e9 ||
        !map.in_bounds(static_cast<int32_t>(xy[0]), static_cast<int32_t>(xy[1])))
      return core::Status::error(core::StatusCode::kInvalidRequest,
                                 option + " is outside the map (" + std::to_string(map.width()) +
                                     " x " + std::to_string(map.height()) + " cells)");
    return core::Cell{static_cast<int32_t>(xy[0]), static_cast<int32_t>(xy[1])};
  }
  const auto cell = map.world_to_cell(xy[0], xy[1]);
  if (!cell) {
    char bounds[160];
    std::snprintf(bounds, sizeof bounds, "[%g, %g] x [%g, %g] m", map.origin_x(),
                  map.origin_x() + map.width() * map.resolution(), map.origin_y(),
                  map.origin_y() + map.height() * map.resolution());
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               option + " is outside the map " + bounds);
  }
  return *cell;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vnsba_plan: plan on a map file offline and draw the run as SVG"};
  std::string map_path;
  std::vector<double> start, goal;
  std::string planner_name = "vns_bastar";
  std::string svg_path;
  bool cells = false;
  core::SliceOptions slice;
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
  app.add_option("--robot-radius", build.robot_radius, "inflate obstacles by this, metres");
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
  settings.record_expansions = !svg_path.empty();
  settings.compute_length_ratio = true;
  const core::PlannerOptions options = core::make_options(*kind, settings);
  if (const core::Status valid = core::validate(options); !valid.is_ok()) {
    std::fprintf(stderr, "%s\n", valid.message.c_str());  // names the option at fault
    return kBadInput;
  }
  const bool octomap = has_suffix(map_path, ".bt") || has_suffix(map_path, ".ot");
  for (const CLI::Option* option : octomap_options)
    if (option->count() > 0 && !octomap) {
      std::fprintf(stderr, "%s: only for OctoMap files (.bt, .ot), not %s\n",
                   option->get_name().c_str(), map_path.c_str());
      return kBadInput;
    }
  if (!bounds.empty()) slice.bounds = core::SliceBounds{bounds[0], bounds[1], bounds[2], bounds[3]};
  auto grid = load_map(map_path, slice);
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
  const auto start_cell = to_cell(*map, start, cells, "--start");
  const auto goal_cell = to_cell(*map, goal, cells, "--goal");
  for (const auto* c : {&start_cell, &goal_cell})
    if (!*c) {
      std::fprintf(stderr, "%s\n", c->error().message.c_str());
      return kBadInput;
    }

  const core::PlanQuery query{*start_cell, *goal_cell};
  core::Planner planner(map);
  const core::PlanResult result = planner.plan(query, options);
  const core::Metrics& m = result.metrics;
  std::printf("%s %s length_m=%.3f turns=%d turn_angle_deg=%.1f expanded=%lld time_us=%lld",
              std::string(core::to_string(result.planner)).c_str(),
              std::string(core::to_string(result.status.code)).c_str(), m.length_m, m.turns,
              m.turn_angle_deg, static_cast<long long>(m.expanded),
              static_cast<long long>(m.planning_time_us));
  if (std::isfinite(m.length_ratio)) std::printf(" length_ratio=%.4f", m.length_ratio);
  std::printf("\n");
  if (!result.status.is_ok()) std::fprintf(stderr, "%s\n", result.status.message.c_str());

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
