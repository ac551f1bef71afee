// Our A* against a reference: a careful, self-contained flat-array A* with an indexed binary
// heap, the kind a user would write or take from a library (Google Benchmark).
//
// The reference is written for this comparison only and shares nothing with core/ but the map's
// blocked cells: its own padded byte grid, generation-stamped g and parent arrays, a binary heap
// indexed by cell, octile heuristic, 8 neighbours without corner cutting, ties towards larger g,
// and the same quantized step costs (so that both expand the same nodes and the comparison is
// of implementation cost alone). Each benchmark iteration is one query, cycling through every
// k-th scenario of the map. Both report the same optimal costs (checked per query: a mismatch
// stops the benchmark with an error). Compare as ratios within one run:
//
//   build/release/bench/vnsba_astar_reference_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "scenario_maps.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"

namespace {

using namespace vnsba::core;
using namespace vnsba::maps;

constexpr size_t kScenariosPerMap = 100;
const char* const kBenchMaps[] = {"random512-20-0", "16room_000", "maze512-4-0", "ost100d",
                                  "Berlin_0_256"};

class ReferenceAStar {
 public:
  explicit ReferenceAStar(const GridMap& map)
      : width_(map.width() + 2), cells_(static_cast<size_t>(width_) * (map.height() + 2)) {
    free_.assign(cells_, 0);
    for (int32_t y = 0; y < map.height(); ++y)
      for (int32_t x = 0; x < map.width(); ++x) free_[index(x, y)] = map.blocked(x, y) ? 0 : 1;
    g_.assign(cells_, 0.0);
    parent_.assign(cells_, 0);
    stamp_.assign(cells_, 0);
    heap_pos_.assign(cells_, 0);
  }

  // Cost of the optimal path (cells), infinity when there is none; `expanded` counts pops.
  double plan(const Cell& start, const Cell& goal, int64_t& expanded) {
    ++generation_;
    heap_.clear();
    goal_x_ = goal.x;
    goal_y_ = goal.y;
    const uint32_t s = index(start.x, start.y), t = index(goal.x, goal.y);
    open(s, 0.0, s);
    expanded = 0;
    const int32_t w = width_;
    const int32_t offsets[8] = {1, -1, w, -w, w + 1, w - 1, -w + 1, -w - 1};
    while (!heap_.empty()) {
      const uint32_t n = pop();
      ++expanded;
      if (n == t) return g_[n];
      const double gn = g_[n];
      const bool e = free_[n + 1], west = free_[n - 1], north = free_[n + w], south = free_[n - w];
      const bool ok[8] = {e,
                          west,
                          north,
                          south,
                          e && north && free_[n + w + 1],
                          west && north && free_[n + w - 1],
                          e && south && free_[n - w + 1],
                          west && south && free_[n - w - 1]};
      for (int k = 0; k < 8; ++k) {
        if (!ok[k]) continue;
        const uint32_t m = n + offsets[k];
        const double gm = gn + (k < 4 ? 1.0 : kDiagonal);
        if (stamp_[m] != generation_) {
          open(m, gm, n);
        } else if (heap_pos_[m] != kClosed && gm < g_[m]) {
          g_[m] = gm;
          parent_[m] = n;
          heap_[heap_pos_[m]].f = gm + h(m);
          heap_[heap_pos_[m]].g = gm;
          up(heap_pos_[m]);
        }
      }
    }
    return std::numeric_limits<double>::infinity();
  }

 private:
  static constexpr uint32_t kClosed = std::numeric_limits<uint32_t>::max();
  static constexpr double kDiagonal = vnsba::core::detail::kStepCostDiagonal;
  struct Entry {
    double f;
    double g;
    uint32_t node;
  };

  uint32_t index(int32_t x, int32_t y) const {
    return static_cast<uint32_t>((y + 1) * width_ + (x + 1));
  }
  double h(uint32_t n) const {
    const double dx = std::abs(static_cast<int32_t>(n % width_) - 1 - goal_x_);
    const double dy = std::abs(static_cast<int32_t>(n / width_) - 1 - goal_y_);
    return dx + dy + (kDiagonal - 2.0) * std::min(dx, dy);
  }
  static bool before(const Entry& a, const Entry& b) {
    return a.f < b.f || (a.f == b.f && a.g > b.g);
  }
  void open(uint32_t n, double g, uint32_t parent) {
    stamp_[n] = generation_;
    g_[n] = g;
    parent_[n] = parent;
    heap_.push_back({g + h(n), g, n});
    heap_pos_[n] = static_cast<uint32_t>(heap_.size() - 1);
    up(heap_.size() - 1);
  }
  uint32_t pop() {
    const uint32_t top = heap_[0].node;
    heap_pos_[top] = kClosed;
    heap_[0] = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) {
      heap_pos_[heap_[0].node] = 0;
      down(0);
    }
    return top;
  }
  void up(size_t i) {
    const Entry e = heap_[i];
    while (i > 0 && before(e, heap_[(i - 1) / 2])) {
      heap_[i] = heap_[(i - 1) / 2];
      heap_pos_[heap_[i].node] = static_cast<uint32_t>(i);
      i = (i - 1) / 2;
    }
    heap_[i] = e;
    heap_pos_[e.node] = static_cast<uint32_t>(i);
  }
  void down(size_t i) {
    const Entry e = heap_[i];
    for (;;) {
      size_t c = 2 * i + 1;
      if (c >= heap_.size()) break;
      if (c + 1 < heap_.size() && before(heap_[c + 1], heap_[c])) ++c;
      if (!before(heap_[c], e)) break;
      heap_[i] = heap_[c];
      heap_pos_[heap_[i].node] = static_cast<uint32_t>(i);
      i = c;
    }
    heap_[i] = e;
    heap_pos_[e.node] = static_cast<uint32_t>(i);
  }

  int32_t width_;
  size_t cells_;
  int32_t goal_x_ = 0, goal_y_ = 0;
  uint32_t generation_ = 0;
  std::vector<uint8_t> free_;
  std::vector<double> g_;
  std::vector<uint32_t> parent_, stamp_, heap_pos_;
  std::vector<Entry> heap_;
};

struct BenchMap {
  std::string name;
  std::shared_ptr<const GridMap> map;
  std::vector<PlanQuery> queries;
  std::vector<double> optimal;    // the published optimum of each query, cells
  std::vector<double> tolerance;  // relative 1e-6, or the file's printed precision
};

std::vector<BenchMap>& bench_maps() {
  static std::vector<BenchMap> maps;
  return maps;
}

template <class PlanOne>
void run_queries(benchmark::State& state, const BenchMap* bench, PlanOne&& plan_one) {
  std::vector<double> times_us;
  int64_t expanded_total = 0;
  size_t next = 0;
  for (auto _ : state) {
    const size_t i = next;
    next = (next + 1) % bench->queries.size();
    int64_t expanded = 0;
    const auto t0 = std::chrono::steady_clock::now();
    const double cost = plan_one(bench->queries[i], expanded);
    const auto t1 = std::chrono::steady_clock::now();
    if (!(std::abs(cost - bench->optimal[i]) <= bench->tolerance[i])) {
      state.SkipWithError(("query " + std::to_string(i) + ": cost " + std::to_string(cost) +
                           ", published optimum " + std::to_string(bench->optimal[i]))
                              .c_str());
      break;
    }
    expanded_total += expanded;
    times_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
  }
  if (times_us.empty()) return;
  std::nth_element(times_us.begin(), times_us.begin() + times_us.size() / 2, times_us.end());
  state.counters["median_us"] = times_us[times_us.size() / 2];
  state.counters["expanded/query"] =
      benchmark::Counter(static_cast<double>(expanded_total), benchmark::Counter::kAvgIterations);
  state.counters["expansions/s"] =
      benchmark::Counter(static_cast<double>(expanded_total), benchmark::Counter::kIsRate);
}

void ours(benchmark::State& state, const BenchMap* bench) {
  Planner planner(bench->map);
  const PlannerOptions options = default_options(PlannerKind::kAStar);
  run_queries(state, bench, [&](const PlanQuery& q, int64_t& expanded) {
    const PlanResult r = planner.plan(q, options);
    expanded = r.metrics.expanded;
    return r.status.is_ok() ? r.metrics.raw_cost_cells : std::numeric_limits<double>::infinity();
  });
}

void reference(benchmark::State& state, const BenchMap* bench) {
  ReferenceAStar astar(*bench->map);
  run_queries(state, bench, [&](const PlanQuery& q, int64_t& expanded) {
    return astar.plan(q.start, q.goal, expanded);
  });
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = std::string(VNSBA_DATA_DIR) + "/movingai";
  for (const char* name : kBenchMaps) {
    auto loaded = vnsba::bench::load_scenario_map(dir, name);
    if (!loaded) continue;
    const auto& scenarios = loaded->scenarios;
    BenchMap bench{name, loaded->map, {}, {}, {}};
    const size_t step = std::max<size_t>(1, scenarios.size() / kScenariosPerMap);
    for (size_t i = 0; i < scenarios.size(); i += step) {
      const MovingAiScenario& s = scenarios[i];
      bench.queries.push_back({s.start, s.goal});
      bench.optimal.push_back(s.optimal_length);
      bench.tolerance.push_back(std::max(1e-6 * s.optimal_length, s.optimal_resolution));
    }
    bench_maps().push_back(std::move(bench));
  }
  if (bench_maps().empty()) {
    std::fprintf(stderr, "no Moving AI maps in %s: nothing to measure\n", dir.c_str());
    return 0;
  }
  for (const BenchMap& bench : bench_maps()) {
    // Every query three times over, for both: the same work, so times compare directly.
    const auto iterations = static_cast<benchmark::IterationCount>(3 * bench.queries.size());
    benchmark::RegisterBenchmark(("AStar/ours/" + bench.name).c_str(), ours, &bench)
        ->Unit(benchmark::kMicrosecond)
        ->Iterations(iterations);
    benchmark::RegisterBenchmark(("AStar/reference/" + bench.name).c_str(), reference, &bench)
        ->Unit(benchmark::kMicrosecond)
        ->Iterations(iterations);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
