#include "request_admission.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <utility>

#include "answers.hpp"
#include "map_input.hpp"
#include "request_intake.hpp"
#include "robot_poses.hpp"
#include "vnsba/node/action_catalog.hpp"
#include "work_queues.hpp"

namespace vnsba::node {

namespace {

// The queue's id of an action goal: the action and the goal's id, whatever the namespace (a
// long namespace once made it longer than a request id may be, and every goal failed).
std::string action_job_id(const ActionServer& server, const GoalUuid& id) {
  return std::string(nav2_action(server.kind()).id_name) + ":" + uuid_text(id);
}

// The fewest poses a path through `goals` from `start` can have at `spacing` metres: the straight
// lines between them (a path is never shorter), one pose per spacing and one at each end.
double fewest_path_poses(const std::vector<PoseStampedMsg>& goals, const PoseStampedMsg* start,
                         double spacing) {
  double length = 0.0;
  const PoseStampedMsg* from = start;
  for (const PoseStampedMsg& to : goals) {
    if (from != nullptr) {
      const double dx = to.pose().position().x() - from->pose().position().x();
      const double dy = to.pose().position().y() - from->pose().position().y();
      if (std::isfinite(dx) && std::isfinite(dy)) length += std::hypot(dx, dy);
    }
    from = &to;
  }
  return std::floor(length / spacing) + 1.0;
}

}  // namespace

RequestAdmission::RequestAdmission(const NodeConfig& config, const Fleet& fleet,
                                   RequestIntake& intake, MapInput& maps, WorkQueues& queues,
                                   RobotPoses& poses, Answers& answers)
    : cfg_(config),
      intake_(intake),
      maps_(maps),
      queues_(queues),
      poses_(poses),
      answers_(answers),
      goals_(fleet.size()) {}

void RequestAdmission::on_request(const Robot& robot, Job job) {
  ++received_;
  intake_.taken(robot);  // until its status is handed to DDS (Replier)
  submit(robot, std::move(job));
}

void RequestAdmission::on_goal(const Robot& robot, PoseStampedMsg&& goal,
                               const RequestIdentity& identity) {
  Job job;
  job.id = "goal-" + std::to_string(++goals_[robot.index]);
  job.identity = identity;
  job.goal = std::move(goal);
  poses_.start_of(robot, job);
  on_request(robot, std::move(job));
}

std::string RequestAdmission::goal_refusal(const ActionGoal& goal) const {
  const size_t poses = goal.goals.size();
  const size_t max_poses = static_cast<size_t>(cfg_.actions.max_goal_poses);
  if (poses == 0) return "goals: empty (NO_VIAPOINTS_GIVEN)";
  if (poses > max_poses) {
    return "goals: found " + std::to_string(poses) + " poses, expected at most " +
           std::to_string(max_poses) + " (actions.max_goal_poses)";
  }
  const std::shared_ptr<const ActiveMap> map = maps_.current();
  if (!map) return "";
  // A result that cannot fit actions.max_result_poses is refused before any planning.
  const double spacing = std::max(cfg_.planner.path_spacing_for(map->grid->resolution()),
                                  min_path_spacing(map->grid->resolution()));
  const double fewest =
      fewest_path_poses(goal.goals, goal.use_start ? &goal.start : nullptr, spacing);
  if (!(fewest > cfg_.actions.max_result_poses)) return "";
  return fmt::format(
      "goals: a path through them needs at least {:.0f} poses at {:g} m apart (the straight "
      "lines between them), more than actions.max_result_poses ({})",
      fewest, spacing, cfg_.actions.max_result_poses);
}

void RequestAdmission::on_action_goal(const Robot& robot, ActionServer& server, ActionGoal&& goal) {
  Job job;
  job.id = action_job_id(server, goal.id);
  job.identity = goal.identity;
  job.planner = std::move(goal.planner_id);
  job.action = std::make_shared<ActionJob>();
  job.action->server = &server;
  job.action->goal_id = goal.id;
  ++received_;
  intake_.taken(robot);  // until its result is stored (Answers)
  // Checked before the request rules: Nav2's own codes for these.
  if (const std::string refused = goal_refusal(goal); !refused.empty()) {
    ActionOutcome outcome;
    outcome.state = GoalState::kAborted;
    outcome.error_code = goal.goals.empty()
                             ? kNoViapointsGiven
                             : nav2_error_code(server.kind(), wire::INVALID_REQUEST, false);
    outcome.error_msg = refused;
    spdlog::warn("goal '{}'{}: ABORTED ({})", job.id, robot.label(), outcome.error_msg);
    answers_.abort_goal(robot, server, goal.id, std::move(outcome));
    return;
  }
  job.goal = std::move(goal.goals.front());
  job.action->more_goals.assign(std::make_move_iterator(goal.goals.begin() + 1),
                                std::make_move_iterator(goal.goals.end()));
  if (goal.use_start) {
    job.start = std::move(goal.start);
  } else {
    poses_.start_of(robot, job);  // robot_pose_source: the topic or tf
    job.action->tf_problem =
        !job.missing_start.empty() && cfg_.robot_pose_source == RobotPoseSource::kTf;
  }
  submit(robot, std::move(job));
}

void RequestAdmission::on_action_cancel(const Robot& robot, ActionServer& server,
                                        const std::vector<GoalUuid>& ids) {
  const std::string reason = "canceled by its client";
  std::vector<std::string> job_ids;
  for (const GoalUuid& id : ids) job_ids.push_back(action_job_id(server, id));
  std::vector<Job> removed = queues_.cancel(robot, job_ids, reason);
  // A goal still waiting for the first map.
  std::vector<Job> waiting = maps_.take_waiting(robot, [&](const Job& job) {
    return job.action && job.action->server == &server &&
           std::find(ids.begin(), ids.end(), job.action->goal_id) != ids.end();
  });
  for (Job& job : waiting) removed.push_back(std::move(job));
  for (const Job& job : removed) {
    spdlog::info("goal '{}'{}: CANCELED ({})", job.id, robot.label(), reason);
    answers_.answer(robot, job, {wire::CANCELED, reason});
  }
}

void RequestAdmission::submit(const Robot& robot, Job job) {
  if (intake_.refusing()) {
    spdlog::info("request '{}'{}: CANCELED (node is shutting down)", printable(job.id),
                 robot.label());
    answers_.answer(robot, job, {wire::CANCELED, "node is shutting down"});
    return;
  }
  if (!accepting_) {
    const std::string why =
        "the node is inactive (lifecycle: managed; activate it with change_state to plan)";
    spdlog::info("request '{}'{}: NODE_INACTIVE", printable(job.id), robot.label());
    answers_.answer(robot, job, {wire::NODE_INACTIVE, why});
    return;
  }
  // Checked before it may touch anything: only a request that would be planned preempts,
  // replaces or queues (see requests.hpp). Checked once: the worker plans it as resolved here.
  const MapInput::ForRequest found = maps_.map_for(robot, job);
  if (found.waits) return;  // before the first map: MapInput hands it on when one comes
  const std::shared_ptr<const ActiveMap>& map = found.map;
  ResolvedRequest resolved =
      resolve_request(job, robot.cfg, map ? map->grid.get() : nullptr, maps_.topic());
  if (!resolved.status.ok()) {
    if (job.action) job.action->invalid_planner = resolved.invalid_planner;
    spdlog::warn("request '{}'{}: {} ({})", printable(job.id), robot.label(),
                 code_name(resolved.status.code), resolved.status.message);
    answers_.answer(robot, job, resolved.status, resolved.planner_name, nullptr,
                    map ? map->stamp : TimeMsg());
    return;
  }
  job.resolved = std::make_shared<const ResolvedRequest>(std::move(resolved));
  job.resolved_on = map->grid;
  // Writers are thread-safe; these answers do not wait for the worker.
  // Out of the queue, nobody else reads or writes these any more: no lock for their reasons.
  for (const Job& old : queues_.admit(robot, std::move(job))) {
    spdlog::info("request '{}'{}: CANCELED ({})", printable(old.id), robot.label(),
                 old.interruption->reason);
    answers_.answer(robot, old, {wire::CANCELED, old.interruption->reason});
  }
}

}  // namespace vnsba::node
