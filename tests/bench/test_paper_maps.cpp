// The paper's maps in bench/maps/paper: they load, start and goal are where the paper puts them
// and connected, the scenario's optimum (written by an independent Dijkstra) matches A*, and every
// planner plans a collision-free path on each, in the paper's configuration and with our
// post-processing.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "bench/common.hpp"
#include "bench/sweep.hpp"
#include "vnsba/core/line_of_sight.hpp"
#include "vnsba/core/planner.hpp"

namespace vnsba::test {
namespace {

using core::PlannerKind;

struct PaperMapSpec {
  std::string name;
  int size;  // cells per side
};

const std::vector<PaperMapSpec> kPaperMaps = {{"A", 20},
                                              {"B", 40},
                                              {"C", 60},
                                              {"D", 80},
                                              {"sweep_simple", 40},
                                              {"sweep_middle", 40},
                                              {"sweep_bars", 40},
                                              {"sweep_random", 40}};

bench::LoadedMap load(const std::string& name) {
  auto loaded = bench::load_map_with_scenarios(VNSBA_PAPER_MAPS_DIR "/" + name + ".map");
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error().message);
  return loaded ? std::move(loaded).value() : bench::LoadedMap{};
}

TEST(PaperMaps, LoadWithStartAndGoalAtOppositeCornersAndTheirOptimum) {
  for (const auto& spec : kPaperMaps) {
    SCOPED_TRACE(spec.name);
    const bench::LoadedMap m = load(spec.name);
    ASSERT_TRUE(m.map);
    EXPECT_EQ(m.map->width(), spec.size);
    EXPECT_EQ(m.map->height(), spec.size);
    EXPECT_GT(m.map->blocked_count(), 0) << "a paper map without obstacles";
    ASSERT_EQ(m.scenarios.size(), 1u);
    const auto& s = m.scenarios.front();
    // Bottom-left to top-right (rows counted from the bottom).
    EXPECT_EQ(s.start, (core::Cell{0, 0}));
    EXPECT_EQ(s.goal, (core::Cell{spec.size - 1, spec.size - 1}));
    EXPECT_TRUE(m.map->free(s.start));
    EXPECT_TRUE(m.map->free(s.goal));
    // The optimum in the file comes from the generator's own Dijkstra: A* must agree, which
    // also proves start and goal connected.
    core::Planner planner(m.map);
    const auto r = planner.plan({s.start, s.goal}, core::default_options(PlannerKind::kAStar));
    ASSERT_TRUE(r.status.is_ok()) << r.status.message;
    EXPECT_NEAR(r.metrics.raw_cost_cells, s.optimal_length, 1e-6);
  }
}

TEST(PaperMaps, RandomSweepMapHasTwentyPercentDensity) {
  const bench::LoadedMap m = load("sweep_random");
  ASSERT_TRUE(m.map);
  const double density =
      static_cast<double>(m.map->blocked_count()) / static_cast<double>(m.map->cell_count());
  EXPECT_NEAR(density, 0.20, 0.02);
}

// Every segment of a continuous path stays in free cells (the one line-of-sight implementation)
// and every point is inside the map.
void expect_collision_free(const core::GridMap& map, const std::vector<core::Point2>& path,
                           core::CornerPolicy policy) {
  for (size_t i = 0; i < path.size(); ++i) {
    EXPECT_GE(path[i].x(), 0.0);
    EXPECT_GE(path[i].y(), 0.0);
    EXPECT_LE(path[i].x(), map.width());
    EXPECT_LE(path[i].y(), map.height());
    if (i > 0) {
      EXPECT_TRUE(core::line_of_sight(map, path[i - 1], path[i], policy))
          << "segment " << i - 1 << " (" << path[i - 1].transpose() << ") -> ("
          << path[i].transpose() << ") crosses a blocked cell";
    }
  }
}

TEST(PaperMaps, EveryPlannerSucceedsWithCollisionFreePaths) {
  for (const auto& spec : kPaperMaps) {
    const bench::LoadedMap m = load(spec.name);
    ASSERT_TRUE(m.map);
    const auto& s = m.scenarios.front();
    core::Planner planner(m.map);
    for (const auto kind : core::all_planner_kinds()) {
      for (const bool post_processed : {false, true}) {
        SCOPED_TRACE(spec.name + " " + std::string(core::to_string(kind)) +
                     (post_processed ? " +prune+smooth" : " paper"));
        core::PlannerOptions options = core::default_options(kind);
        if (post_processed) options.prune = options.smooth = true;
        options.compute_length_ratio = true;
        const auto r = planner.plan({s.start, s.goal}, options);
        ASSERT_TRUE(r.status.is_ok()) << r.status.message;
        ASSERT_FALSE(r.raw_path.empty());
        EXPECT_EQ(r.raw_path.front(), s.start);
        EXPECT_EQ(r.raw_path.back(), s.goal);
        for (const auto& c : r.raw_path) EXPECT_TRUE(m.map->free(c));
        ASSERT_GE(r.path.size(), 2u);
        EXPECT_NEAR((r.path.front() - core::cell_centre(s.start)).norm(), 0.0, 1e-9);
        EXPECT_NEAR((r.path.back() - core::cell_centre(s.goal)).norm(), 0.0, 1e-9);
        expect_collision_free(*m.map, r.path, options.corner_policy);
        expect_collision_free(*m.map, r.waypoints, options.corner_policy);
        // No path is shorter than the straight line; an 8-connected grid path is never cheaper
        // than the optimal one (the 8-11-13 moves and pruning may be, by cutting corners).
        const double straight = (core::cell_centre(s.goal) - core::cell_centre(s.start)).norm();
        EXPECT_GE(r.metrics.length_cells, straight - 1e-9);
        if (options.neighborhood == core::Neighborhood::kEight) {
          EXPECT_GE(r.metrics.raw_cost_cells / s.optimal_length, 1.0 - 1e-9);
        }
        EXPECT_TRUE(std::isfinite(r.metrics.length_ratio));
        EXPECT_GT(r.metrics.expanded, 0);
      }
    }
  }
}

TEST(PaperMaps, SweepMapNamesMatchTheFiles) {
  for (const auto& name : bench::sweep_map_names()) {
    auto loaded = bench::load_map_with_scenarios(VNSBA_PAPER_MAPS_DIR "/" + name + ".map");
    EXPECT_TRUE(loaded) << name;
  }
}

}  // namespace
}  // namespace vnsba::test
