// VNS-BA* with its two searches on two threads (vns_threads 2) against the same planner on one
// (the oracle: the strict alternation of docs/algorithm.md section 3): every output but the time
// must be equal, field by field, on random maps with obstacles, unknown cells and costs, under
// every option set; on the Moving AI maps (label data); after stopped and canceled searches.
// Each test also checks that the second thread really took part (Planner::searches_shared), so
// that it cannot pass by running everything on one thread.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>
#include <thread>

#include "core/test_support.hpp"
#ifndef VNSBA_THREAD_SANITIZER
#include "core/movingai_support.hpp"
#endif
#include "vnsba/core/planner.hpp"

namespace vnsba::test {
namespace {

using core::CornerPolicy;
using core::GridBuildOptions;
using core::Neighborhood;
using core::OccupancyGrid;
using core::PlannerKind;
using core::PlannerOptions;
using core::PlanResult;

// Under ThreadSanitizer (vnsba_core_tsan_tests) every run is several times slower: fewer maps and
// rounds there, the same checks; and no Moving AI test, which needs vnsba::maps on the
// uninstrumented core.
#ifdef VNSBA_THREAD_SANITIZER
constexpr int kSlowdown = 2;
#else
constexpr int kSlowdown = 1;
#endif

// Equal as numbers, NaN equal to NaN (length_ratio and clearance are NaN where not measured).
bool same_number(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

template <class T>
std::string first_difference(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size())
    return "sizes " + std::to_string(a.size()) + " and " + std::to_string(b.size());
  for (size_t i = 0; i < a.size(); ++i)
    if (!(a[i] == b[i])) return "element " + std::to_string(i);
  return "";
}

// Every output of a plan but its time.
void expect_same_plan(const PlanResult& one, const PlanResult& two, const std::string& where) {
  SCOPED_TRACE(where);
  EXPECT_EQ(one.status.code, two.status.code);
  EXPECT_EQ(one.status.message, two.status.message);
  EXPECT_EQ(one.planner, two.planner);
  const core::Endpoints &e1 = one.endpoints, &e2 = two.endpoints;
  EXPECT_TRUE(e1.start == e2.start && e1.goal == e2.goal &&
              e1.start_adjusted == e2.start_adjusted && e1.goal_adjusted == e2.goal_adjusted &&
              same_number(e1.start_moved_m, e2.start_moved_m) &&
              same_number(e1.goal_moved_m, e2.goal_moved_m) && e1.start_point == e2.start_point &&
              e1.goal_point == e2.goal_point);
  EXPECT_EQ(first_difference(one.raw_path, two.raw_path), "") << "raw path";
  EXPECT_EQ(first_difference(one.waypoints, two.waypoints), "") << "pruned path";
  EXPECT_EQ(first_difference(one.path, two.path), "") << "final path";
  EXPECT_EQ(first_difference(one.world_path, two.world_path), "") << "world path";
  EXPECT_EQ(first_difference(one.expanded_forward, two.expanded_forward), "") << "forward trace";
  EXPECT_EQ(first_difference(one.expanded_backward, two.expanded_backward), "") << "backward trace";
  EXPECT_EQ(one.meeting_cell.has_value(), two.meeting_cell.has_value());
  if (one.meeting_cell && two.meeting_cell) {
    EXPECT_EQ(*one.meeting_cell, *two.meeting_cell);
  }
  const core::Metrics &m1 = one.metrics, &m2 = two.metrics;
  EXPECT_EQ(m1.expanded, m2.expanded);
  EXPECT_EQ(m1.turns, m2.turns);
  EXPECT_TRUE(same_number(m1.length_cells, m2.length_cells));
  EXPECT_TRUE(same_number(m1.length_m, m2.length_m));
  EXPECT_TRUE(same_number(m1.raw_cost_cells, m2.raw_cost_cells));
  EXPECT_TRUE(same_number(m1.turn_angle_deg, m2.turn_angle_deg));
  EXPECT_TRUE(same_number(m1.length_ratio, m2.length_ratio));
  EXPECT_TRUE(same_number(m1.clearance_m, m2.clearance_m));
}

// A map of rooms and corridors: random walls with gaps, scattered obstacles, unknown cells and
// graded values; with an inflation gradient when `costs` (so cost_weight weighs something).
std::shared_ptr<const core::GridMap> random_building(std::mt19937& rng, int width, int height,
                                                     bool costs) {
  OccupancyGrid grid;
  grid.width = width;
  grid.height = height;
  grid.resolution = 0.1;
  grid.data.assign(static_cast<size_t>(width) * height, core::kOccupancyFree);
  auto at = [&](int x, int y) -> int8_t& { return grid.data[static_cast<size_t>(y) * width + x]; };
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // Walls every 20 to 40 cells, each with a gap of 4 cells per 15 cells of its length.
  for (int pass = 0; pass < 2; ++pass) {
    const int length = pass == 0 ? height : width, across = pass == 0 ? width : height;
    for (int wall = 10 + static_cast<int>(rng() % 20); wall < across - 5;
         wall += 20 + static_cast<int>(rng() % 20)) {
      for (int i = 0; i < length; ++i) (pass == 0 ? at(wall, i) : at(i, wall)) = 100;
      for (int gap = 0; gap < length / 15; ++gap) {
        const int from = static_cast<int>(rng() % static_cast<unsigned>(length - 6));
        for (int i = from; i < from + 4; ++i) (pass == 0 ? at(wall, i) : at(i, wall)) = 0;
      }
    }
  }
  for (int8_t& v : grid.data) {
    const double u = unit(rng);
    if (u < 0.05)
      v = 100;
    else if (u < 0.06)
      v = core::kOccupancyUnknown;
    else if (costs && u < 0.20 && v == 0)
      v = static_cast<int8_t>(1 + rng() % 60);
  }
  GridBuildOptions options;
  if (costs) {
    options.inflation_radius = 0.4;
    options.cost_scaling_factor = 6.0;
  }
  auto built = core::GridMap::build(grid, options);
  if (!built) {
    ADD_FAILURE() << built.error().message;
    return nullptr;
  }
  return std::make_shared<const core::GridMap>(std::move(built).value());
}

// The option sets: the paper's configuration, its variants, the cost-aware path and the
// debug outputs (traces, the length ratio's second search).
std::vector<std::pair<std::string, PlannerOptions>> option_sets() {
  std::vector<std::pair<std::string, PlannerOptions>> sets;
  PlannerOptions paper = core::default_options(PlannerKind::kVnsBaStar);
  paper.record_expansions = true;
  sets.emplace_back("paper configuration, traces", paper);
  PlannerOptions eight = paper;
  eight.neighborhood = Neighborhood::kEight;
  eight.corner_policy = CornerPolicy::kTouch;
  eight.prune = eight.smooth = false;
  sets.emplace_back("8-neighbourhood, corners touch, raw path", eight);
  PlannerOptions costs = paper;
  costs.cost_weight = 2.0;
  costs.smoother = core::PathSmoother::kRelax;
  costs.goal_tolerance = 0.3;
  costs.start_tolerance = 0.2;
  sets.emplace_back("costs, relax, tolerances", costs);
  PlannerOptions weights = paper;
  weights.omega = 2.0;
  weights.eta = 0.1;
  weights.corner_policy = CornerPolicy::kAlways;
  weights.record_expansions = false;
  weights.compute_length_ratio = true;
  sets.emplace_back("other weights, corners always, length ratio, no traces", weights);
  return sets;
}

TEST(VnsThreads, TwoThreadsPlanExactlyAsOneOnRandomBuildings) {
  std::mt19937 rng(20261206);
  core::Planner* shared_counter = nullptr;
  int64_t shared = 0, plans = 0, found = 0;
  for (int trial = 0; trial < 8 / kSlowdown; ++trial) {
    const bool costs = trial % 2 == 1;
    const auto map = random_building(rng, 160 + static_cast<int>(rng() % 160),
                                     160 + static_cast<int>(rng() % 160), costs);
    ASSERT_NE(map, nullptr);
    core::Planner one(map), two(map);
    shared_counter = &two;
    std::uniform_int_distribution<int> xs(0, map->width() - 1), ys(0, map->height() - 1);
    for (const auto& [name, base] : option_sets()) {
      PlannerOptions single = base, dual = base;
      single.vns_threads = 1;
      dual.vns_threads = 2;
      for (int query = 0; query < 6; ++query) {
        // Opposite corners' regions: long searches, which the second thread joins.
        const Cell start{xs(rng) / 4, ys(rng) / 4};
        const Cell goal{map->width() - 1 - xs(rng) / 4, map->height() - 1 - ys(rng) / 4};
        std::ostringstream where;
        where << "trial " << trial << ", " << name << ", start (" << start.x << ", " << start.y
              << "), goal (" << goal.x << ", " << goal.y << ")";
        const PlanResult a = one.plan({start, goal}, single);
        const PlanResult b = two.plan({start, goal}, dual);
        expect_same_plan(a, b, where.str());
        ++plans;
        if (a.status.is_ok()) ++found;
      }
    }
    shared += shared_counter->searches_shared();
  }
  RecordProperty("plans", static_cast<int>(plans));
  RecordProperty("searches_shared", static_cast<int>(shared));
  EXPECT_GT(found, plans / 2) << "most queries must have a path";
  // How many depends on how fast the second thread wakes (a loaded machine: later); none at all
  // would mean the test compared one thread with one thread.
  EXPECT_GT(shared, 0) << "the second thread took part in none of " << plans << " searches";
}

// The longest of 100 random queries between free cells that has a path (single-threaded
// planner `planner` says which).
core::PlanQuery long_query(std::mt19937& rng, core::Planner& planner,
                           const PlannerOptions& options) {
  const std::vector<Cell> cells = free_cells(planner.map());
  std::uniform_int_distribution<size_t> any(0, cells.size() - 1);
  core::PlanQuery longest{};
  double longest_length = -1.0;
  for (int tries = 0; tries < 100; ++tries) {
    const core::PlanQuery q{cells[any(rng)], cells[any(rng)]};
    const PlanResult r = planner.plan(q, options);
    if (r.status.is_ok() && r.metrics.length_cells > longest_length) {
      longest = q;
      longest_length = r.metrics.length_cells;
    }
  }
  return longest;
}

// A building of 400 x 400 cells and, on it, a planner with one thread and one with two, with the
// paper's options for each.
struct OneAndTwoThreads {
  explicit OneAndTwoThreads(uint32_t seed)
      : rng(seed), map(random_building(rng, 400, 400, false)), one(map), two(map) {
    dual.vns_threads = 2;
  }
  std::mt19937 rng;
  std::shared_ptr<const core::GridMap> map;
  core::Planner one, two;
  PlannerOptions single = core::default_options(PlannerKind::kVnsBaStar), dual = single;
};

// A search stopped by its budget or canceled, with the second thread at work, leaves the planner
// as good as new: the next plans equal the single-threaded ones.
TEST(VnsThreads, StoppedAndCanceledSearchesLeaveThePlannerReady) {
  OneAndTwoThreads t(7);
  ASSERT_NE(t.map, nullptr);
  auto& [rng, map, one, two, single, dual] = t;
  const core::PlanQuery far = long_query(rng, one, single);
  ASSERT_GT(one.plan(far, single).metrics.length_cells, 300.0) << "no long query found";
  const core::PlanQuery other = long_query(rng, one, single);
  int timeouts = 0;
  for (int round = 0; round < 20 / kSlowdown; ++round) {
    PlannerOptions hurried = dual;
    hurried.max_planning_time = std::chrono::microseconds(100 + 100 * round);
    const PlanResult stopped = two.plan(far, hurried);
    if (stopped.status.code == core::StatusCode::kTimeout) {
      ++timeouts;
    } else {
      ASSERT_TRUE(stopped.status.is_ok()) << stopped.status.message;
    }
    std::atomic<bool> cancel{true};
    EXPECT_EQ(two.plan(far, dual, &cancel).status.code, core::StatusCode::kCanceled);
    expect_same_plan(one.plan(other, single), two.plan(other, dual),
                     "after round " + std::to_string(round));
  }
  EXPECT_GT(timeouts, 0);
  EXPECT_GT(two.searches_shared(), 0);
}

// On a loaded machine (three threads spinning on every core besides the two searches) the two
// threads are often not running at once; the searching thread then takes the backward search
// back and finishes alone. The results stay the single-threaded ones.
TEST(VnsThreads, BusyCoresTakeTheSearchBackWithTheSameResults) {
  OneAndTwoThreads t(23);
  ASSERT_NE(t.map, nullptr);
  auto& [rng, map, one, two, single, dual] = t;
  std::vector<core::PlanQuery> queries;
  for (int i = 0; i < 4; ++i) queries.push_back(long_query(rng, one, single));
  std::vector<PlanResult> expected;
  for (const auto& q : queries) expected.push_back(one.plan(q, single));
  std::atomic<bool> stop{false};
  std::vector<std::thread> load;
  const unsigned busy = std::max(2U, std::thread::hardware_concurrency()) + 1;
  for (unsigned i = 0; i < busy; ++i) {
    load.emplace_back([&stop] {
      while (!stop.load(std::memory_order_relaxed)) {
      }
    });
  }
  for (int round = 0; round < 12 / kSlowdown && two.searches_taken_back() == 0; ++round) {
    for (size_t i = 0; i < queries.size(); ++i) {
      expect_same_plan(expected[i], two.plan(queries[i], dual),
                       "loaded round " + std::to_string(round) + ", query " + std::to_string(i));
    }
  }
  stop = true;
  for (auto& t : load) t.join();
  RecordProperty("searches_shared", static_cast<int>(two.searches_shared()));
  RecordProperty("searches_taken_back", static_cast<int>(two.searches_taken_back()));
  EXPECT_GT(two.searches_taken_back(), 0) << "no search was taken back on loaded cores";
  // And unloaded again, the planner still plans as one thread does.
  for (size_t i = 0; i < queries.size(); ++i)
    expect_same_plan(expected[i], two.plan(queries[i], dual), "after the load");
}

// Planners made and destroyed, moved, and used on several maps: the second thread follows its
// planner (no thread left behind, none shared).
TEST(VnsThreads, PlannersOwnTheirSecondThread) {
  std::mt19937 rng(11);
  const auto map = random_building(rng, 300, 300, true);
  ASSERT_NE(map, nullptr);
  PlannerOptions single = core::default_options(PlannerKind::kVnsBaStar), dual = single;
  single.cost_weight = dual.cost_weight = 1.0;
  dual.vns_threads = 2;
  core::Planner reference(map);
  const core::PlanQuery query = long_query(rng, reference, single);
  int64_t shared = 0;
  const PlanResult expected = reference.plan(query, single);
  ASSERT_TRUE(expected.status.is_ok()) << expected.status.message;
  for (int i = 0; i < 10 / kSlowdown; ++i) {
    core::Planner made(map);
    expect_same_plan(expected, made.plan(query, dual), "fresh planner " + std::to_string(i));
    core::Planner moved(std::move(made));
    expect_same_plan(expected, moved.plan(query, dual), "moved planner " + std::to_string(i));
    shared += moved.searches_shared();
  }
  EXPECT_GT(shared, 0);
}

#ifndef VNSBA_THREAD_SANITIZER
// The Moving AI maps (every class), 12 scenarios per map spread over each file, the paper's
// configuration with traces and with the 8-neighbourhood.
TEST(VnsThreadsData, TwoThreadsPlanExactlyAsOneOnMovingAiMaps) {
  const std::string dir = data_path("movingai");
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << "Moving AI data not found at " << dir;
  int64_t plans = 0, shared = 0;
  int maps = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".map") continue;
    MovingAiCase loaded;
    ASSERT_TRUE(load_movingai(entry.path().string(), &loaded));
    core::Planner one(loaded.map), two(loaded.map);
    PlannerOptions paper = core::default_options(PlannerKind::kVnsBaStar);
    paper.record_expansions = true;
    PlannerOptions eight = paper;
    eight.neighborhood = Neighborhood::kEight;
    const size_t total = loaded.scenarios.size();
    const size_t step = std::max<size_t>(1, total / 12);
    for (size_t i = step / 2; i < total; i += step) {
      const auto& s = loaded.scenarios[i];
      for (PlannerOptions options : {paper, eight}) {
        options.vns_threads = 1;
        const PlanResult a = one.plan({s.start, s.goal}, options);
        options.vns_threads = 2;
        const PlanResult b = two.plan({s.start, s.goal}, options);
        expect_same_plan(a, b,
                         entry.path().filename().string() + " line " + std::to_string(s.line));
        ++plans;
      }
    }
    shared += two.searches_shared();
    ++maps;
  }
  EXPECT_GE(maps, 10);
  EXPECT_GT(shared, 0) << "the second thread took part in none of " << plans << " searches";
  RecordProperty("plans", static_cast<int>(plans));
  RecordProperty("searches_shared", static_cast<int>(shared));
}
#endif  // VNSBA_THREAD_SANITIZER

}  // namespace
}  // namespace vnsba::test
