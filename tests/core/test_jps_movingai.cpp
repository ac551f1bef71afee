// Planner `jps` against the published optima of the Moving AI benchmark scenarios (octile
// moves, no corner cutting), through the public Planner API: every path checked cell by cell
// (tests/core/test_support.hpp) and its length against the optimum. Reads ../shared/data/movingai
// and skips with a message where it is absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/test_support.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"

namespace vnsba::test {
namespace {

// --- Moving AI benchmark scenarios (../shared/data/movingai). ---

// Scenario lines of a .scen file counted without its loader: every non-empty line but the
// "version" header.
size_t count_scenario_lines(const std::string& path) {
  std::ifstream in(path);
  size_t lines = 0;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line.rfind("version", 0) == 0) continue;
    ++lines;
  }
  return lines;
}

// Runs every `every`-th scenario of every map in the Moving AI folder and checks each path cell
// by cell and its length against the published optimum.
void check_movingai_scenarios(size_t every) {
  const std::string dir = data_path("movingai");
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << "Moving AI data not found at " << dir;
  std::vector<std::string> maps;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".map") maps.push_back(entry.path().string());
  }
  std::sort(maps.begin(), maps.end());
  if (maps.empty()) GTEST_SKIP() << "no .map files in " << dir;
  const core::PlannerOptions jps = core::default_options(core::PlannerKind::kJps);
  size_t checked = 0, expected_count = 0, map_count = 0;
  for (const std::string& map_file : maps) {
    const std::string scen_file = map_file + ".scen";
    if (!std::filesystem::exists(scen_file)) continue;
    auto grid = maps::load_movingai_map(map_file);
    ASSERT_TRUE(grid) << grid.error().message;
    auto scenarios = maps::load_movingai_scenarios(scen_file);
    ASSERT_TRUE(scenarios) << scenarios.error().message;
    auto built = GridMap::build(*grid);
    ASSERT_TRUE(built) << built.error().message;
    const auto map = std::make_shared<const GridMap>(std::move(built).value());
    core::Planner planner(map);
    const size_t lines = count_scenario_lines(scen_file);
    expected_count += (lines + every - 1) / every;
    const std::string name = std::filesystem::path(map_file).filename().string();
    for (size_t i = 0; i < scenarios->size(); i += every) {
      const auto& s = (*scenarios)[i];
      const std::string where = name + " line " + std::to_string(s.line);
      const core::PlanResult r = planner.plan({s.start, s.goal}, jps);
      ASSERT_TRUE(r.status.is_ok()) << where << ": " << r.status.message;
      double length = 0.0;
      ASSERT_TRUE(valid_grid_path(*map, r.raw_path, s.start, s.goal, &length)) << where;
      ASSERT_NEAR(r.metrics.raw_cost_cells, length, 1e-9 * std::max(1.0, length)) << where;
      // Relative 1e-6, or the printed precision where the file prints fewer digits.
      const double tolerance = std::max(1e-6 * s.optimal_length, s.optimal_resolution);
      ASSERT_NEAR(length, s.optimal_length, tolerance) << where;
      ++checked;
    }
    ++map_count;
  }
  std::printf("[ jps ] %zu scenarios of %zu maps checked (every %zu)\n", checked, map_count, every);
  ::testing::Test::RecordProperty("scenarios", static_cast<int>(checked));
  ::testing::Test::RecordProperty("maps", static_cast<int>(map_count));
  EXPECT_GT(map_count, 0u);
  EXPECT_GE(checked, expected_count);
}

// Every 20th scenario of every map: the part of the benchmark the sanitizer stage runs too.
TEST(JpsMovingAi, MatchesPublishedOptimaOnEveryTwentiethScenario) {
  check_movingai_scenarios(20);
}

// Every scenario of every map (label `data`, left out of the sanitizer stage:
// tests/CMakeLists.txt).
TEST(JpsMovingAiData, MatchesPublishedOptimaOnEveryScenario) {
  check_movingai_scenarios(1);
}

}  // namespace
}  // namespace vnsba::test
