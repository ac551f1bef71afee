// The robot's pose from tf (robot_pose_source: tf): the newest transform of each frame in its
// parent, as tf2_msgs/TFMessage carries them on /tf and /tf_static, composed along the tree the
// way tf2's lookupTransform(target, source) does for its newest data. No DDS: the node's tf
// readers feed it, and the tests use it alone.
//
// Only the newest transform of each frame is kept (no history, no interpolation): the node asks
// for the robot's pose now, when a goal arrives. A dynamic transform older than the tolerance is
// stale, as tf2's lookups time out, and one stamped after now is refused, as tf2 does not
// extrapolate into the future; a static one (/tf_static) is neither.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vnsba::node {

class TransformTree {
 public:
  // Frames the tree holds at most: a bound on the memory a flood of made-up frames can take.
  static constexpr size_t kMaxFrames = 10000;
  // Transforms a chain from a root frame down to a frame may hold at most. Each new transform
  // walks its parent's chain up to the root (to refuse loops), so this bounds its cost: without
  // it, one /tf message of 20,000 chained frames walked 10,000 ancestors a transform, 12 s under
  // the lock every goal needs, and a flood of them kept goals unanswered for minutes. A robot's
  // tree (map -> odom -> base_footprint -> base_link -> sensors) is a few to a few dozen deep;
  // tf2 itself gives up at 1000 (its loop guard).
  static constexpr size_t kMaxDepth = 100;
  // Seconds a dynamic transform may be stamped after the clock's now: clock skew between hosts
  // (NTP keeps them within milliseconds). A later one is refused at lookup, as tf2 refuses to
  // extrapolate into the future; with use_sim_time that is also every transform stamped before
  // the simulation's clock went back.
  static constexpr double kMaxAheadS = 0.5;

  // Why set() refused a transform; kNone when it was taken.
  enum class Refusal {
    kNone,
    kInvalid,        // an empty frame, a frame its own parent, a non-finite value, zero quaternion
    kLoop,           // it would close a loop
    kTooDeep,        // it would make a chain of more than kMaxDepth transforms
    kTooManyFrames,  // a new frame beyond kMaxFrames
  };
  struct SetResult {
    Refusal refusal = Refusal::kNone;
    std::string problem;  // what is wrong, naming the frames; "" when taken
    bool taken() const { return refusal == Refusal::kNone; }
  };
  // Sets `child`'s pose in `parent` (translation in metres, rotation a quaternion that is
  // normalised here), stamped `stamp_s` seconds; frames are compared without a leading '/'.
  // A refused transform changes nothing. Costs at most kMaxDepth map look-ups.
  SetResult set(std::string_view parent, std::string_view child,
                const Eigen::Vector3d& translation_m, const Eigen::Quaterniond& rotation,
                double stamp_s, bool is_static);

  struct Lookup {
    bool ok = false;
    Eigen::Isometry3d source_in_target = Eigen::Isometry3d::Identity();
    std::string problem;  // when !ok: which frames, and what is missing, stale or in the future
  };
  // The pose of frame `source` in frame `target` (tf2's lookupTransform(target, source) with the
  // newest data). Refused when no chain of received transforms joins them (or one deeper than
  // kMaxDepth does), when a dynamic transform on the chain is older than `tolerance_s` at
  // `now_s` (seconds, the node's clock), or stamped more than kMaxAheadS after `now_s`.
  Lookup lookup(std::string_view target, std::string_view source, double now_s,
                double tolerance_s) const;

  // Drops every dynamic transform (static ones stay): tf2_ros's buffer does this when the
  // clock jumps back. Returns how many were dropped.
  size_t clear_dynamic();

  size_t frame_count() const { return parent_of_.size(); }

 private:
  struct Edge {
    std::string parent;
    Eigen::Isometry3d child_in_parent;
    double stamp_s = 0.0;
    bool is_static = false;
  };
  std::map<std::string, Edge, std::less<>> parent_of_;  // by child frame

  using EdgeRef = const std::pair<const std::string, Edge>*;
  // A frame above the source, with the source's pose in it and the edge walked to reach it.
  struct Ancestor {
    std::string_view frame;
    Eigen::Isometry3d source_in_frame;
    EdgeRef edge;  // from the previous ancestor's frame to this one; null for the source
  };
  // The transforms that join two frames, and the source's pose in the target.
  struct Chain {
    std::vector<EdgeRef> edges;
    Eigen::Isometry3d source_in_target = Eigen::Isometry3d::Identity();
  };
  // lookup()'s steps; each returns the problem (the message of a refused Lookup) or nothing.
  std::optional<std::string> ancestors(std::string_view source, const std::string& too_deep,
                                       std::vector<Ancestor>& up_from_source) const;
  std::optional<std::string> join(std::string_view target, std::string_view source,
                                  const std::vector<Ancestor>& up_from_source,
                                  const std::string& what, const std::string& too_deep,
                                  Chain& chain) const;
  static std::optional<std::string> stamp_problem(const std::vector<EdgeRef>& edges,
                                                  std::string_view target, std::string_view source,
                                                  double now_s, double tolerance_s);
};

}  // namespace vnsba::node
