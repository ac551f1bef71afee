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
//
// centre_los/<map>/<policy>/{bit_walk,scalar}: line of sight between two cell centres; one
// iteration answers the same 4096 fixed random segments, by the bit-grid walk that
// line_of_sight_in_map uses (detail::centre_segment_clear) or by the scalar supercover
// traversal it replaced (tests/core/scalar_line_of_sight.hpp, the tests' oracle). Only segments
// that the summed-area shortcuts do not settle are used (not axis-aligned, a blocked cell in their
// rectangle), since both variants share those shortcuts. Run just these with
//   vnsba_core_bench --benchmark_filter=centre_los
// and read the ratio of the two times (or segments/s) per map and policy. clear_%: segments with
// line of sight (the same for both variants, or one of them is wrong).
//
// grid_build/<radius>: GridMap::build of a 4096 x 4096 map (random512-20-0 tiled 8 x 8, or a
// random one) with robot_radius 0, 3, 10 and 30 cells: inflation is one distance transform, so
// the time should barely depend on the radius (vnsba_core_bench --benchmark_filter=grid_build).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bench/large.hpp"
#include "core/scalar_line_of_sight.hpp"
#include "scenario_maps.hpp"
#include "vnsba/core/line_of_sight.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"

namespace {

using namespace vnsba::core;
using namespace vnsba::maps;

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

// --- Line of sight between cell centres. ---

constexpr size_t kSegmentsPerMap = 4096;
// A street map and a game map (Moving AI); a random map stands in when the data is absent.
const char* const kLineOfSightMaps[] = {"Boston_0_512", "ost100d"};

struct LineOfSightBench {
  std::string name;
  std::shared_ptr<const GridMap> map;
  std::vector<std::pair<Cell, Cell>> segments;
};

std::vector<LineOfSightBench>& line_of_sight_maps() {
  static std::vector<LineOfSightBench> maps;
  return maps;
}

// Random pairs of free cells (fixed seed) that the summed-area shortcuts leave to the walk.
std::vector<std::pair<Cell, Cell>> walked_segments(const GridMap& map) {
  std::vector<Cell> free;
  for (int32_t y = 0; y < map.height(); ++y)
    for (int32_t x = 0; x < map.width(); ++x)
      if (!map.blocked(x, y)) free.push_back({x, y});
  std::vector<std::pair<Cell, Cell>> segments;
  if (free.size() < 2) return segments;
  std::mt19937 rng(42);
  std::uniform_int_distribution<size_t> pick(0, free.size() - 1);
  for (size_t tries = 0; segments.size() < kSegmentsPerMap && tries < 100 * kSegmentsPerMap;
       ++tries) {
    const Cell a = free[pick(rng)], b = free[pick(rng)];
    if (a.x != b.x && a.y != b.y && map.blocked_in_rect(a, b) > 0) segments.push_back({a, b});
  }
  return segments;
}

void add_line_of_sight_map(const std::string& name, GridMap map) {
  LineOfSightBench bench{name, std::make_shared<const GridMap>(std::move(map)), {}};
  bench.segments = walked_segments(*bench.map);
  if (!bench.segments.empty()) line_of_sight_maps().push_back(std::move(bench));
}

void load_line_of_sight_maps(const std::string& dir) {
  for (const char* name : kLineOfSightMaps) {
    auto grid = load_movingai_map(dir + "/" + name + ".map");
    if (!grid) continue;
    auto built = GridMap::build(*grid);
    if (built) add_line_of_sight_map(name, std::move(built).value());
  }
  if (!line_of_sight_maps().empty()) return;
  OccupancyGrid grid;  // 512 x 512, 20 % of the cells blocked at random
  grid.width = grid.height = 512;
  std::mt19937 rng(7);
  std::bernoulli_distribution blocked(0.2);
  for (int32_t i = 0; i < grid.width * grid.height; ++i)
    grid.data.push_back(blocked(rng) ? kOccupancyOccupied : kOccupancyFree);
  add_line_of_sight_map("random512-20", std::move(GridMap::build(grid)).value());
}

void run_centre_los(benchmark::State& state, const LineOfSightBench* bench, CornerPolicy policy,
                    bool bit_walk) {
  const GridMap& map = *bench->map;
  int64_t clear = 0;
  for (auto _ : state) {
    clear = 0;
    for (const auto& [a, b] : bench->segments) {
      const bool visible =
          bit_walk ? detail::centre_segment_clear(map, a, b, policy)
                   : vnsba::test_oracle::line_of_sight_centres_scalar(map, a, b, policy);
      clear += visible;
    }
    benchmark::DoNotOptimize(clear);
  }
  const double segments = static_cast<double>(bench->segments.size());
  state.counters["segments/s"] =
      benchmark::Counter(segments, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["clear_%"] = 100.0 * static_cast<double>(clear) / segments;
}

bool load_maps(const std::string& dir) {
  for (const char* name : kBenchMaps) {
    auto loaded = vnsba::bench::load_scenario_map(dir, name);
    if (!loaded) continue;
    const auto& scenarios = loaded->scenarios;
    BenchMap bench{name, loaded->map, {}};
    const size_t step = std::max<size_t>(1, scenarios.size() / kScenariosPerMap);
    for (size_t i = step - 1; i < scenarios.size() && bench.queries.size() < kScenariosPerMap;
         i += step)
      bench.queries.push_back({scenarios[i].start, scenarios[i].goal});
    bench_maps().push_back(std::move(bench));
  }
  return !bench_maps().empty();
}

}  // namespace

int main(int argc, char** argv) {
  const char* env_dir = std::getenv("VNSBA_DATA_DIR");
  const std::string dir = std::string(env_dir ? env_dir : VNSBA_DATA_DIR) + "/movingai";
  load_line_of_sight_maps(dir);
  for (const LineOfSightBench& bench : line_of_sight_maps()) {
    for (CornerPolicy policy :
         {CornerPolicy::kNever, CornerPolicy::kTouch, CornerPolicy::kAlways}) {
      for (bool bit_walk : {true, false}) {
        const std::string name = "centre_los/" + bench.name + "/" + std::string(to_string(policy)) +
                                 (bit_walk ? "/bit_walk" : "/scalar");
        benchmark::RegisterBenchmark(name.c_str(), run_centre_los, &bench, policy, bit_walk)
            ->Unit(benchmark::kMicrosecond)
            ->MinTime(0.5);
      }
    }
  }
  if (!std::filesystem::exists(dir) || !load_maps(dir)) {
    std::fprintf(stderr,
                 "Moving AI data not found at %s: no planner benchmarks, line of sight on "
                 "whatever maps were found or a random one "
                 "(set VNSBA_DATA_DIR to the folder holding movingai/)\n",
                 dir.c_str());
  }
  for (const BenchMap& bench : bench_maps()) {
    for (PlannerKind kind : all_planner_kinds()) {
      const std::string name = bench.name + "/" + std::string(to_string(kind));
      benchmark::RegisterBenchmark(name.c_str(), run_planner, &bench, kind)
          ->Unit(benchmark::kMicrosecond)
          ->MinTime(1.0);
    }
  }
  static OccupancyGrid tiled = [&] {
    OccupancyGrid tile;
    if (auto loaded = load_movingai_map(dir + "/random512-20-0.map")) {
      tile = std::move(loaded).value();
    } else {
      tile = {512, 512, 1.0, 0.0, 0.0, std::vector<int8_t>(512 * 512, 0)};
      std::mt19937 rng(5);
      for (auto& v : tile.data) v = rng() % 5 == 0 ? 100 : 0;
    }
    return vnsba::bench::grow_grid(tile, 8, vnsba::bench::Growth::kTiled);
  }();
  for (int radius_cells : {0, 3, 10, 30}) {
    const std::string name = "grid_build/" + std::to_string(radius_cells);
    benchmark::RegisterBenchmark(name.c_str(), [radius_cells](benchmark::State& state) {
      GridBuildOptions options;
      options.robot_radius = radius_cells * tiled.resolution;
      for (auto _ : state) benchmark::DoNotOptimize(GridMap::build(tiled, options));
    })->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
