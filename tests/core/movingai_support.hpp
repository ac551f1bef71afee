// Loading a Moving AI benchmark map and its scenarios (the shared data folder), for the core tests
// that read them. Links vnsba::maps, which the checked-core tests do not: kept out of
// test_support.hpp.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/maps/map_io.hpp"

namespace vnsba::test {

struct MovingAiCase {
  std::shared_ptr<const core::GridMap> map;
  std::vector<maps::MovingAiScenario> scenarios;
};

// Reads `map_file` and `map_file + ".scen"` and builds the map with the default options; the
// failure names the file and what was wrong with it.
inline ::testing::AssertionResult load_movingai(const std::string& map_file, MovingAiCase* out) {
  auto grid = maps::load_movingai_map(map_file);
  if (!grid) return ::testing::AssertionFailure() << grid.error().message;
  auto scenarios = maps::load_movingai_scenarios(map_file + ".scen");
  if (!scenarios) return ::testing::AssertionFailure() << scenarios.error().message;
  auto built = core::GridMap::build(*grid);
  if (!built) return ::testing::AssertionFailure() << map_file << ": " << built.error().message;
  out->map = std::make_shared<const core::GridMap>(std::move(built).value());
  out->scenarios = std::move(scenarios).value();
  return ::testing::AssertionSuccess();
}

}  // namespace vnsba::test
