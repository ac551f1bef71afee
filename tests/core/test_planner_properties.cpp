// Property test over thousands of random maps (docs/algorithm.md, issue acceptance list): for every
// planner, success exactly when a path exists; raw paths connected, collision-free and within the
// map; 8-neighbourhood paths never shorter than the optimum and A* equal to it; pruned and
// smoothed paths never entering a blocked cell. Every check uses the oracles of test_support.hpp,
// not the code under test.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "core/test_support.hpp"
#include "vnsba/core/planner.hpp"

namespace vnsba::test {
namespace {

using core::PlannerKind;
using core::PlannerOptions;
using core::PlanResult;

constexpr int kRandomMaps = 2000;

// "" when no cell occurs twice in `path`, else the cell and its two positions.
std::string first_revisit(const std::vector<Cell>& path) {
  std::map<std::pair<int32_t, int32_t>, size_t> seen;
  for (size_t i = 0; i < path.size(); ++i) {
    const auto [it, fresh] = seen.emplace(std::make_pair(path[i].x, path[i].y), i);
    if (!fresh) {
      return "cell (" + std::to_string(path[i].x) + ", " + std::to_string(path[i].y) +
             ") at steps " + std::to_string(it->second) + " and " + std::to_string(i);
    }
  }
  return "";
}

struct Tally {
  int solvable = 0, unsolvable = 0, checked_plans = 0, smoothed_corners = 0;
};

void check_plan(const GridMap& map, const core::PlanQuery& q, const PlannerOptions& o,
                const PlanResult& r, bool reachable, double optimal, Tally& tally,
                const std::string& where) {
  SCOPED_TRACE(where + " planner " + std::string(core::to_string(o.planner)));
  ASSERT_EQ(r.status.is_ok(), reachable) << r.status.message;
  if (!reachable) {
    ASSERT_EQ(r.status.code, core::StatusCode::kNoValidPath);
    return;
  }
  ++tally.checked_plans;
  // Raw path: from start to goal, steps of Chebyshev length 1 or 2, each with exact sight.
  ASSERT_FALSE(r.raw_path.empty());
  ASSERT_EQ(r.raw_path.front(), q.start);
  ASSERT_EQ(r.raw_path.back(), q.goal);
  double raw_cost = 0.0;
  for (size_t i = 1; i < r.raw_path.size(); ++i) {
    const Cell a = r.raw_path[i - 1], b = r.raw_path[i];
    const int cheb = std::max(std::abs(a.x - b.x), std::abs(a.y - b.y));
    ASSERT_TRUE(cheb == 1 || cheb == 2) << "step " << i;
    if (o.neighborhood == core::Neighborhood::kEight) {
      ASSERT_EQ(cheb, 1);
    }
    ASSERT_TRUE(reference_los_centres(map, a, b, o.corner_policy)) << "step " << i;
    raw_cost += std::hypot(a.x - b.x, a.y - b.y);
  }
  ASSERT_NEAR(r.metrics.raw_cost_cells, raw_cost, 1e-9);
  ASSERT_EQ(first_revisit(r.raw_path), "");
  if (o.neighborhood == core::Neighborhood::kEight) {
    ASSERT_GE(raw_cost, optimal - 1e-9);
  }
  if (o.planner == PlannerKind::kAStar || o.planner == PlannerKind::kJps) {  // the exact ones
    ASSERT_NEAR(raw_cost, optimal, 1e-9 * std::max(1.0, optimal));
  }
  // Pruned waypoints: a subsequence of the raw path's centres, each leg with exact sight.
  size_t cursor = 0;
  for (const Point2& w : r.waypoints) {
    while (cursor < r.raw_path.size() && core::cell_centre(r.raw_path[cursor]) != w) ++cursor;
    ASSERT_LT(cursor, r.raw_path.size()) << "waypoint " << w.transpose() << " not on the raw path";
  }
  for (size_t i = 1; i < r.waypoints.size(); ++i) {
    const Cell a{int(std::floor(r.waypoints[i - 1].x())), int(std::floor(r.waypoints[i - 1].y()))};
    const Cell b{int(std::floor(r.waypoints[i].x())), int(std::floor(r.waypoints[i].y()))};
    ASSERT_TRUE(reference_los_centres(map, a, b, o.corner_policy));
  }
  // Final path: starts and ends at the centres, never enters a blocked cell (dense sampling).
  ASSERT_EQ(r.path.front(), core::cell_centre(q.start));
  ASSERT_EQ(r.path.back(), core::cell_centre(q.goal));
  for (size_t i = 1; i < r.path.size(); ++i) {
    ASSERT_TRUE(std::isfinite(r.path[i].x()) && std::isfinite(r.path[i].y()));
    ASSERT_TRUE(segment_clear_sampled(map, r.path[i - 1], r.path[i], o.corner_policy, 32))
        << "final path segment " << i << ": " << r.path[i - 1].transpose() << " -> "
        << r.path[i].transpose();
  }
  if (o.smooth && r.path.size() > r.waypoints.size()) ++tally.smoothed_corners;
  ASSERT_EQ(r.world_path.size(), r.path.size());
  if (q.start != q.goal) {
    ASSERT_GT(r.metrics.expanded, 0);
  }
}

TEST(PlannerProperties, RandomMapsAllPlannersAllCornerPolicies) {
  std::mt19937 rng(20241029);
  std::uniform_int_distribution<int> size(8, 200);
  std::uniform_real_distribution<double> density(0.0, 0.45);
  Tally tally;
  for (int m = 0; m < kRandomMaps; ++m) {
    const int w = size(rng), h = size(rng);
    auto built = GridMap::from_rows(random_rows(rng, w, h, density(rng)));
    ASSERT_TRUE(built);
    auto map = std::make_shared<const GridMap>(std::move(built).value());
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    std::uniform_int_distribution<size_t> pick(0, cells.size() - 1);
    const core::PlanQuery q{cells[pick(rng)], cells[pick(rng)]};
    const CornerPolicy policy = kAllCornerPolicies[m % 3];
    const double optimal = reference_shortest_cost(*map, q.start, q.goal, policy);
    const bool reachable = std::isfinite(optimal);
    (reachable ? tally.solvable : tally.unsolvable)++;
    core::Planner planner(map);
    for (PlannerKind kind : core::all_planner_kinds()) {
      // The paper's configuration, and every planner with pruning and smoothing on too.
      for (bool post : {false, true}) {
        PlannerOptions o = core::default_options(kind);
        o.corner_policy = policy;
        if (post) o.prune = o.smooth = true;
        if (post && kind == PlannerKind::kVnsBaStar) o.neighborhood = core::Neighborhood::kEight;
        const PlanResult r = planner.plan(q, o);
        if (!core::supports(kind, policy)) {  // jps with touch or always: refused, by name
          ASSERT_EQ(r.status.code, core::StatusCode::kInvalidRequest);
          ASSERT_NE(r.status.message.find("corner_policy"), std::string::npos);
          continue;
        }
        check_plan(
            *map, q, o, r, reachable, optimal, tally,
            "map " + std::to_string(m) + " (" + std::to_string(w) + "x" + std::to_string(h) + ")");
        if (::testing::Test::HasFatalFailure()) return;
      }
    }
  }
  // The sample must exercise both outcomes and real smoothing for the properties to mean much.
  EXPECT_GT(tally.solvable, kRandomMaps / 3);
  EXPECT_GT(tally.unsolvable, kRandomMaps / 20);
  EXPECT_GT(tally.smoothed_corners, kRandomMaps);
}

// docs/algorithm.md section 3: the joined raw path of a bidirectional search never visits a cell
// twice, also with the asymmetric 8-11-13 moves (where a search can pop a node the other has
// closed without any generated neighbour showing it). 50,000+ plans: every planner in both
// neighbourhoods and every corner policy, on small random maps (narrow ones too, where the two
// searches meet in corridors).
TEST(PlannerProperties, RawPathsNeverVisitACellTwice) {
  std::mt19937 rng(108014);
  std::uniform_int_distribution<int> size(4, 110);
  std::uniform_real_distribution<double> density(0.0, 0.4);
  int plans = 0, paths = 0;
  while (plans < 51000) {
    auto map = random_shared_map(rng, size(rng), size(rng), density(rng));
    ASSERT_TRUE(map);
    const auto cells = free_cells(*map);
    if (cells.size() < 2) continue;
    std::uniform_int_distribution<size_t> pick(0, cells.size() - 1);
    core::Planner planner(map);
    for (int query = 0; query < 4; ++query) {
      const core::PlanQuery q{cells[pick(rng)], cells[pick(rng)]};
      for (PlannerKind kind : core::all_planner_kinds()) {
        for (core::Neighborhood hood :
             {core::Neighborhood::kEight, core::Neighborhood::kEightElevenThirteen}) {
          for (CornerPolicy policy : kAllCornerPolicies) {
            PlannerOptions o = core::default_options(kind);
            o.corner_policy = policy;
            o.neighborhood = hood;
            o.prune = o.smooth = false;
            if (!core::supports(kind, policy) || !core::supports(kind, hood)) continue;
            const PlanResult r = planner.plan(q, o);
            ++plans;
            if (!r.status.is_ok()) continue;
            ++paths;
            ASSERT_EQ(first_revisit(r.raw_path), "")
                << core::to_string(kind) << " " << core::to_string(hood) << " "
                << core::to_string(policy) << " on a " << map->width() << " x " << map->height()
                << " map, start (" << q.start.x << ", " << q.start.y << "), goal (" << q.goal.x
                << ", " << q.goal.y << ")";
          }
        }
      }
    }
  }
  EXPECT_GT(paths, plans / 3);
}

}  // namespace
}  // namespace vnsba::test
