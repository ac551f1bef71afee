// The exact Euclidean distance transform of a grid: for every cell, the squared distance (in
// cells^2, between cell centres) to the nearest source cell. The one implementation; inflation
// (grid_map.cpp) uses it, so its cost is linear in the cells whatever the robot's radius.
//
// Meijster, Roerdink and Hesselink, "A general algorithm for computing distance transforms in
// linear time" (2000): a vertical pass per column, then the lower envelope of the parabolas
// (x - i)^2 + g(i)^2 along each row. All arithmetic is in integers, so the result is exact.
//
// `cap` bounds the distances that matter: vertical distances above `cap` are stored as cap + 1,
// so every squared distance <= cap^2 is exact and every larger one is reported as some value
// > cap^2. That keeps the per-cell store (the only scratch a cell: the vertical distances) at
// 2 bytes when cap < 65535 (any radius a robot has in practice) and 4 beyond, and lets a caller
// that only asks "within r?" (r <= cap) pay nothing for distances it never needs.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

namespace vnsba::core {

// Squared distances of a row are "far" (> cap^2) when they equal or exceed this.
inline int64_t far_squared_distance(int32_t cap) {
  return (int64_t{cap} + 1) * (int64_t{cap} + 1);
}

// Bytes of scratch a cell squared_distance_rows holds (the vertical distances) for `cap`.
inline size_t distance_transform_bytes_per_cell(int32_t cap) {
  return cap + 1 <= 65535 ? sizeof(uint16_t) : sizeof(int32_t);
}

namespace detail {

// squared_distance_rows with the vertical distances stored as `Vertical` (which holds cap + 1).
template <class Vertical, class IsSource, class OnRow>
bool squared_distance_rows_as(int32_t width, int32_t height, int32_t cap, IsSource&& is_source,
                              OnRow&& on_row, const std::atomic<bool>* cancel) {
  auto canceled = [&] { return cancel != nullptr && cancel->load(std::memory_order_relaxed); };
  const size_t w = static_cast<size_t>(width);
  const int32_t far = cap + 1;  // a vertical distance above cap
  // Phase 1: g(x, y) = vertical distance to the nearest source in column x, at most cap + 1.
  // Row by row (not column by column) so that both passes stream through memory.
  std::vector<Vertical> g(w * static_cast<size_t>(height));
  for (int32_t y = 0; y < height; ++y) {
    if (canceled()) return false;
    Vertical* row = &g[static_cast<size_t>(y) * w];
    const Vertical* below = y > 0 ? row - w : nullptr;
    for (int32_t x = 0; x < width; ++x) {
      row[x] = static_cast<Vertical>(
          is_source(x, y) ? 0 : (below ? std::min(int32_t{below[x]} + 1, far) : far));
    }
  }
  for (int32_t y = height - 2; y >= 0; --y) {
    if (canceled()) return false;
    Vertical* row = &g[static_cast<size_t>(y) * w];
    const Vertical* above = row + w;
    for (int32_t x = 0; x < width; ++x) {
      row[x] =
          static_cast<Vertical>(std::min(int32_t{row[x]}, std::min(int32_t{above[x]} + 1, far)));
    }
  }

  // Phase 2, per row: the lower envelope of f_i(x) = (x - i)^2 + g(i)^2 over the columns i.
  // s[q] is the column of the q-th parabola of the envelope, t[q] the first x where it is the
  // lowest.
  std::vector<int32_t> s(w), t(w);
  std::vector<int64_t> squared(w);
  for (int32_t y = 0; y < height; ++y) {
    if (canceled()) return false;
    const Vertical* gy = &g[static_cast<size_t>(y) * w];
    auto f = [&](int64_t x, int32_t i) { return (x - i) * (x - i) + int64_t{gy[i]} * gy[i]; };
    // First x at which the parabola of column u is at or below that of column i (i < u),
    // floor((u^2 - i^2 + g(u)^2 - g(i)^2) / (2 (u - i))), rounded towards minus infinity.
    auto separation = [&](int32_t i, int32_t u) {
      const int64_t num =
          int64_t{u} * u - int64_t{i} * i + int64_t{gy[u]} * gy[u] - int64_t{gy[i]} * gy[i];
      const int64_t den = 2 * (int64_t{u} - i);
      return num >= 0 ? num / den : -((-num + den - 1) / den);
    };
    // Columns with no source within cap vertically cannot bring any cell within cap: they
    // stay out of the envelope (most of a sparse map's columns, in most rows).
    int32_t u = 0;
    while (u < width && gy[u] == far) ++u;
    if (u == width) {
      std::fill(squared.begin(), squared.end(), far_squared_distance(cap));
      on_row(y, static_cast<const int64_t*>(squared.data()));
      continue;
    }
    int32_t q = 0;
    s[0] = u;
    t[0] = 0;
    for (++u; u < width; ++u) {
      if (gy[u] == far) continue;
      while (q >= 0 && f(t[q], s[q]) > f(t[q], u)) --q;
      if (q < 0) {
        q = 0;
        s[0] = u;
      } else {
        const int64_t first = 1 + separation(s[q], u);
        if (first < width) {
          ++q;
          s[q] = u;
          t[q] = static_cast<int32_t>(first);
        }
      }
    }
    // Distances beyond cap are reported as they come (all > cap^2, some not the true value).
    for (int32_t x = width - 1; x >= 0; --x) {
      squared[x] = f(x, s[q]);
      if (x == t[q]) --q;
    }
    on_row(y, static_cast<const int64_t*>(squared.data()));
  }
  return true;
}

}  // namespace detail

// Calls on_row(y, const int64_t* squared) for y = 0..height-1 in order, with `squared` holding
// the width squared distances (cells^2) of row y. is_source(x, y) says whether cell (x, y) is a
// source. With no source at all every value is far. Returns false (and stops early) when
// `cancel` is raised; it is polled once per row. Scratch: distance_transform_bytes_per_cell(cap)
// a cell, plus 16 bytes a column.
template <class IsSource, class OnRow>
bool squared_distance_rows(int32_t width, int32_t height, int32_t cap, IsSource&& is_source,
                           OnRow&& on_row, const std::atomic<bool>* cancel = nullptr) {
  if (distance_transform_bytes_per_cell(cap) == sizeof(uint16_t)) {
    return detail::squared_distance_rows_as<uint16_t>(width, height, cap, is_source, on_row,
                                                      cancel);
  }
  return detail::squared_distance_rows_as<int32_t>(width, height, cap, is_source, on_row, cancel);
}

}  // namespace vnsba::core
