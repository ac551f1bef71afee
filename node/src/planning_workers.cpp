#include "planning_workers.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "answers.hpp"
#include "debug_publisher.hpp"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "work_queues.hpp"

namespace vnsba::node {

PlanningWorkers::PlanningWorkers(const NodeConfig& config, int workers, const Fleet& fleet,
                                 WorkQueues& queues, const MapInput& maps, Answers& answers,
                                 DebugPublisher& debug, const TimeSource& time)
    : cfg_(config),
      workers_(workers),
      queues_(queues),
      maps_(maps),
      answers_(answers),
      debug_(debug),
      time_(time),
      plan_writers_(fleet.size(), nullptr) {}

core::Status PlanningWorkers::add_plan_writer(Participant& participant, const Robot& robot) {
  auto writer = participant.writer_on<nav_msgs::msg::dds_::Path_PubSubType>(
      robot.topic(cfg_.topics.plan), writer_qos(TopicQos::kLatest, false));
  if (!writer) return writer.error();
  plan_writers_[robot.index] = *writer;
  return core::Status::ok();
}

void PlanningWorkers::start() {
  for (int w = 0; w < workers_; ++w)
    threads_.emplace_back([this, w] { loop(static_cast<size_t>(w)); });
}

void PlanningWorkers::join() {
  for (std::thread& worker : threads_)
    if (worker.joinable()) worker.join();  // answers every queued request first
  threads_.clear();
}

void PlanningWorkers::forget_writers() {
  std::fill(plan_writers_.begin(), plan_writers_.end(), nullptr);
}

size_t PlanningWorkers::plan_readers() const {
  size_t readers = 0;
  for (dds::DataWriter* writer : plan_writers_)
    if (writer != nullptr) readers += static_cast<size_t>(matched_readers(writer));
  return readers;
}

void PlanningWorkers::loop(size_t worker) {
  while (std::optional<WorkQueues::Turn> turn = queues_.next()) {
    const Robot& robot = *turn->robot;
    Job& job = turn->job;
    std::shared_ptr<const ActiveMap> map;
    try {
      handle(robot, job, map, worker);
    } catch (const std::exception& e) {
      // A bug or resource exhaustion, never bad input: the request still gets its one status,
      // the planner is rebuilt (at the next plan on this map), and the node keeps serving.
      spdlog::critical("request '{}'{}: internal error: {}", printable(job.id), robot.label(),
                       e.what());
      if (map && worker < map->planners.size()) map->planners[worker].reset();
      answers_.answer(robot, job,
                      {wire::INTERNAL_ERROR, std::string("internal error: ") + e.what()});
    }
    queues_.finish(robot);
  }
}

void PlanningWorkers::handle(const Robot& robot, Job& job, std::shared_ptr<const ActiveMap>& map,
                             size_t worker) {
  const auto t0 = Clock::now();
  auto reject = [&](const WireStatus& status, const std::string& planner_name = "",
                    const TimeMsg& stamp = TimeMsg()) {
    answers_.answer(robot, job, status, planner_name, nullptr, stamp);
    spdlog::warn("request '{}'{}: {} ({})", printable(job.id), robot.label(),
                 code_name(status.code), status.message);
  };
  if (const std::string interrupted = queues_.interruption(job); !interrupted.empty())
    return reject({wire::CANCELED, interrupted});
  if (job.action) job.action->server->execute(job.action->goal_id);
  map = maps_.current();
  if (!map)
    return reject(
        {wire::NO_MAP, "no map has been accepted yet (slices arrive on '" + maps_.topic() + "')"});
  Leg leg = plan_legs(robot, job, *map, worker);
  if (!leg.planned) return reject(leg.status, leg.planner_name, map->stamp);
  const size_t legs = job.action ? 1 + job.action->more_goals.size() : 1;
  publish(robot, job, leg, legs, *map, t0);
}

ResolvedRequest PlanningWorkers::first_leg(const Robot& robot, const Job& job,
                                           const ActiveMap& map) const {
  if (!job.resolved)
    throw std::logic_error("request '" + printable(job.id) + "' was queued unchecked");
  if (job.resolved_on.lock() == map.grid) return *job.resolved;
  // A newer map than the one the request was accepted on: its cells are that map's.
  return resolve_leg(job, *job.resolved, robot.cfg, map.grid.get(), maps_.topic());
}

PlanningWorkers::Leg PlanningWorkers::plan_legs(const Robot& robot, Job& job, const ActiveMap& map,
                                                size_t worker) {
  Leg leg = plan_leg(robot, job, first_leg(robot, job, map), map, worker);
  if (!leg.planned) return leg;
  // ComputePathThroughPoses: the next legs start where the previous one ended (the goal it
  // actually used) and their paths are joined; the first failure ends the goal with its code.
  const size_t legs = job.action ? 1 + job.action->more_goals.size() : 1;
  core::Metrics total = leg.result.metrics;
  // An action's result carries at most actions.max_result_poses poses.
  const size_t max_poses = static_cast<size_t>(cfg_.actions.max_result_poses);
  auto over_size = [&](size_t leg_number) {
    if (!job.action || !leg.status.ok() || leg.path.poses().size() <= max_poses) return false;
    leg.status = {wire::INVALID_REQUEST,
                  fmt::format("the path has {} poses{}, more than actions.max_result_poses ({})",
                              leg.path.poses().size(),
                              legs > 1 ? fmt::format(" after leg {} of {}", leg_number, legs) : "",
                              max_poses)};
    leg.path = PathMsg();
    return true;
  };
  over_size(1);
  for (size_t k = 1; k < legs && leg.status.ok(); ++k) {
    Job next = job;  // the same id, client, planner, interruption and action
    next.start = leg.path.poses().back();
    next.goal = job.action->more_goals[k - 1];
    Leg following = plan_leg(
        robot, next, resolve_leg(next, *job.resolved, robot.cfg, map.grid.get(), maps_.topic()),
        map, worker);
    total.length_m += following.result.metrics.length_m;
    total.planning_time_us += following.result.metrics.planning_time_us;
    total.expanded += following.result.metrics.expanded;
    total.turns += following.result.metrics.turns;
    total.turn_angle_deg += following.result.metrics.turn_angle_deg;
    total.clearance_m = std::min(total.clearance_m, following.result.metrics.clearance_m);
    if (!following.status.ok()) {
      following.status.message =
          fmt::format("leg {} of {} (to goals[{}]): {}", k + 1, legs, k, following.status.message);
      leg.status = following.status;
      leg.path = PathMsg();
      break;
    }
    auto& poses = leg.path.poses();
    poses.insert(poses.end(), following.path.poses().begin() + 1, following.path.poses().end());
    if (!following.status.message.empty())
      leg.status.message += (leg.status.message.empty() ? "" : "; ") +
                            fmt::format("leg {}: {}", k + 1, following.status.message);
    if (over_size(k + 1)) break;
  }
  if (legs > 1) leg.result.metrics = total;
  return leg;
}

PlanningWorkers::Leg PlanningWorkers::plan_leg(const Robot& robot, Job& job,
                                               ResolvedRequest resolved, const ActiveMap& map,
                                               size_t worker) {
  Leg leg;
  leg.planner_name = resolved.planner_name;
  if (!resolved.status.ok()) {
    if (job.action) job.action->invalid_planner = resolved.invalid_planner;
    leg.status = resolved.status;
    return leg;
  }
  core::PlannerOptions& options = resolved.options;
  // The planners of a map are as many as the workers (MapInput); one is null only after an
  // internal error dropped it (loop).
  std::unique_ptr<core::Planner>& planner = map.planners.at(worker);
  if (!planner) planner = std::make_unique<core::Planner>(map.grid);
  // Recording the expansions costs time and memory: only when something will show them.
  options.record_expansions = debug_.records_expansions(robot);
  leg.result = planner->plan(resolved.query, options, &job.interruption->flag);
  leg.planned = true;
  leg.status = {to_wire_code(leg.result.status.code), leg.result.status.message};
  if (leg.result.status.code == core::StatusCode::kCanceled)
    leg.status.message = queues_.interruption(job);
  if (!leg.status.ok()) return leg;
  // Poses at most planner.path_spacing apart (default: this map's resolution), never finer
  // than min_path_spacing (a bound on the pose count).
  const double resolution = map.grid->resolution();
  const double configured = cfg_.planner.path_spacing_for(resolution);
  const double spacing = std::max(configured, min_path_spacing(resolution));
  std::vector<std::string> remarks;
  if (std::string moved = describe_adjusted_endpoints(leg.result.endpoints, *map.grid, options);
      !moved.empty())
    remarks.push_back(std::move(moved));
  if (!resolved.warning.empty()) remarks.push_back(resolved.warning);
  if (spacing > configured) {
    remarks.push_back(fmt::format(
        "warning: planner.path_spacing {:g} m is finer than {:g} cells at this map's resolution "
        "of {:g} m; poses are {:g} m apart",
        configured, kMinPathSpacingCells, resolution, spacing));
  }
  for (const std::string& remark : remarks)
    leg.status.message += (leg.status.message.empty() ? "" : "; ") + remark;
  leg.path = to_path_msg(leg.result, cfg_.frame_id, time_.now(), spacing, resolved.goal_yaw);
  return leg;
}

void PlanningWorkers::publish(const Robot& robot, const Job& job, Leg& leg, size_t legs,
                              const ActiveMap& map, Clock::time_point t0) {
  const std::string id = printable(job.id);
  const std::string& planner_name = leg.planner_name;
  const core::PlanResult& result = leg.result;
  WireStatus& status = leg.status;
  // The debug layers carry the path's stamp: a client ties them to its plan by it.
  const TimeMsg stamp = status.ok() ? leg.path.header().stamp() : time_.now();
  if (status.ok()) {
    if (!plan_writers_[robot.index]->write(&leg.path))
      spdlog::error("could not publish the path of '{}'{}", id, robot.label());
    ++plans_ok_;
  }
  // The endpoints are the plan's once core resolved them: every outcome but a refusal of the
  // query itself (which resolve_request normally catches first).
  const bool resolved_endpoints =
      legs == 1 && (status.ok() || status.code == wire::NO_VALID_PATH ||
                    status.code == wire::TIMEOUT || status.code == wire::CANCELED);
  answers_.answer(robot, job, status, planner_name, &result.metrics, map.stamp, std::move(leg.path),
                  resolved_endpoints ? &result.endpoints : nullptr, map.grid.get());
  debug_.publish(robot, job.id, result, *map.grid, stamp);
  const auto total_us =
      std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - t0).count();
  spdlog::log(status.ok() ? spdlog::level::info : spdlog::level::warn,
              "plan '{}'{} {} {}: length {:.2f} m, clearance {:.3f} m, {} turns, {:.1f} deg, {} "
              "expanded, {} us planning, {} us total{}{}",
              id, robot.label(), planner_name, code_name(status.code), result.metrics.length_m,
              result.metrics.clearance_m, result.metrics.turns, result.metrics.turn_angle_deg,
              result.metrics.expanded, result.metrics.planning_time_us, total_us,
              status.message.empty() ? "" : ": ", status.message);
}

}  // namespace vnsba::node
