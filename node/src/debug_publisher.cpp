#include "debug_publisher.hpp"

#include <spdlog/spdlog.h>

#include "geometry_msgs/msg/PointStampedPubSubTypes.h"
#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "vnsba/node/requests.hpp"
#include "vnsba_msgs/msg/PlannerDebugPubSubTypes.h"

namespace vnsba::node {

DebugPublisher::DebugPublisher(const NodeConfig& config, const Fleet& fleet)
    : cfg_(config), writers_(fleet.size()) {}

template <class PubSubType>
core::Status DebugPublisher::add_layer(Participant& participant, const Robot& robot,
                                       const std::string& topic, dds::DataWriter*& out) {
  auto writer =
      participant.writer_on<PubSubType>(robot.topic(topic), writer_qos(TopicQos::kLatched, true));
  if (!writer) return writer.error();
  out = *writer;
  return core::Status::ok();
}

core::Status DebugPublisher::add_writers(Participant& participant, const Robot& robot) {
  // debug.publish: never creates no debug endpoint at all (a fleet's discovery traffic).
  if (cfg_.debug == DebugPublishing::kNever) return core::Status::ok();
  using PathType = nav_msgs::msg::dds_::Path_PubSubType;
  using GridType = nav_msgs::msg::dds_::OccupancyGrid_PubSubType;
  Writers& writers = writers_[robot.index];
  auto debug = participant.writer_on<vnsba_msgs::msg::dds_::PlannerDebug_PubSubType>(
      robot.topic(cfg_.topics.planner_debug), writer_qos(TopicQos::kDebug, true));
  if (!debug) return debug.error();
  writers.debug = *debug;
  // In order, stopping at the first failure.
  core::Status layers =
      add_layer<PathType>(participant, robot, cfg_.topics.plan_raw, writers.raw_path);
  if (layers.is_ok())
    layers = add_layer<PathType>(participant, robot, cfg_.topics.plan_pruned, writers.pruned_path);
  if (layers.is_ok())
    layers = add_layer<GridType>(participant, robot, cfg_.topics.expansions_forward,
                                 writers.expansions_forward);
  if (layers.is_ok())
    layers = add_layer<GridType>(participant, robot, cfg_.topics.expansions_backward,
                                 writers.expansions_backward);
  if (layers.is_ok())
    layers = add_layer<geometry_msgs::msg::dds_::PointStamped_PubSubType>(
        participant, robot, cfg_.topics.meeting_point, writers.meeting_point);
  return layers;
}

void DebugPublisher::forget_writers() {
  for (Writers& writers : writers_) writers = Writers();
}

bool DebugPublisher::publishing(dds::DataWriter* writer) const {
  if (writer == nullptr) return false;  // not created (debug.publish: never)
  switch (cfg_.debug) {
    case DebugPublishing::kAlways:
      return true;
    case DebugPublishing::kNever:
      return false;
    case DebugPublishing::kAuto:
      return matched_readers(writer) > 0;
  }
  return false;
}

bool DebugPublisher::records_expansions(const Robot& robot) const {
  const Writers& writers = writers_[robot.index];
  return publishing(writers.debug) || publishing(writers.expansions_forward) ||
         publishing(writers.expansions_backward);
}

void DebugPublisher::publish(const Robot& robot, const std::string& id,
                             const core::PlanResult& result, const core::GridMap& map,
                             const TimeMsg& stamp) {
  const Writers& writers = writers_[robot.index];
  const std::string& frame = cfg_.frame_id;
  auto write = [&](dds::DataWriter* writer, auto&& msg, const char* what) {
    if (!writer->write(&msg))
      spdlog::warn("could not publish the {} of '{}'{}", what, printable(id), robot.label());
  };
  if (result.metrics.expanded > 0 && publishing(writers.debug))
    write(writers.debug, to_debug_msg(echoed_id(id), result, map, frame, stamp), "debug");
  if (!result.raw_path.empty() && publishing(writers.raw_path))
    write(writers.raw_path, to_raw_path_msg(result, map, frame, stamp), "raw path");
  if (!result.waypoints.empty() && publishing(writers.pruned_path))
    write(writers.pruned_path, to_pruned_path_msg(result, map, frame, stamp), "pruned path");
  if (result.metrics.expanded > 0 && publishing(writers.expansions_forward))
    write(writers.expansions_forward, to_expansions_msg(result.expanded_forward, map, frame, stamp),
          "forward expansions");
  if (result.metrics.expanded > 0 && publishing(writers.expansions_backward))
    write(writers.expansions_backward,
          to_expansions_msg(result.expanded_backward, map, frame, stamp), "backward expansions");
  if (result.meeting_cell && publishing(writers.meeting_point))
    write(writers.meeting_point, to_point_msg(*result.meeting_cell, map, frame, stamp),
          "meeting point");
}

}  // namespace vnsba::node
