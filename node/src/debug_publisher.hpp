// What a plan looked like inside, for rviz2 and vnsba_recorder: planner_debug (vnsba_msgs) and
// the debug layers in stock ROS 2 types (the raw and pruned paths, both directions'
// expansions, the meeting point), each robot on its own topics. debug.publish: always, never
// (no debug endpoint at all: a fleet's discovery traffic), or auto (while a reader is matched).
#pragma once

#include <string>
#include <vector>

#include "fleet.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/node/dds.hpp"

namespace vnsba::node {

class DebugPublisher {
 public:
  DebugPublisher(const NodeConfig& config, const Fleet& fleet);
  DebugPublisher(const DebugPublisher&) = delete;
  DebugPublisher& operator=(const DebugPublisher&) = delete;

  // `robot`'s debug writer and layers, in order, stopping at the first failure; none with
  // debug.publish: never.
  core::Status add_writers(Participant& participant, const Robot& robot);
  // Whether a plan of `robot` should record its expansions (costly in time and memory): only
  // when something will show them.
  bool records_expansions(const Robot& robot) const;
  // The debug of plan `id` of `robot` on `map`, stamped `stamp` (the path's: a client ties them
  // to its plan by it).
  void publish(const Robot& robot, const std::string& id, const core::PlanResult& result,
               const core::GridMap& map, const TimeMsg& stamp);
  // Once the participant is gone.
  void forget_writers();

 private:
  // Null when not created (debug.publish: never).
  struct Writers {
    dds::DataWriter* debug = nullptr;
    dds::DataWriter* raw_path = nullptr;
    dds::DataWriter* pruned_path = nullptr;
    dds::DataWriter* expansions_forward = nullptr;
    dds::DataWriter* expansions_backward = nullptr;
    dds::DataWriter* meeting_point = nullptr;
  };
  const NodeConfig& cfg_;
  std::vector<Writers> writers_;  // by Robot::index

  // Whether to publish on `writer` now (debug.publish: auto = while a reader is matched).
  bool publishing(dds::DataWriter* writer) const;
  // A debug layer: transient local, keep last 1, so that an rviz2 display opened after a run
  // still shows it, whatever durability it asks for.
  template <class PubSubType>
  core::Status add_layer(Participant& participant, const Robot& robot, const std::string& topic,
                         dds::DataWriter*& out);
};

}  // namespace vnsba::node
