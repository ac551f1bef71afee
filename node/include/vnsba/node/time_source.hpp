// The node's clock: the system clock, or with use_sim_time the newest rosgraph_msgs/Clock on
// /clock (zero until the first one arrives, as a ROS 2 node with use_sim_time sees it). It
// stamps everything the node publishes and ages the transforms of robot_pose_source: tf.
#pragma once

#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <cstdint>

#include "vnsba/node/convert.hpp"

namespace vnsba::node {

// What a Clock sample did to the node's clock.
enum class ClockUpdate {
  kIgnored,          // use_sim_time is off: the system clock stays
  kFollowed,         // the clock moved on (or stood still, as a paused simulation's does)
  kJumpedBack,       // the clock went back (a simulation reset): followed, as ROS 2 does; tf2_ros
                     // then clears its buffer's dynamic transforms (TransformTree::clear_dynamic)
  kRefusedNegative,  // a time before the epoch, which ROS time never is: the clock stays
};

class TimeSource {
 public:
  explicit TimeSource(bool use_sim_time) : use_sim_time_(use_sim_time) {}

  // A Clock sample (from the DDS listener). Ignored without use_sim_time. A jump
  // back is followed and logged once per jump; negative times are refused, logged once until a
  // valid time arrives (a simulator that repeats a bad clock at 100 Hz is one warning).
  ClockUpdate set_sim_time(const TimeMsg& time) {
    if (!use_sim_time_) return ClockUpdate::kIgnored;
    const int64_t ns = to_nanoseconds(time);
    const int64_t previous = sim_ns_.load();
    if (ns < 0) {
      if (!negative_warned_)
        spdlog::warn(
            "use_sim_time: refused a clock of {:.9f} s, before the epoch (ROS time is never "
            "negative); the node's clock stays at {:.9f} s",
            ns * 1e-9, previous * 1e-9);
      negative_warned_ = true;
      return ClockUpdate::kRefusedNegative;
    }
    negative_warned_ = false;
    sim_ns_.store(ns);
    if (ns >= previous) return ClockUpdate::kFollowed;
    spdlog::warn(
        "use_sim_time: the clock went back from {:.9f} s to {:.9f} s (a simulation reset?); the "
        "node follows it, and transforms stamped after the new time count as from the future "
        "until newer ones replace them",
        previous * 1e-9, ns * 1e-9);
    return ClockUpdate::kJumpedBack;
  }

  TimeMsg now() const { return use_sim_time_ ? to_time_msg(sim_ns_.load()) : now_msg(); }
  double now_seconds() const { return to_seconds(now()); }

  bool use_sim_time() const { return use_sim_time_; }

 private:
  const bool use_sim_time_;
  std::atomic<int64_t> sim_ns_{0};
  std::atomic<bool> negative_warned_{false};
};

}  // namespace vnsba::node
