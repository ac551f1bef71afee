// Loading the Moving AI maps the core benchmarks run on (Google Benchmark executables).
#pragma once

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/maps/map_io.hpp"

namespace vnsba::bench {

struct ScenarioMap {
  std::string name;
  std::shared_ptr<const core::GridMap> map;
  std::vector<maps::MovingAiScenario> scenarios;
};

// `dir`/`name`.map and its .scen file, or nothing (with the reason on stderr: a benchmark skips
// what is absent rather than fail).
inline std::optional<ScenarioMap> load_scenario_map(const std::string& dir,
                                                    const std::string& name) {
  const std::string path = dir + "/" + name + ".map";
  auto grid = maps::load_movingai_map(path);
  auto scenarios = maps::load_movingai_scenarios(path + ".scen");
  if (!grid || !scenarios) {
    std::fprintf(stderr, "skipping %s: %s\n", name.c_str(),
                 (!grid ? grid.error() : scenarios.error()).message.c_str());
    return std::nullopt;
  }
  auto built = core::GridMap::build(*grid);
  if (!built) {
    std::fprintf(stderr, "skipping %s: %s\n", name.c_str(), built.error().message.c_str());
    return std::nullopt;
  }
  return ScenarioMap{name, std::make_shared<const core::GridMap>(std::move(built).value()),
                     std::move(scenarios).value()};
}

}  // namespace vnsba::bench
