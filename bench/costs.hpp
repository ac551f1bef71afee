// `vnsba_bench costs`: binary planning (the paper, config/paper.yaml) against cost-aware planning
// (config/default.yaml's robot settings, docs/algorithm.md section 8) against cost-aware planning
// with the relax smoother (planner.smoother: relax, its weights at their defaults) for each
// planner, on the demo scene's routes, on seeded random queries of held-in OctoMap slices and on
// the Moving AI maps: length, turns, total turn angle, max curvature, clearance and time per side,
// and the targets (issue 34 item 3): against binary, cost-aware + relax keeps the total
// turn angle at most 1.3x, the clearance at least 1.5x and the length at most 1.15x on the demo's
// routes and the slices; the smoother adds at most 20 % to a plan's time (median over queries of
// the time with relax / the time without it). First, the same targets for the default configuration
// itself
// (`planner.name: auto` with the robot's costs against auto without them), then the table for
// choosing the cost-aware planner auto runs: every cost-aware planner with auto's settings, its
// time per query over astar's, and its path length and turn angle over astar's.
//
// The robot and the slice band are config/default.yaml's, read from the node's config library
// (it needs no DDS, so the core-only build that bench/make_results.sh makes has it too): the
// benchmark runs the defaults the node runs, with no copy of their values.
#pragma once

#include <string>
#include <vector>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/planner_options.hpp"

namespace vnsba::bench {

// The robot settings of config/default.yaml (metres, per metre, a plain weight).
struct RobotSettings {
  double robot_radius = 0.0;         // map.robot_radius, metres
  double inflation_radius = 0.0;     // map.inflation_radius, metres
  double cost_scaling_factor = 3.0;  // map.cost_scaling_factor, per metre
  double cost_weight = 0.0;          // planner.cost_weight
  double goal_tolerance = 0.0;       // planner.goal_tolerance, metres
  double start_tolerance = 0.0;      // planner.start_tolerance, metres
};
const RobotSettings& default_yaml_robot();

// The demo scene's slice (tools/demo.sh: the config's height band, the tree's leaf size):
// default.yaml's slicer.z_min and z_max, metres.
struct SliceBand {
  double z_min = 0.0;
  double z_max = 0.0;
};
const SliceBand& default_slice_band();

// The demo's routes that end OK (tools/demo.sh runs office_route with three planners; here every
// route runs with every planner). Metres, in the scene's frame. A test keeps them tools/demo.sh's.
struct Route {
  const char* name;
  double start_x, start_y, goal_x, goal_y;
};
inline constexpr Route kDemoRoutes[] = {
    {"corridor", -6.0, 0.5, 27.0, -0.5},
    {"office_route", 2.0, -6.0, 16.0, -6.5},
    {"hall_to_corridor", 16.0, -6.5, -6.0, 0.0},
};

// Moving AI maps carry no scale; they are read at this many metres a cell (an office slice's), so
// that the robot's metres mean a number of cells (inflation_radius 0.55 m = 11 cells).
inline constexpr double kMovingAiResolution = 0.05;

struct CostsOptions {
  std::string maps_dir;    // Moving AI maps with scenarios ("" or missing: that part is skipped)
  std::string scene_path;  // the demo scene, an OctoMap (.bt); also the first held-in slice
  // More held-in OctoMaps (.bt), sliced like the scene (default_slice_band(), the tree's
  // leaf size); a file that does not exist is skipped with a message, an empty name is ignored.
  std::vector<std::string> slice_paths;
  int slice_queries = 20;           // seeded random queries per slice (0: none)
  unsigned seed = 1;                // of those queries
  double min_query_distance = 3.0;  // metres between a random query's start and goal, at least
  std::vector<core::PlannerKind> planners;  // empty: all
  int max_scenarios = 40;                   // per Moving AI map, spread over the file
  int repetitions = 5;  // timed plans per scene or slice query and side (median), interleaved
  RobotSettings robot = default_yaml_robot();
  // Progress of the Moving AI part on stderr (queries done / total, elapsed, ETA, at most once a
  // second) even when stderr is not a terminal; on a terminal it is always shown.
  bool progress = false;
};

// The grid build options and planner settings of each side: binary is the paper's (no radius,
// no gradient, cost_weight 0, exact endpoints); cost-aware is `robot` (smoother none); cost-aware
// + relax is `robot` with smoother relax. On Moving AI maps the
// radius is left out (`with_radius` false): their scenarios' endpoints are free cells of the
// binary map, and a radius would block some, so there only the gradient and the weight differ.
core::GridBuildOptions build_options(const RobotSettings& robot, bool with_radius);
core::PlannerSettings planner_settings(const RobotSettings& robot);

// The options `planner.name: auto` plans with for `robot` (config/default.yaml: prune and smooth
// on, the planner core::recommended_planner picks for robot.cost_weight and the moves) and
// `smoother`: with default_yaml_robot() and kRelax the default configuration (astar), with
// RobotSettings{} (cost_weight 0) and kNone the binary default (jps).
core::PlannerOptions default_config_options(const RobotSettings& robot,
                                            core::PathSmoother smoother);
// A cost-aware planner as auto's cost-aware side runs, only the planner differing: `robot`,
// prune and smooth on, smoother relax (the planner's own neighbourhood: vns_bastar 8-11-13).
core::PlannerOptions cost_aware_relax_options(core::PlannerKind kind, const RobotSettings& robot);

int run_costs(const CostsOptions& options);

}  // namespace vnsba::bench
