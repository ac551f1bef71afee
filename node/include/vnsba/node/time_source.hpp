// The node's clock: the system clock, or with use_sim_time the newest rosgraph_msgs/Clock on
// /clock (zero until the first one arrives, as a ROS 2 node with use_sim_time sees it). It
// stamps everything the node publishes and ages the transforms of robot_pose_source: tf.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

#include "vnsba/node/convert.hpp"

namespace vnsba::node {

class TimeSource {
 public:
  explicit TimeSource(bool use_sim_time) : use_sim_time_(use_sim_time) {}

  // A Clock sample (DDS listener thread). Ignored without use_sim_time; a clock that goes
  // backwards (a simulation reset) is followed, as ROS 2 does.
  void set_sim_time(const TimeMsg& time) {
    if (use_sim_time_) sim_ns_.store(to_nanoseconds(time));
  }

  TimeMsg now() const { return use_sim_time_ ? to_time_msg(sim_ns_.load()) : now_msg(); }
  double now_seconds() const { return to_seconds(now()); }

  bool use_sim_time() const { return use_sim_time_; }

 private:
  const bool use_sim_time_;
  std::atomic<int64_t> sim_ns_{0};
};

}  // namespace vnsba::node
