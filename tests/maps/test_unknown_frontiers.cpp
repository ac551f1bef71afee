// Unknown cells on slices cut from real OctoMaps (issue 45, item 8): a slice has unknown cells
// along every scan frontier. With config/default.yaml's robot (robot_radius 0.15 m, a cost
// gradient to 0.55 m, unknown cells blocked) only occupied cells are inflated, as in Nav2's
// inflation layer, so a corridor that no occupied cell narrows stays open. Oracles, independent
// of GridMap: the blocked cells by their definition (occupied, unknown, or within the radius of an
// occupied centre, brute force in a window), and which queries connect (a flood over the cells
// the oracle leaves free, 8-connected, no corner cut). The planner must find a path exactly for
// the connected queries. The embedded scene is always there; the data set's OctoMaps are skipped
// with a message when absent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <queue>
#include <random>
#include <string>
#include <vector>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/octomap_slice.hpp"

namespace {

namespace fs = std::filesystem;
using vnsba::core::Cell;
using vnsba::core::GridBuildOptions;
using vnsba::core::GridMap;
using vnsba::core::OccupancyGrid;

// config/default.yaml's map section.
GridBuildOptions default_robot() {
  GridBuildOptions o;
  o.occupied_threshold = 65;
  o.allow_unknown = false;
  o.robot_radius = 0.15;
  o.inflation_radius = 0.55;
  o.cost_scaling_factor = 3.0;
  return o;
}

// Blocked by definition: occupied or unknown, or a free cell whose centre lies within the radius
// of an occupied centre (and, with inflate_unknown, of an unknown one).
std::vector<bool> blocked_by_definition(const OccupancyGrid& g, double radius_cells,
                                        bool inflate_unknown) {
  const int reach = static_cast<int>(std::ceil(radius_cells));
  std::vector<bool> out(g.data.size(), false);
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      bool blocked = g.at(x, y) != 0;
      for (int dy = -reach; dy <= reach && !blocked; ++dy)
        for (int dx = -reach; dx <= reach && !blocked; ++dx) {
          const int ox = x + dx, oy = y + dy;
          if (ox < 0 || oy < 0 || ox >= g.width || oy >= g.height) continue;
          const int v = g.at(ox, oy);
          const bool source = v >= 65 || (inflate_unknown && v < 0);
          blocked = source && dx * dx + dy * dy <= radius_cells * radius_cells + 1e-9;
        }
      out[static_cast<size_t>(y) * g.width + x] = blocked;
    }
  return out;
}

// The components of the free cells, 8-connected, a diagonal step only between two free
// orthogonal neighbours (corner_policy never).
std::vector<int> components(const OccupancyGrid& g, const std::vector<bool>& blocked) {
  std::vector<int> label(blocked.size(), -1);
  int next = 0;
  auto free_at = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < g.width && y < g.height &&
           !blocked[static_cast<size_t>(y) * g.width + x];
  };
  for (int y0 = 0; y0 < g.height; ++y0)
    for (int x0 = 0; x0 < g.width; ++x0) {
      if (!free_at(x0, y0) || label[static_cast<size_t>(y0) * g.width + x0] >= 0) continue;
      std::queue<Cell> open;
      open.push({x0, y0});
      label[static_cast<size_t>(y0) * g.width + x0] = next;
      while (!open.empty()) {
        const Cell c = open.front();
        open.pop();
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int x = c.x + dx, y = c.y + dy;
            if ((dx == 0 && dy == 0) || !free_at(x, y)) continue;
            if (dx != 0 && dy != 0 && !(free_at(c.x + dx, c.y) && free_at(c.x, c.y + dy))) continue;
            int& l = label[static_cast<size_t>(y) * g.width + x];
            if (l >= 0) continue;
            l = next;
            open.push({x, y});
          }
      }
      ++next;
    }
  return label;
}

struct Counts {
  int queries = 0, connected = 0, found = 0;
};

// Builds the slice's grid with `options`, checks every cell against the definition, and plans
// each query: a path exactly when the oracle connects it.
Counts check_slice(const OccupancyGrid& slice, GridBuildOptions options,
                   const std::vector<std::pair<Cell, Cell>>& queries) {
  Counts counts;
  auto built = GridMap::build(slice, options);
  EXPECT_TRUE(built.has_value()) << built.error().message;
  if (!built) return counts;
  auto map = std::make_shared<const GridMap>(std::move(built).value());
  const double radius_cells = options.robot_radius / slice.resolution;
  const std::vector<bool> blocked =
      blocked_by_definition(slice, radius_cells, options.inflate_unknown);
  size_t mismatches = 0;
  for (int y = 0; y < slice.height; ++y)
    for (int x = 0; x < slice.width; ++x)
      if (map->blocked(x, y) != blocked[static_cast<size_t>(y) * slice.width + x] &&
          ++mismatches <= 5)
        ADD_FAILURE() << "cell (" << x << ", " << y << "): blocked " << map->blocked(x, y)
                      << ", by definition " << blocked[static_cast<size_t>(y) * slice.width + x];
  EXPECT_EQ(mismatches, 0u);
  const std::vector<int> label = components(slice, blocked);
  vnsba::core::Planner planner(map);
  const vnsba::core::PlannerOptions plan_options =
      vnsba::core::default_options(vnsba::core::PlannerKind::kAStar);
  for (const auto& [a, b] : queries) {
    ++counts.queries;
    const bool connected = label[static_cast<size_t>(a.y) * slice.width + a.x] ==
                           label[static_cast<size_t>(b.y) * slice.width + b.x];
    const auto r = planner.plan({a, b}, plan_options);
    const bool found = r.status.is_ok();
    counts.connected += connected;
    counts.found += found;
    EXPECT_EQ(found, connected) << "(" << a.x << ", " << a.y << ") -> (" << b.x << ", " << b.y
                                << "): " << r.status.message;
  }
  return counts;
}

// The slice at config/default.yaml's band (0.1..1.5 m): 40 queries between cells free either
// way, at least 40 cells apart, checked with unknown cells not inflated (the default) and
// inflated (inflate_unknown). Not inflating them only opens ways: every query that connects with
// them inflated connects without.
void check_octomap(const std::string& path) {
  auto tree = vnsba::maps::load_octree(path);
  ASSERT_TRUE(tree.has_value()) << tree.error().message;
  vnsba::maps::SliceOptions band;
  auto slice = vnsba::maps::slice_octree(**tree, band);
  ASSERT_TRUE(slice.has_value()) << slice.error().message;
  size_t unknown = 0;
  for (const int8_t v : slice->data) unknown += v < 0;
  ASSERT_GT(unknown, 0u) << path << ": a slice with no unknown cell tests nothing here";
  const GridBuildOptions nav2 = default_robot();
  GridBuildOptions inflated = nav2;
  inflated.inflate_unknown = true;
  const std::vector<bool> stricter = blocked_by_definition(
      *slice, inflated.robot_radius / slice->resolution, /*inflate_unknown=*/true);
  std::vector<Cell> free_cells;
  for (int y = 0; y < slice->height; ++y)
    for (int x = 0; x < slice->width; ++x)
      if (!stricter[static_cast<size_t>(y) * slice->width + x]) free_cells.push_back({x, y});
  ASSERT_GE(free_cells.size(), 2u);
  std::mt19937 rng(1);
  std::uniform_int_distribution<size_t> pick(0, free_cells.size() - 1);
  std::vector<std::pair<Cell, Cell>> queries;
  while (queries.size() < 40) {
    const Cell a = free_cells[pick(rng)], b = free_cells[pick(rng)];
    if (std::hypot(a.x - b.x, a.y - b.y) >= 40) queries.push_back({a, b});
  }
  const Counts open = check_slice(*slice, nav2, queries);
  const Counts closed = check_slice(*slice, inflated, queries);
  EXPECT_GE(open.found, closed.found);
  std::printf(
      "%s: %d x %d cells, %zu unknown; of 40 queries %d connect with unknown cells not "
      "inflated, %d with them inflated\n",
      fs::path(path).filename().c_str(), slice->width, slice->height, unknown, open.found,
      closed.found);
}

TEST(UnknownFrontiers, TheSceneConnectsAsNav2sConventionSays) {
  check_octomap(VNSBA_SCENE_PATH);
}

TEST(UnknownFrontiers, TheDataSetsOctoMapsConnectAsNav2sConventionSays) {
  const std::string dir = std::string(VNSBA_DATA_DIR) + "/octomap";
  if (!fs::exists(dir + "/fr_078_tidyup.bt"))
    GTEST_SKIP() << dir << "/fr_078_tidyup.bt is absent: the data set beside the project is needed";
  check_octomap(dir + "/fr_078_tidyup.bt");
}

}  // namespace
