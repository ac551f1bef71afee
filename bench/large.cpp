#include "bench/large.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bench/common.hpp"
#include "vnsba/core/planner_options.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/render/progress.hpp"

namespace vnsba::bench {

namespace {

constexpr int kSourceSize = 512;  // cells a side of every source map

struct LargeMapSpec {
  const char* name;       // Moving AI map, kSourceSize a side
  const char* map_class;  // as `vnsba_bench movingai` names it
  Growth growth;
};
constexpr LargeMapSpec kLargeMaps[] = {
    {"Boston_0_512", "street", Growth::kScaled},
    {"16room_000", "room", Growth::kScaled},
    {"random512-20-0", "random", Growth::kTiled},
};

// A scenario's query on the grown map (see large.hpp).
core::PlanQuery grown_query(const maps::MovingAiScenario& s, int factor, Growth growth,
                            int32_t source_width, int32_t source_height) {
  if (growth == Growth::kScaled) {
    auto centre = [&](const core::Cell& c) {
      return core::Cell{c.x * factor + factor / 2, c.y * factor + factor / 2};
    };
    return {centre(s.start), centre(s.goal)};
  }
  const core::Cell last_copy{(factor - 1) * source_width, (factor - 1) * source_height};
  return {s.start, {s.goal.x + last_copy.x, s.goal.y + last_copy.y}};
}

struct Sample {
  std::vector<double> time_us;
  std::vector<double> expanded;
  int failures = 0;
};

}  // namespace

// The source grid grown to `factor` times its side, either way (see large.hpp). Resolution and
// origin are irrelevant to planning in cells; the slice is given 5 cm cells, as an office's.
core::OccupancyGrid grow_grid(const core::OccupancyGrid& source, int factor, Growth growth) {
  core::OccupancyGrid g;
  g.width = source.width * factor;
  g.height = source.height * factor;
  g.resolution = 0.05;
  g.data.resize(static_cast<size_t>(g.width) * g.height);
  for (int32_t y = 0; y < g.height; ++y)
    for (int32_t x = 0; x < g.width; ++x)
      g.data[static_cast<size_t>(y) * g.width + x] =
          growth == Growth::kScaled ? source.at(x / factor, y / factor)
                                    : source.at(x % source.width, y % source.height);
  return g;
}

int run_large(const LargeOptions& options) {
  const std::vector<core::PlannerKind> planners =
      options.planners.empty()
          ? std::vector<core::PlannerKind>{core::PlannerKind::kAStar, core::PlannerKind::kJps,
                                           core::PlannerKind::kVnsBaStar}
          : options.planners;
  if (options.queries < 1) {
    std::fprintf(stderr, "vnsba_bench large: --queries must be >= 1, got %d\n", options.queries);
    return kExitBadInput;
  }
  for (const int size : options.sizes) {
    if (size < kSourceSize || size % kSourceSize != 0 || size > 16384) {
      std::fprintf(
          stderr, "vnsba_bench large: --sizes: %d is not a multiple of %d cells from %d to 16384\n",
          size, kSourceSize, kSourceSize);
      return kExitBadInput;
    }
  }
  std::vector<std::string> headers = {"map",    "cells",         "planner",       "queries",
                                      "failed", "time p50 (ms)", "time p95 (ms)", "expanded p50"};
  const bool with_astar =
      std::find(planners.begin(), planners.end(), core::PlannerKind::kAStar) != planners.end();
  if (with_astar) headers.push_back("p50 / A*'s");
  MarkdownTable table(headers);
  bool all_ok = true;
  // The plans to come, for the progress line (a scenario file that does not load counts 0 and
  // fails below).
  int64_t plans_total = 0;
  for (const LargeMapSpec& spec : kLargeMaps)
    if (const auto scenarios =
            maps::load_movingai_scenarios(options.maps_dir + "/" + spec.name + ".map.scen"))
      plans_total +=
          static_cast<int64_t>(pick_scenarios(scenarios->size(), options.queries).size() *
                               planners.size() * options.sizes.size());
  render::Progress progress("vnsba_bench large", plans_total,
                            render::progress_wanted(options.progress));
  int64_t plans_done = 0;
  for (const LargeMapSpec& spec : kLargeMaps) {
    auto loaded = load_map_with_scenarios(options.maps_dir + "/" + spec.name + ".map");
    if (!loaded) {
      std::fprintf(stderr, "vnsba_bench large: %s\n", loaded.error().message.c_str());
      return kExitBadInput;
    }
    if (loaded->grid.width != kSourceSize || loaded->grid.height != kSourceSize) {
      std::fprintf(stderr, "vnsba_bench large: %s is %d x %d cells, expected %d x %d\n", spec.name,
                   loaded->grid.width, loaded->grid.height, kSourceSize, kSourceSize);
      return kExitBadInput;
    }
    for (const int size : options.sizes) {
      const int factor = size / kSourceSize;
      core::GridBuildOptions build;
      build.max_cells = int64_t{size} * size;
      auto built = core::GridMap::build(grow_grid(loaded->grid, factor, spec.growth), build);
      if (!built) {
        std::fprintf(stderr, "vnsba_bench large: %s at %d: %s\n", spec.name, size,
                     built.error().message.c_str());
        return kExitBadInput;
      }
      auto map = std::make_shared<const core::GridMap>(std::move(built).value());
      core::Planner planner(map);  // allocates the search state once, as the node does
      std::vector<core::PlanQuery> queries;
      for (const size_t i : pick_scenarios(loaded->scenarios.size(), options.queries))
        queries.push_back(grown_query(loaded->scenarios[i], factor, spec.growth, loaded->grid.width,
                                      loaded->grid.height));
      std::fprintf(stderr, "%s %s x%d (%d x %d): %zu queries\n", spec.name,
                   spec.growth == Growth::kScaled ? "scaled" : "tiled", factor, size, size,
                   queries.size());
      std::vector<Sample> samples(planners.size());
      // Interleaved by query, so that a slow moment of the machine hits every planner alike.
      for (const core::PlanQuery& q : queries) {
        std::vector<bool> found;
        for (size_t p = 0; p < planners.size(); ++p) {
          const TimedPlan timed = timed_plan(planner, q, core::make_options(planners[p], {}));
          samples[p].time_us.push_back(timed.time_us);
          samples[p].expanded.push_back(static_cast<double>(timed.result.metrics.expanded));
          found.push_back(timed.result.status.is_ok());
          if (!found.back()) ++samples[p].failures;
          progress.update(++plans_done);
        }
        // Every planner here is complete: all find a path or none does (a tiled query's two
        // copies may not be connected). Anything else is a planner's failure.
        if (std::adjacent_find(found.begin(), found.end(), std::not_equal_to<>()) != found.end()) {
          std::fprintf(stderr, "vnsba_bench large: planners disagree on (%d, %d) -> (%d, %d)\n",
                       q.start.x, q.start.y, q.goal.x, q.goal.y);
          all_ok = false;
        }
      }
      double astar_p50 = NAN;
      for (size_t p = 0; p < planners.size(); ++p)
        if (planners[p] == core::PlannerKind::kAStar) astar_p50 = median(samples[p].time_us);
      for (size_t p = 0; p < planners.size(); ++p) {
        const Sample& s = samples[p];
        std::vector<std::string> row = {std::string(spec.name) + " (" + spec.map_class + ", " +
                                            (spec.growth == Growth::kScaled ? "scaled" : "tiled") +
                                            ")",
                                        std::to_string(size) + "²",
                                        std::string(core::to_string(planners[p])),
                                        std::to_string(s.time_us.size()),
                                        std::to_string(s.failures),
                                        format(median(s.time_us) / 1000.0, 2),
                                        format(percentile(s.time_us, 95) / 1000.0, 2),
                                        format(median(s.expanded), 0)};
        if (with_astar) row.push_back(format(median(s.time_us) / astar_p50, 4));
        table.add_row(row);
      }
    }
  }
  progress.finish(plans_done);
  std::printf(
      "**Large maps.** Planning time per query (search and each planner's paper "
      "configuration of pruning and smoothing), p50 and p95 over the same queries, "
      "planners interleaved query by query.\n\n%s\n",
      table.str().c_str());
  return all_ok ? kExitOk : kExitFailure;
}

}  // namespace vnsba::bench
