// The one place where IDL types and core types meet. Everything the node receives is checked
// here, field by field, and every message it sends is built here.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "builtin_interfaces/msg/Time.h"
#include "geometry_msgs/msg/PointStamped.h"
#include "geometry_msgs/msg/PoseStamped.h"
#include "geometry_msgs/msg/PoseWithCovarianceStamped.h"
#include "nav_msgs/msg/OccupancyGrid.h"
#include "nav_msgs/msg/Path.h"
#include "octomap_msgs/msg/Octomap.h"
#include "rosgraph_msgs/msg/Clock.h"
#include "tf2_msgs/msg/TFMessage.h"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/core/search_trace.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/node/transforms.hpp"
#include "vnsba_msgs/msg/PlanRequest.h"
#include "vnsba_msgs/msg/PlanStatus.h"
#include "vnsba_msgs/msg/PlannerDebug.h"

namespace vnsba::node {

namespace wire = vnsba_msgs::msg::PlanStatus_Constants;
using OccupancyGridMsg = nav_msgs::msg::dds_::OccupancyGrid_;
using PoseStampedMsg = geometry_msgs::msg::dds_::PoseStamped_;
using PoseWithCovarianceStampedMsg = geometry_msgs::msg::dds_::PoseWithCovarianceStamped_;
using PointStampedMsg = geometry_msgs::msg::dds_::PointStamped_;
using TFMessageMsg = tf2_msgs::msg::dds_::TFMessage_;
using ClockMsg = rosgraph_msgs::msg::dds_::Clock_;
using PathMsg = nav_msgs::msg::dds_::Path_;
using PlanRequestMsg = vnsba_msgs::msg::dds_::PlanRequest_;
using PlanStatusMsg = vnsba_msgs::msg::dds_::PlanStatus_;
using PlannerDebugMsg = vnsba_msgs::msg::dds_::PlannerDebug_;
using TimeMsg = builtin_interfaces::msg::dds_::Time_;
using OctomapMsg = octomap_msgs::msg::dds_::Octomap_;

// A status as it goes on the wire: a PlanStatus_Constants code and a message naming the field.
struct WireStatus {
  uint8_t code = wire::OK;
  std::string message;
  bool ok() const { return code == wire::OK; }
};

// `text` made safe to log or echo: control characters (C0, DEL, C1) and bytes that are not
// UTF-8 become \n, \t, \r, \\ or \xNN, so an id cannot forge log lines or drive a terminal;
// beyond `max_bytes` of input it is cut (on a character boundary) and says how long it was.
std::string printable(std::string_view text, size_t max_bytes = 128);

// The DDS sample identity of a request: unique per request even when a client reuses an id.
struct RequestIdentity {
  uint8_t subject = wire::SUBJECT_REQUEST;  // SUBJECT_REQUEST or SUBJECT_GOAL_POSE
  std::array<uint8_t, 16> writer_guid{};    // GUID prefix (12 bytes) + entity id (4 bytes)
  int64_t sequence_number = 0;

  // Same DDS participant (GUID prefix) as `other`: the same client.
  bool same_client(const RequestIdentity& other) const;
};

uint8_t to_wire_code(core::StatusCode code);
// "OK", "NO_MAP", ... for a PlanStatus_Constants code ("UNKNOWN" otherwise).
std::string code_name(uint8_t code);

TimeMsg to_time_msg(std::chrono::system_clock::time_point t);
TimeMsg to_time_msg(int64_t nanoseconds);
int64_t to_nanoseconds(const TimeMsg& t);
double to_seconds(const TimeMsg& t);
// robot_pose_type PoseWithCovarianceStamped: the pose and its header (the covariance is unused).
PoseStampedMsg to_pose_stamped(const PoseWithCovarianceStampedMsg& msg);
// Puts every transform of a tf2_msgs/TFMessage (from /tf, or /tf_static when `is_static`) into
// `tree`; returns what was wrong with those it refused (see TransformTree::set), made printable.
// Refusals at a limit of the tree (kMaxDepth, kMaxFrames) are one line each per message: the
// first, and how many more (a flood of made-up frames is one warning, not thousands).
std::vector<std::string> add_transforms(const TFMessageMsg& msg, bool is_static,
                                        TransformTree& tree);
TimeMsg now_msg();

// The decimal a float32 field was written from: the shortest decimal that rounds to `value` as
// a float (std::to_chars), as a double. ROS messages carry a map's resolution as float32
// (nav_msgs/MapMetaData): a map_server map of 0.05 m arrives as 0.05000000074505806, and read
// as that it plans on another grid than the file's 0.05 (cells of inflation, costs, which cell
// holds a point). The one IDL -> core conversion of such fields.
double float32_decimal(float value);

// Whether two frame ids name one frame: equal once a leading '/' is dropped from each, as tf2
// does ("/map" from a ROS 1 bridge or an old config is "map"). Anything else differs ("odom").
bool same_frame(std::string_view a, std::string_view b);

// A slice off the bus, checked and converted: frame, size, resolution (read as
// float32_decimal), origin (finite, and near enough to the frame's origin that the cells' world
// coordinates keep a millionth of a cell in doubles; an orientation that is the identity: no
// rotation, since grids must be axis-aligned, and not the zero or a non-finite quaternion), data
// length, values in -1..100, size limit. Errors are FRAME_MISMATCH or INVALID_MAP with the
// offending field named.
struct SliceCheck {
  WireStatus status;
  core::OccupancyGrid grid;  // valid when status.ok()
};
SliceCheck from_slice_msg(OccupancyGridMsg&& msg, const std::string& expected_frame,
                          int64_t max_cells);

// What the node holds to convert a slice of width x height cells built with `options` (bytes):
// the planning grid and the build's scratch (core::GridMap::estimate_memory, the one source of a
// map's figures) and the slice's values the build reads, one byte a cell (the message's data,
// moved into the core::OccupancyGrid, never copied). The sample DDS received is freed when it is
// taken, before the conversion starts.
struct SliceMemory {
  core::MapMemoryEstimate map;
  size_t slice_bytes = 0;  // the slice's values
  size_t peak_bytes() const { return map.peak_bytes() + slice_bytes; }
};
SliceMemory slice_memory(int32_t width, int32_t height, const core::GridBuildOptions& options);

// A MiB figure as the node prints it (sizes in bytes; 1 MiB = 2^20 bytes): rounded up, so that a
// budget of the figure printed holds what it counts.
int64_t mib_rounded_up(size_t bytes);

// OK when converting a width x height slice with `options` fits `memory_budget_mb` (MiB,
// map.memory_budget_mb); else INVALID_MAP naming the slice's size, the MiB it needs (and what of
// it is the grid, the build's scratch and the values) and the key with its value.
WireStatus check_memory_budget(int32_t width, int32_t height, const core::GridBuildOptions& options,
                               int memory_budget_mb);

// The inverse (for the slicer and tests): a core grid as a slice in `frame` stamped `stamp`.
OccupancyGridMsg to_slice_msg(const core::OccupancyGrid& grid, const std::string& frame,
                              const TimeMsg& stamp);

// An octomap_msgs/Octomap off the bus as a tree: binary must be true (full-probability trees
// are not supported), id "OcTree", resolution finite and > 0, data a complete binary stream.
// Errors are INVALID_MAP naming the field.
struct TreeCheck {
  WireStatus status;
  std::shared_ptr<octomap::OcTree> tree;  // set when status.ok()
};
TreeCheck from_octomap_msg(const OctomapMsg& msg);

// A tree as a binary octomap_msgs/Octomap (what octomap_server publishes on octomap_binary).
OctomapMsg to_octomap_msg(const octomap::OcTree& tree, const std::string& frame,
                          const TimeMsg& stamp);

// A request's pose: finite position, finite and non-zero quaternion, frame equal to the map's
// (empty counts as the map's). `field` names it in messages ("start", "goal").
struct PoseCheck {
  WireStatus status;
  double x = 0.0;  // metres
  double y = 0.0;
};
PoseCheck check_pose(const PoseStampedMsg& pose, const std::string& field,
                     const std::string& expected_frame);

// The positions (x, y metres) of a path to check (is_path_valid), in its order: "" in `problem`
// when the path is in `expected_frame` (its header's frame_id, and each pose's that is not
// empty, same_frame; an empty one is the map's, as in goals) and lists at most `max_poses`
// poses; otherwise `problem` says which field is at fault and the positions are empty. A
// position that is not finite stays so (the check finds it off the map).
std::vector<Eigen::Vector2d> path_positions(const PathMsg& path, const std::string& expected_frame,
                                            size_t max_poses, std::string& problem);

// A pose message at (x, y) metres with heading `yaw` radians.
PoseStampedMsg to_pose_msg(double x, double y, double yaw, const std::string& frame,
                           const TimeMsg& stamp);

// The final path as nav_msgs/Path: core::path_poses(result.world_path, spacing_m, goal_yaw),
// poses at most spacing_m metres apart, each facing along the path (the tangent), the last one
// with goal_yaw (radians) when it is set (docs/algorithm.md section 8, "Path poses").
PathMsg to_path_msg(const core::PlanResult& result, const std::string& frame, const TimeMsg& stamp,
                    double spacing_m, std::optional<double> goal_yaw = std::nullopt);
// The same for any polyline in metres (spacing_m <= 0: its vertices only, tangent yaw).
PathMsg to_path_msg(const std::vector<Eigen::Vector2d>& points, const std::string& frame,
                    const TimeMsg& stamp, double spacing_m,
                    std::optional<double> goal_yaw = std::nullopt);

// Debug layers in stock ROS 2 types (topics plan_raw, plan_pruned, planner_expansions_*,
// planner_meeting_point), for rviz2's own displays:
// the search's grid path, a pose at each cell centre (tangent yaw);
PathMsg to_raw_path_msg(const core::PlanResult& result, const core::GridMap& map,
                        const std::string& frame, const TimeMsg& stamp);
// the waypoints after pruning (tangent yaw);
PathMsg to_pruned_path_msg(const core::PlanResult& result, const core::GridMap& map,
                           const std::string& frame, const TimeMsg& stamp);
// the cells one search expanded, on the map's geometry: 0 = not expanded, 1..100 = the order of
// expansion (first 1, last 100), which rviz2's Map display shows with its "costmap" colours;
OccupancyGridMsg to_expansions_msg(const std::vector<core::Cell>& expanded,
                                   const core::GridMap& map, const std::string& frame,
                                   const TimeMsg& stamp);
// a cell's centre (the meeting cell of a bidirectional search).
PointStampedMsg to_point_msg(const core::Cell& cell, const core::GridMap& map,
                             const std::string& frame, const TimeMsg& stamp);

// The smallest pose spacing the node publishes on a map of `resolution` metres per cell:
// kMinPathSpacingCells cells (as fine as the finest spline sampling, sample_step 0.05 cells), so
// that a path never holds more than 20 poses per cell of its length.
inline constexpr double kMinPathSpacingCells = core::kSampleStepRange.min;
double min_path_spacing(double resolution);

// What the status message of an OK plan says about moved endpoints, "" when none moved:
// "goal moved 0.070 m to the nearest free cell (1.225, 4.575) m (goal_tolerance 0.3 m)", and
// likewise for the start ("; " between them). Positions are the used cells' centres.
std::string describe_adjusted_endpoints(const core::Endpoints& endpoints, const core::GridMap& map,
                                        const core::PlannerOptions& options);

// A status answering the request `identity` (null: a report about a map, SUBJECT_MAP).
// clearance_m is metrics->clearance_m for an OK status, NaN otherwise. start_x ... goal_moved_m
// describe `endpoints` on `map` (the cells a plan used, their centres in metres) when both are
// given; otherwise the positions are NaN, the flags false and the distances 0.
PlanStatusMsg to_status_msg(const std::string& request_id, const RequestIdentity* identity,
                            const WireStatus& status, const std::string& planner,
                            const core::Metrics* metrics, const TimeMsg& map_stamp, PathMsg path,
                            const core::Endpoints* endpoints = nullptr,
                            const core::GridMap* map = nullptr);

PlannerDebugMsg to_debug_msg(const std::string& request_id, const core::PlanResult& result,
                             const core::GridMap& map, const std::string& frame,
                             const TimeMsg& stamp);

// --- What the node publishes, read back into core types (for the recorder and tests). ---

// Metrics of a PlanStatus (as computed by the node; zero unless the code is OK; clearance_m NaN
// unless OK, +inf on a map without obstacles).
core::Metrics metrics_from_status_msg(const PlanStatusMsg& msg);

// A pose's (x, y) position in metres, or nullopt when either is not finite (no frame check:
// the recorder keeps what was sent, valid or not).
std::optional<Eigen::Vector2d> position_of(const PoseStampedMsg& pose);

// The (x, y) positions of a path's poses, metres.
std::vector<Eigen::Vector2d> from_path_msg(const PathMsg& msg);

// A PlannerDebug in core types (cells index the grid its info describes). The request id is
// the message's; the rest is the trace.
struct DebugData {
  std::string request_id;
  core::SearchTrace trace;
};
DebugData from_debug_msg(const PlannerDebugMsg& msg);

}  // namespace vnsba::node
