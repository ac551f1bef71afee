// The synthetic indoor floor of the node benchmarks, sized for default.yaml's robot (0.15 m
// radius, 0.55 m cost gradient): rooms of 5 m x 5 m, walls 0.1 m thick, a 1 m doorway in every
// wall segment at a seeded random place. Lengths are metres, turned into cells at `resolution`.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "vnsba/core/grid_map.hpp"

namespace vnsba::bench {

inline constexpr double kIndoorRoomMetres = 5.0;
inline constexpr double kIndoorWallMetres = 0.1;
inline constexpr double kIndoorDoorMetres = 1.0;

inline core::OccupancyGrid indoor_map(int size, double resolution) {
  const auto cells = [resolution](double metres) {
    return std::max(1, static_cast<int>(std::lround(metres / resolution)));
  };
  const int room = cells(kIndoorRoomMetres), wall = cells(kIndoorWallMetres);
  const int door = cells(kIndoorDoorMetres);
  core::OccupancyGrid g;
  g.width = g.height = size;
  g.resolution = resolution;
  g.data.assign(static_cast<size_t>(size) * size, 0);
  const auto set = [&](int x, int y, int8_t value) {
    if (x >= 0 && y >= 0 && x < size && y < size) g.data[static_cast<size_t>(y) * size + x] = value;
  };
  std::mt19937 rng(static_cast<unsigned>(size));
  // A doorway starts at least one wall thickness from either corner of its segment.
  std::uniform_int_distribution<int> door_start(wall, std::max(wall, room - wall - door));
  for (int line = room; line < size; line += room) {
    for (int i = 0; i < size; ++i) {
      for (int t = 0; t < wall; ++t) {
        set(i, line + t, 100);  // horizontal wall
        set(line + t, i, 100);  // vertical wall
      }
    }
    for (int start = 0; start + room <= size; start += room) {
      const int d = start + door_start(rng);
      for (int k = 0; k < door; ++k) {
        for (int t = 0; t < wall; ++t) {
          set(d + k, line + t, 0);
          set(line + t, d + k, 0);
        }
      }
    }
  }
  return g;
}

// Nearest-rank percentile of `values`, p in [0, 1]; 0 for none.
inline double percentile(const std::vector<double>& sample, double p) {
  if (sample.empty()) return 0.0;
  std::vector<double> values = sample;
  const size_t rank =
      std::min(values.size() - 1, static_cast<size_t>(p * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank),
                   values.end());
  return values[rank];
}

}  // namespace vnsba::bench
