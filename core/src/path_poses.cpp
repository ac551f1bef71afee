#include "vnsba/core/path_poses.hpp"

#include <cmath>
#include <cstddef>
#include <string>

#include "vnsba/core/geometry.hpp"

namespace vnsba::core {
namespace {

constexpr double kPi = 3.14159265358979323846;

// An angle in radians wrapped into (-pi, pi]. std::remainder by 2*kPi (an exact doubling of kPi)
// returns an angle already in [-kPi, kPi] unchanged, so tangents and in-range goals stay exact;
// atan2 can return -pi (for a -0.0 y component), which the half-open range maps to +pi.
double wrap_angle(double radians) {
  const double wrapped = std::remainder(radians, 2.0 * kPi);
  return wrapped <= -kPi ? kPi : wrapped;
}

// `path` without consecutive points closer than kPathDuplicateDistance to the last one kept.
std::vector<Eigen::Vector2d> without_duplicates(const std::vector<Eigen::Vector2d>& path) {
  std::vector<Eigen::Vector2d> kept;
  kept.reserve(path.size());
  for (const Eigen::Vector2d& p : path) {
    if (kept.empty() || !((p - kept.back()).norm() < kPathDuplicateDistance)) kept.push_back(p);
  }
  return kept;
}

}  // namespace

Status validate_path_spacing(const std::vector<Eigen::Vector2d>& path, double spacing_m) {
  if (!std::isfinite(spacing_m) || spacing_m <= 0.0)
    return Status::error(
        StatusCode::kInvalidRequest,
        "path spacing is " + std::to_string(spacing_m) + " m, must be finite and > 0");
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (!path[i].allFinite())
      return Status::error(StatusCode::kInvalidRequest,
                           "path point " + std::to_string(i) + " is not finite");
  }
  return Status::ok();
}

std::vector<Pose2> path_poses(const std::vector<Eigen::Vector2d>& path, double spacing_m,
                              std::optional<double> goal_yaw) {
  const std::vector<Eigen::Vector2d> vertices = without_duplicates(path);
  std::vector<Pose2> poses;
  if (vertices.empty()) return poses;
  const bool subdivide = std::isfinite(spacing_m) && spacing_m > 0.0;
  for (std::size_t i = 0; i + 1 < vertices.size(); ++i) {
    const Eigen::Vector2d& a = vertices[i];
    const Eigen::Vector2d& b = vertices[i + 1];
    const double yaw = wrap_angle(heading(a, b));
    // ceil(length / spacing) parts of length <= spacing; NaN or inf (a non-finite point, or a
    // ratio past the double range) means one part, so the loop below is always bounded.
    const double parts = subdivide ? std::ceil((b - a).norm() / spacing_m) : 1.0;
    const std::size_t count =
        std::isfinite(parts) && parts > 1.0 ? static_cast<std::size_t>(parts) : std::size_t{1};
    for (std::size_t k = 0; k < count; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / static_cast<double>(count));
      poses.push_back({p.x(), p.y(), yaw});
    }
  }
  // The last vertex exactly (not a + (b - a) * 1, which may round), facing the way it was reached.
  const Eigen::Vector2d& last = vertices.back();
  const double arriving =
      vertices.size() > 1 ? wrap_angle(heading(vertices[vertices.size() - 2], last)) : 0.0;
  const bool goal_given = goal_yaw.has_value() && std::isfinite(*goal_yaw);
  poses.push_back({last.x(), last.y(), goal_given ? wrap_angle(*goal_yaw) : arriving});
  return poses;
}

std::optional<double> yaw_from_quaternion(double x, double y, double z, double w,
                                          double tolerance) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || !std::isfinite(w))
    return std::nullopt;
  const double norm = std::sqrt(x * x + y * y + z * z + w * w);
  // Written as !(<=) so a NaN tolerance refuses rather than accepts.
  if (!(std::abs(norm - 1.0) <= tolerance)) return std::nullopt;
  // The formula holds for a unit quaternion; scaling first keeps a slightly off one exact.
  x /= norm;
  y /= norm;
  z /= norm;
  w /= norm;
  return wrap_angle(std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)));
}

}  // namespace vnsba::core
