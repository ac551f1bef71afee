#include "fleet_router.hpp"

#include <string>
#include <utility>

#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "replier.hpp"
#include "request_admission.hpp"
#include "request_intake.hpp"
#include "vnsba/node/action_catalog.hpp"
#include "vnsba_msgs/msg/PlanRequestPubSubTypes.h"

namespace vnsba::node {

FleetRouter::FleetRouter(const NodeConfig& config, const Fleet& fleet, RequestAdmission& admission,
                         RequestIntake& intake, Replier& replier, const TimeSource& time)
    : cfg_(config),
      admission_(admission),
      intake_(intake),
      replier_(replier),
      time_(time),
      actions_(fleet.size()) {}

FleetRouter::~FleetRouter() = default;

core::Status FleetRouter::add_request_readers(NodeReaders& readers, const Robot& robot) {
  // Taken only while the robot has room for their answers.
  auto has_room = [&intake = intake_, &robot] { return intake.may_take(robot); };
  auto wake = [&intake = intake_] { intake.wake(); };
  RequestAdmission& admission = admission_;
  if (core::Status s = readers.add<geometry_msgs::msg::dds_::PoseStamped_PubSubType>(
          robot.topic(cfg_.topics.goal_pose), reader_qos(TopicQos::kEvents),
          make_intake_listener<PoseStampedMsg>(
              [&admission, &robot](PoseStampedMsg&& m, const dds::SampleInfo& info) {
                admission.on_goal(robot, std::move(m), identity_of(info, wire::SUBJECT_GOAL_POSE));
              },
              has_room, wake),
          &intake_.inputs(robot));
      !s.is_ok())
    return s;
  return readers.add<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(
      robot.topic(cfg_.topics.plan_request), reader_qos(TopicQos::kEvents),
      make_intake_listener<PlanRequestMsg>(
          [&admission, &robot](PlanRequestMsg&& m, const dds::SampleInfo& info) {
            Job job;
            job.id = std::move(m.id());
            job.identity = identity_of(info, wire::SUBJECT_REQUEST);
            job.start = std::move(m.start());
            job.goal = std::move(m.goal());
            job.planner = std::move(m.planner());
            admission.on_request(robot, std::move(job));
          },
          has_room, wake),
      &intake_.inputs(robot));
}

core::Status FleetRouter::add_action_servers(NodeReaders& readers, const ParticipantWatch* vendors,
                                             const Robot& robot) {
  RequestAdmission& admission = admission_;
  RequestIntake& intake = intake_;
  const TimeSource& time = time_;
  for (const Nav2ActionInfo& action : nav2_actions()) {  // one server per registered action
    const ActionKind kind = action.kind;
    const std::string& action_name = cfg_.topics.*action.topic;
    ActionServer::Hooks hooks;
    hooks.on_goal = [&admission, &robot](ActionServer& server, ActionGoal&& goal) {
      admission.on_action_goal(robot, server, std::move(goal));
    };
    hooks.on_cancel = [&admission, &robot](ActionServer& server, const std::vector<GoalUuid>& ids) {
      admission.on_action_cancel(robot, server, ids);
    };
    hooks.may_take = [&intake, &robot] { return intake.may_take(robot); };
    hooks.wake_intake = [&intake] { intake.wake(); };
    hooks.now = [&time] { return time.now(); };
    hooks.accepting = [&admission] { return admission.accepting(); };
    auto server = std::make_unique<ActionServer>(kind, ros_topic_name(robot.cfg, action_name),
                                                 robot.cfg, vendors, replier_.mutex(),
                                                 replier_.wake(), std::move(hooks));
    const core::Status created = readers.add_action_server(*server, intake_.inputs(robot));
    replier_.add_action_server(robot, *server, created.is_ok());
    actions_[robot.index].push_back(std::move(server));
    if (!created.is_ok()) return created;
  }
  return core::Status::ok();
}

void FleetRouter::release() {
  for (auto& servers : actions_) servers.clear();
}

}  // namespace vnsba::node
