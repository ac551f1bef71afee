// The node's conversions of plans into messages without DDS (convert.hpp): path poses, the
// status fields of docs/algorithm.md section 8 (clearance, the endpoints used) and its messages.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "vnsba/core/planner.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"

namespace vnsba::test {
namespace {

namespace wire = node::wire;

double yaw_of(const node::PoseStampedMsg& pose) {
  const auto& q = pose.pose().orientation();
  EXPECT_NEAR(q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w(), 1.0, 1e-12);
  return 2.0 * std::atan2(q.z(), q.w());
}

double angle_between(double a, double b) {
  return std::abs(std::remainder(a - b, 2.0 * M_PI));
}

core::PlanResult result_with_path(std::vector<Eigen::Vector2d> world_path) {
  core::PlanResult r;
  r.status = core::Status::ok();
  r.world_path = std::move(world_path);
  return r;
}

// Poses at most spacing apart, each facing the next one (atan2 computed here), the last facing
// the goal's yaw when given, else along the last segment; every vertex of the path is a pose.
TEST(PathMsg, PosesAreSpacedWithTangentYawAndTheGoalYawLast) {
  const core::PlanResult r = result_with_path({{0.0, 0.0}, {1.0, 0.0}, {1.0, 0.35}, {0.4, 0.95}});
  for (const double spacing : {0.3, 0.05, 5.0}) {
    for (const std::optional<double> goal_yaw : {std::optional<double>(), std::optional(-2.5)}) {
      SCOPED_TRACE("spacing " + std::to_string(spacing) +
                   (goal_yaw ? ", goal yaw -2.5" : ", no goal yaw"));
      const node::PathMsg msg = node::to_path_msg(r, "map", node::now_msg(), spacing, goal_yaw);
      EXPECT_EQ(msg.header().frame_id(), "map");
      const auto& poses = msg.poses();
      ASSERT_GE(poses.size(), r.world_path.size());
      size_t vertex = 0;
      for (size_t i = 0; i < poses.size(); ++i) {
        const double x = poses[i].pose().position().x(), y = poses[i].pose().position().y();
        if (vertex < r.world_path.size() &&
            std::hypot(x - r.world_path[vertex].x(), y - r.world_path[vertex].y()) < 1e-12)
          ++vertex;
        if (i + 1 == poses.size()) break;
        const double nx = poses[i + 1].pose().position().x();
        const double ny = poses[i + 1].pose().position().y();
        EXPECT_LE(std::hypot(nx - x, ny - y), spacing + 1e-12) << i;
        EXPECT_LT(angle_between(yaw_of(poses[i]), std::atan2(ny - y, nx - x)), 1e-9) << i;
      }
      EXPECT_EQ(vertex, r.world_path.size()) << "every vertex is a pose";
      const double last = yaw_of(poses.back());
      const double tangent = std::atan2(0.95 - 0.35, 0.4 - 1.0);
      EXPECT_LT(angle_between(last, goal_yaw.value_or(tangent)), 1e-9);
    }
  }
  // A path of one cell: one pose, with the goal's yaw.
  const node::PathMsg one =
      node::to_path_msg(result_with_path({{2.0, 3.0}}), "map", node::now_msg(), 0.1, 1.0);
  ASSERT_EQ(one.poses().size(), 1u);
  EXPECT_NEAR(yaw_of(one.poses()[0]), 1.0, 1e-12);
}

// 30 x 100 cells at 0.05 m, origin (0, 0): cell (24, 91) has its centre at (1.225, 4.575) m.
core::GridMap open_map() {
  core::OccupancyGrid g;
  g.width = 30;
  g.height = 100;
  g.resolution = 0.05;
  g.data.assign(3000, 0);
  return std::move(core::GridMap::build(g)).value();
}

TEST(StatusMsg, AdjustedEndpointsAreDescribedInMetres) {
  const core::GridMap map = open_map();
  core::PlannerOptions options;
  options.goal_tolerance = 0.3;
  options.start_tolerance = 0.25;
  core::Endpoints e;
  e.start = {2, 3};
  e.goal = {24, 91};
  EXPECT_EQ(node::describe_adjusted_endpoints(e, map, options), "");
  e.goal_adjusted = true;
  e.goal_moved_m = 0.07;
  EXPECT_EQ(node::describe_adjusted_endpoints(e, map, options),
            "goal moved 0.070 m to the nearest free cell (1.225, 4.575) m (goal_tolerance 0.3 m)");
  e.start_adjusted = true;
  e.start_moved_m = 0.0354;
  EXPECT_EQ(node::describe_adjusted_endpoints(e, map, options),
            "start moved 0.035 m to the nearest free cell (0.125, 0.175) m (start_tolerance 0.25 "
            "m); goal moved 0.070 m to the nearest free cell (1.225, 4.575) m (goal_tolerance "
            "0.3 m)");
}

TEST(StatusMsg, ClearanceAndTheUsedEndpointsAreFilledAndReadBack) {
  const core::GridMap map = open_map();
  core::Metrics metrics;
  metrics.length_m = 3.5;
  metrics.clearance_m = 0.42;
  core::Endpoints e;
  e.start = {2, 3};
  e.goal = {24, 91};
  e.goal_adjusted = true;
  e.goal_moved_m = 0.07;
  node::RequestIdentity id;
  const node::PlanStatusMsg ok = node::to_status_msg(
      "r", &id, {wire::OK, ""}, "vns_bastar", &metrics, node::TimeMsg(), node::PathMsg(), &e, &map);
  EXPECT_DOUBLE_EQ(ok.clearance_m(), 0.42);
  EXPECT_NEAR(ok.start_x(), 0.125, 1e-12);
  EXPECT_NEAR(ok.start_y(), 0.175, 1e-12);
  EXPECT_NEAR(ok.goal_x(), 1.225, 1e-12);
  EXPECT_NEAR(ok.goal_y(), 4.575, 1e-12);
  EXPECT_FALSE(ok.start_adjusted());
  EXPECT_TRUE(ok.goal_adjusted());
  EXPECT_EQ(ok.start_moved_m(), 0.0);
  EXPECT_DOUBLE_EQ(ok.goal_moved_m(), 0.07);
  EXPECT_DOUBLE_EQ(node::metrics_from_status_msg(ok).clearance_m, 0.42);
  EXPECT_DOUBLE_EQ(node::metrics_from_status_msg(ok).length_m, 3.5);

  // No obstacle: +inf, as is.
  metrics.clearance_m = std::numeric_limits<double>::infinity();
  const node::PlanStatusMsg open = node::to_status_msg("r", &id, {wire::OK, ""}, "astar", &metrics,
                                                       node::TimeMsg(), node::PathMsg(), &e, &map);
  EXPECT_TRUE(std::isinf(open.clearance_m()) && open.clearance_m() > 0);
  EXPECT_TRUE(std::isinf(node::metrics_from_status_msg(open).clearance_m));

  // Not OK: NaN clearance whatever the metrics say; no endpoints: NaN positions, no flags.
  const node::PlanStatusMsg failed =
      node::to_status_msg("r", &id, {wire::NO_VALID_PATH, "no path"}, "astar", &metrics,
                          node::TimeMsg(), node::PathMsg());
  EXPECT_TRUE(std::isnan(failed.clearance_m()));
  EXPECT_TRUE(std::isnan(node::metrics_from_status_msg(failed).clearance_m));
  EXPECT_TRUE(std::isnan(failed.start_x()) && std::isnan(failed.goal_y()));
  EXPECT_FALSE(failed.start_adjusted() || failed.goal_adjusted());
  const node::PlanStatusMsg map_report = node::to_status_msg(
      "", nullptr, {wire::INVALID_MAP, "bad"}, "", nullptr, node::TimeMsg(), node::PathMsg());
  EXPECT_TRUE(std::isnan(map_report.clearance_m()));
  EXPECT_TRUE(std::isnan(map_report.goal_x()));
}

// Frames (issue: "/map" from ROS 1 bridges and old configs got FRAME_MISMATCH): a leading '/'
// does not make another frame, on the message's side or the config's; another name still does.
TEST(Frames, ALeadingSlashNamesTheSameFrame) {
  EXPECT_TRUE(node::same_frame("map", "map"));
  EXPECT_TRUE(node::same_frame("/map", "map"));
  EXPECT_TRUE(node::same_frame("map", "/map"));
  EXPECT_FALSE(node::same_frame("odom", "map"));
  EXPECT_FALSE(node::same_frame("//map", "map"));  // tf2 drops one slash only
  EXPECT_FALSE(node::same_frame("/", "map"));

  const node::PoseStampedMsg slashed = node::to_pose_msg(1.0, 2.0, 0.0, "/map", node::now_msg());
  EXPECT_TRUE(node::check_pose(slashed, "start", "map").status.ok());
  const node::PoseStampedMsg odom = node::to_pose_msg(1.0, 2.0, 0.0, "odom", node::now_msg());
  const node::PoseCheck refused = node::check_pose(odom, "start", "map");
  EXPECT_EQ(refused.status.code, wire::FRAME_MISMATCH);
  EXPECT_NE(refused.status.message.find("start.header.frame_id is 'odom'"), std::string::npos);

  core::OccupancyGrid grid;
  grid.width = 2;
  grid.height = 1;
  grid.resolution = 0.5;
  grid.data = {0, 100};
  EXPECT_TRUE(
      node::from_slice_msg(node::to_slice_msg(grid, "/map", node::now_msg()), "map", 1 << 20)
          .status.ok());
  EXPECT_EQ(node::from_slice_msg(node::to_slice_msg(grid, "odom", node::now_msg()), "map", 1 << 20)
                .status.code,
            wire::FRAME_MISMATCH);
}

// The debug layers in stock types: the expansions grid has the map's geometry and numbers the
// cells in expansion order; the paths pass through the cells' centres.
TEST(DebugLayers, ExpansionsAreOrderedOnTheMapGeometryAndPathsThroughCellCentres) {
  core::OccupancyGrid g;
  g.width = 7;
  g.height = 5;
  g.resolution = 0.2;
  g.origin_x = -1.0;
  g.origin_y = 3.0;
  g.data.assign(35, 0);
  const core::GridMap map = std::move(core::GridMap::build(g)).value();
  const std::vector<core::Cell> expanded = {{0, 0}, {1, 0}, {1, 1}, {6, 4}};
  const node::OccupancyGridMsg grid =
      node::to_expansions_msg(expanded, map, "map", node::to_time_msg(int64_t{5'000'000'000}));
  EXPECT_EQ(grid.info().width(), 7u);
  EXPECT_EQ(grid.info().height(), 5u);
  EXPECT_FLOAT_EQ(grid.info().resolution(), 0.2f);
  EXPECT_DOUBLE_EQ(grid.info().origin().position().x(), -1.0);
  EXPECT_DOUBLE_EQ(grid.info().origin().position().y(), 3.0);
  EXPECT_EQ(grid.header().stamp().sec(), 5);
  ASSERT_EQ(grid.data().size(), 35u);
  auto at = [&](int x, int y) { return grid.data()[static_cast<size_t>(y) * 7 + x]; };
  EXPECT_EQ(at(0, 0), 1);  // first
  EXPECT_EQ(at(1, 0), 34);
  EXPECT_EQ(at(1, 1), 67);
  EXPECT_EQ(at(6, 4), 100);  // last
  int nonzero = 0;
  for (int8_t v : grid.data()) nonzero += v != 0;
  EXPECT_EQ(nonzero, 4);
  // One expansion is both first and last: 1.
  EXPECT_EQ(node::to_expansions_msg({{3, 2}}, map, "map", node::now_msg()).data()[2 * 7 + 3], 1);

  core::PlanResult result;
  result.raw_path = {{0, 0}, {1, 1}, {2, 1}};
  result.waypoints = {{0.5, 0.5}, {2.5, 1.5}};
  const node::PathMsg raw = node::to_raw_path_msg(result, map, "map", node::now_msg());
  ASSERT_EQ(raw.poses().size(), 3u);
  EXPECT_NEAR(raw.poses()[1].pose().position().x(), -1.0 + 1.5 * 0.2, 1e-12);
  EXPECT_NEAR(raw.poses()[1].pose().position().y(), 3.0 + 1.5 * 0.2, 1e-12);
  const node::PathMsg pruned = node::to_pruned_path_msg(result, map, "map", node::now_msg());
  ASSERT_EQ(pruned.poses().size(), 2u);
  EXPECT_NEAR(pruned.poses()[1].pose().position().x(), -1.0 + 2.5 * 0.2, 1e-12);
  const node::PointStampedMsg point = node::to_point_msg({6, 4}, map, "map", node::now_msg());
  EXPECT_NEAR(point.point().x(), -1.0 + 6.5 * 0.2, 1e-12);
  EXPECT_NEAR(point.point().y(), 3.0 + 4.5 * 0.2, 1e-12);
}

TEST(Time, NanosecondsRoundTripAndNanosecStaysInRange) {
  for (const int64_t ns : {int64_t{0}, int64_t{1'500'000'000}, int64_t{-1}, int64_t{-2'250'000'000},
                           int64_t{1'700'000'000'123'456'789}}) {
    const node::TimeMsg t = node::to_time_msg(ns);
    EXPECT_LT(t.nanosec(), 1'000'000'000u) << ns;
    EXPECT_EQ(node::to_nanoseconds(t), ns);
  }
}

// Issue 31 item 7: a slice's origin must be a position a double resolves to a millionth of a
// cell, and carry a rotation that is one and is none (the identity); each refusal names the
// field and, for the position, the limit in metres.
TEST(SliceMsg, AnOriginThatIsNoRotationOrTooFarIsRefusedNamingTheField) {
  core::OccupancyGrid grid;
  grid.width = 40;
  grid.height = 30;
  grid.resolution = 0.05;
  grid.data.assign(1200, 0);
  auto check = [&](auto edit) {
    node::OccupancyGridMsg msg = node::to_slice_msg(grid, "map", node::now_msg());
    edit(msg.info().origin());
    return node::from_slice_msg(std::move(msg), "map", 1 << 20).status;
  };
  auto expect_refused = [](const node::WireStatus& status, const std::vector<std::string>& parts) {
    EXPECT_EQ(status.code, wire::INVALID_MAP) << status.message;
    for (const std::string& part : parts)
      EXPECT_NE(status.message.find(part), std::string::npos) << status.message;
  };
  using Pose = geometry_msgs::msg::dds_::Pose_;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_refused(check([&](Pose& o) { o.orientation().w(nan); }),
                 {"info.origin.orientation", "(0, 0, 0, nan)", "must be finite"});
  expect_refused(check([](Pose& o) { o.orientation().w(0.0); }),
                 {"info.origin.orientation", "zero quaternion"});
  expect_refused(check([](Pose& o) {
                   o.orientation().z(std::sin(0.3));
                   o.orientation().w(std::cos(0.3));
                 }),
                 {"info.origin.orientation", "must be the identity"});
  // The identity however written: w = -1, or not normalised.
  EXPECT_TRUE(check([](Pose& o) { o.orientation().w(-1.0); }).ok());
  EXPECT_TRUE(check([](Pose& o) { o.orientation().w(2.5); }).ok());

  // 1e15 m: a double steps by 0.125 m there, more than two cells of 0.05 m. The limit is
  // 0.05 m * 1e-6 / 2^-52 = 225,179,981 m.
  expect_refused(check([](Pose& o) { o.position().x(1e15); }),
                 {"info.origin.position (1e+15, 0)", "2.2518e+08 m"});
  expect_refused(check([](Pose& o) { o.position().y(-2.3e8); }),
                 {"info.origin.position (0, -2.3e+08)"});
  expect_refused(check([&](Pose& o) { o.position().z(nan); }),
                 {"info.origin.position (0, 0, nan) must be finite"});
  // UTM coordinates (easting 500 km, northing 5,000 km) are fine.
  EXPECT_TRUE(check([](Pose& o) {
                o.position().x(500000.0);
                o.position().y(5e6);
              }).ok());
}

// A map_server map of 0.05 m arrives with the float32 0.05000000074505806: the grid is the
// file's 0.05 m again (the decimal the float was written from), whatever the resolution.
TEST(SliceMsg, AFloat32ResolutionIsTheDecimalItWasWrittenFrom) {
  for (const double resolution : {0.05, 0.1, 0.025, 0.3, 0.08, 0.123456}) {
    core::OccupancyGrid grid;
    grid.width = grid.height = 2;
    grid.resolution = resolution;
    grid.data.assign(4, 0);
    const node::SliceCheck received =
        node::from_slice_msg(node::to_slice_msg(grid, "map", node::now_msg()), "map", 1 << 20);
    ASSERT_TRUE(received.status.ok()) << received.status.message;
    EXPECT_EQ(received.grid.resolution, resolution);
    EXPECT_NE(double(static_cast<float>(resolution)), resolution) << "not a float32 case";
  }
  EXPECT_EQ(node::float32_decimal(0.05f), 0.05);
  EXPECT_EQ(node::float32_decimal(1e-7f), 1e-7);
  EXPECT_EQ(node::float32_decimal(3.0f), 3.0);
}

// Issue 47: a slice's values cross from the message into the grid the build reads without a
// copy (the buffer itself moves), so a big slice is held once while it is converted.
TEST(SliceMsg, TheValuesMoveIntoTheGridWithoutACopy) {
  core::OccupancyGrid grid;
  grid.width = 300;
  grid.height = 200;
  grid.data.assign(size_t{300} * 200, 0);
  node::OccupancyGridMsg msg = node::to_slice_msg(grid, "map", node::now_msg());
  const int8_t* values = msg.data().data();
  node::OccupancyGridMsg taken = std::move(msg);  // as the listener and the slot hand it on
  ASSERT_EQ(taken.data().data(), values);
  const node::SliceCheck received = node::from_slice_msg(std::move(taken), "map", 1 << 20);
  ASSERT_TRUE(received.status.ok()) << received.status.message;
  EXPECT_EQ(received.grid.data.data(), values);
}

// Issue 47: what converting a slice holds is the map core estimates plus the slice's values, one
// byte a cell; the estimate bounds what a real build holds (GridMap::bytes).
TEST(SliceMemory, CountsTheGridTheScratchAndTheValuesAndBoundsARealBuild) {
  const node::NodeConfig config = node::default_config().config.value();
  const core::GridBuildOptions options = node::planning_grid_options(config);
  core::OccupancyGrid grid;
  grid.width = 333;
  grid.height = 121;
  grid.resolution = 0.05;
  grid.data.assign(size_t{333} * 121, 0);
  for (int x = 0; x < 300; ++x) grid.data[size_t{60} * 333 + x] = 100;  // a wall: costs, inflation
  const node::SliceMemory memory = node::slice_memory(333, 121, options);
  EXPECT_EQ(memory.slice_bytes, grid.data.size());
  EXPECT_EQ(memory.peak_bytes(), memory.map.map_bytes + memory.map.scratch_bytes + 333 * 121);
  const auto built = core::GridMap::build(grid, options);
  ASSERT_TRUE(built.has_value()) << built.error().message;
  EXPECT_GT(built->bytes(), 0u);
  EXPECT_LE(built->bytes(), memory.map.map_bytes);
}

// Issue 47: a slice whose conversion needs more than map.memory_budget_mb is refused naming its
// size, the MiB it needed and the key; a budget of exactly the figure printed accepts it.
TEST(SliceMemory, ASliceOverTheBudgetIsRefusedNamingItsSizeTheFigureAndTheKey) {
  const node::NodeConfig config = node::default_config().config.value();
  const core::GridBuildOptions options = node::planning_grid_options(config);
  const int32_t width = 3000, height = 2500;
  const size_t peak = node::slice_memory(width, height, options).peak_bytes();
  const int64_t needed_mib = node::mib_rounded_up(peak);
  // The figure is the bytes in MiB (2^20 bytes), rounded up.
  EXPECT_GE(needed_mib * (int64_t{1} << 20), static_cast<int64_t>(peak));
  EXPECT_LT((needed_mib - 1) * (int64_t{1} << 20), static_cast<int64_t>(peak));
  ASSERT_GT(needed_mib, 1);
  const int under = static_cast<int>(needed_mib - 1);
  const node::WireStatus refused = node::check_memory_budget(width, height, options, under);
  EXPECT_EQ(refused.code, wire::INVALID_MAP);
  for (const std::string& part :
       {std::string("3000 x 2500 cells"), "needs " + std::to_string(needed_mib) + " MiB",
        "map.memory_budget_mb = " + std::to_string(under)})
    EXPECT_NE(refused.message.find(part), std::string::npos) << part << " in " << refused.message;
  EXPECT_TRUE(node::check_memory_budget(width, height, options, static_cast<int>(needed_mib)).ok());
}

// Issue 47: with default.yaml, a 10,000 x 10,000 slice (500 m x 500 m at 5 cm) is within the
// memory budget and map.max_cells. Only figures: nothing of that size is allocated.
TEST(SliceMemory, DefaultYamlTakesTenThousandByTenThousand) {
  const node::NodeConfig config = node::default_config().config.value();
  const core::GridBuildOptions options = node::planning_grid_options(config);
  EXPECT_GE(config.map.max_cells, int64_t{10000} * 10000);
  const node::WireStatus status =
      node::check_memory_budget(10000, 10000, options, config.map_memory_budget_mb);
  EXPECT_TRUE(status.ok()) << status.message;
}

}  // namespace
}  // namespace vnsba::test
