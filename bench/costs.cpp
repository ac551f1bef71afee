#include "bench/costs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "bench/common.hpp"
#include "bench/movingai.hpp"
#include "vnsba/core/metrics.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/render/progress.hpp"

namespace vnsba::bench {

namespace {

// The three sides of every comparison. Cost-aware and cost-aware + relax plan on the same map
// (the robot's) with the same settings, but for the smoother.
enum Side { kBinary = 0, kCostAware = 1, kRelax = 2 };
constexpr int kSides = 3;
constexpr Side kAllSides[] = {kBinary, kCostAware, kRelax};
constexpr const char* kSideName[] = {"binary", "cost-aware", "cost-aware + relax"};
// The map a side plans on: 0 the binary map, 1 the robot's.
constexpr int map_of(int side) {
  return side == kBinary ? 0 : 1;
}

// The targets (issue 34 item 3): cost-aware + relax against binary on the demo's routes
// and the held-in slices, and the smoother's time (cost-aware + relax against cost-aware).
constexpr double kTurnAngleTarget = 1.3;  // total turn angle ratio, at most
constexpr double kClearanceTarget = 1.5;  // clearance ratio, at least
constexpr double kLengthTarget = 1.15;    // length ratio, at most
constexpr double kOverheadTarget = 1.2;   // median time ratio, at most
// A binary path turning less than this in total (a straight corridor) makes the turn angle ratio
// huge: such ratios are printed and flagged.
constexpr double kTinyTurnAngleDeg = 10.0;

// One plan's outcome: lengths and clearances in metres on the scene and the slices, in cells on
// Moving AI maps; max curvature per metre there, per cell here; turn angle in degrees.
struct Outcome {
  bool ok = false;
  double length = NAN;
  double clearance = NAN;
  double turns = NAN;
  double turn_angle = NAN;
  double curvature = NAN;
  double expanded = 0.0;
  double time_us = NAN;
};

// What a unit of the map is worth in the tables' units.
struct Units {
  double per_metre;      // lengths and clearances: 1 (metres) or 1 / resolution (cells)
  double per_cell_turn;  // curvature per cell times this: 1 / resolution (per metre) or 1
};

// One query on the three sides.
struct QueryOutcome {
  std::string label;  // a route's name, or "" for a random query or a scenario
  Outcome o[kSides];
  bool all_ok() const { return o[kBinary].ok && o[kCostAware].ok && o[kRelax].ok; }
};

// The options of `kind` on one side. jps plans on uniform costs only: on both cost-aware sides it
// runs with cost_weight 0 (as the node plans a request for jps), on the cost-aware map (radius,
// tolerances), and is named so in the tables; its relax side smooths without the cost term.
core::PlannerOptions side_options(core::PlannerKind kind, const RobotSettings& robot, int side) {
  core::PlannerSettings settings = planner_settings(side == kBinary ? RobotSettings{} : robot);
  settings.smoother = side == kRelax ? core::PathSmoother::kRelax : core::PathSmoother::kNone;
  core::PlannerOptions options = core::make_options(kind, settings);
  core::drop_unsupported_costs(options);
  return options;
}

std::string planner_label(core::PlannerKind kind) {
  std::string name(core::to_string(kind));
  if (!core::supports_costs(kind)) name += " (uniform costs)";
  return name;
}

Outcome outcome_of(const TimedPlan& timed, const Units& units) {
  Outcome o;
  const core::Metrics& m = timed.result.metrics;
  o.ok = timed.result.status.is_ok();
  o.expanded = static_cast<double>(m.expanded);
  o.time_us = timed.time_us;
  if (o.ok) {
    o.length = m.length_m * units.per_metre;
    o.clearance = m.clearance_m * units.per_metre;
    o.turns = m.turns;
    o.turn_angle = m.turn_angle_deg;
    o.curvature = core::max_curvature(timed.result.path) * units.per_cell_turn;
  }
  return o;
}

// Plans `query` on the three sides, in an order that starts at `first_side` and rotates, so that
// no side always runs right after another on the same map. With repetitions > 0 each side's time
// is the median of that many more plans, interleaved side by side (the first plans, which give
// the metrics, warm the search state up); with 0 it is the first plan's.
QueryOutcome plan_query(std::vector<core::Planner>& planner_of, const core::PlanQuery& query,
                        const core::PlannerOptions (&options)[kSides], int repetitions,
                        const Units& units, int first_side = 0) {
  QueryOutcome q;
  for (int k = 0; k < kSides; ++k) {
    const int side = (first_side + k) % kSides;
    q.o[side] = outcome_of(timed_plan(planner_of[map_of(side)], query, options[side]), units);
  }
  if (repetitions > 0) {
    std::vector<double> times[kSides];
    for (int r = 0; r < repetitions; ++r) {
      for (int k = 0; k < kSides; ++k) {
        const int side = (first_side + r + k) % kSides;
        times[side].push_back(timed_plan(planner_of[map_of(side)], query, options[side]).time_us);
      }
    }
    for (const int side : kAllSides) q.o[side].time_us = median(std::move(times[side]));
  }
  return q;
}

double sum_of(const std::vector<double>& values) {
  double total = 0.0;
  for (double v : values) total += v;
  return total;
}

// a / b, with 0 / 0 = 1 (neither path turns, say) and a / 0 = inf.
double ratio(double a, double b) {
  if (b == 0.0) return a == 0.0 ? 1.0 : INFINITY;
  return a / b;
}

std::string ratio_text(double value, int decimals) {
  if (std::isinf(value) && value > 0) return "inf";
  return format(value, decimals);
}

// "a / b / c" over the three sides; "failed" for a side that found no path.
std::string triple(const Outcome (&o)[kSides], double Outcome::*field, int decimals,
                   double scale = 1.0) {
  std::string out;
  for (const int side : kAllSides) {
    if (side != kBinary) out += " / ";
    out += o[side].ok ? format(o[side].*field * scale, decimals) : "failed";
  }
  return out;
}
std::string triple(const double (&values)[kSides], int decimals) {
  return format(values[kBinary], decimals) + " / " + format(values[kCostAware], decimals) + " / " +
         format(values[kRelax], decimals);
}

bool angle_met(double r) {
  return r <= kTurnAngleTarget;
}
bool clearance_met(double r) {
  return r >= kClearanceTarget;
}
bool length_met(double r) {
  return r <= kLengthTarget;
}
bool overhead_met(double r) {
  return r <= kOverheadTarget;
}
std::string verdict(bool met) {
  return met ? "met" : "**missed**";
}

// Ratios of cost-aware + relax to binary over a set of queries: the ratio of the sums over the
// queries (the aggregate) and the median of the per-query ratios.
struct Ratio {
  double of_sums = NAN;
  double median = NAN;
  std::string text(int decimals) const {
    return ratio_text(of_sums, decimals) + " / " + ratio_text(median, decimals);
  }
};

// A set of queries (the demo's routes, a slice's random queries, all of them) for one planner.
struct SetStats {
  int queries = 0;
  int failed[kSides] = {0, 0, 0};
  int compared = 0;  // queries every side solved: the ones the statistics below are over
  int tiny = 0;      // of those, the ones whose binary turn angle is below kTinyTurnAngleDeg
  Ratio angle, clearance, length;
  double angle_median_untiny = NAN;  // median turn angle ratio over the queries not flagged
  double overhead_ms = NAN;          // median of per-query added times, relax - cost-aware
  double overhead = NAN;             // median of per-query time ratios, relax / cost-aware
  double versus_binary = NAN;        // median of per-query time ratios, relax / binary
  double median_length[kSides], median_turns[kSides], median_angle[kSides],
      median_curvature[kSides], median_clearance[kSides], median_time_us[kSides];
  double total_turns[kSides] = {0, 0, 0};

  // "met", or "**missed**: " and the targets missed with the statistic that misses them.
  std::string path_verdict() const {
    if (compared == 0) return "n/a (no query)";
    std::string missed;
    auto check = [&](const char* name, const Ratio& r, bool (*met)(double)) {
      const bool sums = met(r.of_sums), med = met(r.median);
      if (sums && med) return;
      missed += std::string(missed.empty() ? "" : ", ") + name + " (" +
                (!sums && !med ? "sums, median"
                 : !sums       ? "sums"
                               : "median") +
                ")";
    };
    check("turn angle", angle, angle_met);
    check("clearance", clearance, clearance_met);
    check("length", length, length_met);
    return missed.empty() ? "met" : "**missed**: " + missed;
  }
  bool path_met() const { return path_verdict() == "met"; }
  std::string queries_text() const {
    std::string text = std::to_string(queries);
    if (failed[kBinary] + failed[kCostAware] + failed[kRelax] > 0)
      text += " (**failed** " + std::to_string(failed[kBinary]) + " / " +
              std::to_string(failed[kCostAware]) + " / " + std::to_string(failed[kRelax]) + ")";
    return text;
  }
};

SetStats stats_of(const std::vector<const QueryOutcome*>& set) {
  SetStats s;
  s.queries = static_cast<int>(set.size());
  std::vector<double> length[kSides], turns[kSides], angle[kSides], curvature[kSides],
      clearance[kSides], time_us[kSides];
  std::vector<double> angle_ratio, angle_ratio_untiny, clearance_ratio, length_ratio, overhead,
      overhead_ms, versus_binary;
  double clearance_sum[kSides] = {0, 0, 0};
  for (const QueryOutcome* q : set) {
    for (const int side : kAllSides)
      if (!q->o[side].ok) ++s.failed[side];
    if (!q->all_ok()) continue;
    ++s.compared;
    for (const int side : kAllSides) {
      const Outcome& o = q->o[side];
      length[side].push_back(o.length);
      turns[side].push_back(o.turns);
      angle[side].push_back(o.turn_angle);
      curvature[side].push_back(o.curvature);
      time_us[side].push_back(o.time_us);
      s.total_turns[side] += o.turns;
    }
    const Outcome& b = q->o[kBinary];
    const Outcome& r = q->o[kRelax];
    angle_ratio.push_back(ratio(r.turn_angle, b.turn_angle));
    if (b.turn_angle < kTinyTurnAngleDeg)
      ++s.tiny;
    else
      angle_ratio_untiny.push_back(angle_ratio.back());
    length_ratio.push_back(ratio(r.length, b.length));
    // A map without obstacles has infinite clearances: no ratio.
    if (std::isfinite(b.clearance) && std::isfinite(r.clearance)) {
      for (const int side : kAllSides) clearance[side].push_back(q->o[side].clearance);
      clearance_sum[kBinary] += b.clearance;
      clearance_sum[kRelax] += r.clearance;
      clearance_ratio.push_back(ratio(r.clearance, b.clearance));
    }
    overhead.push_back(r.time_us / q->o[kCostAware].time_us);
    overhead_ms.push_back((r.time_us - q->o[kCostAware].time_us) / 1000.0);
    versus_binary.push_back(r.time_us / b.time_us);
  }
  for (const int side : kAllSides) {
    s.median_length[side] = median(length[side]);
    s.median_turns[side] = median(turns[side]);
    s.median_angle[side] = median(angle[side]);
    s.median_curvature[side] = median(curvature[side]);
    s.median_clearance[side] = median(clearance[side]);
    s.median_time_us[side] = median(time_us[side]);
  }
  if (s.compared > 0) {
    s.angle = {ratio(sum_of(angle[kRelax]), sum_of(angle[kBinary])), median(angle_ratio)};
    s.length = {ratio(sum_of(length[kRelax]), sum_of(length[kBinary])), median(length_ratio)};
    if (!clearance_ratio.empty())
      s.clearance = {ratio(clearance_sum[kRelax], clearance_sum[kBinary]), median(clearance_ratio)};
    s.angle_median_untiny = median(angle_ratio_untiny);
    s.overhead = median(overhead);
    s.overhead_ms = median(overhead_ms);
    s.versus_binary = median(versus_binary);
  }
  return s;
}

std::vector<const QueryOutcome*> pointers(const std::vector<QueryOutcome>& queries) {
  std::vector<const QueryOutcome*> out;
  for (const QueryOutcome& q : queries) out.push_back(&q);
  return out;
}

// The columns of a set's targets row (after the planner and, where there is one, the set).
const std::vector<std::string> kTargetHeaders = {
    "queries (failed b / c / r)",
    "turn angle ratio, sums / median (<= 1.3)",
    "binary turn angle < 10 deg (median ratio without them)",
    "clearance ratio, sums / median (>= 1.5)",
    "length ratio, sums / median (<= 1.15)",
    "path targets",
    "smoother time ratio, median (<= 1.2)",
    "smoother time added, median (ms)",
    "time ratio vs binary, median"};
std::vector<std::string> target_cells(const SetStats& s) {
  return {s.queries_text(),
          s.angle.text(2),
          s.tiny > 0
              ? std::to_string(s.tiny) + " flagged (" + ratio_text(s.angle_median_untiny, 2) + ")"
              : "0",
          s.clearance.text(2),
          s.length.text(3),
          s.path_verdict(),
          format(s.overhead, 2) +
              (s.compared > 0 ? " (" + verdict(overhead_met(s.overhead)) + ")" : ""),
          format(s.overhead_ms, 3),
          format(s.versus_binary, 2)};
}

std::vector<std::string> with_headers(std::vector<std::string> first,
                                      const std::vector<std::string>& rest) {
  first.insert(first.end(), rest.begin(), rest.end());
  return first;
}

// --- The OctoMap slices -----------------------------------------------------------------------

// A held-in OctoMap sliced at kDemoSliceZMin-kDemoSliceZMax, with its binary and cost-aware maps
// and a planner on each.
struct SlicedScene {
  std::string name;  // the file's name
  core::OccupancyGrid grid;
  std::shared_ptr<const core::GridMap> maps[2];
  std::vector<core::Planner> planner_of;  // on maps[0], maps[1]
};

// Prints what is wrong, naming `what` (the option), and returns nothing on failure.
std::optional<SlicedScene> load_sliced(const std::string& path, const RobotSettings& robot,
                                       const char* what) {
  auto tree = maps::load_octree(path);
  if (!tree) {
    std::fprintf(stderr, "vnsba_bench costs: %s: %s\n", what, tree.error().message.c_str());
    return std::nullopt;
  }
  maps::SliceOptions slice;
  slice.z_min = kDemoSliceZMin;
  slice.z_max = kDemoSliceZMax;
  auto grid = maps::slice_octree(**tree, slice);
  if (!grid) {
    std::fprintf(stderr, "vnsba_bench costs: %s: %s\n", what, grid.error().message.c_str());
    return std::nullopt;
  }
  SlicedScene scene;
  scene.name = std::filesystem::path(path).filename().string();
  scene.grid = std::move(grid).value();
  const RobotSettings robot_of[2] = {RobotSettings{}, robot};
  for (int m : {0, 1}) {
    auto built = core::GridMap::build(scene.grid, build_options(robot_of[m], true));
    if (!built) {
      std::fprintf(stderr, "vnsba_bench costs: %s (%s map): %s\n", what, kSideName[m],
                   built.error().message.c_str());
      return std::nullopt;
    }
    scene.maps[m] = std::make_shared<const core::GridMap>(std::move(built).value());
    scene.planner_of.emplace_back(scene.maps[m]);
  }
  return scene;
}

// `count` seeded random queries between free cells of `map` that one component of free cells
// joins (4-connected: the 8-neighbourhood with corner policy never connects the same cells), the
// centres at least `min_cells` apart. Fewer when the draws run out (1000 per query).
std::vector<std::pair<core::Cell, core::Cell>> random_queries(const core::GridMap& map, int count,
                                                              unsigned seed, double min_cells) {
  const int32_t width = map.width(), height = map.height();
  std::vector<int32_t> component(static_cast<size_t>(width) * static_cast<size_t>(height), -1);
  std::vector<core::Cell> free_cells;
  std::vector<core::Cell> stack;
  int32_t label = 0;
  for (int32_t y = 0; y < height; ++y) {
    for (int32_t x = 0; x < width; ++x) {
      const size_t at = static_cast<size_t>(y) * width + x;
      if (map.blocked(x, y) || component[at] >= 0) continue;
      component[at] = label;
      stack.push_back({x, y});
      while (!stack.empty()) {
        const core::Cell c = stack.back();
        stack.pop_back();
        free_cells.push_back(c);
        const core::Cell next[4] = {{c.x + 1, c.y}, {c.x - 1, c.y}, {c.x, c.y + 1}, {c.x, c.y - 1}};
        for (const core::Cell& n : next) {
          if (!map.in_bounds(n) || map.blocked(n)) continue;
          int32_t& mark = component[static_cast<size_t>(n.y) * width + n.x];
          if (mark >= 0) continue;
          mark = label;
          stack.push_back(n);
        }
      }
      ++label;
    }
  }
  std::vector<std::pair<core::Cell, core::Cell>> queries;
  if (free_cells.empty() || count <= 0) return queries;
  // The raw engine's output (not a distribution, whose algorithm the standard leaves open), so
  // that a seed gives the same queries with every standard library.
  std::mt19937 rng(seed);
  const size_t n = free_cells.size();
  for (int64_t draws = 0; static_cast<int>(queries.size()) < count && draws < 1000LL * count;
       ++draws) {
    const core::Cell s = free_cells[rng() % n];
    const core::Cell g = free_cells[rng() % n];
    if (component[static_cast<size_t>(s.y) * width + s.x] !=
        component[static_cast<size_t>(g.y) * width + g.x])
      continue;
    if (std::hypot(s.x - g.x, s.y - g.y) < min_cells) continue;
    queries.emplace_back(s, g);
  }
  return queries;
}

// --- The demo scene and the slices ------------------------------------------------------------

constexpr const char* kSidesNote =
    "Cells with three values: binary / cost-aware / cost-aware + relax. Ratios: cost-aware + relax "
    "/ binary (turn angle, clearance, length; targets <= 1.3, >= 1.5, <= 1.15); smoother time "
    "ratio: cost-aware + relax / cost-aware (target <= 1.2); time ratio vs binary: cost-aware + "
    "relax / binary. Sums / median: the ratio of the sums over the queries (the aggregate) and "
    "the median of the per-query ratios; a set meets a path target when both do.";

struct OctomapResult {
  bool ok = true;       // every plan of the demo's routes and the slices' queries succeeded
  bool loaded = false;  // the scene loaded
  std::string text;
};

OctomapResult run_octomaps(const CostsOptions& options,
                           const std::vector<core::PlannerKind>& planners) {
  OctomapResult out;
  std::optional<SlicedScene> scene = load_sliced(options.scene_path, options.robot, "--scene");
  if (!scene) return out;
  out.loaded = true;
  const core::GridMap& scene_map = *scene->maps[1];
  const Units metres{1.0, 1.0 / scene_map.resolution()};

  // 1. The demo's routes, every planner.
  std::map<core::PlannerKind, std::vector<QueryOutcome>> demo;
  for (const core::PlannerKind kind : planners) {
    core::PlannerOptions plan_options[kSides];
    for (const int side : kAllSides) plan_options[side] = side_options(kind, options.robot, side);
    for (const Route& route : kDemoRoutes) {
      const auto start = scene_map.world_to_cell(route.start_x, route.start_y);
      const auto goal = scene_map.world_to_cell(route.goal_x, route.goal_y);
      if (!start || !goal) {
        std::fprintf(stderr, "vnsba_bench costs: route %s lies outside the scene\n", route.name);
        out.ok = false;
        return out;
      }
      const core::PlanQuery query(*start, *goal,
                                  scene_map.world_to_grid(route.start_x, route.start_y),
                                  scene_map.world_to_grid(route.goal_x, route.goal_y));
      QueryOutcome q =
          plan_query(scene->planner_of, query, plan_options, options.repetitions, metres);
      q.label = route.name;
      for (const int side : kAllSides) {
        if (q.o[side].ok) continue;
        std::fprintf(stderr, "vnsba_bench costs: %s on route %s (%s) found no path\n",
                     core::to_string(kind).data(), route.name, kSideName[side]);
        out.ok = false;
      }
      demo[kind].push_back(std::move(q));
    }
  }

  MarkdownTable routes({"planner", "route", "length (m)", "turns", "turn angle (deg)",
                        "max curvature (1/m)", "clearance (m)", "time (ms)",
                        "turn angle ratio (<= 1.3)", "clearance ratio (>= 1.5)",
                        "length ratio (<= 1.15)", "path targets", "smoother time ratio (<= 1.2)",
                        "time ratio vs binary"});
  MarkdownTable demo_summary(
      with_headers({"planner"}, with_headers(kTargetHeaders, {"turns total", "time median (ms)"})));
  for (const core::PlannerKind kind : planners) {
    for (const QueryOutcome& q : demo[kind]) {
      const Outcome& b = q.o[kBinary];
      const Outcome& r = q.o[kRelax];
      std::vector<std::string> row = {planner_label(kind),
                                      q.label,
                                      triple(q.o, &Outcome::length, 2),
                                      triple(q.o, &Outcome::turns, 0),
                                      triple(q.o, &Outcome::turn_angle, 0),
                                      triple(q.o, &Outcome::curvature, 2),
                                      triple(q.o, &Outcome::clearance, 3),
                                      triple(q.o, &Outcome::time_us, 2, 1e-3)};
      if (q.all_ok()) {
        const double angle = ratio(r.turn_angle, b.turn_angle);
        const double clearance = ratio(r.clearance, b.clearance);
        const double length = ratio(r.length, b.length);
        const double overhead = r.time_us / q.o[kCostAware].time_us;
        std::string missed;
        if (!angle_met(angle)) missed += "turn angle";
        if (!clearance_met(clearance))
          missed += std::string(missed.empty() ? "" : ", ") + "clearance";
        if (!length_met(length)) missed += std::string(missed.empty() ? "" : ", ") + "length";
        std::string angle_text = ratio_text(angle, 2);
        if (b.turn_angle < kTinyTurnAngleDeg)
          angle_text += " (flagged: binary turns " + format(b.turn_angle, 1) + " deg)";
        row.insert(row.end(), {angle_text, ratio_text(clearance, 2), format(length, 3),
                               missed.empty() ? "met" : "**missed**: " + missed,
                               format(overhead, 2) + " (" + verdict(overhead_met(overhead)) + ")",
                               format(r.time_us / b.time_us, 2)});
      } else {
        row.insert(row.end(), {"n/a", "n/a", "n/a", "**failed**", "n/a", "n/a"});
      }
      routes.add_row(std::move(row));
    }
    const SetStats s = stats_of(pointers(demo[kind]));
    std::vector<std::string> row = {planner_label(kind)};
    const std::vector<std::string> cells = target_cells(s);
    row.insert(row.end(), cells.begin(), cells.end());
    double time_ms[kSides];
    for (const int side : kAllSides) time_ms[side] = s.median_time_us[side] / 1000.0;
    row.insert(row.end(), {triple(s.total_turns, 0), triple(time_ms, 2)});
    demo_summary.add_row(std::move(row));
  }
  char head[1024];
  std::snprintf(
      head, sizeof head,
      "**Demo scene** (%s, sliced at %.1f-%.1f m, %d x %d cells at %.2f m): the demo's three "
      "routes that end OK, every planner, on three sides: binary (config/paper.yaml: no radius, "
      "no gradient, cost_weight 0, smoother none), cost-aware (config/default.yaml: robot_radius "
      "%.2f m, inflation_radius %.2f m, cost_scaling_factor %.1f, cost_weight %.1f, "
      "goal_tolerance %.2f m, start_tolerance %.2f m; smoother none) and cost-aware + relax (the "
      "same with smoother relax, its weights at their defaults). Time: median of %d plans per "
      "side, the sides interleaved. Max curvature: the largest heading change over the mean "
      "length of its two segments, per metre.\n\n",
      scene->name.c_str(), kDemoSliceZMin, kDemoSliceZMax, scene->grid.width, scene->grid.height,
      scene->grid.resolution, options.robot.robot_radius, options.robot.inflation_radius,
      options.robot.cost_scaling_factor, options.robot.cost_weight, options.robot.goal_tolerance,
      options.robot.start_tolerance, options.repetitions);
  std::string text = std::string(head) + kSidesNote +
                     "\n\nPer planner, over the three routes:\n\n" + demo_summary.str() +
                     "\nPer route:\n\n" + routes.str() + "\n";

  // 2. The held-in slices: the scene, then the others; seeded random queries on each.
  struct SliceRun {
    std::string name;
    std::map<core::PlannerKind, std::vector<QueryOutcome>> queries;
  };
  std::vector<SliceRun> slice_runs;
  std::string slices_head;
  std::vector<std::string> slice_paths = {options.scene_path};
  for (const std::string& path : options.slice_paths) {
    if (path.empty()) continue;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      std::fprintf(stderr, "vnsba_bench costs: skipping the slice of %s: no such file\n",
                   path.c_str());
      slices_head += "(" + path + " is absent: skipped.)\n\n";
      continue;
    }
    slice_paths.push_back(path);
  }
  if (options.slice_queries > 0) {
    for (size_t i = 0; i < slice_paths.size(); ++i) {
      std::optional<SlicedScene> loaded;
      if (i == 0) {
        loaded = std::move(scene);
        scene.reset();
      } else {
        loaded = load_sliced(slice_paths[i], options.robot, "--slices");
      }
      if (!loaded) {
        out.ok = false;
        continue;
      }
      const core::GridMap& map = *loaded->maps[1];
      const Units units{1.0, 1.0 / map.resolution()};
      const auto picked = random_queries(map, options.slice_queries, options.seed,
                                         options.min_query_distance / map.resolution());
      SliceRun run;
      run.name = loaded->name;
      for (const core::PlannerKind kind : planners) {
        core::PlannerOptions plan_options[kSides];
        for (const int side : kAllSides)
          plan_options[side] = side_options(kind, options.robot, side);
        for (size_t k = 0; k < picked.size(); ++k) {
          const auto& [start, goal] = picked[k];
          QueryOutcome q =
              plan_query(loaded->planner_of, core::PlanQuery(start, goal), plan_options,
                         options.repetitions, units, static_cast<int>(k % kSides));
          for (const int side : kAllSides) {
            if (q.o[side].ok) continue;
            std::fprintf(stderr,
                         "vnsba_bench costs: %s on %s, query %zu (cells %d,%d -> %d,%d), %s: no "
                         "path\n",
                         core::to_string(kind).data(), loaded->name.c_str(), k, start.x, start.y,
                         goal.x, goal.y, kSideName[side]);
            out.ok = false;
          }
          run.queries[kind].push_back(std::move(q));
        }
      }
      char line[512];
      std::snprintf(line, sizeof line,
                    "%s: %d x %d cells at %.2f m, %zu random queries (seed %u, start and goal "
                    "at least %.1f m apart, connected on the cost-aware map%s)",
                    loaded->name.c_str(), loaded->grid.width, loaded->grid.height,
                    loaded->grid.resolution, picked.size(), options.seed,
                    options.min_query_distance,
                    static_cast<int>(picked.size()) < options.slice_queries
                        ? ": fewer than asked, the draws ran out"
                        : "");
      slices_head += std::string("- ") + line + "\n";
      std::fprintf(stderr, "%s: %zu random queries x %zu planners x 3 sides\n",
                   loaded->name.c_str(), picked.size(), planners.size());
      slice_runs.push_back(std::move(run));
    }
  }
  if (slice_runs.empty()) {
    out.text = text + "**Held-in OctoMap slices**: not measured (" +
               (options.slice_queries > 0 ? "no slice loaded" : "--slice-queries 0") + ").\n\n";
    return out;
  }
  text +=
      "**Held-in OctoMap slices** (sliced at " + format(kDemoSliceZMin, 1) + "-" +
      format(kDemoSliceZMax, 1) +
      " m like the demo scene), every planner on the same seeded random queries, the three sides "
      "as above, time the median of " +
      std::to_string(options.repetitions) +
      " plans per side. A failed plan is counted in the queries column (failed binary / "
      "cost-aware / relax) and left out of the medians and ratios.\n\n" +
      slices_head +
      "\nMedians over each slice's queries (binary / cost-aware / cost-aware + relax):\n\n";
  MarkdownTable medians({"slice", "planner", "queries (failed b / c / r)", "length (m)", "turns",
                         "turn angle (deg)", "max curvature (1/m)", "clearance (m)", "time (ms)"});
  MarkdownTable targets(with_headers({"planner", "query set"}, kTargetHeaders));
  MarkdownTable choice({"planner", "time median, relax (ms): demo routes / slices",
                        "time ratio vs binary, median (all)", "smoother time ratio, median (all)",
                        "turns total, relax: demo routes / slices",
                        "turns total, binary: demo routes / slices", "path targets (all)"});
  struct Pick {
    std::string planner;
    double value = INFINITY;
  } fastest, fewest_turns;
  for (const core::PlannerKind kind : planners) {
    std::vector<const QueryOutcome*> all = pointers(demo[kind]), slices;
    for (const SliceRun& run : slice_runs) {
      const std::vector<const QueryOutcome*> set = pointers(run.queries.at(kind));
      const SetStats s = stats_of(set);
      double time_ms[kSides];
      for (const int side : kAllSides) time_ms[side] = s.median_time_us[side] / 1000.0;
      medians.add_row({run.name, planner_label(kind), s.queries_text(), triple(s.median_length, 2),
                       triple(s.median_turns, 1), triple(s.median_angle, 0),
                       triple(s.median_curvature, 2), triple(s.median_clearance, 3),
                       triple(time_ms, 2)});
      std::vector<std::string> row = {planner_label(kind), run.name + " random"};
      const std::vector<std::string> cells = target_cells(s);
      row.insert(row.end(), cells.begin(), cells.end());
      targets.add_row(std::move(row));
      slices.insert(slices.end(), set.begin(), set.end());
    }
    all.insert(all.end(), slices.begin(), slices.end());
    const SetStats pooled = stats_of(all);
    std::vector<std::string> row = {planner_label(kind), "**all: demo routes + slices**"};
    const std::vector<std::string> cells = target_cells(pooled);
    row.insert(row.end(), cells.begin(), cells.end());
    targets.add_row(std::move(row));
    const SetStats on_demo = stats_of(pointers(demo[kind]));
    const SetStats on_slices = stats_of(slices);
    choice.add_row(
        {planner_label(kind),
         format(on_demo.median_time_us[kRelax] / 1000.0, 2) + " / " +
             format(on_slices.median_time_us[kRelax] / 1000.0, 2),
         format(pooled.versus_binary, 2), format(pooled.overhead, 2),
         format(on_demo.total_turns[kRelax], 0) + " / " + format(on_slices.total_turns[kRelax], 0),
         format(on_demo.total_turns[kBinary], 0) + " / " +
             format(on_slices.total_turns[kBinary], 0),
         pooled.path_verdict()});
    if (core::supports_costs(kind)) {
      if (pooled.median_time_us[kRelax] < fastest.value)
        fastest = {planner_label(kind), pooled.median_time_us[kRelax]};
      if (pooled.total_turns[kRelax] < fewest_turns.value)
        fewest_turns = {planner_label(kind), pooled.total_turns[kRelax]};
    }
  }
  text += medians.str() +
          "\nTargets per query set and overall (the demo's routes and every slice's queries "
          "pooled):\n\n" +
          targets.str() +
          "\nChoosing a default: cost-aware + relax per planner over the demo's routes and the "
          "slices' queries (turns: totals over the queries).\n\n" +
          choice.str() + "\n";
  if (!fastest.planner.empty()) {
    text +=
        "Among the cost-aware planners with relax, the lowest median time over the demo's "
        "routes and the slices' queries is " +
        fastest.planner + "'s (" + format(fastest.value / 1000.0, 2) +
        " ms); the fewest turns in total, " + fewest_turns.planner + "'s (" +
        format(fewest_turns.value, 0) + ").\n\n";
  }
  out.text = text;
  return out;
}

// --- Moving AI maps ---------------------------------------------------------------------------

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
  const RobotSettings robot_of[2] = {RobotSettings{}, options.robot};
  const Units cells{1.0 / kMovingAiResolution, 1.0};
  // class -> planner -> queries
  std::map<std::string, std::map<core::PlannerKind, std::vector<QueryOutcome>>> samples;
  // Queries to come (each planned on the three sides), for the progress line; a scenario file
  // that does not load counts 0 and fails below.
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
    for (int m : {0, 1}) {
      auto built = core::GridMap::build(grid, build_options(robot_of[m], false));
      if (!built) {
        std::fprintf(stderr, "vnsba_bench costs: %s (%s): %s\n", loaded->name.c_str(), kSideName[m],
                     built.error().message.c_str());
        out.ok = false;
        return out;
      }
      planner_of.emplace_back(std::make_shared<const core::GridMap>(std::move(built).value()));
    }
    const auto picked = pick_scenarios(loaded->scenarios.size(), options.max_scenarios);
    for (const core::PlannerKind kind : planners) {
      std::vector<QueryOutcome>& sample = samples[map_class][kind];
      core::PlannerOptions plan_options[kSides];
      for (const int side : kAllSides) {
        plan_options[side] = side_options(kind, options.robot, side);
        if (!picked.empty()) {  // warm-up: the first plan touches the search state
          const auto& s = loaded->scenarios[picked.front()];
          planner_of[map_of(side)].plan({s.start, s.goal}, plan_options[side]);
        }
      }
      // Interleaved by query, so that a slow moment of the machine hits every side alike; one
      // timed plan per side and query.
      for (size_t k = 0; k < picked.size(); ++k) {
        const maps::MovingAiScenario& s = loaded->scenarios[picked[k]];
        sample.push_back(plan_query(planner_of, {s.start, s.goal}, plan_options, 0, cells,
                                    static_cast<int>(k % kSides)));
        progress.update(++queries_done);
      }
    }
    std::fprintf(stderr, "%s (%s): %zu scenarios x %zu planners x 3 sides\n", loaded->name.c_str(),
                 map_class.c_str(), picked.size(), planners.size());
  }
  progress.finish(queries_done);

  MarkdownTable table({"class", "planner", "queries (failed b / c / r)",
                       "length ratio vs binary, mean: cost-aware / relax", "turns",
                       "turn angle (deg)", "max curvature (1/cell)", "clearance (cells)",
                       "time median (us)", "smoother time ratio, median (<= 1.2)",
                       "time ratio vs binary, median",
                       "expanded ratio cost-aware / binary (total)"});
  std::map<core::PlannerKind, std::vector<double>> overhead_all;
  std::vector<double> astar_time[2], astar_expanded[2];
  bool disagreements = false;
  for (const auto& [map_class, by_planner] : samples) {
    for (const core::PlannerKind kind : planners) {
      const std::vector<QueryOutcome>& queries = by_planner.at(kind);
      int failed[kSides] = {0, 0, 0};
      std::vector<double> length_ratio[kSides], turns[kSides], angle[kSides], curvature[kSides],
          clearance[kSides], time_us[kSides], expanded[kSides], overhead, versus_binary;
      for (const QueryOutcome& q : queries) {
        for (const int side : kAllSides) {
          if (!q.o[side].ok) ++failed[side];
          time_us[side].push_back(q.o[side].time_us);
          expanded[side].push_back(q.o[side].expanded);
        }
        if (!q.all_ok()) {
          // The gradient blocks nothing and the smoother cannot fail without a time budget: a
          // query some side solved and another did not is a planner's failure.
          if (q.o[kBinary].ok || q.o[kCostAware].ok || q.o[kRelax].ok) disagreements = true;
          continue;
        }
        for (const int side : kAllSides) {
          const Outcome& o = q.o[side];
          length_ratio[side].push_back(o.length / q.o[kBinary].length);
          turns[side].push_back(o.turns);
          angle[side].push_back(o.turn_angle);
          curvature[side].push_back(o.curvature);
          if (std::isfinite(o.clearance)) clearance[side].push_back(o.clearance);
        }
        overhead.push_back(q.o[kRelax].time_us / q.o[kCostAware].time_us);
        versus_binary.push_back(q.o[kRelax].time_us / q.o[kBinary].time_us);
      }
      overhead_all[kind].insert(overhead_all[kind].end(), overhead.begin(), overhead.end());
      double mean_turns[kSides], mean_angle[kSides], mean_curvature[kSides], mean_clearance[kSides],
          median_time[kSides];
      for (const int side : kAllSides) {
        mean_turns[side] = mean(turns[side]);
        mean_angle[side] = mean(angle[side]);
        mean_curvature[side] = mean(curvature[side]);
        mean_clearance[side] = mean(clearance[side]);
        median_time[side] = median(time_us[side]);
      }
      std::string queries_text = std::to_string(queries.size());
      if (failed[kBinary] + failed[kCostAware] + failed[kRelax] > 0)
        queries_text += " (**failed** " + std::to_string(failed[kBinary]) + " / " +
                        std::to_string(failed[kCostAware]) + " / " +
                        std::to_string(failed[kRelax]) + ")";
      const double med_overhead = median(overhead);
      table.add_row({map_class, planner_label(kind), queries_text,
                     format(mean(length_ratio[kCostAware]), 3) + " / " +
                         format(mean(length_ratio[kRelax]), 3),
                     triple(mean_turns, 1), triple(mean_angle, 0), triple(mean_curvature, 2),
                     triple(mean_clearance, 2), triple(median_time, 1),
                     format(med_overhead, 2) +
                         (overhead.empty() ? "" : " (" + verdict(overhead_met(med_overhead)) + ")"),
                     format(median(versus_binary), 2),
                     format(sum_of(expanded[kCostAware]) / sum_of(expanded[kBinary]), 2)});
      if (kind == core::PlannerKind::kAStar) {
        for (int m : {0, 1}) {
          astar_time[m].insert(astar_time[m].end(), time_us[m].begin(), time_us[m].end());
          astar_expanded[m].insert(astar_expanded[m].end(), expanded[m].begin(), expanded[m].end());
        }
      }
    }
  }
  if (disagreements) {
    std::fprintf(stderr,
                 "vnsba_bench costs: a query was solved on one side and not another (the "
                 "gradient blocks nothing, so this is a planner's failure)\n");
    out.ok = false;
  }
  char head[1024];
  std::snprintf(
      head, sizeof head,
      "**Moving AI maps** (%zu maps, at most %d scenarios each, read at %.2f m a cell): binary "
      "against cost-aware and cost-aware + relax with config/default.yaml's gradient and weight "
      "(inflation_radius %.2f m = %.0f cells, cost_scaling_factor %.1f, cost_weight %.1f) but no "
      "robot radius, which would block some scenarios' endpoints. Cells with three values: "
      "binary / cost-aware / cost-aware + relax, means over the queries every side solved "
      "(clearance: maps without obstacles left out), times the median of one timed plan per "
      "query and side. Length ratio: final length / binary final length per query; smoother "
      "time ratio: cost-aware + relax / cost-aware per query (target <= 1.2); expansion ratio: "
      "cost-aware total / binary total over the same queries.\n\n",
      maps->size(), options.max_scenarios, kMovingAiResolution, options.robot.inflation_radius,
      options.robot.inflation_radius / kMovingAiResolution, options.robot.cost_scaling_factor,
      options.robot.cost_weight);
  std::string text = head + table.str() + "\n";
  MarkdownTable overhead_table(
      {"planner", "queries", "smoother time ratio, median (<= 1.2)", "target"});
  for (const core::PlannerKind kind : planners) {
    const std::vector<double>& v = overhead_all[kind];
    const double m = median(v);
    overhead_table.add_row({planner_label(kind), std::to_string(v.size()), format(m, 2),
                            v.empty() ? "n/a" : verdict(overhead_met(m))});
  }
  text += "The smoother's time over every Moving AI query:\n\n" + overhead_table.str() + "\n";
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
  if (options.slice_queries < 0) {
    std::fprintf(stderr, "vnsba_bench costs: --slice-queries must be >= 0, got %d\n",
                 options.slice_queries);
    return kExitBadInput;
  }
  if (!(std::isfinite(options.min_query_distance) && options.min_query_distance >= 0.0)) {
    std::fprintf(stderr, "vnsba_bench costs: --min-distance must be >= 0 metres, got %g\n",
                 options.min_query_distance);
    return kExitBadInput;
  }
  const std::vector<core::PlannerKind> planners =
      options.planners.empty() ? core::all_planner_kinds() : options.planners;
  const OctomapResult octomaps = run_octomaps(options, planners);
  if (!octomaps.loaded) return kExitBadInput;  // the scene could not be loaded
  const MovingAiResult maps = run_maps(options, planners);
  std::printf("%s", octomaps.text.c_str());
  if (maps.ran) std::printf("%s", maps.text.c_str());
  return octomaps.ok && maps.ok ? kExitOk : kExitFailure;
}

}  // namespace vnsba::bench
