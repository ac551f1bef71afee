// The robot's pose from tf (robot_pose_source: tf): the newest transform of each frame in its
// parent, as tf2_msgs/TFMessage carries them on /tf and /tf_static, composed along the tree the
// way tf2's lookupTransform(target, source) does for its newest data. No DDS: the node's tf
// readers feed it, and the tests use it alone.
//
// Only the newest transform of each frame is kept (no history, no interpolation): the node asks
// for the robot's pose now, when a goal arrives. A dynamic transform older than the tolerance is
// stale, as tf2's lookups time out; a static one (/tf_static) never is.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <map>
#include <string>
#include <string_view>

namespace vnsba::node {

class TransformTree {
 public:
  // Frames the tree holds at most: a bound on the memory a flood of made-up frames can take.
  static constexpr size_t kMaxFrames = 10000;

  // Sets `child`'s pose in `parent` (translation in metres, rotation a quaternion that is
  // normalised here), stamped `stamp_s` seconds; frames are compared without a leading '/'.
  // Returns "" when taken, else what is wrong, naming the frames: an empty frame, a frame its own
  // parent, a non-finite value or zero quaternion, a transform that would close a loop, or one
  // frame too many. A refused transform changes nothing.
  std::string set(std::string_view parent, std::string_view child,
                  const Eigen::Vector3d& translation_m, const Eigen::Quaterniond& rotation,
                  double stamp_s, bool is_static);

  struct Lookup {
    bool ok = false;
    Eigen::Isometry3d source_in_target = Eigen::Isometry3d::Identity();
    std::string problem;  // when !ok: which frames, and what is missing or stale
  };
  // The pose of frame `source` in frame `target` (tf2's lookupTransform(target, source) with the
  // newest data). Refused when no chain of received transforms joins them, or when a dynamic
  // transform on the chain is older than `tolerance_s` at `now_s` (seconds, the node's clock).
  Lookup lookup(std::string_view target, std::string_view source, double now_s,
                double tolerance_s) const;

  size_t frame_count() const { return parent_of_.size(); }

 private:
  struct Edge {
    std::string parent;
    Eigen::Isometry3d child_in_parent;
    double stamp_s = 0.0;
    bool is_static = false;
  };
  std::map<std::string, Edge, std::less<>> parent_of_;  // by child frame
};

}  // namespace vnsba::node
