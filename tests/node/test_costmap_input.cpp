// map.cost_source: costmap (issue 32, item 4): a Nav2 global costmap on the slice topic is planned
// on as it is. Oracles: the same costs given as an own map with the costmap's threshold and no
// inflation (the paths must be equal), and the costmap's own cells (no path through 99 or 100).
#include <gtest/gtest.h>

#include <cmath>

#include "bus_client.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

// A Nav2-style costmap (nav2_costmap_2d's inflation layer, then its cost_translation_table into
// an OccupancyGrid), 120 x 80 cells of 0.05 m: walls across the middle (x = 60) with two doors,
// 0.5 m (10 cells) and 0.7 m (14 cells) wide, an unknown patch, and around every lethal cell the
// inscribed ring (distance <= 0.15 m: 99) and the decaying cost out to 0.55 m:
// 252 * exp(-3 * (d - 0.15)) as costmap_2d's 1..252 scale, then 1 + 97 * (cost - 1) / 251.
core::OccupancyGrid nav2_costmap() {
  core::OccupancyGrid g;
  g.width = 120;
  g.height = 80;
  g.resolution = 0.05;
  std::vector<bool> lethal(static_cast<size_t>(g.width * g.height), false);
  for (int y = 0; y < g.height; ++y) {
    const bool door = (y >= 15 && y < 25) || (y >= 50 && y < 64);
    if (!door) lethal[static_cast<size_t>(y * g.width + 60)] = true;
  }
  g.data.assign(lethal.size(), 0);
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      double d = 1e9;  // metres to the nearest lethal cell centre (brute force)
      for (int ly = 0; ly < g.height; ++ly)
        if (lethal[static_cast<size_t>(ly * g.width + 60)])
          d = std::min(d, std::hypot(x - 60, y - ly) * g.resolution);
      int8_t value = 0;
      if (d == 0.0) {
        value = 100;
      } else if (d <= 0.15 + 1e-9) {
        value = 99;
      } else if (d <= 0.55) {
        const double cost = 252.0 * std::exp(-3.0 * (d - 0.15));
        value = static_cast<int8_t>(1 + (97 * (static_cast<int>(cost) - 1)) / 251);
      }
      g.data[static_cast<size_t>(y * g.width + x)] = value;
    }
  }
  for (int y = 70; y < 76; ++y)
    for (int x = 10; x < 20; ++x) g.data[static_cast<size_t>(y * g.width + x)] = -1;
  return g;
}

node::NodeConfig with_topics(node::NodeConfig base, const std::string& tag) {
  const node::NodeConfig names = test_config(tag);
  base.domain_id = names.domain_id;
  base.topics = names.topics;
  base.planner.settings.max_planning_time = std::chrono::seconds(10);
  return base;
}

bool crosses_blocked(const core::OccupancyGrid& g, const PlanStatusMsg& status) {
  const auto& poses = status.path().poses();
  for (size_t i = 0; i + 1 < poses.size(); ++i) {
    const auto& a = poses[i].pose().position();
    const auto& b = poses[i + 1].pose().position();
    const int n = std::max(
        2, static_cast<int>(std::hypot(b.x() - a.x(), b.y() - a.y()) / g.resolution * 64) + 1);
    for (int k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) / (n - 1);
      const int cx = static_cast<int>(std::floor((a.x() + t * (b.x() - a.x())) / g.resolution));
      const int cy = static_cast<int>(std::floor((a.y() + t * (b.y() - a.y())) / g.resolution));
      if (cx < 0 || cy < 0 || cx >= g.width || cy >= g.height) return true;
      const int v = g.at(cx, cy);
      if (v < 0 || v >= node::kCostmapInscribed) return true;
    }
  }
  return false;
}

TEST(CostmapInput, PlansOnTheCostmapAsItIsLikeAnOwnMapOfTheSameCostsWithoutInflation) {
  const core::OccupancyGrid grid = nav2_costmap();
  node::NodeConfig costmap_cfg = *node::default_config().config;
  costmap_cfg.map_cost_source = node::MapCostSource::kCostmap;
  node::NodeConfig own_cfg = *node::default_config().config;
  own_cfg.map.occupied_threshold = node::kCostmapInscribed;
  own_cfg.map.robot_radius = 0.0;
  own_cfg.map.inflation_radius = 0.0;
  Running costmap(with_topics(costmap_cfg, "costmap_in"));
  Running own(with_topics(own_cfg, "costmap_own"));
  ASSERT_TRUE(costmap.start_with_map(grid));
  ASSERT_TRUE(own.start_with_map(grid));
  int compared = 0;
  for (const std::string planner : {"", "astar", "vns_bastar"}) {
    for (const auto& [gx, gy] : {std::pair{5.3, 1.0}, std::pair{5.5, 2.9}, std::pair{4.1, 3.6}}) {
      SCOPED_TRACE("planner '" + planner + "' to (" + std::to_string(gx) + ", " +
                   std::to_string(gy) + ")");
      const std::string id = "c" + std::to_string(compared++);
      costmap.client.publish_request(id, 0.4, 0.6, gx, gy, planner);
      own.client.publish_request(id, 0.4, 0.6, gx, gy, planner);
      const auto a = costmap.client.wait_status(id);
      const auto b = own.client.wait_status(id);
      ASSERT_TRUE(a.has_value() && b.has_value());
      EXPECT_EQ(a->code(), node::wire::OK) << a->message();
      EXPECT_EQ(a->code(), b->code());
      EXPECT_FALSE(crosses_blocked(grid, *a)) << "through an inscribed, lethal or unknown cell";
      ASSERT_EQ(a->path().poses().size(), b->path().poses().size());
      for (size_t i = 0; i < a->path().poses().size(); ++i) {
        EXPECT_DOUBLE_EQ(a->path().poses()[i].pose().position().x(),
                         b->path().poses()[i].pose().position().x());
        EXPECT_DOUBLE_EQ(a->path().poses()[i].pose().position().y(),
                         b->path().poses()[i].pose().position().y());
      }
    }
  }
}

// What the issue measured: read as an occupancy map (the default), a costmap's 65..98 cells are
// walls and get inflated again, and its doors close; read as a costmap, both doors are open.
TEST(CostmapInput, NarrowDoorsOfACostmapStayOpenOnlyWhenReadAsACostmap) {
  const core::OccupancyGrid grid = nav2_costmap();
  node::NodeConfig costmap_cfg = *node::default_config().config;
  costmap_cfg.map_cost_source = node::MapCostSource::kCostmap;
  Running costmap(with_topics(costmap_cfg, "door_costmap"));
  Running own(with_topics(*node::default_config().config, "door_own"));
  ASSERT_TRUE(costmap.start_with_map(grid));
  ASSERT_TRUE(own.start_with_map(grid));
  // Through the 0.5 m door (y 0.75..1.25 m) and the 0.7 m one (y 2.5..3.2 m): a start and goal
  // level with each door, far enough from the wall that both are free either way.
  const std::pair<double, double> doors[] = {{1.0, 1.0}, {2.85, 2.85}};
  for (const auto& [sy, gy] : doors) {
    const std::string id = "door" + std::to_string(sy);
    costmap.client.publish_request(id, 1.5, sy, 4.5, gy, "astar");
    own.client.publish_request(id, 1.5, sy, 4.5, gy, "astar");
    const auto through = costmap.client.wait_status(id);
    const auto closed = own.client.wait_status(id);
    ASSERT_TRUE(through.has_value() && closed.has_value());
    EXPECT_EQ(through->code(), node::wire::OK) << through->message();
    EXPECT_FALSE(crosses_blocked(grid, *through));
    EXPECT_EQ(closed->code(), node::wire::NO_VALID_PATH) << closed->message();
  }
}

}  // namespace
}  // namespace vnsba::test
