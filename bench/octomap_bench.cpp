// OctoMap slicing benchmarks (Google Benchmark).
//
// One iteration is one slice_octree call. Counters:
//   leaves/slice   leaves overlapping the band (counted once, outside the timed loop, with
//                  OctoMap's own leaf_bbx iterator: the work the slice has to do)
//   cells          cells in the output grid
//   leaves/s       leaves in the band per second of wall time (rate)
// Trees: geb079.bt and fr_078_tidyup.bt from VNSBA_DATA_DIR/octomap (skipped when absent), and a
// synthetic 0.05 m tree with 2,000,000 leaves (200 x 200 x 50 voxels, a hashed occupied / free
// pattern that does not prune), sliced with a band holding half of them (~1,000,000 leaves) and
// with a one-layer band (40,000): the time follows the leaves in the band, not the tree.
#include <benchmark/benchmark.h>
#include <octomap/OcTree.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "vnsba/maps/octomap_slice.hpp"

namespace {

using vnsba::maps::SliceOptions;

struct Case {
  std::string name;
  std::shared_ptr<const octomap::OcTree> tree;
  SliceOptions options;
  double leaves_in_band = 0;
};

// Leaves whose z extent overlaps [z_min, z_max] by a positive length (the slice's rule).
double count_leaves_in_band(const octomap::OcTree& tree, double z_min, double z_max) {
  double x0, y0, z0, x1, y1, z1;
  tree.getMetricMin(x0, y0, z0);
  tree.getMetricMax(x1, y1, z1);
  const double eps = tree.getResolution() / 4;  // stay inside the tree's key space
  const octomap::point3d lo(static_cast<float>(x0 + eps), static_cast<float>(y0 + eps),
                            static_cast<float>(std::max(z_min, z0 + eps)));
  const octomap::point3d hi(static_cast<float>(x1 - eps), static_cast<float>(y1 - eps),
                            static_cast<float>(std::min(z_max, z1 - eps)));
  double count = 0;
  for (auto it = tree.begin_leafs_bbx(lo, hi), end = tree.end_leafs_bbx(); it != end; ++it) {
    const double half = it.getSize() / 2;
    if (it.getZ() - half < z_max && it.getZ() + half > z_min) ++count;
  }
  return count;
}

void run_slice(benchmark::State& state, const Case* c) {
  int64_t cells = 0;
  for (auto _ : state) {
    auto grid = vnsba::maps::slice_octree(*c->tree, c->options);
    if (!grid) {
      state.SkipWithError(grid.error().message.c_str());
      return;
    }
    cells = int64_t{grid->width} * grid->height;
    benchmark::DoNotOptimize(grid->data.data());
  }
  state.counters["leaves/slice"] = c->leaves_in_band;
  state.counters["cells"] = static_cast<double>(cells);
  state.counters["leaves/s"] = benchmark::Counter(
      c->leaves_in_band * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

// 200 x 200 x 50 voxels of 0.05 m from the origin, each occupied or free by a hash of its key,
// so siblings almost never agree and pruning keeps nearly every leaf.
std::shared_ptr<octomap::OcTree> synthetic_tree() {
  auto tree = std::make_shared<octomap::OcTree>(0.05);
  for (int x = 0; x < 200; ++x) {
    for (int y = 0; y < 200; ++y) {
      for (int z = 0; z < 50; ++z) {
        uint32_t h = static_cast<uint32_t>(x) * 73856093u ^ static_cast<uint32_t>(y) * 19349663u ^
                     static_cast<uint32_t>(z) * 83492791u;
        h ^= h >> 13;
        h *= 0x5bd1e995u;
        h ^= h >> 15;
        const octomap::OcTreeKey key(static_cast<octomap::key_type>(32768 + x),
                                     static_cast<octomap::key_type>(32768 + y),
                                     static_cast<octomap::key_type>(32768 + z));
        tree->setNodeValue(key, (h & 1u) ? 2.0f : -2.0f, /*lazy_eval=*/true);
      }
    }
  }
  tree->updateInnerOccupancy();
  tree->prune();
  return tree;
}

SliceOptions band(double z_min, double z_max) {
  SliceOptions o;
  o.z_min = z_min;
  o.z_max = z_max;
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  static std::vector<Case> cases;  // registered benchmarks keep pointers into it: reserve first
  cases.reserve(8);

  const std::string dir = std::string(VNSBA_DATA_DIR) + "/octomap";
  for (const char* file : {"geb079.bt", "fr_078_tidyup.bt"}) {
    const std::string path = dir + "/" + file;
    if (!std::filesystem::exists(path)) {
      std::fprintf(stderr, "skipping %s: OctoMap data not found at %s\n", file, dir.c_str());
      continue;
    }
    auto tree = vnsba::maps::load_octree(path);
    if (!tree) {
      std::fprintf(stderr, "skipping %s: %s\n", file, tree.error().message.c_str());
      continue;
    }
    const SliceOptions o = band(0.1, 1.5);  // floor to head height: a typical robot band
    cases.push_back({file + std::string(" band [0.1, 1.5]"), *tree, o,
                     count_leaves_in_band(**tree, o.z_min, o.z_max)});
  }

  const std::shared_ptr<const octomap::OcTree> synthetic = synthetic_tree();
  std::fprintf(stderr, "synthetic tree: %zu leaves after pruning\n", synthetic->getNumLeafNodes());
  for (const auto& [z_min, z_max, label] :
       {std::tuple{0.0, 1.25, "synthetic 2M leaves, band of 25 layers"},
        std::tuple{0.6, 0.65, "synthetic 2M leaves, band of 1 layer"},
        std::tuple{0.0, 2.5, "synthetic 2M leaves, band of all 50 layers"}}) {
    cases.push_back(
        {label, synthetic, band(z_min, z_max), count_leaves_in_band(*synthetic, z_min, z_max)});
  }

  for (const Case& c : cases) {
    benchmark::RegisterBenchmark(("slice/" + c.name).c_str(), run_slice, &c)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
