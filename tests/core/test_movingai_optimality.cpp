// A* path costs equal the published optimal lengths of the Moving AI benchmark scenarios
// (octile moves, no corner cutting = CornerPolicy::kNever). Reads ../shared/data/movingai and
// skips with a message where it is absent. `vnsba_bench optimality` runs every scenario.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/movingai_support.hpp"
#include "core/test_support.hpp"
#include "vnsba/core/planner.hpp"

namespace vnsba::test {
namespace {

// At least 8 maps from every class (game, maze, room, random, street), 200 scenarios each,
// spread evenly over the file so short and long queries are both covered.
const char* const kOptimalityMaps[] = {"arena",          "den312d",      "brc202d",
                                       "lak303d",        "ost003d",      "AR0011SR",
                                       "BigGameHunters", "maze512-16-0", "16room_000",
                                       "random512-20-0", "Berlin_0_256", "Boston_0_512"};
constexpr size_t kScenariosPerMap = 200;

TEST(MovingAiOptimality, AStarMatchesPublishedOptima) {
  const std::string dir = data_path("movingai");
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << "Moving AI data not found at " << dir;
  size_t checked = 0, maps = 0;
  for (const char* name : kOptimalityMaps) {
    MovingAiCase loaded;
    ASSERT_TRUE(load_movingai(dir + "/" + name + ".map", &loaded));
    const auto* scenarios = &loaded.scenarios;
    core::Planner planner(loaded.map);
    const auto options = core::default_options(core::PlannerKind::kAStar);
    const size_t total = scenarios->size();
    const size_t step = std::max<size_t>(1, total / kScenariosPerMap);
    for (size_t i = 0; i < total; i += step) {
      const auto& s = (*scenarios)[i];
      const auto r = planner.plan({s.start, s.goal}, options);
      ASSERT_TRUE(r.status.is_ok()) << name << " line " << s.line << ": " << r.status.message;
      // Relative 1e-6, or the printed precision where the file prints fewer digits.
      const double tolerance = std::max(1e-6 * s.optimal_length, s.optimal_resolution);
      ASSERT_NEAR(r.metrics.raw_cost_cells, s.optimal_length, tolerance)
          << name << " line " << s.line;
      ++checked;
    }
    ++maps;
  }
  EXPECT_GE(maps, 8u);
  EXPECT_GE(checked, 2000u);
  RecordProperty("scenarios", static_cast<int>(checked));
}

}  // namespace
}  // namespace vnsba::test
