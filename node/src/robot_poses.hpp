// Where each robot is, for the start of a goal that has none of its own (a goal_pose goal, an
// action goal without use_start): the newest pose on its robot_pose topic, or its base frame
// looked up in the transforms received on tf and tf_static (robot_pose_source), whose age the
// node's clock (use_sim_time) decides.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "fleet.hpp"
#include "node_readers.hpp"
#include "vnsba/node/requests.hpp"
#include "vnsba/node/time_source.hpp"
#include "vnsba/node/transforms.hpp"

namespace vnsba::node {

class RobotPoses {
 public:
  RobotPoses(const NodeConfig& config, const Fleet& fleet, TimeSource& time);
  RobotPoses(const RobotPoses&) = delete;
  RobotPoses& operator=(const RobotPoses&) = delete;

  // The clock reader (use_sim_time only): read first, so that the first goal already has the
  // simulation's time.
  core::Status add_clock_reader(NodeReaders& readers);
  // The tf_static and tf readers (robot_pose_source tf only), one for every robot.
  core::Status add_transform_readers(NodeReaders& readers);
  // `robot`'s robot_pose reader (robot_pose_source topic only).
  core::Status add_pose_reader(NodeReaders& readers, const Robot& robot);

  // The start of a goal of `robot`: job.start, or job.missing_start saying what is missing.
  void start_of(const Robot& robot, Job& job);
  // Where `robot` is (x, y metres in frame_id), taken as a goal's start is: nullopt when there is
  // no pose yet, or it is in another frame or not finite (is_path_valid then checks every pose).
  std::optional<Eigen::Vector2d> position_of(const Robot& robot);

 private:
  struct LastPose {
    std::mutex mutex;
    std::optional<PoseStampedMsg> pose;  // under mutex
  };
  const NodeConfig& cfg_;
  TimeSource& time_;
  std::vector<std::unique_ptr<LastPose>> poses_;  // by Robot::index

  std::mutex tf_mutex_;
  TransformTree transforms_;         // under tf_mutex_
  std::set<std::string> tf_warned_;  // refused transforms already logged, under tf_mutex_
  void on_transforms(const TFMessageMsg& msg, bool is_static);
  // The start from the transforms (robot_pose_source tf).
  void start_from_transforms(const Robot& robot, Job& job);
};

}  // namespace vnsba::node
