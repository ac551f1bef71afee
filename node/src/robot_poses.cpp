#include "robot_poses.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <utility>

#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "geometry_msgs/msg/PoseWithCovarianceStampedPubSubTypes.h"
#include "rosgraph_msgs/msg/ClockPubSubTypes.h"
#include "tf2_msgs/msg/TFMessagePubSubTypes.h"

namespace vnsba::node {

RobotPoses::RobotPoses(const NodeConfig& config, const Fleet& fleet, TimeSource& time)
    : cfg_(config), time_(time) {
  for (size_t i = 0; i < fleet.size(); ++i) poses_.push_back(std::make_unique<LastPose>());
}

core::Status RobotPoses::add_clock_reader(NodeReaders& readers) {
  if (!cfg_.use_sim_time) return core::Status::ok();
  return readers.add<rosgraph_msgs::msg::dds_::Clock_PubSubType>(
      dds_topic_name(cfg_, cfg_.topics.clock), reader_qos(TopicQos::kStream),
      make_listener<ClockMsg>([this](ClockMsg&& m, const dds::SampleInfo&) {
        // A clock gone back (a simulation reset): transforms stamped in the old timeline
        // would all be "from the future", so they go, as in ROS.
        if (time_.set_sim_time(m.clock()) == ClockUpdate::kJumpedBack) {
          std::lock_guard<std::mutex> lock(tf_mutex_);
          transforms_.clear_dynamic();
        }
      }));
}

core::Status RobotPoses::add_transform_readers(NodeReaders& readers) {
  if (cfg_.robot_pose_source != RobotPoseSource::kTf) return core::Status::ok();
  for (const bool is_static : {true, false}) {
    if (core::Status s = readers.add<tf2_msgs::msg::dds_::TFMessage_PubSubType>(
            dds_topic_name(cfg_, is_static ? cfg_.topics.tf_static : cfg_.topics.tf),
            reader_qos(is_static ? TopicQos::kStatic : TopicQos::kStream),
            make_listener<TFMessageMsg>(
                [this, is_static](TFMessageMsg&& m, const dds::SampleInfo&) {
                  on_transforms(m, is_static);
                }));
        !s.is_ok())
      return s;
  }
  return core::Status::ok();
}

core::Status RobotPoses::add_pose_reader(NodeReaders& readers, const Robot& robot) {
  // With robot_pose_source tf the transforms give every robot's pose.
  if (cfg_.robot_pose_source == RobotPoseSource::kTf) return core::Status::ok();
  LastPose& last = *poses_[robot.index];
  if (cfg_.robot_pose_type == RobotPoseType::kPoseWithCovarianceStamped) {
    return readers.add<geometry_msgs::msg::dds_::PoseWithCovarianceStamped_PubSubType>(
        robot.topic(cfg_.topics.robot_pose), reader_qos(TopicQos::kLatest),
        make_listener<PoseWithCovarianceStampedMsg>(
            [&last](PoseWithCovarianceStampedMsg&& m, const dds::SampleInfo&) {
              std::lock_guard<std::mutex> lock(last.mutex);
              last.pose = to_pose_stamped(m);
            }));
  }
  return readers.add<geometry_msgs::msg::dds_::PoseStamped_PubSubType>(
      robot.topic(cfg_.topics.robot_pose), reader_qos(TopicQos::kLatest),
      make_listener<PoseStampedMsg>([&last](PoseStampedMsg&& m, const dds::SampleInfo&) {
        std::lock_guard<std::mutex> lock(last.mutex);
        last.pose = std::move(m);
      }));
}

void RobotPoses::start_of(const Robot& robot, Job& job) {
  if (cfg_.robot_pose_source != RobotPoseSource::kTopic) return start_from_transforms(robot, job);
  LastPose& last = *poses_[robot.index];
  std::lock_guard<std::mutex> lock(last.mutex);
  if (last.pose) {
    job.start = *last.pose;
  } else {
    job.missing_start =
        "start: no robot_pose received yet on '" + robot.topic(cfg_.topics.robot_pose) + "'";
  }
}

std::optional<Eigen::Vector2d> RobotPoses::position_of(const Robot& robot) {
  Job job;
  start_of(robot, job);
  if (!job.missing_start.empty()) return std::nullopt;
  const PoseCheck pose = check_pose(job.start, "robot_pose", cfg_.frame_id);
  if (!pose.status.ok()) return std::nullopt;
  return Eigen::Vector2d(pose.x, pose.y);
}

void RobotPoses::start_from_transforms(const Robot& robot, Job& job) {
  TransformTree::Lookup found;
  {
    std::lock_guard<std::mutex> lock(tf_mutex_);
    found = transforms_.lookup(cfg_.frame_id, robot.base_frame, time_.now_seconds(),
                               cfg_.transform_tolerance_s);
  }
  if (!found.ok) {
    job.missing_start = "start (robot_pose_source tf, '" + dds_topic_name(cfg_, cfg_.topics.tf) +
                        "' and '" + dds_topic_name(cfg_, cfg_.topics.tf_static) +
                        "'): " + found.problem;
    return;
  }
  const Eigen::Vector3d t = found.source_in_target.translation();
  const Eigen::Quaterniond q(found.source_in_target.rotation());
  job.start.header().frame_id(cfg_.frame_id);
  job.start.header().stamp(time_.now());
  job.start.pose().position().x(t.x());
  job.start.pose().position().y(t.y());
  job.start.pose().position().z(t.z());
  job.start.pose().orientation().x(q.x());
  job.start.pose().orientation().y(q.y());
  job.start.pose().orientation().z(q.z());
  job.start.pose().orientation().w(q.w());
}

void RobotPoses::on_transforms(const TFMessageMsg& msg, bool is_static) {
  std::vector<std::string> refused;
  {
    std::lock_guard<std::mutex> lock(tf_mutex_);
    refused = add_transforms(msg, is_static, transforms_);
    // Each distinct problem once (a broadcaster repeats a bad transform at its rate), and a
    // bounded number of them.
    refused.erase(std::remove_if(refused.begin(), refused.end(),
                                 [&](const std::string& problem) {
                                   return tf_warned_.size() >= 100 ||
                                          !tf_warned_.insert(problem).second;
                                 }),
                  refused.end());
  }
  for (const std::string& problem : refused)
    spdlog::warn("'{}': refused {}",
                 dds_topic_name(cfg_, is_static ? cfg_.topics.tf_static : cfg_.topics.tf), problem);
}

}  // namespace vnsba::node
