// The poses of a published path (docs/algorithm.md section 8, "Path poses"): positions at most
// path_spacing metres apart along the final path, each with the path's tangent as yaw, the last
// with the goal's orientation when the goal carries a valid (unit) quaternion.
//
// Units: world coordinates in metres (as PlanResult::world_path), angles in radians in (-pi, pi].
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "vnsba/core/status.hpp"

namespace vnsba::core {

struct Pose2 {
  double x = 0.0;    // metres
  double y = 0.0;    // metres
  double yaw = 0.0;  // radians in (-pi, pi], 0 along +x, counter-clockwise
};

// Consecutive path vertices closer than this (metres) are one vertex: a zero-length segment has
// no heading, and one of a nanometre only has rounding noise for one.
inline constexpr double kPathDuplicateDistance = 1e-9;

// The preconditions of path_poses: spacing_m finite and > 0 (kInvalidRequest otherwise) and
// every point of `path` finite (kInvalidRequest naming the first bad point). The pose count is
// about polyline length / spacing_m; bounding it is the caller's choice of spacing.
Status validate_path_spacing(const std::vector<Eigen::Vector2d>& path, double spacing_m);

// The poses a robot controller receives for a path: `path` is the final path in world
// coordinates (metres, as PlanResult::world_path). Every vertex of `path` is kept (after dropping
// consecutive duplicates closer than kPathDuplicateDistance), and each segment longer than
// spacing_m is split into ceil(length / spacing_m) equal parts, so consecutive poses are at most
// spacing_m apart. Each pose's yaw is the tangent: the heading of the input segment leaving it
// (the last pose: the segment arriving at it), by core::heading (geometry.hpp).
// When goal_yaw is set (and finite), the last pose takes it instead, wrapped into (-pi, pi].
// A path of one point gives one pose with yaw = goal_yaw or 0. An empty path gives no pose.
// Preconditions are checked by validate_path_spacing; with spacing_m not finite or <= 0 this
// returns the vertices only (no subdivision), and a segment whose part count is not finite
// (a non-finite point) is not subdivided either: it never loops forever.
std::vector<Pose2> path_poses(const std::vector<Eigen::Vector2d>& path, double spacing_m,
                              std::optional<double> goal_yaw = std::nullopt);

// How far (absolute) the norm of a goal quaternion may be from 1 and still count as a rotation:
// 1e-3 accepts float round-off and hand-typed four-digit quaternions, refuses anything scaled.
inline constexpr double kQuaternionNormTolerance = 1e-3;

// Yaw (radians, (-pi, pi]) of a rotation quaternion (x, y, z, w) about any axis, as the heading of
// the rotated x axis projected on the plane: atan2(2(wz + xy), 1 - 2(y^2 + z^2)), evaluated on the
// quaternion scaled to unit norm. nullopt when any component is not finite or the norm differs
// from 1 by more than `tolerance`: docs/algorithm.md section 8 takes the goal's orientation only
// from a valid (unit) quaternion. (With the rotated x axis vertical, pitch +-pi/2, yaw is
// undefined; the result is then whatever atan2 gives for two near-zero arguments.)
std::optional<double> yaw_from_quaternion(double x, double y, double z, double w,
                                          double tolerance = kQuaternionNormTolerance);

}  // namespace vnsba::core
