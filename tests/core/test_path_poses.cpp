// Path poses and goal yaw (docs/algorithm.md section 8, "Path poses"): invariants on random
// polylines checked against computations made here (atan2, point-segment distance, lengths),
// never against numbers copied from a run.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/test_support.hpp"
#include "vnsba/core/path_poses.hpp"
#include "vnsba/core/planner.hpp"

namespace vnsba::core {
namespace {

using Points = std::vector<Eigen::Vector2d>;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDistanceTolerance = 1e-9;  // metres: distances and positions
constexpr double kRelativeLengthTolerance = 1e-9;
constexpr double kAngleTolerance = 1e-12;    // radians: two atan2 of the same difference
constexpr double kDuplicateDistance = 1e-9;  // metres: the documented duplicate threshold

// a - b as an angle in [-pi, pi], so pi and -pi (the same heading) compare equal.
double angle_difference(double a, double b) {
  return std::remainder(a - b, 2.0 * kPi);
}

double segment_heading(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::atan2(b.y() - a.y(), b.x() - a.x());
}

double distance_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t =
      d.squaredNorm() == 0.0 ? 0.0 : std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * d)).norm();
}

double length_of(const Points& points) {
  double total = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) total += (points[i] - points[i - 1]).norm();
  return total;
}

Eigen::Vector2d position(const Pose2& pose) {
  return {pose.x, pose.y};
}

Points deduplicated(const Points& path) {
  Points kept;
  for (const Eigen::Vector2d& p : path) {
    if (kept.empty() || (p - kept.back()).norm() >= kDuplicateDistance) kept.push_back(p);
  }
  return kept;
}

// A random polyline: 1-12 vertices, segment lengths log-uniform in [1e-6, 100] m, random
// directions, with some exact and sub-threshold (1e-12 m) duplicates mixed in.
Points random_polyline(std::mt19937& rng) {
  std::uniform_int_distribution<int> vertex_count(1, 12);
  std::uniform_real_distribution<double> log_length(std::log(1e-6), std::log(100.0));
  std::uniform_real_distribution<double> direction(-kPi, kPi);
  std::uniform_real_distribution<double> coordinate(-50.0, 50.0);
  std::uniform_int_distribution<int> duplicate_kind(0, 9);  // 0: exact, 1: 1e-12 m off, else none
  Points path{{coordinate(rng), coordinate(rng)}};
  const int n = vertex_count(rng);
  while (static_cast<int>(path.size()) < n) {
    const int kind = duplicate_kind(rng);
    if (kind == 0) {
      path.push_back(path.back());
    } else if (kind == 1) {
      path.push_back(path.back() + Eigen::Vector2d(1e-12, -1e-12));
    } else {
      const double length = std::exp(log_length(rng)), angle = direction(rng);
      path.push_back(path.back() + length * Eigen::Vector2d(std::cos(angle), std::sin(angle)));
    }
  }
  return path;
}

// Every invariant of path_poses(path, spacing, goal_yaw) for a valid spacing.
void expect_invariants(const Points& path, double spacing, std::optional<double> goal_yaw) {
  SCOPED_TRACE(::testing::Message() << path.size() << " points, spacing " << spacing << " m");
  const Points vertices = deduplicated(path);
  const std::vector<Pose2> poses = path_poses(path, spacing, goal_yaw);
  ASSERT_FALSE(vertices.empty());
  ASSERT_FALSE(poses.empty());

  // Pose count: one per vertex plus ceil(length / spacing) - 1 inside each longer segment.
  std::size_t expected_count = 1;
  for (std::size_t k = 0; k + 1 < vertices.size(); ++k) {
    const double parts = std::ceil((vertices[k + 1] - vertices[k]).norm() / spacing);
    expected_count += static_cast<std::size_t>(std::max(1.0, parts));
  }
  ASSERT_EQ(poses.size(), expected_count);

  // Each vertex is a pose, in order: vertex_pose[k] is the index of vertex k among the poses.
  std::vector<std::size_t> vertex_pose;
  std::size_t next = 0;
  for (const Eigen::Vector2d& v : vertices) {
    while (next < poses.size() && position(poses[next]) != v) ++next;
    ASSERT_LT(next, poses.size()) << "vertex (" << v.x() << ", " << v.y() << ") missing";
    vertex_pose.push_back(next++);
  }
  EXPECT_EQ(vertex_pose.front(), 0u);
  EXPECT_EQ(vertex_pose.back(), poses.size() - 1);
  // Every raw input vertex, duplicates included, is within the duplicate distance of a pose.
  for (const Eigen::Vector2d& p : path) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector2d& v : vertices) nearest = std::min(nearest, (p - v).norm());
    EXPECT_LT(nearest, kDuplicateDistance);
  }

  for (std::size_t k = 0; k + 1 < vertices.size(); ++k) {
    const Eigen::Vector2d& a = vertices[k];
    const Eigen::Vector2d& b = vertices[k + 1];
    const double expected_yaw = segment_heading(a, b);
    const std::size_t first = vertex_pose[k], end = vertex_pose[k + 1];
    const double part = (b - a).norm() / static_cast<double>(end - first);
    for (std::size_t i = first; i < end; ++i) {
      const Eigen::Vector2d p = position(poses[i]), q = position(poses[i + 1]);
      EXPECT_LT(distance_to_segment(p, a, b), kDistanceTolerance) << "pose " << i;
      EXPECT_LE((q - p).norm(), spacing + kDistanceTolerance) << "pose " << i;
      EXPECT_NEAR((q - p).norm(), part, kDistanceTolerance) << "unequal parts at pose " << i;
      EXPECT_NEAR(angle_difference(poses[i].yaw, expected_yaw), 0.0, kAngleTolerance);
    }
  }

  for (const Pose2& pose : poses) {
    EXPECT_GT(pose.yaw, -kPi);
    EXPECT_LE(pose.yaw, kPi);
  }
  const double last_yaw = goal_yaw ? *goal_yaw
                          : vertices.size() > 1
                              ? segment_heading(vertices[vertices.size() - 2], vertices.back())
                              : 0.0;
  EXPECT_NEAR(angle_difference(poses.back().yaw, last_yaw), 0.0, kAngleTolerance);

  Points pose_points;
  for (const Pose2& pose : poses) pose_points.push_back(position(pose));
  const double input_length = length_of(vertices);
  EXPECT_NEAR(length_of(pose_points), input_length, kRelativeLengthTolerance * input_length);
}

TEST(PathPoses, RandomPolylinesKeepEveryInvariant) {
  std::mt19937 rng(20240917);
  std::uniform_real_distribution<double> spacing(0.01, 2.0);
  std::uniform_real_distribution<double> yaw(-kPi, kPi);
  std::bernoulli_distribution with_goal_yaw(0.5);
  for (int trial = 0; trial < 2000; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const Points path = random_polyline(rng);
    const double s = spacing(rng);
    const std::optional<double> goal =
        with_goal_yaw(rng) ? std::optional<double>(yaw(rng)) : std::nullopt;
    expect_invariants(path, s, goal);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

// The same invariants on the paths the planners return (every planner, with and without pruning
// and smoothing, on random maps of 5 cm cells as the property tests draw them), at the node's
// default spacing (the resolution) and a coarser one.
TEST(PathPoses, PlannedPathsOnRandomMapsKeepEveryInvariant) {
  std::mt19937 rng(20261202);
  std::uniform_int_distribution<int> side(8, 90);
  std::uniform_real_distribution<double> density(0.0, 0.35);
  std::uniform_real_distribution<double> yaw(-kPi, kPi);
  int paths = 0;
  for (int m = 0; m < 60; ++m) {
    auto built =
        GridMap::from_rows(test::random_rows(rng, side(rng), side(rng), density(rng)), 0.05);
    ASSERT_TRUE(built);
    auto map = std::make_shared<const GridMap>(std::move(built).value());
    const auto cells = test::free_cells(*map);
    if (cells.size() < 2) continue;
    std::uniform_int_distribution<size_t> pick(0, cells.size() - 1);
    Planner planner(map);
    const PlanQuery query{cells[pick(rng)], cells[pick(rng)]};
    for (PlannerKind kind : all_planner_kinds()) {
      for (bool post : {false, true}) {
        SCOPED_TRACE(::testing::Message() << "map " << m << " " << to_string(kind)
                                          << (post ? " with pruning and smoothing" : ""));
        PlannerOptions options = default_options(kind);
        if (post) options.prune = options.smooth = true;
        const PlanResult r = planner.plan(query, options);
        if (!r.status.is_ok()) continue;
        const Points world(r.world_path.begin(), r.world_path.end());
        for (const double spacing : {map->resolution(), 0.3}) {
          expect_invariants(world, spacing, m % 2 ? std::optional<double>(yaw(rng)) : std::nullopt);
          if (::testing::Test::HasFatalFailure()) return;
        }
        ++paths;
      }
    }
  }
  EXPECT_GT(paths, 400);
}

TEST(PathPoses, SegmentExactlyOneSpacingLongIsNotSplit) {
  // 0.5 is exact in binary, so length / spacing is exactly 1 part per segment.
  const Points path{{0.0, 0.0}, {0.5, 0.0}, {0.5, 0.5}};
  EXPECT_EQ(path_poses(path, 0.5).size(), path.size());
  expect_invariants(path, 0.5, std::nullopt);
  expect_invariants(path, 0.125, std::nullopt);
}

TEST(PathPoses, ConsecutiveDuplicatesAreDropped) {
  const Eigen::Vector2d a(1.0, 2.0), b(4.0, 6.0);
  const Points path{a, a, a + Eigen::Vector2d(0.5e-9, 0.0), b, b};
  const std::vector<Pose2> poses = path_poses(path, 10.0);
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(position(poses[0]), a);
  EXPECT_EQ(position(poses[1]), b);
  EXPECT_DOUBLE_EQ(poses[0].yaw, segment_heading(a, b));
  EXPECT_DOUBLE_EQ(poses[1].yaw, segment_heading(a, b));
  expect_invariants(path, 0.3, std::nullopt);
}

TEST(PathPoses, HeadingOfMinusPiIsReportedAsPi) {
  // b - a = (-1, -0.0): atan2 gives -pi exactly, outside the half-open range (-pi, pi].
  const Points path{{1.0, 0.0}, {0.0, -0.0}};
  for (const Pose2& pose : path_poses(path, 0.25)) EXPECT_EQ(pose.yaw, kPi);
  // A goal yaw of -pi is the same heading, reported as +pi.
  EXPECT_EQ(path_poses(path, 0.25, -kPi).back().yaw, kPi);
}

TEST(PathPoses, EmptyPathGivesNoPose) {
  EXPECT_TRUE(path_poses({}, 0.1).empty());
  EXPECT_TRUE(path_poses({}, 0.1, 1.0).empty());
}

TEST(PathPoses, SinglePointGivesOnePose) {
  const Eigen::Vector2d p(-3.5, 7.25);
  for (const Points& path : {Points{p}, Points{p, p, p + Eigen::Vector2d(0.0, 1e-12)}}) {
    const std::vector<Pose2> without_goal = path_poses(path, 0.1);
    ASSERT_EQ(without_goal.size(), 1u);
    EXPECT_EQ(position(without_goal[0]), p);
    EXPECT_EQ(without_goal[0].yaw, 0.0);
    const std::vector<Pose2> with_goal = path_poses(path, 0.1, -2.0);
    ASSERT_EQ(with_goal.size(), 1u);
    EXPECT_EQ(position(with_goal[0]), p);
    EXPECT_EQ(with_goal[0].yaw, -2.0);
  }
}

TEST(PathPoses, GoalYawReplacesOnlyTheLastTangent) {
  const Points path{{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}};
  const std::vector<Pose2> tangent = path_poses(path, 0.25);
  const std::vector<Pose2> goal = path_poses(path, 0.25, 3.0);
  ASSERT_EQ(tangent.size(), goal.size());
  for (std::size_t i = 0; i + 1 < goal.size(); ++i) EXPECT_EQ(goal[i].yaw, tangent[i].yaw);
  EXPECT_EQ(goal.back().yaw, 3.0);
  EXPECT_NEAR(tangent.back().yaw, kPi / 2.0, kAngleTolerance);
  // A goal yaw outside (-pi, pi] is wrapped into it: the same heading.
  const std::vector<Pose2> wrapped = path_poses(path, 0.25, 3.0 + 4.0 * kPi);
  EXPECT_NEAR(wrapped.back().yaw, 3.0, 1e-12);
}

TEST(PathPoses, InvalidSpacingGivesVerticesOnly) {
  const Points path{{0.0, 0.0}, {10.0, 0.0}, {10.0, -20.0}, {10.0, -20.0}, {-5.0, 3.0}};
  const Points vertices = deduplicated(path);
  for (const double spacing :
       {0.0, -1.0, -0.0, std::numeric_limits<double>::quiet_NaN(),
        std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
    SCOPED_TRACE(::testing::Message() << "spacing " << spacing);
    EXPECT_FALSE(validate_path_spacing(path, spacing).is_ok());
    const std::vector<Pose2> poses = path_poses(path, spacing, 0.5);
    ASSERT_EQ(poses.size(), vertices.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(position(poses[i]), vertices[i]);
      if (i + 1 < poses.size()) {
        EXPECT_NEAR(angle_difference(poses[i].yaw, segment_heading(vertices[i], vertices[i + 1])),
                    0.0, kAngleTolerance);
      }
    }
    EXPECT_EQ(poses.back().yaw, 0.5);
  }
}

TEST(PathPoses, ValidateRefusesNonFinitePoints) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(validate_path_spacing({{0.0, 0.0}, {1.0, 1.0}}, 0.1).is_ok());
  EXPECT_TRUE(validate_path_spacing({}, 0.1).is_ok());
  const Status bad = validate_path_spacing({{0.0, 0.0}, {nan, 1.0}}, 0.1);
  EXPECT_EQ(bad.code, StatusCode::kInvalidRequest);
  EXPECT_NE(bad.message.find("point 1"), std::string::npos) << bad.message;
  // Unchecked, a non-finite point still ends: its segments are not subdivided.
  const Points path{{0.0, 0.0}, {std::numeric_limits<double>::infinity(), 0.0}, {1.0, 1.0}};
  EXPECT_EQ(path_poses(path, 0.1).size(), path.size());
}

// Quaternion (x, y, z, w) of a rotation by `yaw` about z, built here, not by the code under test.
Eigen::Vector4d yaw_quaternion(double yaw) {
  return {0.0, 0.0, std::sin(yaw / 2.0), std::cos(yaw / 2.0)};
}

TEST(PathPoses, YawFromQuaternionRoundTrip) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> yaw(-kPi, kPi);
  for (int trial = 0; trial < 1000; ++trial) {
    const double expected = yaw(rng);
    const Eigen::Vector4d q = yaw_quaternion(expected);
    const std::optional<double> got = yaw_from_quaternion(q.x(), q.y(), q.z(), q.w());
    ASSERT_TRUE(got.has_value());
    EXPECT_NEAR(angle_difference(*got, expected), 0.0, 1e-12);
    EXPECT_GT(*got, -kPi);
    EXPECT_LE(*got, kPi);
    // -q is the same rotation.
    const std::optional<double> negated = yaw_from_quaternion(-q.x(), -q.y(), -q.z(), -q.w());
    ASSERT_TRUE(negated.has_value());
    EXPECT_NEAR(angle_difference(*negated, expected), 0.0, 1e-12);
  }
  // Half a turn: +pi, never -pi.
  const Eigen::Vector4d half_turn = yaw_quaternion(kPi);
  EXPECT_NEAR(*yaw_from_quaternion(half_turn.x(), half_turn.y(), half_turn.z(), half_turn.w()), kPi,
              1e-12);
  // Signed zeros make atan2(-0.0, -1) = -pi exactly; the half-open range reports it as +pi.
  EXPECT_EQ(*yaw_from_quaternion(-0.0, 0.0, 1.0, -0.0), kPi);
}

TEST(PathPoses, YawFromQuaternionOfAnyRotationIsTheRotatedXHeading) {
  // Rotations with roll and pitch too (|pitch| < 1.4 rad, so the x axis never points straight
  // up): the yaw is the heading of the rotated x axis, computed here through Eigen's matrix.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  std::uniform_real_distribution<double> pitch(-1.4, 1.4);
  for (int trial = 0; trial < 1000; ++trial) {
    const Eigen::Quaterniond q = Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(pitch(rng), Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitX());
    const Eigen::Vector3d x_axis = q.toRotationMatrix().col(0);
    const double expected = std::atan2(x_axis.y(), x_axis.x());
    const std::optional<double> got = yaw_from_quaternion(q.x(), q.y(), q.z(), q.w());
    ASSERT_TRUE(got.has_value());
    EXPECT_NEAR(angle_difference(*got, expected), 0.0, 1e-9);
  }
  // Roll/pitch-free rotations about z (built through Eigen) give exactly their angle.
  for (const double yaw : {0.0, 0.3, -1.2, kPi / 2.0, -kPi / 2.0, 3.0}) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
    EXPECT_NEAR(*yaw_from_quaternion(q.x(), q.y(), q.z(), q.w()), yaw, 1e-12);
  }
}

TEST(PathPoses, YawFromQuaternionRefusesInvalidQuaternions) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Vector4d unit = yaw_quaternion(0.7);
  for (const double scale : {0.5, 2.0, 0.0, 1.0 + 2e-3, 1.0 - 2e-3}) {
    const Eigen::Vector4d q = unit * scale;
    EXPECT_FALSE(yaw_from_quaternion(q.x(), q.y(), q.z(), q.w())) << "norm " << scale;
  }
  EXPECT_FALSE(yaw_from_quaternion(0.0, 0.0, 0.0, 0.0));
  for (int component = 0; component < 4; ++component) {
    for (const double bad : {nan, inf, -inf}) {
      Eigen::Vector4d q = unit;
      q[component] = bad;
      EXPECT_FALSE(yaw_from_quaternion(q.x(), q.y(), q.z(), q.w()))
          << "component " << component << " = " << bad;
    }
  }
  // Within the tolerance (1e-3) a quaternion is accepted, with the yaw of its unit direction.
  const Eigen::Vector4d near_unit = unit * (1.0 + 5e-4);
  const std::optional<double> got =
      yaw_from_quaternion(near_unit.x(), near_unit.y(), near_unit.z(), near_unit.w());
  ASSERT_TRUE(got.has_value());
  EXPECT_NEAR(*got, 0.7, 1e-12);
  // A custom tolerance is honoured, and a NaN one refuses.
  EXPECT_FALSE(
      yaw_from_quaternion(near_unit.x(), near_unit.y(), near_unit.z(), near_unit.w(), 1e-4));
  EXPECT_FALSE(yaw_from_quaternion(unit.x(), unit.y(), unit.z(), unit.w(), nan));
}

}  // namespace
}  // namespace vnsba::core
