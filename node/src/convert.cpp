#include "vnsba/node/convert.hpp"

#include <octomap/OcTree.h>

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>

#include "vnsba/core/path_poses.hpp"
#include "vnsba/maps/world_text.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/status_codes.hpp"

namespace vnsba::node {

namespace {

WireStatus error(uint8_t code, std::string message) {
  return {code, std::move(message)};
}

bool finite(double v) {
  return std::isfinite(v);
}

std::string num(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// Length of the well-formed UTF-8 character at text[i] (1..4), or 0 when it is not one.
size_t utf8_length(std::string_view text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
  if (n == 0 || i + n > text.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((byte(i + k) & 0xc0) != 0x80) return 0;
  // Well-formed only (RFC 3629): no overlong forms, no surrogates, nothing above U+10FFFF.
  const unsigned char c1 = n > 1 ? byte(i + 1) : 0;
  if (n == 2 && c < 0xc2) return 0;
  if (n == 3 && ((c == 0xe0 && c1 < 0xa0) || (c == 0xed && c1 >= 0xa0))) return 0;
  if (n == 4 && (c > 0xf4 || (c == 0xf0 && c1 < 0x90) || (c == 0xf4 && c1 >= 0x90))) return 0;
  return n;
}

// Characters that reorder or hide text where a log is read (bidirectional overrides and
// isolates, U+202A..U+202E and U+2066..U+2069): escaped like control characters.
bool is_bidi_control(std::string_view text, size_t i, size_t n) {
  if (n != 3 || static_cast<unsigned char>(text[i]) != 0xe2) return false;
  const unsigned char b1 = static_cast<unsigned char>(text[i + 1]);
  const unsigned char b2 = static_cast<unsigned char>(text[i + 2]);
  return (b1 == 0x80 && b2 >= 0xaa && b2 <= 0xae) || (b1 == 0x81 && b2 >= 0xa6 && b2 <= 0xa9);
}

std::string hex_escape(unsigned char c) {
  char text[8];
  std::snprintf(text, sizeof(text), "\\x%02x", c);
  return text;
}

}  // namespace

std::string printable(std::string_view text, size_t max_bytes) {
  std::string out;
  size_t i = 0;
  for (; i < text.size() && i < max_bytes;) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const size_t n = utf8_length(text, i);
    if (n == 0) {  // not UTF-8: shown byte by byte
      out += hex_escape(c);
      ++i;
      continue;
    }
    if (i + n > max_bytes) break;  // never cut a character
    if (n == 1) {
      if (c == '\n')
        out += "\\n";
      else if (c == '\t')
        out += "\\t";
      else if (c == '\r')
        out += "\\r";
      else if (c == '\\')
        out += "\\\\";
      else if (c < 0x20 || c == 0x7f)
        out += hex_escape(c);
      else
        out += static_cast<char>(c);
    } else if ((n == 2 && c == 0xc2 && static_cast<unsigned char>(text[i + 1]) < 0xa0) ||
               is_bidi_control(text, i, n)) {
      for (size_t k = 0; k < n; ++k)  // C1 controls, bidi controls
        out += hex_escape(static_cast<unsigned char>(text[i + k]));
    } else {
      out.append(text.substr(i, n));
    }
    i += n;
  }
  if (i < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

bool RequestIdentity::same_client(const RequestIdentity& other) const {
  return std::memcmp(writer_guid.data(), other.writer_guid.data(), 12) == 0;
}

// The one table lives in status_codes.hpp (no DDS); here it is held to the IDL's constants.
static_assert(plan_status_code(core::StatusCode::kOk) == wire::OK);
static_assert(plan_status_code(core::StatusCode::kInvalidMap) == wire::INVALID_MAP);
static_assert(plan_status_code(core::StatusCode::kInvalidRequest) == wire::INVALID_REQUEST);
static_assert(plan_status_code(core::StatusCode::kStartOutsideMap) == wire::START_OUTSIDE_MAP);
static_assert(plan_status_code(core::StatusCode::kGoalOutsideMap) == wire::GOAL_OUTSIDE_MAP);
static_assert(plan_status_code(core::StatusCode::kStartOccupied) == wire::START_OCCUPIED);
static_assert(plan_status_code(core::StatusCode::kGoalOccupied) == wire::GOAL_OCCUPIED);
static_assert(plan_status_code(core::StatusCode::kNoValidPath) == wire::NO_VALID_PATH);
static_assert(plan_status_code(core::StatusCode::kTimeout) == wire::TIMEOUT);
static_assert(plan_status_code(core::StatusCode::kCanceled) == wire::CANCELED);
static_assert(plan_status_code(core::StatusCode::kInternalError) == wire::INTERNAL_ERROR);

uint8_t to_wire_code(core::StatusCode code) {
  return plan_status_code(code);
}

std::string code_name(uint8_t code) {
  static const char* const kNames[] = {"OK",
                                       "NO_MAP",
                                       "INVALID_MAP",
                                       "INVALID_REQUEST",
                                       "FRAME_MISMATCH",
                                       "START_OUTSIDE_MAP",
                                       "GOAL_OUTSIDE_MAP",
                                       "START_OCCUPIED",
                                       "GOAL_OCCUPIED",
                                       "NO_VALID_PATH",
                                       "TIMEOUT",
                                       "CANCELED",
                                       "INTERNAL_ERROR",
                                       "NODE_INACTIVE"};
  return code < sizeof(kNames) / sizeof(kNames[0]) ? kNames[code] : "UNKNOWN";
}

TimeMsg to_time_msg(int64_t nanoseconds) {
  // Floor division: nanosec stays in [0, 1e9) for times before the epoch too.
  int64_t sec = nanoseconds / 1'000'000'000;
  int64_t nanosec = nanoseconds % 1'000'000'000;
  if (nanosec < 0) {
    nanosec += 1'000'000'000;
    --sec;
  }
  TimeMsg msg;
  msg.sec(static_cast<int32_t>(sec));
  msg.nanosec(static_cast<uint32_t>(nanosec));
  return msg;
}

TimeMsg to_time_msg(std::chrono::system_clock::time_point t) {
  return to_time_msg(
      std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
}

int64_t to_nanoseconds(const TimeMsg& t) {
  return int64_t{t.sec()} * 1'000'000'000 + int64_t{t.nanosec()};
}

double to_seconds(const TimeMsg& t) {
  return static_cast<double>(to_nanoseconds(t)) * 1e-9;
}

PoseStampedMsg to_pose_stamped(const PoseWithCovarianceStampedMsg& msg) {
  PoseStampedMsg out;
  out.header(msg.header());
  out.pose(msg.pose().pose());
  return out;
}

std::vector<std::string> add_transforms(const TFMessageMsg& msg, bool is_static,
                                        TransformTree& tree) {
  std::vector<std::string> problems;
  // Refusals at a limit (too deep, too many frames) come in floods: one line each for the
  // message, the first refused and how many more.
  struct AtLimit {
    std::string first;
    size_t count = 0;
  };
  std::map<TransformTree::Refusal, AtLimit> at_limit;
  for (const auto& t : msg.transforms()) {
    const auto& v = t.transform().translation();
    const auto& q = t.transform().rotation();
    TransformTree::SetResult result = tree.set(
        t.header().frame_id(), t.child_frame_id(), Eigen::Vector3d(v.x(), v.y(), v.z()),
        Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()), to_seconds(t.header().stamp()), is_static);
    if (result.taken()) continue;
    if (result.refusal == TransformTree::Refusal::kTooDeep ||
        result.refusal == TransformTree::Refusal::kTooManyFrames) {
      AtLimit& limit = at_limit[result.refusal];
      if (limit.count++ == 0) limit.first = std::move(result.problem);
      continue;
    }
    problems.push_back(printable(result.problem, 256));
  }
  for (const auto& [refusal, limit] : at_limit) {
    std::string line = printable(limit.first, 256);
    if (limit.count > 1)
      line += " (and " + std::to_string(limit.count - 1) + " more transforms of this message)";
    problems.push_back(std::move(line));
  }
  return problems;
}

TimeMsg now_msg() {
  return to_time_msg(std::chrono::system_clock::now());
}

double float32_decimal(float value) {
  // Shortest round-trip text (std::to_chars) of the float, read back as a double: 0.05f prints
  // "0.05", which is 0.05 as a double. Non-finite values come back as they are.
  char text[32];
  const std::to_chars_result printed = std::to_chars(text, text + sizeof text, value);
  double decimal = value;
  if (printed.ec == std::errc()) std::from_chars(text, printed.ptr, decimal);
  return decimal;
}

bool same_frame(std::string_view a, std::string_view b) {
  return without_leading_slash(a) == without_leading_slash(b);
}

namespace {

// from_slice_msg's checks of a slice's fields: each adds "<field> ...; " to `bad` per problem.

void add_slice_size_problems(const OccupancyGridMsg& msg, int64_t max_cells,
                             std::ostringstream& bad) {
  const auto& info = msg.info();
  if (info.width() == 0 || info.height() == 0)
    bad << "info.width x info.height is " << info.width() << " x " << info.height()
        << ", must be > 0; ";
  // Both are uint32: their product is below 2^64, exact in uint64 (in int64 it overflowed).
  const uint64_t cells = uint64_t{info.width()} * uint64_t{info.height()};
  if (max_cells < 0 || cells > static_cast<uint64_t>(max_cells))
    bad << "info.width x info.height = " << info.width() << " x " << info.height() << " = " << cells
        << " cells is too large: the limit is map.max_cells = " << max_cells << "; ";
  else if (msg.data().size() != cells)
    bad << "data has " << msg.data().size()
        << " values, expected info.width x info.height = " << cells << "; ";
}

void add_slice_origin_problems(const OccupancyGridMsg& msg, std::ostringstream& bad) {
  const auto& info = msg.info();
  const bool resolution_ok = finite(info.resolution()) && info.resolution() > 0.0f;
  if (!resolution_ok)
    bad << "info.resolution is " << info.resolution() << ", must be finite and > 0; ";
  const auto& p = info.origin().position();
  if (!finite(p.x()) || !finite(p.y()) || !finite(p.z())) {
    bad << "info.origin.position (" << num(p.x()) << ", " << num(p.y()) << ", " << num(p.z())
        << ") must be finite; ";
  } else if (resolution_ok && info.width() > 0 && info.height() > 0) {
    // World coordinates of the cells must keep a millionth of a cell: a double resolves
    // |c| * 2^-52 metres at |c| metres, so the map must stay within resolution * 1e-6 / 2^-52
    // (225,000 km at 0.05 m) of the frame's origin. A 1e15 m origin holds 0.125 m steps.
    const double resolution = float32_decimal(info.resolution());
    const double limit = resolution * 1e-6 / std::numeric_limits<double>::epsilon();
    const double reach =
        std::max({std::abs(p.x()), std::abs(p.y()), std::abs(p.x() + resolution * info.width()),
                  std::abs(p.y() + resolution * info.height())});
    if (!(reach <= limit))
      bad << "info.origin.position (" << num(p.x()) << ", " << num(p.y()) << ") m puts the map "
          << num(reach) << " m from the frame's origin, more than the " << num(limit)
          << " m within which cells of " << num(resolution)
          << " m keep a millionth of a cell in double precision; ";
  }
}

// Only axis-aligned grids: the origin may carry no rotation (x = y = z = 0, w != 0; tf2
// normalises the quaternion). The all-zero quaternion is no rotation at all: ROS 2's messages
// default w to 1, so a publisher that sends 0 left the field unset.
void add_slice_rotation_problems(const OccupancyGridMsg& msg, std::ostringstream& bad) {
  const auto& q = msg.info().origin().orientation();
  const double q_norm = std::hypot(std::hypot(q.x(), q.y()), std::hypot(q.z(), q.w()));
  std::ostringstream quaternion;
  quaternion << "info.origin.orientation (x, y, z, w) = (" << num(q.x()) << ", " << num(q.y())
             << ", " << num(q.z()) << ", " << num(q.w()) << ")";
  if (!finite(q.x()) || !finite(q.y()) || !finite(q.z()) || !finite(q.w()))
    bad << quaternion.str() << " must be finite; ";
  else if (q_norm < 1e-9)
    bad << quaternion.str() << " is the zero quaternion, not a rotation (w = 1 for a grid "
        << "without rotation); ";
  else if (std::max({std::abs(q.x()), std::abs(q.y()), std::abs(q.z())}) > 1e-9 * q_norm)
    bad << quaternion.str() << " must be the identity (rotated grids are not supported); ";
}

// The first value outside -1..100, as the message names it; "" when there is none.
std::string first_bad_slice_value(const OccupancyGridMsg& msg) {
  for (size_t i = 0; i < msg.data().size(); ++i) {
    const int8_t v = msg.data()[i];
    if (v < -1 || v > 100)
      return "data[" + std::to_string(i) + "] = " + std::to_string(int{v}) + ", expected -1..100";
  }
  return "";
}

}  // namespace

SliceCheck from_slice_msg(OccupancyGridMsg&& msg, const std::string& expected_frame,
                          int64_t max_cells) {
  SliceCheck out;
  const std::string& frame = msg.header().frame_id();
  if (!frame.empty() && !same_frame(frame, expected_frame)) {
    out.status = error(wire::FRAME_MISMATCH, "slice header.frame_id is '" + printable(frame) +
                                                 "', the node plans in '" + expected_frame + "'");
    return out;
  }
  std::ostringstream bad;
  add_slice_size_problems(msg, max_cells, bad);
  add_slice_origin_problems(msg, bad);
  add_slice_rotation_problems(msg, bad);
  std::string message = bad.str();
  if (!message.empty()) {
    message.resize(message.size() - 2);
    out.status = error(wire::INVALID_MAP, "invalid slice: " + message);
    return out;
  }
  if (const std::string value = first_bad_slice_value(msg); !value.empty()) {
    out.status = error(wire::INVALID_MAP, "invalid slice: " + value);
    return out;
  }
  const auto& info = msg.info();
  out.grid.width = static_cast<int32_t>(info.width());
  out.grid.height = static_cast<int32_t>(info.height());
  // MapMetaData carries the resolution as a float32: map_server's 0.05 arrives as
  // 0.05000000074505806, which turned robot_radius 0.15 m into 2.99999996 cells instead of 3
  // (metres_to_cells) and planned on another inflation than vnsba_plan reading the same file.
  out.grid.resolution = float32_decimal(info.resolution());
  out.grid.origin_x = info.origin().position().x();  // metres
  out.grid.origin_y = info.origin().position().y();
  out.grid.data = std::move(msg.data());
  return out;
}

SliceMemory slice_memory(int32_t width, int32_t height, const core::GridBuildOptions& options) {
  SliceMemory memory;
  memory.map = core::GridMap::estimate_memory(width, height, options);
  memory.slice_bytes = static_cast<size_t>(std::max(width, 0)) *
                       static_cast<size_t>(std::max(height, 0)) * sizeof(int8_t);
  return memory;
}

int64_t mib_rounded_up(size_t bytes) {
  constexpr size_t kMib = size_t{1} << 20;
  return static_cast<int64_t>((bytes + kMib - 1) / kMib);
}

WireStatus check_memory_budget(int32_t width, int32_t height, const core::GridBuildOptions& options,
                               int memory_budget_mb) {
  const SliceMemory memory = slice_memory(width, height, options);
  const size_t budget_bytes = static_cast<size_t>(std::max(memory_budget_mb, 0)) << 20;
  if (memory.peak_bytes() <= budget_bytes) return {};
  std::ostringstream message;
  message << "slice of " << width << " x " << height << " cells needs "
          << mib_rounded_up(memory.peak_bytes()) << " MiB to convert (planning grid "
          << mib_rounded_up(memory.map.map_bytes) << " MiB, build scratch "
          << mib_rounded_up(memory.map.scratch_bytes) << " MiB, slice values "
          << mib_rounded_up(memory.slice_bytes)
          << " MiB), over map.memory_budget_mb = " << memory_budget_mb << " (MiB)";
  return error(wire::INVALID_MAP, message.str());
}

namespace {

// The geometry of an axis-aligned grid as nav_msgs/MapMetaData.
nav_msgs::msg::dds_::MapMetaData_ map_info(double resolution, int64_t width, int64_t height,
                                           double origin_x, double origin_y, const TimeMsg& stamp) {
  nav_msgs::msg::dds_::MapMetaData_ info;
  info.map_load_time(stamp);
  info.resolution(static_cast<float>(resolution));
  info.width(static_cast<uint32_t>(width));
  info.height(static_cast<uint32_t>(height));
  info.origin().position().x(origin_x);
  info.origin().position().y(origin_y);
  info.origin().orientation().w(1.0);
  return info;
}

nav_msgs::msg::dds_::MapMetaData_ map_info(const core::GridMap& map, const TimeMsg& stamp) {
  return map_info(map.resolution(), map.width(), map.height(), map.origin_x(), map.origin_y(),
                  stamp);
}

}  // namespace

OccupancyGridMsg to_slice_msg(const core::OccupancyGrid& grid, const std::string& frame,
                              const TimeMsg& stamp) {
  OccupancyGridMsg msg;
  msg.header().frame_id(frame);
  msg.header().stamp(stamp);
  msg.info(map_info(grid.resolution, grid.width, grid.height, grid.origin_x, grid.origin_y, stamp));
  msg.data(grid.data);
  return msg;
}

TreeCheck from_octomap_msg(const OctomapMsg& msg) {
  TreeCheck out;
  if (!msg.binary()) {
    out.status = error(wire::INVALID_MAP,
                       "octomap binary is false: only binary trees (occupied/free) "
                       "are supported, as on octomap_server's octomap_binary");
    return out;
  }
  auto tree = maps::octree_from_binary_data(msg.data(), msg.resolution(), msg.id());
  if (!tree) {
    out.status = error(wire::INVALID_MAP, "octomap: " + tree.error().message);
    return out;
  }
  out.tree = std::move(tree).value();
  return out;
}

OctomapMsg to_octomap_msg(const octomap::OcTree& tree, const std::string& frame,
                          const TimeMsg& stamp) {
  OctomapMsg msg;
  msg.header().frame_id(frame);
  msg.header().stamp(stamp);
  msg.binary(true);
  msg.id("OcTree");
  msg.resolution(tree.getResolution());
  msg.data(maps::octree_to_binary_data(tree));
  return msg;
}

PoseCheck check_pose(const PoseStampedMsg& pose, const std::string& field,
                     const std::string& expected_frame) {
  PoseCheck out;
  const std::string& frame = pose.header().frame_id();
  if (!frame.empty() && !same_frame(frame, expected_frame)) {
    out.status = error(wire::FRAME_MISMATCH, field + ".header.frame_id is '" + printable(frame) +
                                                 "', the map's frame is '" + expected_frame + "'");
    return out;
  }
  const auto& p = pose.pose().position();
  const char* axis[] = {"x", "y", "z"};
  const double values[] = {p.x(), p.y(), p.z()};
  for (int i = 0; i < 3; ++i) {
    if (!finite(values[i])) {
      out.status = error(wire::INVALID_REQUEST, field + ".pose.position." + axis[i] + " is " +
                                                    num(values[i]) + ", must be finite");
      return out;
    }
  }
  const auto& q = pose.pose().orientation();
  if (!finite(q.x()) || !finite(q.y()) || !finite(q.z()) || !finite(q.w())) {
    out.status = error(wire::INVALID_REQUEST, field + ".pose.orientation must be finite");
    return out;
  }
  out.x = p.x();
  out.y = p.y();
  return out;
}

std::vector<Eigen::Vector2d> path_positions(const PathMsg& path, const std::string& expected_frame,
                                            size_t max_poses, std::string& problem) {
  problem.clear();
  auto wrong_frame = [&](const std::string& field, const std::string& frame) {
    problem = field + ".frame_id is '" + printable(frame) + "', the map's frame is '" +
              expected_frame + "'";
  };
  const std::string& frame = path.header().frame_id();
  if (!frame.empty() && !same_frame(frame, expected_frame)) {
    wrong_frame("path.header", frame);
    return {};
  }
  if (path.poses().size() > max_poses) {
    problem = "path.poses: " + std::to_string(path.poses().size()) + " poses, at most " +
              std::to_string(max_poses) + " (actions.max_result_poses)";
    return {};
  }
  std::vector<Eigen::Vector2d> out;
  out.reserve(path.poses().size());
  for (size_t i = 0; i < path.poses().size(); ++i) {
    const PoseStampedMsg& pose = path.poses()[i];
    const std::string& pose_frame = pose.header().frame_id();
    if (!pose_frame.empty() && !same_frame(pose_frame, expected_frame)) {
      wrong_frame("path.poses[" + std::to_string(i) + "].header", pose_frame);
      return {};
    }
    out.emplace_back(pose.pose().position().x(), pose.pose().position().y());
  }
  return out;
}

PoseStampedMsg to_pose_msg(double x, double y, double yaw, const std::string& frame,
                           const TimeMsg& stamp) {
  PoseStampedMsg msg;
  msg.header().frame_id(frame);
  msg.header().stamp(stamp);
  msg.pose().position().x(x);
  msg.pose().position().y(y);
  // A rotation of `yaw` about z.
  msg.pose().orientation().z(std::sin(yaw / 2.0));
  msg.pose().orientation().w(std::cos(yaw / 2.0));
  return msg;
}

PathMsg to_path_msg(const std::vector<Eigen::Vector2d>& points, const std::string& frame,
                    const TimeMsg& stamp, double spacing_m, std::optional<double> goal_yaw) {
  PathMsg msg;
  msg.header().frame_id(frame);
  msg.header().stamp(stamp);
  const std::vector<core::Pose2> poses = core::path_poses(points, spacing_m, goal_yaw);
  msg.poses().reserve(poses.size());
  for (const core::Pose2& p : poses)
    msg.poses().push_back(to_pose_msg(p.x, p.y, p.yaw, frame, stamp));
  return msg;
}

PathMsg to_path_msg(const core::PlanResult& result, const std::string& frame, const TimeMsg& stamp,
                    double spacing_m, std::optional<double> goal_yaw) {
  return to_path_msg(result.world_path, frame, stamp, spacing_m, goal_yaw);
}

PathMsg to_raw_path_msg(const core::PlanResult& result, const core::GridMap& map,
                        const std::string& frame, const TimeMsg& stamp) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(result.raw_path.size());
  for (const core::Cell& cell : result.raw_path) points.push_back(map.cell_centre_world(cell));
  return to_path_msg(points, frame, stamp, /*spacing_m=*/0.0);
}

PathMsg to_pruned_path_msg(const core::PlanResult& result, const core::GridMap& map,
                           const std::string& frame, const TimeMsg& stamp) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(result.waypoints.size());
  for (const core::Point2& w : result.waypoints) points.push_back(map.grid_to_world(w));
  return to_path_msg(points, frame, stamp, /*spacing_m=*/0.0);
}

OccupancyGridMsg to_expansions_msg(const std::vector<core::Cell>& expanded,
                                   const core::GridMap& map, const std::string& frame,
                                   const TimeMsg& stamp) {
  OccupancyGridMsg msg;
  msg.header().frame_id(frame);
  msg.header().stamp(stamp);
  msg.info(map_info(map, stamp));
  std::vector<int8_t> data(static_cast<size_t>(map.width()) * static_cast<size_t>(map.height()), 0);
  const size_t n = expanded.size();
  for (size_t i = 0; i < n; ++i) {
    const core::Cell& c = expanded[i];
    if (!map.in_bounds(c)) continue;  // never: the searches close cells of this map
    // 1 for the first expansion ... 100 for the last: the order, on rviz2's costmap colours.
    data[static_cast<size_t>(c.y) * static_cast<size_t>(map.width()) + static_cast<size_t>(c.x)] =
        static_cast<int8_t>(1 + (99 * i) / std::max<size_t>(n - 1, 1));
  }
  msg.data(std::move(data));
  return msg;
}

PointStampedMsg to_point_msg(const core::Cell& cell, const core::GridMap& map,
                             const std::string& frame, const TimeMsg& stamp) {
  PointStampedMsg msg;
  msg.header().frame_id(frame);
  msg.header().stamp(stamp);
  const Eigen::Vector2d centre = map.cell_centre_world(cell);
  msg.point().x(centre.x());
  msg.point().y(centre.y());
  return msg;
}

double min_path_spacing(double resolution) {
  return kMinPathSpacingCells * resolution;
}

std::string describe_adjusted_endpoints(const core::Endpoints& endpoints, const core::GridMap& map,
                                        const core::PlannerOptions& options) {
  auto moved = [&](const char* which, const core::Cell& cell, double distance, double tolerance,
                   const char* key) {
    const Eigen::Vector2d c = map.cell_centre_world(cell);
    return std::string(which) + " moved " + maps::metres_text(distance) +
           " m to the nearest free cell (" + maps::metres_text(c.x()) + ", " +
           maps::metres_text(c.y()) + ") m (" + key + " " + maps::short_number(tolerance) + " m)";
  };
  std::string out;
  if (endpoints.start_adjusted)
    out = moved("start", endpoints.start, endpoints.start_moved_m, options.start_tolerance,
                "start_tolerance");
  if (endpoints.goal_adjusted) {
    out += (out.empty() ? "" : "; ") + moved("goal", endpoints.goal, endpoints.goal_moved_m,
                                             options.goal_tolerance, "goal_tolerance");
  }
  return out;
}

PlanStatusMsg to_status_msg(const std::string& request_id, const RequestIdentity* identity,
                            const WireStatus& status, const std::string& planner,
                            const core::Metrics* metrics, const TimeMsg& map_stamp, PathMsg path,
                            const core::Endpoints* endpoints, const core::GridMap* map) {
  PlanStatusMsg msg;
  msg.request_id(request_id);
  if (identity != nullptr) {
    msg.subject(identity->subject);
    msg.request_writer_guid(identity->writer_guid);
    msg.request_sequence_number(identity->sequence_number);
  } else {
    msg.subject(wire::SUBJECT_MAP);
  }
  msg.code(status.code);
  msg.code_name(code_name(status.code));
  msg.message(status.message);
  msg.planner(planner);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  msg.length_ratio(nan);
  msg.clearance_m(nan);
  if (metrics != nullptr) {
    msg.length_m(metrics->length_m);
    msg.length_cells(metrics->length_cells);
    msg.raw_cost_cells(metrics->raw_cost_cells);
    msg.turns(metrics->turns);
    msg.turn_angle_deg(metrics->turn_angle_deg);
    msg.expanded(metrics->expanded);
    msg.planning_time_us(metrics->planning_time_us);
    msg.length_ratio(metrics->length_ratio);
    if (status.ok()) msg.clearance_m(metrics->clearance_m);
  }
  msg.start_x(nan);
  msg.start_y(nan);
  msg.goal_x(nan);
  msg.goal_y(nan);
  if (endpoints != nullptr && map != nullptr) {
    // Where the path begins and ends: the requested point, or the centre of the cell a tolerance
    // moved it to (core::Endpoints), so the status and the path's first and last poses agree.
    auto used = [&](const core::Cell& cell, const core::Point2& point) {
      const bool in_cell =
          point.allFinite() && std::floor(point.x()) == cell.x && std::floor(point.y()) == cell.y;
      return map->grid_to_world(in_cell ? point : core::cell_centre(cell));
    };
    const Eigen::Vector2d s = used(endpoints->start, endpoints->start_point);
    const Eigen::Vector2d g = used(endpoints->goal, endpoints->goal_point);
    msg.start_x(s.x());
    msg.start_y(s.y());
    msg.goal_x(g.x());
    msg.goal_y(g.y());
    msg.start_adjusted(endpoints->start_adjusted);
    msg.goal_adjusted(endpoints->goal_adjusted);
    msg.start_moved_m(endpoints->start_moved_m);
    msg.goal_moved_m(endpoints->goal_moved_m);
  }
  msg.map_stamp(map_stamp);
  msg.path(std::move(path));
  return msg;
}

PlannerDebugMsg to_debug_msg(const std::string& request_id, const core::PlanResult& result,
                             const core::GridMap& map, const std::string& frame,
                             const TimeMsg& stamp) {
  PlannerDebugMsg msg;
  msg.header().frame_id(frame);
  msg.header().stamp(stamp);
  msg.request_id(request_id);
  msg.planner(std::string(core::to_string(result.planner)));
  msg.info(map_info(map, stamp));
  auto cells = [](const std::vector<core::Cell>& in) {
    std::vector<vnsba_msgs::msg::dds_::GridCell_> out(in.size());
    for (size_t i = 0; i < in.size(); ++i) {
      out[i].x(in[i].x);
      out[i].y(in[i].y);
    }
    return out;
  };
  msg.expanded_forward(cells(result.expanded_forward));
  msg.expanded_backward(cells(result.expanded_backward));
  msg.has_meeting_cell(result.meeting_cell.has_value());
  if (result.meeting_cell) {
    msg.meeting_cell().x(result.meeting_cell->x);
    msg.meeting_cell().y(result.meeting_cell->y);
  }
  msg.raw_path(cells(result.raw_path));
  for (const core::Point2& w : result.waypoints) {
    const Eigen::Vector2d world = map.grid_to_world(w);
    geometry_msgs::msg::dds_::Point_ point;
    point.x(world.x());
    point.y(world.y());
    msg.pruned_waypoints().push_back(point);
  }
  return msg;
}

core::Metrics metrics_from_status_msg(const PlanStatusMsg& msg) {
  core::Metrics m;
  m.length_m = msg.length_m();
  m.length_cells = msg.length_cells();
  m.raw_cost_cells = msg.raw_cost_cells();
  m.turns = msg.turns();
  m.turn_angle_deg = msg.turn_angle_deg();
  m.expanded = msg.expanded();
  m.planning_time_us = msg.planning_time_us();
  m.length_ratio = msg.length_ratio();
  m.clearance_m = msg.clearance_m();
  return m;
}

std::optional<Eigen::Vector2d> position_of(const PoseStampedMsg& pose) {
  const Eigen::Vector2d p(pose.pose().position().x(), pose.pose().position().y());
  if (!p.allFinite()) return std::nullopt;
  return p;
}

std::vector<Eigen::Vector2d> from_path_msg(const PathMsg& msg) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(msg.poses().size());
  for (const auto& pose : msg.poses())
    out.emplace_back(pose.pose().position().x(), pose.pose().position().y());
  return out;
}

DebugData from_debug_msg(const PlannerDebugMsg& msg) {
  DebugData d;
  d.request_id = msg.request_id();
  core::SearchTrace& t = d.trace;
  t.planner = msg.planner();
  // MapMetaData sizes are uint32; anything above int32 cannot be a map the node planned on.
  t.width = static_cast<int32_t>(std::min<uint32_t>(msg.info().width(), INT32_MAX));
  t.height = static_cast<int32_t>(std::min<uint32_t>(msg.info().height(), INT32_MAX));
  t.resolution = float32_decimal(msg.info().resolution());
  t.origin_x = msg.info().origin().position().x();
  t.origin_y = msg.info().origin().position().y();
  auto cells = [](const std::vector<vnsba_msgs::msg::dds_::GridCell_>& in) {
    std::vector<core::Cell> out(in.size());
    for (size_t i = 0; i < in.size(); ++i) out[i] = {in[i].x(), in[i].y()};
    return out;
  };
  t.expanded_forward = cells(msg.expanded_forward());
  t.expanded_backward = cells(msg.expanded_backward());
  if (msg.has_meeting_cell())
    t.meeting_cell = core::Cell{msg.meeting_cell().x(), msg.meeting_cell().y()};
  t.raw_path = cells(msg.raw_path());
  for (const auto& p : msg.pruned_waypoints()) t.pruned_waypoints.emplace_back(p.x(), p.y());
  return d;
}

}  // namespace vnsba::node
