#include "answers.hpp"

#include <algorithm>
#include <utility>

#include "replier.hpp"
#include "request_intake.hpp"

namespace vnsba::node {

Answers::Answers(const Fleet& fleet, Replier& replier, RequestIntake& intake)
    : fleet_(fleet), replier_(replier), intake_(intake) {}

void Answers::answer(const Robot& robot, const Job& job, const WireStatus& status,
                     const std::string& planner, const core::Metrics* metrics,
                     const TimeMsg& map_stamp, PathMsg path, const core::Endpoints* endpoints,
                     const core::GridMap* map) {
  if (job.action) return finish_action(robot, job, status, metrics, std::move(path));
  PlanStatusMsg msg = to_status_msg(echoed_id(job.id), &job.identity, status, planner, metrics,
                                    map_stamp, std::move(path), endpoints, map);
  // A plan_request's client is waited for; goal_pose goals (rviz2) have no status reader.
  std::optional<GuidPrefix> requester;
  if (job.identity.subject == wire::SUBJECT_REQUEST) {
    requester.emplace();
    std::copy_n(job.identity.writer_guid.begin(), requester->size(), requester->begin());
  }
  replier_.hold(robot, std::move(msg), "request '" + printable(job.id) + "'" + robot.label(),
                /*is_answer=*/true, requester);
  ++published_;
}

void Answers::abort_goal(const Robot& robot, ActionServer& server, const GoalUuid& id,
                         ActionOutcome outcome) {
  server.execute(id);  // rcl_action: ACCEPTED -> EXECUTING -> ABORTED
  server.finish(id, std::move(outcome));
  intake_.answered(robot);
  ++published_;
}

void Answers::finish_action(const Robot& robot, const Job& job, const WireStatus& status,
                            const core::Metrics* metrics, PathMsg path) {
  ActionServer& server = *job.action->server;
  ActionOutcome outcome;
  if (status.ok()) {
    outcome.state = GoalState::kSucceeded;
  } else if (status.code == wire::CANCELED && server.canceling(job.action->goal_id)) {
    outcome.state = GoalState::kCanceled;  // the client asked; otherwise (preempted, shutdown)
  } else {                                 // the goal is aborted, as Nav2's servers do
    outcome.state = GoalState::kAborted;
    server.execute(job.action->goal_id);  // rcl_action: from ACCEPTED only through EXECUTING
  }
  outcome.error_code = nav2_error_code(server.kind(), status.code, job.action->invalid_planner);
  if (!status.ok() && job.action->tf_problem)
    outcome.error_code = nav2_error_code(server.kind(), wire::FRAME_MISMATCH, false);
  // A success carries no error_msg, as Nav2's planner server's: what the plan's status message
  // says beside it (a goal moved by goal_tolerance, costs not applied) is in the log line of
  // the plan (PlanningWorkers) and on plan_status for plan_request clients.
  if (!status.ok()) outcome.error_msg = status.message;
  if (outcome.state == GoalState::kCanceled) outcome.error_code = 0;
  if (metrics != nullptr) outcome.planning_time_s = metrics->planning_time_us / 1e6;
  outcome.path = std::move(path);
  server.finish(job.action->goal_id, std::move(outcome));
  intake_.answered(robot);
  intake_.resume(robot);
  ++published_;
}

void Answers::report_map(const WireStatus& status, const TimeMsg& map_stamp) {
  // The map is every robot's: each robot's tools see the report.
  for (const Robot& robot : fleet_)
    replier_.hold(robot, to_status_msg("", nullptr, status, "", nullptr, map_stamp, PathMsg()),
                  "a slice" + robot.label(), /*is_answer=*/false);
}

}  // namespace vnsba::node
