// The synthetic indoor floor of the node benchmarks: rooms of 20 x 20 cells, walls one cell
// thick, a two-cell doorway in every wall segment at a seeded random place.
#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include "vnsba/core/grid_map.hpp"

namespace vnsba::bench {

inline core::OccupancyGrid indoor_map(int size, double resolution) {
  core::OccupancyGrid g;
  g.width = g.height = size;
  g.resolution = resolution;
  g.data.assign(static_cast<size_t>(size) * size, 0);
  std::mt19937 rng(size);
  std::uniform_int_distribution<int> door(2, 16);
  for (int wall = 20; wall < size; wall += 20) {
    for (int i = 0; i < size; ++i) {
      g.data[static_cast<size_t>(wall) * size + i] = 100;  // horizontal wall
      g.data[static_cast<size_t>(i) * size + wall] = 100;  // vertical wall
    }
    for (int room = 0; room + 20 <= size; room += 20) {
      const int d = room + door(rng);
      for (int k = 0; k < 2; ++k) {
        g.data[static_cast<size_t>(wall) * size + d + k] = 0;
        g.data[static_cast<size_t>(d + k) * size + wall] = 0;
      }
    }
  }
  return g;
}

// Nearest-rank percentile of `values`, p in [0, 1]; 0 for none.
inline double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  const size_t rank =
      std::min(values.size() - 1, static_cast<size_t>(p * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank),
                   values.end());
  return values[rank];
}

}  // namespace vnsba::bench
