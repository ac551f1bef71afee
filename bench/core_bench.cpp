// Core planner benchmarks on Moving AI maps (Google Benchmark).
//
// For each of four maps and each planner, one benchmark iteration is one query, cycling through
// a fixed scenario set (every k-th line of the map's .scen file, so short and long queries are
// both represented). Counters:
//   expansions/s        closed nodes per second of wall time (rate)
//   expanded/query      mean closed nodes per query
//   median_us           median wall time of one query (search + post-processing)
//   state_B/cell/dir    peak bytes of search state per map cell per search direction
// Compare planners as ratios within one run: the machines are shared and noisy.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "vnsba/core/map_io.hpp"
#include "vnsba/core/planner.hpp"

namespace {

using namespace vnsba::core;

constexpr size_t kScenariosPerMap = 64;
const char* const kBenchMaps[] = {"random512-20-0", "16room_000", "maze512-4-0", "ost100d"};

struct BenchMap {
  std::string name;
  std::shared_ptr<const GridMap> map;
  std::vector<PlanQuery> queries;
};

std::vector<BenchMap>& bench_maps() {
  static std::vector<BenchMap> maps;
  return maps;
}

void run_planner(benchmark::State& state, const BenchMap* bench, PlannerKind kind) {
  Planner planner(bench->map);
  const PlannerOptions options = default_options(kind);
  std::vector<double> times_us;
  int64_t expanded = 0;
  size_t next = 0;
  for (auto _ : state) {
    const PlanQuery& q = bench->queries[next];
    next = (next + 1) % bench->queries.size();
    const auto t0 = std::chrono::steady_clock::now();
    PlanResult r = planner.plan(q, options);
    const auto t1 = std::chrono::steady_clock::now();
    if (!r.status.is_ok()) {
      state.SkipWithError(("query failed: " + r.status.message).c_str());
      break;
    }
    expanded += r.metrics.expanded;
    times_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    benchmark::DoNotOptimize(r);
  }
  if (times_us.empty()) return;
  std::nth_element(times_us.begin(), times_us.begin() + times_us.size() / 2, times_us.end());
  state.counters["median_us"] = times_us[times_us.size() / 2];
  state.counters["expansions/s"] =
      benchmark::Counter(static_cast<double>(expanded), benchmark::Counter::kIsRate);
  state.counters["expanded/query"] =
      benchmark::Counter(static_cast<double>(expanded), benchmark::Counter::kAvgIterations);
  state.counters["state_B/cell/dir"] = planner.peak_bytes_per_cell_per_direction();
}

bool load_maps(const std::string& dir) {
  for (const char* name : kBenchMaps) {
    const std::string path = dir + "/" + name + ".map";
    auto grid = load_movingai_map(path);
    auto scenarios = load_movingai_scenarios(path + ".scen");
    if (!grid || !scenarios) {
      std::fprintf(stderr, "skipping %s: %s\n", name,
                   (!grid ? grid.error() : scenarios.error()).message.c_str());
      continue;
    }
    auto built = GridMap::build(*grid);
    if (!built) continue;
    BenchMap bench{name, std::make_shared<const GridMap>(std::move(built).value()), {}};
    const size_t step = std::max<size_t>(1, scenarios->size() / kScenariosPerMap);
    for (size_t i = step - 1; i < scenarios->size() && bench.queries.size() < kScenariosPerMap;
         i += step)
      bench.queries.push_back({(*scenarios)[i].start, (*scenarios)[i].goal});
    bench_maps().push_back(std::move(bench));
  }
  return !bench_maps().empty();
}

}  // namespace

int main(int argc, char** argv) {
  const char* env_dir = std::getenv("VNSBA_DATA_DIR");
  const std::string dir = std::string(env_dir ? env_dir : VNSBA_DATA_DIR) + "/movingai";
  if (!std::filesystem::exists(dir) || !load_maps(dir)) {
    std::fprintf(stderr,
                 "Moving AI data not found at %s: nothing to benchmark "
                 "(set VNSBA_DATA_DIR to the folder holding movingai/)\n",
                 dir.c_str());
    return 0;
  }
  for (const BenchMap& bench : bench_maps()) {
    for (PlannerKind kind : all_planner_kinds()) {
      const std::string name = bench.name + "/" + std::string(to_string(kind));
      benchmark::RegisterBenchmark(name.c_str(), run_planner, &bench, kind)
          ->Unit(benchmark::kMicrosecond)
          ->MinTime(1.0);
    }
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
