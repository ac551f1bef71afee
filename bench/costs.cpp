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
#include "vnsba/node/config.hpp"
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
    // Every side's turns counted the same way: the corners of its final path at half a cell
    // (what a relaxed plan reports; an unrelaxed one reports its pruned waypoints' turns, which
    // count every step of a grid staircase).
    const core::TurnStats corners = core::turn_stats(
        core::simplify_polyline(timed.result.path, core::kRelaxedCornerToleranceCells));
    o.turns = corners.turns;
    o.turn_angle = corners.total_angle_deg;
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

// Whether every side of `q` found a path; each side that did not is named on stderr with `what`
// (the planner or configuration and the query).
bool every_side_found_a_path(const QueryOutcome& q, const std::string& what) {
  bool all = true;
  for (const int side : kAllSides) {
    if (q.o[side].ok) continue;
    std::fprintf(stderr, "vnsba_bench costs: %s (%s): no path\n", what.c_str(), kSideName[side]);
    all = false;
  }
  return all;
}

// One query planned with each of `options` on the same map, in an order that starts at `first`
// and rotates; times as plan_query's (with repetitions > 0 the median of that many more plans,
// interleaved planner by planner).
std::vector<Outcome> plan_each(core::Planner& planner, const core::PlanQuery& query,
                               const std::vector<core::PlannerOptions>& options, int repetitions,
                               const Units& units, int first = 0) {
  const size_t n = options.size();
  std::vector<Outcome> out(n);
  for (size_t k = 0; k < n; ++k) {
    const size_t i = (first + k) % n;
    out[i] = outcome_of(timed_plan(planner, query, options[i]), units);
  }
  if (repetitions > 0) {
    std::vector<std::vector<double>> times(n);
    for (int r = 0; r < repetitions; ++r) {
      for (size_t k = 0; k < n; ++k) {
        const size_t i = (first + r + k) % n;
        times[i].push_back(timed_plan(planner, query, options[i]).time_us);
      }
    }
    for (size_t i = 0; i < n; ++i) out[i].time_us = median(std::move(times[i]));
  }
  return out;
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

// --- Choosing the cost-aware planner of auto --------------------------------------------------

// The reference of the choice table: A*, the optimal cost-aware planner (auto with costs runs
// core::kCostAwareChoice, chosen from this table).
constexpr core::PlannerKind kChoiceReference = core::PlannerKind::kAStar;

// The planners of the choice table: kChoiceReference first, then every planner of `planners`
// that plans with costs (jps, on uniform costs only, is no candidate).
std::vector<core::PlannerKind> choice_planners(const std::vector<core::PlannerKind>& planners) {
  std::vector<core::PlannerKind> out = {kChoiceReference};
  for (const core::PlannerKind kind : planners)
    if (kind != kChoiceReference && core::supports_costs(kind)) out.push_back(kind);
  return out;
}

// Each query of a set planned by every choice planner: [query][planner], planners as
// choice_planners' (the reference at 0).
using ChoiceQueries = std::vector<std::vector<Outcome>>;

// One planner against the reference over a set of queries.
struct ChoiceStats {
  int queries = 0;
  int failed = 0;    // queries this planner did not solve
  int compared = 0;  // queries both it and the reference solved: the statistics are over these
  double time_ratio = NAN;         // median of per-query ratios, its time / the reference's
  double median_time_ratio = NAN;  // ratio of median times
  double median_time_us = NAN;
  double length_ratio = NAN;  // ratio of sums
  double angle_ratio = NAN;   // ratio of sums
};

ChoiceStats choice_stats(const std::vector<const ChoiceQueries*>& sets, size_t planner) {
  ChoiceStats s;
  std::vector<double> times, reference_times;
  double length = 0, reference_length = 0, angle = 0, reference_angle = 0;
  for (const ChoiceQueries* set : sets) {
    for (const std::vector<Outcome>& q : *set) {
      ++s.queries;
      const Outcome& o = q[planner];
      const Outcome& ref = q[0];
      if (!o.ok) ++s.failed;
      if (!o.ok || !ref.ok) continue;
      ++s.compared;
      times.push_back(o.time_us);
      reference_times.push_back(ref.time_us);
      length += o.length;
      reference_length += ref.length;
      angle += o.turn_angle;
      reference_angle += ref.turn_angle;
    }
  }
  if (s.compared > 0) {
    s.time_ratio = median_of_ratios(times, reference_times);
    s.median_time_us = median(times);
    s.median_time_ratio = s.median_time_us / median(reference_times);
    s.length_ratio = ratio(length, reference_length);
    s.angle_ratio = ratio(angle, reference_angle);
  }
  return s;
}

// --- The OctoMap slices -----------------------------------------------------------------------

// A held-in OctoMap sliced at default_slice_band(), with its binary and cost-aware maps
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
  slice.z_min = default_slice_band().z_min;
  slice.z_max = default_slice_band().z_max;
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
  bool ok = true;            // every plan of the demo's routes and the slices' queries succeeded
  bool loaded = false;       // the scene loaded
  std::string default_text;  // the default configuration's comparison
  std::string text;          // the three sides per planner
  ChoiceQueries choice;      // the demo's routes and the slices' queries, every choice planner
};

// The three sides of the default configuration's comparison, in the places of binary,
// cost-aware and cost-aware + relax: auto without costs (the binary default, on the binary map),
// auto with costs and smoother none, auto with costs and smoother relax (the default).
struct DefaultConfig {
  core::PlannerOptions options[kSides];
  explicit DefaultConfig(const RobotSettings& robot)
      : options{default_config_options(RobotSettings{}, core::PathSmoother::kNone),
                default_config_options(robot, core::PathSmoother::kNone),
                default_config_options(robot, core::PathSmoother::kRelax)} {}
};

// A query set of the default configuration's table.
struct DefaultSet {
  std::string name;
  std::vector<QueryOutcome> queries;
};

std::string default_config_text(const CostsOptions& options, const DefaultConfig& config,
                                const std::vector<DefaultSet>& demo_routes,
                                const std::vector<DefaultSet>& slices) {
  const core::PlannerOptions& binary = config.options[kBinary];
  const core::PlannerOptions& chosen = config.options[kRelax];
  MarkdownTable table(
      {"query set", "queries (failed: binary default / default, smoother none / default)",
       "turn angle ratio, sums / median (<= 1.3)",
       "binary default's turn angle < 10 deg (median ratio without them)",
       "clearance ratio, sums / median (>= 1.5)", "length ratio, sums / median (<= 1.15)",
       "path targets", "smoother time ratio, median (<= 1.2)", "smoother time added, median (ms)",
       "time ratio vs binary default, median",
       "time median (ms): binary default / smoother none / default"});
  auto add = [&](const std::string& name, const std::vector<const QueryOutcome*>& set) {
    const SetStats s = stats_of(set);
    std::vector<std::string> row = {name};
    const std::vector<std::string> cells = target_cells(s);
    row.insert(row.end(), cells.begin(), cells.end());
    double time_ms[kSides];
    for (const int side : kAllSides) time_ms[side] = s.median_time_us[side] / 1000.0;
    row.push_back(triple(time_ms, 2));
    table.add_row(std::move(row));
    return s;
  };
  std::vector<const QueryOutcome*> all_demo, all;
  for (const DefaultSet& set : demo_routes) {
    add(set.name, pointers(set.queries));
    const auto p = pointers(set.queries);
    all_demo.insert(all_demo.end(), p.begin(), p.end());
  }
  add("demo routes", all_demo);
  all = all_demo;
  for (const DefaultSet& set : slices) {
    const auto p = pointers(set.queries);
    add(set.name + " random", p);
    all.insert(all.end(), p.begin(), p.end());
  }
  const SetStats pooled = add("**all: demo routes + slices**", all);
  char head[2048];
  std::snprintf(
      head, sizeof head,
      "**The default configuration** (config/default.yaml, `planner.name: auto`; issue 34's "
      "targets are stated for it), on the demo's routes and the held-in slices' queries (the "
      "same queries as the tables below). The default: auto with the robot's costs, which runs "
      "%s (core::recommended_planner for cost_weight %.1f) with prune and smooth on and smoother "
      "relax on the robot's map (robot_radius %.2f m, inflation_radius %.2f m, goal_tolerance "
      "%.2f m, start_tolerance %.2f m). The binary default: auto without costs (cost_weight 0), "
      "which runs %s with prune and smooth on and smoother none on the binary map (no radius, no "
      "gradient, exact endpoints). Ratios: the default / the binary default, as the ratio of the "
      "sums over a set's queries and the median of the per-query ratios (a set meets a path "
      "target when both do); smoother time ratio: the default / the same with smoother none, "
      "median of per-query ratios. Time: median of %d plans per side, the sides interleaved.\n\n",
      std::string(core::to_string(chosen.planner)).c_str(), options.robot.cost_weight,
      options.robot.robot_radius, options.robot.inflation_radius, options.robot.goal_tolerance,
      options.robot.start_tolerance, std::string(core::to_string(binary.planner)).c_str(),
      options.repetitions);
  std::string text = head + table.str() + "\n";
  if (pooled.compared > 0) {
    text += "Pooled over the " + std::to_string(pooled.compared) +
            " queries, the default configuration's path targets: " + pooled.path_verdict() +
            "; its smoother time ratio: " + format(pooled.overhead, 2) + " (" +
            verdict(overhead_met(pooled.overhead)) + ").\n\n";
  }
  return text;
}

OctomapResult run_octomaps(const CostsOptions& options,
                           const std::vector<core::PlannerKind>& planners,
                           const std::vector<core::PlannerKind>& choice_kinds) {
  OctomapResult out;
  std::optional<SlicedScene> scene = load_sliced(options.scene_path, options.robot, "--scene");
  if (!scene) return out;
  out.loaded = true;
  const core::GridMap& scene_map = *scene->maps[1];
  const Units metres{1.0, 1.0 / scene_map.resolution()};
  const DefaultConfig default_config(options.robot);
  std::vector<core::PlannerOptions> choice_options;
  for (const core::PlannerKind kind : choice_kinds)
    choice_options.push_back(cost_aware_relax_options(kind, options.robot));
  std::vector<DefaultSet> default_routes, default_slices;

  // The demo's routes, as queries of the scene.
  std::vector<core::PlanQuery> route_queries;
  for (const Route& route : kDemoRoutes) {
    const auto start = scene_map.world_to_cell(route.start_x, route.start_y);
    const auto goal = scene_map.world_to_cell(route.goal_x, route.goal_y);
    if (!start || !goal) {
      std::fprintf(stderr, "vnsba_bench costs: route %s lies outside the scene\n", route.name);
      out.ok = false;
      return out;
    }
    route_queries.emplace_back(*start, *goal, scene_map.world_to_grid(route.start_x, route.start_y),
                               scene_map.world_to_grid(route.goal_x, route.goal_y));
  }
  // 0. The default configuration and the choice planners on the demo's routes.
  for (size_t r = 0; r < route_queries.size(); ++r) {
    QueryOutcome q = plan_query(scene->planner_of, route_queries[r], default_config.options,
                                options.repetitions, metres);
    q.label = kDemoRoutes[r].name;
    out.ok &= every_side_found_a_path(
        q, std::string("the default configuration on route ") + kDemoRoutes[r].name);
    default_routes.push_back({kDemoRoutes[r].name, {std::move(q)}});
    out.choice.push_back(plan_each(scene->planner_of[1], route_queries[r], choice_options,
                                   options.repetitions, metres, static_cast<int>(r)));
  }

  // 1. The demo's routes, every planner.
  std::map<core::PlannerKind, std::vector<QueryOutcome>> demo;
  for (const core::PlannerKind kind : planners) {
    core::PlannerOptions plan_options[kSides];
    for (const int side : kAllSides) plan_options[side] = side_options(kind, options.robot, side);
    for (size_t r = 0; r < route_queries.size(); ++r) {
      const Route& route = kDemoRoutes[r];
      QueryOutcome q = plan_query(scene->planner_of, route_queries[r], plan_options,
                                  options.repetitions, metres);
      q.label = route.name;
      out.ok &= every_side_found_a_path(
          q, std::string(core::to_string(kind)) + " on route " + route.name);
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
      scene->name.c_str(), default_slice_band().z_min, default_slice_band().z_max,
      scene->grid.width, scene->grid.height, scene->grid.resolution, options.robot.robot_radius,
      options.robot.inflation_radius, options.robot.cost_scaling_factor, options.robot.cost_weight,
      options.robot.goal_tolerance, options.robot.start_tolerance, options.repetitions);
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
          out.ok &= every_side_found_a_path(
              q, std::string(core::to_string(kind)) + " on " + loaded->name + ", query " +
                     std::to_string(k) + " (cells " + std::to_string(start.x) + "," +
                     std::to_string(start.y) + " -> " + std::to_string(goal.x) + "," +
                     std::to_string(goal.y) + ")");
          run.queries[kind].push_back(std::move(q));
        }
      }
      DefaultSet default_set{loaded->name, {}};
      for (size_t k = 0; k < picked.size(); ++k) {
        const core::PlanQuery query(picked[k].first, picked[k].second);
        QueryOutcome q = plan_query(loaded->planner_of, query, default_config.options,
                                    options.repetitions, units, static_cast<int>(k % kSides));
        out.ok &= every_side_found_a_path(
            q, "the default configuration on " + loaded->name + ", query " + std::to_string(k));
        default_set.queries.push_back(std::move(q));
        out.choice.push_back(plan_each(loaded->planner_of[1], query, choice_options,
                                       options.repetitions, units, static_cast<int>(k)));
      }
      default_slices.push_back(std::move(default_set));
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
  out.default_text = default_config_text(options, default_config, default_routes, default_slices);
  if (slice_runs.empty()) {
    out.text = text + "**Held-in OctoMap slices**: not measured (" +
               (options.slice_queries > 0 ? "no slice loaded" : "--slice-queries 0") + ").\n\n";
    return out;
  }
  text +=
      "**Held-in OctoMap slices** (sliced at " + format(default_slice_band().z_min, 1) + "-" +
      format(default_slice_band().z_max, 1) +
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
  std::map<std::string, ChoiceQueries> choice;  // per class, every choice planner
};

MovingAiResult run_maps(const CostsOptions& options, const std::vector<core::PlannerKind>& planners,
                        const std::vector<core::PlannerKind>& choice_kinds) {
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
      queries_total +=
          static_cast<int64_t>(pick_scenarios(scenarios->size(), options.max_scenarios).size() *
                               (planners.size() + choice_kinds.size()));
  std::vector<core::PlannerOptions> choice_options;
  for (const core::PlannerKind kind : choice_kinds)
    choice_options.push_back(cost_aware_relax_options(kind, options.robot));
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
    // The choice planners, each with auto's cost-aware settings, interleaved query by query.
    if (!picked.empty()) {
      const auto& s = loaded->scenarios[picked.front()];
      for (const core::PlannerOptions& o : choice_options) planner_of[1].plan({s.start, s.goal}, o);
    }
    ChoiceQueries& choice = out.choice[map_class];
    for (size_t k = 0; k < picked.size(); ++k) {
      const maps::MovingAiScenario& s = loaded->scenarios[picked[k]];
      choice.push_back(plan_each(planner_of[1], {s.start, s.goal}, choice_options, 0, cells,
                                 static_cast<int>(k)));
      queries_done += static_cast<int64_t>(choice_options.size());
      progress.update(queries_done);
    }
    std::fprintf(stderr,
                 "%s (%s): %zu scenarios x (%zu planners x 3 sides + %zu cost-aware planners)\n",
                 loaded->name.c_str(), map_class.c_str(), picked.size(), planners.size(),
                 choice_options.size());
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
    // Both sides' times are in the same query order (one entry per query and side).
    const double per_query_ratio = median_of_ratios(astar_time[kCostAware], astar_time[kBinary]);
    const double total_ratio = sum_of(astar_time[kCostAware]) / sum_of(astar_time[kBinary]);
    const double median_ratio = median(astar_time[kCostAware]) / median(astar_time[kBinary]);
    const double expanded_ratio =
        sum_of(astar_expanded[kCostAware]) / sum_of(astar_expanded[kBinary]);
    // Time per expanded node: what "only the move cost changes" costs, apart from the larger
    // search that a heuristic blind to costs (octile distance) leaves A* to do.
    const double per_expansion_ratio = total_ratio / expanded_ratio;
    char line[1024];
    std::snprintf(line, sizeof line,
                  "Cost-aware A* / binary A* time over all %zu queries: %.2f per query (the "
                  "median of per-query ratios; target at most 1.3: %s), %.2f in total, %.2f as "
                  "the ratio of median times. It expands %.2f times the nodes "
                  "(the octile heuristic cannot see costs, so every node whose detour costs less "
                  "than the optimal path's cost penalty is expanded); per expanded node it takes "
                  "%.2f times binary A*'s time.\n\n",
                  astar_time[kBinary].size(), per_query_ratio,
                  per_query_ratio <= 1.3 ? "met" : "**missed**", total_ratio, median_ratio,
                  expanded_ratio, per_expansion_ratio);
    text += line;
  }
  out.text = text;
  return out;
}

// --- The choice table ---------------------------------------------------------------------------

std::string choice_text(const CostsOptions& options, const std::vector<core::PlannerKind>& kinds,
                        const ChoiceQueries& octomaps,
                        const std::map<std::string, ChoiceQueries>& classes) {
  const std::string reference(core::to_string(kChoiceReference));
  MarkdownTable table({"query set", "planner", "queries (failed)",
                       "time / " + reference + "'s, median of per-query ratios",
                       "ratio of median times", "time median (ms)",
                       "length / " + reference + "'s (ratio of sums)",
                       "turn angle / " + reference + "'s (ratio of sums)"});
  auto add = [&](const std::string& name, const std::vector<const ChoiceQueries*>& sets) {
    for (size_t i = 0; i < kinds.size(); ++i) {
      const ChoiceStats s = choice_stats(sets, i);
      std::string queries = std::to_string(s.queries);
      if (s.failed > 0) queries += " (**failed** " + std::to_string(s.failed) + ")";
      table.add_row({name, std::string(core::to_string(kinds[i])), queries, format(s.time_ratio, 2),
                     format(s.median_time_ratio, 2), format(s.median_time_us / 1000.0, 3),
                     format(s.length_ratio, 3), ratio_text(s.angle_ratio, 2)});
    }
  };
  add("demo routes + slices", {&octomaps});
  std::vector<const ChoiceQueries*> all_classes;
  for (const auto& [name, queries] : classes) {
    add("Moving AI " + name, {&queries});
    all_classes.push_back(&queries);
  }
  if (!all_classes.empty()) add("Moving AI, all classes", all_classes);
  char head[2048];
  std::snprintf(
      head, sizeof head,
      "**Choosing the cost-aware planner of auto** (core::kCostAwareChoice): every cost-aware "
      "planner with the default configuration's cost-aware settings (the robot's costs and "
      "tolerances, prune and smooth on, smoother relax; each planner's own neighbourhood: "
      "vns_bastar 8-11-13, the others 8), only the planner differing, on the same queries, "
      "interleaved query by query: the demo's routes and the slices' queries (on the robot's "
      "map; time the median of %d plans) and the Moving AI scenarios (cost_weight %.1f and the "
      "gradient, no radius; one timed plan per query and planner). jps plans on uniform costs "
      "only and is no candidate. The headline is the median over queries of (the planner's time "
      "/ %s's time on the same query); the ratio of median times is given beside it. Length and "
      "turn angle: the ratio of the sums over the queries both solved.\n\n",
      options.repetitions, options.robot.cost_weight, reference.c_str());
  return head + table.str() + "\n";
}

// config/default.yaml as the node reads it (compiled into the config library). It always loads: a
// default.yaml that did not would fail the build's own config tests first.
const node::NodeConfig& default_yaml_config() {
  static const node::NodeConfig config = [] {
    const node::ConfigResult defaults = node::default_config();
    if (!defaults.config) {
      for (const std::string& error : defaults.errors) std::fprintf(stderr, "%s\n", error.c_str());
      std::abort();
    }
    return *defaults.config;
  }();
  return config;
}

}  // namespace

const RobotSettings& default_yaml_robot() {
  static const RobotSettings robot = [] {
    const node::NodeConfig& c = default_yaml_config();
    const core::PlannerOptions planner = c.planner.options();
    return RobotSettings{c.map.robot_radius,  c.map.inflation_radius, c.map.cost_scaling_factor,
                         planner.cost_weight, planner.goal_tolerance, planner.start_tolerance};
  }();
  return robot;
}

const SliceBand& default_slice_band() {
  static const SliceBand band{default_yaml_config().slicer.z_min,
                              default_yaml_config().slicer.z_max};
  return band;
}

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

core::PlannerOptions cost_aware_relax_options(core::PlannerKind kind, const RobotSettings& robot) {
  core::PlannerSettings settings = planner_settings(robot);
  settings.smoother = core::PathSmoother::kRelax;
  return core::make_options(kind, core::with_auto_defaults(settings));  // auto's, for `kind`
}

core::PlannerOptions default_config_options(const RobotSettings& robot,
                                            core::PathSmoother smoother) {
  core::PlannerSettings settings = planner_settings(robot);
  settings.smoother = smoother;
  return core::make_auto_options(settings);  // as the node reads `name: auto`
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
  const std::vector<core::PlannerKind> choice_kinds = choice_planners(planners);
  const OctomapResult octomaps = run_octomaps(options, planners, choice_kinds);
  if (!octomaps.loaded) return kExitBadInput;  // the scene could not be loaded
  const MovingAiResult maps = run_maps(options, planners, choice_kinds);
  std::printf("%s", octomaps.default_text.c_str());
  std::printf("%s", choice_text(options, choice_kinds, octomaps.choice, maps.choice).c_str());
  std::printf("%s", octomaps.text.c_str());
  if (maps.ran) std::printf("%s", maps.text.c_str());
  return octomaps.ok && maps.ok ? kExitOk : kExitFailure;
}

}  // namespace vnsba::bench
