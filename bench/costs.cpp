#include "bench/costs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench/common.hpp"
#include "bench/movingai.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/render/progress.hpp"

namespace vnsba::bench {

namespace {

// The two sides of every comparison.
enum Side { kBinary = 0, kCostAware = 1 };
constexpr const char* kSideName[] = {"binary", "cost-aware"};

// One plan's outcome, in the map's units (metres on the scene, cells on Moving AI maps).
struct Outcome {
  bool ok = false;
  double length = NAN;
  double clearance = NAN;
  int turns = 0;
  double expanded = 0.0;
  double time_us = NAN;
};

// The options of `kind` on one side. jps plans on uniform costs only: on the cost-aware side it
// runs with cost_weight 0 (as the node plans a request for jps), on the cost-aware map (radius,
// tolerances), and is named so in the tables.
core::PlannerOptions side_options(core::PlannerKind kind, const RobotSettings& robot) {
  core::PlannerOptions options = core::make_options(kind, planner_settings(robot));
  core::drop_unsupported_costs(options);
  return options;
}

std::string planner_label(core::PlannerKind kind) {
  std::string name(core::to_string(kind));
  if (!core::supports_costs(kind)) name += " (uniform costs)";
  return name;
}

Outcome outcome_of(const TimedPlan& timed, double unit_per_metre) {
  Outcome o;
  const core::Metrics& m = timed.result.metrics;
  o.ok = timed.result.status.is_ok();
  o.expanded = static_cast<double>(m.expanded);
  o.time_us = timed.time_us;
  if (o.ok) {
    o.length = m.length_m * unit_per_metre;
    o.clearance = m.clearance_m * unit_per_metre;
    o.turns = m.turns;
  }
  return o;
}

double min_of(const std::vector<double>& values) {
  double least = INFINITY;
  for (double v : values) least = std::min(least, v);
  return values.empty() ? NAN : least;
}

double max_of(const std::vector<double>& values) {
  double most = -INFINITY;
  for (double v : values) most = std::max(most, v);
  return values.empty() ? NAN : most;
}

double sum_of(const std::vector<double>& values) {
  double total = 0.0;
  for (double v : values) total += v;
  return total;
}

// --- The demo scene ---------------------------------------------------------------------------

struct SceneResult {
  bool ok = true;  // every route planned on both sides
  std::string text;
};

SceneResult run_scene(const CostsOptions& options, const std::vector<core::PlannerKind>& planners) {
  SceneResult out;
  auto tree = maps::load_octree(options.scene_path);
  if (!tree) {
    std::fprintf(stderr, "vnsba_bench costs: --scene: %s\n", tree.error().message.c_str());
    out.ok = false;
    return out;
  }
  maps::SliceOptions slice;
  slice.z_min = kDemoSliceZMin;
  slice.z_max = kDemoSliceZMax;
  auto grid = maps::slice_octree(**tree, slice);
  if (!grid) {
    std::fprintf(stderr, "vnsba_bench costs: --scene: %s\n", grid.error().message.c_str());
    out.ok = false;
    return out;
  }
  const RobotSettings sides[2] = {RobotSettings{}, options.robot};
  std::shared_ptr<const core::GridMap> maps[2];
  for (int side : {kBinary, kCostAware}) {
    auto built = core::GridMap::build(*grid, build_options(sides[side], true));
    if (!built) {
      std::fprintf(stderr, "vnsba_bench costs: the scene's %s map: %s\n", kSideName[side],
                   built.error().message.c_str());
      out.ok = false;
      return out;
    }
    maps[side] = std::make_shared<const core::GridMap>(std::move(built).value());
  }
  core::Planner planner_of[2] = {core::Planner(maps[kBinary]), core::Planner(maps[kCostAware])};

  MarkdownTable routes({"planner", "route", "length binary (m)", "length cost-aware (m)",
                        "length ratio", "clearance binary (m)", "clearance cost-aware (m)",
                        "turns binary", "turns cost-aware", "time binary (ms)",
                        "time cost-aware (ms)"});
  MarkdownTable summary({"planner", "min clearance binary (m)", "min clearance cost-aware (m)",
                         "min clearance ratio (target >= 2)", "worst length ratio (target <= 1.10)",
                         "targets", "time ratio (total)"});
  for (const core::PlannerKind kind : planners) {
    std::vector<double> clearance[2], time_us[2], length_ratio;
    for (const Route& route : kDemoRoutes) {
      Outcome o[2];
      for (int side : {kBinary, kCostAware}) {
        const core::GridMap& map = *maps[side];
        const auto start = map.world_to_cell(route.start_x, route.start_y);
        const auto goal = map.world_to_cell(route.goal_x, route.goal_y);
        if (!start || !goal) {
          std::fprintf(stderr, "vnsba_bench costs: route %s lies outside the scene\n", route.name);
          out.ok = false;
          return out;
        }
        const core::PlanQuery query(*start, *goal, map.world_to_grid(route.start_x, route.start_y),
                                    map.world_to_grid(route.goal_x, route.goal_y));
        const core::PlannerOptions plan_options = side_options(kind, sides[side]);
        o[side] = outcome_of(timed_plan(planner_of[side], query, plan_options), 1.0);
        o[side].time_us =
            median_plan_time_us(planner_of[side], query, plan_options, options.repetitions);
        if (!o[side].ok) {
          std::fprintf(stderr, "vnsba_bench costs: %s on route %s (%s) found no path\n",
                       core::to_string(kind).data(), route.name, kSideName[side]);
          out.ok = false;
        }
        clearance[side].push_back(o[side].clearance);
        time_us[side].push_back(o[side].time_us);
      }
      length_ratio.push_back(o[kCostAware].length / o[kBinary].length);
      routes.add_row({planner_label(kind), route.name, format(o[kBinary].length, 2),
                      format(o[kCostAware].length, 2), format(length_ratio.back(), 3),
                      format(o[kBinary].clearance, 3), format(o[kCostAware].clearance, 3),
                      std::to_string(o[kBinary].turns), std::to_string(o[kCostAware].turns),
                      format(o[kBinary].time_us / 1000.0, 2),
                      format(o[kCostAware].time_us / 1000.0, 2)});
    }
    const double least[2] = {min_of(clearance[kBinary]), min_of(clearance[kCostAware])};
    const double gain = least[kCostAware] / least[kBinary];
    const double worst_length = max_of(length_ratio);
    const bool met = gain >= 2.0 && worst_length <= 1.10;
    summary.add_row({planner_label(kind), format(least[kBinary], 3), format(least[kCostAware], 3),
                     format(gain, 1), format(worst_length, 3), met ? "met" : "**missed**",
                     format(sum_of(time_us[kCostAware]) / sum_of(time_us[kBinary]), 2)});
  }
  char head[512];
  std::snprintf(head, sizeof head,
                "**Demo scene** (%s, sliced at %.1f-%.1f m, %d x %d cells at %.2f m): the demo's "
                "three routes that end OK, every planner, binary (config/paper.yaml: no radius, no "
                "gradient, cost_weight 0) against cost-aware (config/default.yaml: robot_radius "
                "%.2f m, inflation_radius %.2f m, cost_scaling_factor %.1f, cost_weight %.1f, "
                "goal_tolerance %.2f m, start_tolerance %.2f m). Time: median of %d plans.\n\n",
                std::filesystem::path(options.scene_path).filename().string().c_str(),
                kDemoSliceZMin, kDemoSliceZMax, grid->width, grid->height, grid->resolution,
                options.robot.robot_radius, options.robot.inflation_radius,
                options.robot.cost_scaling_factor, options.robot.cost_weight,
                options.robot.goal_tolerance, options.robot.start_tolerance, options.repetitions);
  out.text = std::string(head) + summary.str() + "\n" + routes.str() + "\n";
  return out;
}

// --- Moving AI maps ---------------------------------------------------------------------------

struct ClassSample {
  std::vector<double> length_ratio;  // cost-aware / binary, per query both solved
  std::vector<double> clearance[2];  // cells
  std::vector<double> turns[2];
  std::vector<double> time_us[2];
  std::vector<double> expanded[2];
  int failures = 0;  // a query one side solved and the other did not
};

struct MovingAiResult {
  bool ok = true;
  bool ran = false;
  std::string text;
};

MovingAiResult run_maps(const CostsOptions& options,
                        const std::vector<core::PlannerKind>& planners) {
  MovingAiResult out;
  auto maps = list_scenario_maps(options.maps_dir);
  if (!maps) {
    std::fprintf(stderr, "vnsba_bench costs: skipping the Moving AI maps: %s\n",
                 maps.error().message.c_str());
    return out;
  }
  out.ran = true;
  const RobotSettings sides[2] = {RobotSettings{}, options.robot};
  // class -> planner -> sample
  std::map<std::string, std::map<core::PlannerKind, ClassSample>> samples;
  // Queries to come (each planned on both sides), for the progress line; a scenario file that
  // does not load counts 0 and fails below.
  int64_t queries_total = 0;
  for (const std::string& path : *maps)
    if (const auto scenarios = maps::load_movingai_scenarios(path + ".scen"))
      queries_total += static_cast<int64_t>(
          pick_scenarios(scenarios->size(), options.max_scenarios).size() * planners.size());
  render::Progress progress("vnsba_bench costs", queries_total,
                            render::progress_wanted(options.progress));
  int64_t queries_done = 0;
  for (const std::string& path : *maps) {
    auto loaded = load_map_with_scenarios(path);
    if (!loaded) {
      std::fprintf(stderr, "vnsba_bench costs: %s\n", loaded.error().message.c_str());
      out.ok = false;
      return out;
    }
    const std::string map_class =
        movingai_map_class(options.maps_dir, std::filesystem::path(path).filename().string());
    core::OccupancyGrid grid = loaded->grid;
    grid.resolution = kMovingAiResolution;
    std::vector<core::Planner> planner_of;
    for (int side : {kBinary, kCostAware}) {
      auto built = core::GridMap::build(grid, build_options(sides[side], false));
      if (!built) {
        std::fprintf(stderr, "vnsba_bench costs: %s (%s): %s\n", loaded->name.c_str(),
                     kSideName[side], built.error().message.c_str());
        out.ok = false;
        return out;
      }
      planner_of.emplace_back(std::make_shared<const core::GridMap>(std::move(built).value()));
    }
    const auto picked = pick_scenarios(loaded->scenarios.size(), options.max_scenarios);
    for (const core::PlannerKind kind : planners) {
      ClassSample& sample = samples[map_class][kind];
      core::PlannerOptions plan_options[2];
      for (int side : {kBinary, kCostAware}) {
        plan_options[side] = side_options(kind, sides[side]);
        if (!picked.empty()) {  // warm-up: the first plan touches the search state
          const auto& s = loaded->scenarios[picked.front()];
          planner_of[side].plan({s.start, s.goal}, plan_options[side]);
        }
      }
      // Interleaved by query, so that a slow moment of the machine hits both sides alike.
      for (const size_t index : picked) {
        const maps::MovingAiScenario& s = loaded->scenarios[index];
        Outcome o[2];
        for (int side : {kBinary, kCostAware}) {
          // Cells: metres / resolution.
          o[side] = outcome_of(timed_plan(planner_of[side], {s.start, s.goal}, plan_options[side]),
                               1.0 / kMovingAiResolution);
          sample.time_us[side].push_back(o[side].time_us);
          sample.expanded[side].push_back(o[side].expanded);
        }
        progress.update(++queries_done);
        if (o[kBinary].ok != o[kCostAware].ok) ++sample.failures;
        if (!o[kBinary].ok || !o[kCostAware].ok) continue;
        sample.length_ratio.push_back(o[kCostAware].length / o[kBinary].length);
        for (int side : {kBinary, kCostAware}) {
          if (std::isfinite(o[side].clearance)) sample.clearance[side].push_back(o[side].clearance);
          sample.turns[side].push_back(o[side].turns);
        }
      }
    }
    std::fprintf(stderr, "%s (%s): %zu scenarios x %zu planners x 2 sides\n", loaded->name.c_str(),
                 map_class.c_str(), picked.size(), planners.size());
  }
  progress.finish(queries_done);

  MarkdownTable table({"class", "planner", "length ratio mean (max)", "clearance binary (cells)",
                       "clearance cost-aware (cells)", "turns binary", "turns cost-aware",
                       "time median binary (us)", "time median cost-aware (us)",
                       "time ratio (total)", "expanded ratio (total)"});
  std::vector<double> astar_time[2], astar_expanded[2];
  bool disagreements = false;
  for (const auto& [map_class, by_planner] : samples) {
    for (const core::PlannerKind kind : planners) {
      const ClassSample& s = by_planner.at(kind);
      if (s.failures > 0) disagreements = true;
      table.add_row(
          {map_class, planner_label(kind),
           format(mean(s.length_ratio), 3) + " (" + format(max_of(s.length_ratio), 3) + ")",
           format(mean(s.clearance[kBinary]), 2), format(mean(s.clearance[kCostAware]), 2),
           format(mean(s.turns[kBinary]), 1), format(mean(s.turns[kCostAware]), 1),
           format(median(s.time_us[kBinary]), 1), format(median(s.time_us[kCostAware]), 1),
           format(sum_of(s.time_us[kCostAware]) / sum_of(s.time_us[kBinary]), 2),
           format(sum_of(s.expanded[kCostAware]) / sum_of(s.expanded[kBinary]), 2)});
      if (kind == core::PlannerKind::kAStar) {
        for (int side : {kBinary, kCostAware}) {
          astar_time[side].insert(astar_time[side].end(), s.time_us[side].begin(),
                                  s.time_us[side].end());
          astar_expanded[side].insert(astar_expanded[side].end(), s.expanded[side].begin(),
                                      s.expanded[side].end());
        }
      }
    }
  }
  if (disagreements) {
    std::fprintf(stderr,
                 "vnsba_bench costs: a query was solved on one side and not the other (the "
                 "gradient blocks nothing, so this is a planner's failure)\n");
    out.ok = false;
  }
  char head[768];
  std::snprintf(
      head, sizeof head,
      "**Moving AI maps** (%zu maps, at most %d scenarios each, read at %.2f m a cell): binary "
      "against cost-aware with config/default.yaml's gradient and weight (inflation_radius %.2f "
      "m = %.0f cells, cost_scaling_factor %.1f, cost_weight %.1f) but no robot radius, which "
      "would block some scenarios' endpoints. Length ratio: cost-aware / binary final length per "
      "query; clearance in cells (maps without obstacles left out); time and expansion ratios: "
      "cost-aware total / binary total over the same queries.\n\n",
      maps->size(), options.max_scenarios, kMovingAiResolution, options.robot.inflation_radius,
      options.robot.inflation_radius / kMovingAiResolution, options.robot.cost_scaling_factor,
      options.robot.cost_weight);
  std::string text = head + table.str() + "\n";
  if (!astar_time[kBinary].empty()) {
    const double total_ratio = sum_of(astar_time[kCostAware]) / sum_of(astar_time[kBinary]);
    const double median_ratio = median(astar_time[kCostAware]) / median(astar_time[kBinary]);
    const double expanded_ratio =
        sum_of(astar_expanded[kCostAware]) / sum_of(astar_expanded[kBinary]);
    // Time per expanded node: what "only the move cost changes" costs, apart from the larger
    // search that a heuristic blind to costs (octile distance) leaves A* to do.
    const double per_expansion_ratio = total_ratio / expanded_ratio;
    char line[1024];
    std::snprintf(line, sizeof line,
                  "Cost-aware A* / binary A* time over all %zu queries: %.2f in total, %.2f "
                  "between medians (target at most 1.3: %s). It expands %.2f times the nodes "
                  "(the octile heuristic cannot see costs, so every node whose detour costs less "
                  "than the optimal path's cost penalty is expanded); per expanded node it takes "
                  "%.2f times binary A*'s time.\n\n",
                  astar_time[kBinary].size(), total_ratio, median_ratio,
                  total_ratio <= 1.3 ? "met" : "**missed**", expanded_ratio, per_expansion_ratio);
    text += line;
  }
  out.text = text;
  return out;
}

}  // namespace

core::GridBuildOptions build_options(const RobotSettings& robot, bool with_radius) {
  core::GridBuildOptions build;
  build.robot_radius = with_radius ? robot.robot_radius : 0.0;
  build.inflation_radius = robot.inflation_radius;
  build.cost_scaling_factor = robot.cost_scaling_factor;
  return build;
}

core::PlannerSettings planner_settings(const RobotSettings& robot) {
  core::PlannerSettings settings;
  settings.cost_weight = robot.cost_weight;
  settings.goal_tolerance = robot.goal_tolerance;
  settings.start_tolerance = robot.start_tolerance;
  return settings;
}

int run_costs(const CostsOptions& options) {
  if (options.max_scenarios < 0) {
    std::fprintf(stderr, "vnsba_bench costs: --max-scenarios must be >= 0, got %d\n",
                 options.max_scenarios);
    return kExitBadInput;
  }
  if (options.repetitions < 1) {
    std::fprintf(stderr, "vnsba_bench costs: --repetitions must be >= 1, got %d\n",
                 options.repetitions);
    return kExitBadInput;
  }
  const std::vector<core::PlannerKind> planners =
      options.planners.empty() ? core::all_planner_kinds() : options.planners;
  const SceneResult scene = run_scene(options, planners);
  if (scene.text.empty()) return kExitBadInput;  // the scene could not be loaded
  const MovingAiResult maps = run_maps(options, planners);
  std::printf("%s", scene.text.c_str());
  if (maps.ran) std::printf("%s", maps.text.c_str());
  return scene.ok && maps.ok ? kExitOk : kExitFailure;
}

}  // namespace vnsba::bench
