// is_path_valid's check (path_validity.hpp) against a brute-force oracle on small random maps:
// the oracle classifies each pose's cell from the raw occupancy values and the distances to every
// obstacle cell, and applies Nav2's rule as kilted's planner_server.cpp writes it (lethal or
// inscribed, or a cost of max_cost or more; unknown lethal or free per the request), from the
// pose closest to the robot.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "vnsba/node/path_validity.hpp"

namespace vnsba::node {
namespace {

struct OracleCell {
  bool off_map = false;
  bool occupied = false;  // lethal
  bool unknown = false;   // kept unknown (allow_unknown false)
  bool inflated = false;  // within robot_radius of an obstacle
  double cost = 0.0;      // a free cell's cost in [0, 1)
};

// Every fact of the cell under (x, y) from the grid's values alone.
OracleCell oracle_cell(const core::OccupancyGrid& grid, const core::GridBuildOptions& options,
                       double x, double y) {
  OracleCell out;
  const double gx = (x - grid.origin_x) / grid.resolution;
  const double gy = (y - grid.origin_y) / grid.resolution;
  if (!std::isfinite(gx) || !std::isfinite(gy) || gx < 0 || gy < 0 || gx >= grid.width ||
      gy >= grid.height) {
    out.off_map = true;
    return out;
  }
  const int cx = static_cast<int>(gx), cy = static_cast<int>(gy);
  const int v = grid.at(cx, cy);
  if (v >= options.occupied_threshold) {
    out.occupied = true;
    return out;
  }
  if (v < 0 && !options.allow_unknown) {
    out.unknown = true;
    return out;
  }
  // Obstacles: occupied cells (unknown ones are not inflated: inflate_unknown false).
  double nearest = std::numeric_limits<double>::infinity();  // metres, centre to centre
  for (int oy = 0; oy < grid.height; ++oy)
    for (int ox = 0; ox < grid.width; ++ox)
      if (grid.at(ox, oy) >= options.occupied_threshold)
        nearest = std::min(nearest, std::hypot(ox - cx, oy - cy) * grid.resolution);
  if (options.robot_radius > 0 && nearest <= options.robot_radius + 1e-9) {
    out.inflated = true;
    return out;
  }
  out.cost = v > 0 ? v / 100.0 : 0.0;
  if (options.inflation_radius > 0 && nearest <= options.inflation_radius + 1e-9)
    out.cost = std::max(
        out.cost, 0.99 * std::exp(-options.cost_scaling_factor * (nearest - options.robot_radius)));
  return out;
}

// Kilted's planner_server isPathValid, written out for one pose (use_radius true).
bool oracle_pose_valid(const OracleCell& cell, const PathCheckRules& rules) {
  int cost = 0;
  if (cell.off_map || cell.occupied)
    cost = 254;
  else if (cell.inflated)
    cost = 253;
  else if (cell.unknown)
    cost = 255;
  else
    cost = static_cast<int>(std::lround(std::min(252.0, cell.cost / 0.99 * 252.0)));
  if (cost == 255) cost = rules.unknown_is_obstacle ? 254 : 0;
  return !(cost >= rules.max_cost || cost == 254 || cost == 253);
}

TEST(PathValidity, MatchesABruteForceOracleOnRandomMaps) {
  std::mt19937 rng(48);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked_poses = 0, invalid_poses = 0, valid_paths = 0;
  for (int trial = 0; trial < 300; ++trial) {
    core::OccupancyGrid grid;
    grid.width = 4 + static_cast<int>(rng() % 10);
    grid.height = 4 + static_cast<int>(rng() % 10);
    grid.resolution = trial % 2 == 0 ? 0.5 : 0.1;
    grid.origin_x = -1.0 + unit(rng);
    grid.origin_y = -0.5 * unit(rng);
    for (int i = 0; i < grid.width * grid.height; ++i) {
      const double r = unit(rng);
      grid.data.push_back(r < 0.08   ? int8_t{100}
                          : r < 0.16 ? int8_t{-1}
                          : r < 0.4  ? static_cast<int8_t>(1 + rng() % 64)
                                     : int8_t{0});
    }
    core::GridBuildOptions options;
    options.occupied_threshold = 65;
    options.allow_unknown = trial % 3 == 0;
    options.robot_radius = (trial % 4) * 0.5 * grid.resolution;  // 0, 0.5, 1, 1.5 cells
    options.inflation_radius = trial % 5 == 0 ? 0.0 : options.robot_radius + 3 * grid.resolution;
    auto built = core::GridMap::build(grid, options);
    ASSERT_TRUE(built.has_value()) << built.error().message;
    const core::GridMap& map = *built;

    PathCheckRules rules;
    if (trial % 2 == 1) {  // Kilted's fields; the others keep Humble's and Jazzy's
      rules.max_cost = static_cast<uint8_t>(rng() % 256);
      rules.unknown_is_obstacle = rng() % 2 == 0;
    }
    std::vector<Eigen::Vector2d> poses;
    const int count = static_cast<int>(rng() % 12);
    for (int i = 0; i < count; ++i) {
      const double x = grid.origin_x + (unit(rng) * 1.2 - 0.1) * grid.width * grid.resolution;
      const double y = grid.origin_y + (unit(rng) * 1.2 - 0.1) * grid.height * grid.resolution;
      poses.emplace_back(x, i == 3 && trial % 7 == 0 ? std::nan("") : y);
    }
    std::optional<Eigen::Vector2d> robot;
    if (trial % 6 != 0 && !poses.empty())
      robot = poses[rng() % poses.size()] + Eigen::Vector2d(0.01, 0);

    const PathValidity got = check_path(map, poses, robot, rules);
    // The oracle: the first closest pose, then every pose on from it.
    size_t first = 0;
    if (robot) {
      double best = std::numeric_limits<double>::max();
      for (size_t i = 0; i < poses.size(); ++i) {
        const double d = std::hypot(poses[i].x() - robot->x(), poses[i].y() - robot->y());
        if (d < best) best = d, first = i;
      }
    }
    std::vector<int32_t> expected;
    for (size_t i = first; i < poses.size(); ++i) {
      ++checked_poses;
      if (!oracle_pose_valid(oracle_cell(grid, options, poses[i].x(), poses[i].y()), rules))
        expected.push_back(static_cast<int32_t>(i));
    }
    invalid_poses += static_cast<int>(expected.size());
    EXPECT_EQ(got.first_checked, first) << "trial " << trial;
    EXPECT_EQ(got.invalid_pose_indices, expected) << "trial " << trial;
    EXPECT_EQ(got.is_valid, !poses.empty() && expected.empty()) << "trial " << trial;
    valid_paths += got.is_valid ? 1 : 0;
  }
  // The maps exercised both answers.
  EXPECT_GT(invalid_poses, 50);
  EXPECT_GT(checked_poses - invalid_poses, 50);
  EXPECT_GT(valid_paths, 10);
}

TEST(PathValidity, NavTwosRulesOnHandMadeCells) {
  // Row 0 (bottom): free, graded 50, occupied, unknown; 1 m cells at the origin.
  core::OccupancyGrid grid;
  grid.width = 4;
  grid.height = 1;
  grid.resolution = 1.0;
  grid.data = {0, 50, 100, -1};
  const core::GridMap map = std::move(core::GridMap::build(grid, {})).value();
  const std::vector<Eigen::Vector2d> path = {
      {0.5, 0.5}, {1.5, 0.5}, {2.5, 0.5}, {3.5, 0.5}, {9.0, 0.5}};
  // Humble and Jazzy: occupied, unknown (the map keeps it so) and off the map.
  EXPECT_EQ(check_path(map, path, std::nullopt, {}).invalid_pose_indices,
            (std::vector<int32_t>{2, 3, 4}));
  // From the pose closest to the robot: the ones behind it do not count.
  EXPECT_EQ(check_path(map, path, Eigen::Vector2d(3.4, 0.6), {}).invalid_pose_indices,
            (std::vector<int32_t>{3, 4}));
  // Kilted: unknown as free, and max_cost at the graded cell's cost (50 -> 127 on Nav2's scale).
  EXPECT_EQ(nav2_cost(map, {1, 0}), 127);
  EXPECT_EQ(check_path(map, path, std::nullopt, {127, false}).invalid_pose_indices,
            (std::vector<int32_t>{1, 2, 4}));
  EXPECT_EQ(check_path(map, path, std::nullopt, {128, false}).invalid_pose_indices,
            (std::vector<int32_t>{2, 4}));
  // An empty path is invalid, as in Nav2.
  EXPECT_FALSE(check_path(map, {}, std::nullopt, {}).is_valid);
}

}  // namespace
}  // namespace vnsba::node
