// The distance transform against brute force: every squared distance up to the cap is exact,
// every larger one is reported as beyond it.
#include <gtest/gtest.h>

#include <atomic>
#include <limits>
#include <random>
#include <vector>

#include "vnsba/core/distance_transform.hpp"

namespace vnsba::test {
namespace {

struct Field {
  int32_t width, height;
  std::vector<uint8_t> source;  // row-major
  bool at(int32_t x, int32_t y) const { return source[static_cast<size_t>(y) * width + x] != 0; }
};

// Squared distance (cells^2) from (x, y) to the nearest source by trying every source; the
// largest int64 when there is none.
int64_t brute_force(const Field& f, int32_t x, int32_t y) {
  int64_t best = std::numeric_limits<int64_t>::max();
  for (int32_t sy = 0; sy < f.height; ++sy)
    for (int32_t sx = 0; sx < f.width; ++sx)
      if (f.at(sx, sy))
        best = std::min(best, int64_t{sx - x} * (sx - x) + int64_t{sy - y} * (sy - y));
  return best;
}

std::vector<int64_t> transform(const Field& f, int32_t cap, int* rows_seen = nullptr) {
  std::vector<int64_t> out(f.source.size(), -1);
  int32_t expected_row = 0;
  const bool done = core::squared_distance_rows(
      f.width, f.height, cap, [&](int32_t x, int32_t y) { return f.at(x, y); },
      [&](int32_t y, const int64_t* squared) {
        EXPECT_EQ(y, expected_row++) << "rows come in order";
        std::copy(squared, squared + f.width, out.begin() + static_cast<size_t>(y) * f.width);
      });
  EXPECT_TRUE(done);
  if (rows_seen != nullptr) *rows_seen = expected_row;
  return out;
}

void expect_matches_brute_force(const Field& f, int32_t cap, const std::string& what) {
  const std::vector<int64_t> got = transform(f, cap);
  const int64_t far = core::far_squared_distance(cap);
  for (int32_t y = 0; y < f.height; ++y) {
    for (int32_t x = 0; x < f.width; ++x) {
      const int64_t expected = brute_force(f, x, y);
      const int64_t value = got[static_cast<size_t>(y) * f.width + x];
      if (expected <= int64_t{cap} * cap) {
        ASSERT_EQ(value, expected) << what << " cell " << x << "," << y;
      } else {
        ASSERT_GT(value, int64_t{cap} * cap) << what << " cell " << x << "," << y;
        ASSERT_GE(value, std::min(expected, far)) << what << " cell " << x << "," << y;
      }
    }
  }
}

TEST(DistanceTransform, EqualsBruteForceOnRandomGrids) {
  std::mt19937 rng(2024);
  for (int trial = 0; trial < 300; ++trial) {
    Field f;
    f.width = 1 + static_cast<int32_t>(rng() % 40);
    f.height = 1 + static_cast<int32_t>(rng() % 40);
    const double density = (trial % 7) * 0.1 * ((trial % 3) ? 1.0 : 0.05);
    std::bernoulli_distribution source(density);
    f.source.resize(static_cast<size_t>(f.width) * f.height);
    for (auto& s : f.source) s = source(rng);
    // Caps below, at and far beyond the grid's diagonal.
    for (int32_t cap : {1, 2, 3, 7, 20, 100}) {
      expect_matches_brute_force(f, cap,
                                 "trial " + std::to_string(trial) + " cap " + std::to_string(cap));
    }
  }
}

TEST(DistanceTransform, NoSourceMeansEverythingIsFar) {
  Field f{13, 9, std::vector<uint8_t>(13 * 9, 0)};
  int rows = 0;
  const std::vector<int64_t> got = transform(f, 5, &rows);
  EXPECT_EQ(rows, 9);
  for (int64_t v : got) EXPECT_GT(v, 25);
}

TEST(DistanceTransform, OneSourceGivesTheSquaredDistanceToIt) {
  Field f{31, 17, std::vector<uint8_t>(31 * 17, 0)};
  f.source[static_cast<size_t>(4) * 31 + 22] = 1;
  const std::vector<int64_t> got = transform(f, 40);
  for (int32_t y = 0; y < f.height; ++y)
    for (int32_t x = 0; x < f.width; ++x)
      EXPECT_EQ(got[static_cast<size_t>(y) * f.width + x],
                int64_t{x - 22} * (x - 22) + int64_t{y - 4} * (y - 4));
}

TEST(DistanceTransform, ARaisedCancelFlagStopsBeforeAnyRow) {
  Field f{8, 8, std::vector<uint8_t>(64, 1)};
  std::atomic<bool> cancel{true};
  int rows = 0;
  EXPECT_FALSE(core::squared_distance_rows(
      8, 8, 3, [&](int32_t x, int32_t y) { return f.at(x, y); },
      [&](int32_t, const int64_t*) { ++rows; }, &cancel));
  EXPECT_EQ(rows, 0);
}

}  // namespace
}  // namespace vnsba::test
