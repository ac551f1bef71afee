#include "vnsba/node/requests.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <variant>

#include "vnsba/core/path_poses.hpp"
#include "vnsba/maps/world_text.hpp"

namespace vnsba::node {

namespace {

std::string too_long(const char* field, size_t bytes, size_t limit) {
  return std::string(field) + ": " + std::to_string(bytes) + " bytes, longer than the limit of " +
         std::to_string(limit) + " bytes";
}

// Distance (metres) from (x, y) to the map's rectangle; 0 inside it.
double distance_to_map(const core::GridMap& map, double x, double y) {
  const Eigen::Vector2d lo = map.grid_to_world({0, 0});
  const Eigen::Vector2d hi = map.grid_to_world({double(map.width()), double(map.height())});
  const double dx = std::max({lo.x() - x, 0.0, x - hi.x()});
  const double dy = std::max({lo.y() - y, 0.0, y - hi.y()});
  return std::hypot(dx, dy);
}

}  // namespace

std::string echoed_id(const std::string& id) {
  return id.size() <= kMaxIdBytes ? id : id.substr(0, kMaxIdBytes);
}

namespace {

// The id's and the planner name's lengths, and an empty id: the failure, or nullopt. Sets
// out.invalid_planner when the planner name is at fault (Nav2: INVALID_PLANNER, whatever the
// reason the name is bad).
std::optional<WireStatus> check_id_and_planner_name(const Job& job, ResolvedRequest& out) {
  if (job.id.size() > kMaxIdBytes)
    return WireStatus{wire::INVALID_REQUEST, too_long("id", job.id.size(), kMaxIdBytes)};
  if (job.id.empty()) return WireStatus{wire::INVALID_REQUEST, "id: must not be empty"};
  if (job.planner.size() > kMaxPlannerNameBytes) {
    out.invalid_planner = true;
    return WireStatus{wire::INVALID_REQUEST,
                      too_long("planner", job.planner.size(), kMaxPlannerNameBytes)};
  }
  return std::nullopt;
}

// The lengths of the start's and the goal's frame ids: the failure, or nullopt.
std::optional<WireStatus> check_frame_id_lengths(const Job& job) {
  const std::pair<const char*, const PoseStampedMsg*> poses[] = {{"start", &job.start},
                                                                 {"goal", &job.goal}};
  for (const auto& [field, pose] : poses) {
    const size_t bytes = pose->header().frame_id().size();
    if (bytes > kMaxFrameIdBytes)
      return WireStatus{
          wire::INVALID_REQUEST,
          too_long((std::string(field) + ".header.frame_id").c_str(), bytes, kMaxFrameIdBytes)};
  }
  return std::nullopt;
}

// The planner and its options (out.options, out.planner_name, out.warning): the failure, or
// nullopt. No planner named: the configured one (planner.name, auto's choice included). `auto`:
// auto's rule on the file's keys. A planner: every configured key, the rest that planner's paper
// configuration. An alias (planner.aliases, GridBased by default) names one of these.
std::optional<WireStatus> choose_planner(const Job& job, const NodeConfig& config,
                                         ResolvedRequest& out) {
  std::string planner = job.planner;
  if (const auto target = config.planner.alias_target(planner))
    planner = *target == kDefaultPlannerAlias ? std::string() : *target;
  if (planner.empty()) {
    out.options = config.planner.options();
  } else if (planner == core::kAutoPlannerName) {
    out.options = config.planner.auto_options();
  } else if (const auto requested = core::planner_kind_from_string(planner)) {
    out.options = config.planner.options(*requested);
  } else {
    out.invalid_planner = true;
    std::string known = core::accepted_planner_names();
    for (const auto& [name, target] : config.planner.aliases) known += ", " + name;
    return WireStatus{wire::INVALID_REQUEST, "planner: unknown planner '" + printable(job.planner) +
                                                 "' (known: " + known + ")"};
  }
  out.planner_name = std::string(core::to_string(out.options.planner));
  // jps plans on uniform costs only (its jump rules need every move of a kind to cost the same).
  // A request that picks it on a node configured with costs asked for the shortest path, fast:
  // it gets that, and the status says the costs were not applied. (A config that names jps
  // itself must set cost_weight 0: there the two keys contradict each other.)
  if (const double configured = out.options.cost_weight;
      core::drop_unsupported_costs(out.options)) {
    out.warning = "warning: " + out.planner_name +
                  " plans on uniform cell costs: planner.cost_weight " +
                  maps::short_number(configured) +
                  " not applied (this is the shortest path, not the cheapest: astar plans the "
                  "cheapest)";
  }
  // The configuration is valid for its own planner (checked at load); a request's planner may
  // not accept it (jps with a corner_policy it cannot search with).
  if (core::Status s = core::validate(out.options); !s.is_ok()) {
    out.invalid_planner = true;
    return WireStatus{wire::INVALID_REQUEST,
                      "planner: " + out.planner_name +
                          " cannot plan with the node's planner.* settings: " + s.message};
  }
  out.planner_warning = out.warning;
  return std::nullopt;
}

// The goal's cell on `map` (out of it within goal_tolerance), or the failure.
std::variant<core::Cell, WireStatus> goal_cell_on(const core::GridMap& map, const PoseCheck& goal,
                                                  double goal_tolerance) {
  auto goal_outside = [&] {
    return WireStatus{wire::GOAL_OUTSIDE_MAP,
                      maps::goal_outside_message(map, goal.x, goal.y, goal_tolerance)};
  };
  if (const std::optional<core::Cell> inside = map.world_to_cell(goal.x, goal.y)) return *inside;
  // Outside the map, core may still move the goal onto it within goal_tolerance. A point
  // farther than that from the map has no free cell within reach (and its cell index could
  // overflow), so it is refused here.
  if (!(goal_tolerance > 0.0) || distance_to_map(map, goal.x, goal.y) > goal_tolerance)
    return goal_outside();
  // Within goal_tolerance of the map, but its cell index must also fit an int32: at a
  // resolution below about 1e-7 m, 100 m are more cells than that (the cast would be undefined).
  constexpr double kMaxCellIndex = 1e9;
  const core::Point2 goal_point = map.world_to_grid(goal.x, goal.y);
  if (!(std::abs(goal_point.x()) < kMaxCellIndex && std::abs(goal_point.y()) < kMaxCellIndex)) {
    return WireStatus{wire::GOAL_OUTSIDE_MAP,
                      maps::outside_map_message("goal", map, goal.x, goal.y) +
                          ", more than 1e9 cells of " + maps::short_number(map.resolution()) +
                          " m away (beyond a cell index)"};
  }
  return core::Cell{static_cast<int32_t>(std::floor(goal_point.x())),
                    static_cast<int32_t>(std::floor(goal_point.y()))};
}

// The start and goal of `job` checked and located on `map` (out.query, out.goal_yaw, and the
// orientation's remark appended to out.warning), with the planner's options already in `out`:
// the failure, or nullopt.
std::optional<WireStatus> locate_endpoints(const Job& job, const NodeConfig& config,
                                           const core::GridMap* map, const std::string& map_topic,
                                           ResolvedRequest& out) {
  if (!job.missing_start.empty()) return WireStatus{wire::INVALID_REQUEST, job.missing_start};
  const PoseCheck start = check_pose(job.start, "start", config.frame_id);
  if (!start.status.ok()) return start.status;
  const PoseCheck goal = check_pose(job.goal, "goal", config.frame_id);
  if (!goal.status.ok()) return goal.status;
  if (map == nullptr) {
    return WireStatus{
        wire::NO_MAP,
        "no map has been accepted yet (slices arrive on '" +
            (map_topic.empty() ? dds_topic_name(config, config.topics.projected_map) : map_topic) +
            "')"};
  }
  const auto start_cell = map->world_to_cell(start.x, start.y);
  if (!start_cell) {
    return WireStatus{wire::START_OUTSIDE_MAP,
                      maps::outside_map_message("start", *map, start.x, start.y)};
  }
  const double goal_tolerance = out.options.goal_tolerance;
  const std::variant<core::Cell, WireStatus> goal_cell = goal_cell_on(*map, goal, goal_tolerance);
  if (const WireStatus* refused = std::get_if<WireStatus>(&goal_cell)) return *refused;
  out.query =
      core::PlanQuery(*start_cell, std::get<core::Cell>(goal_cell),
                      map->world_to_grid(start.x, start.y), map->world_to_grid(goal.x, goal.y));
  if (core::Status s = core::check_query(*map, out.query, out.options); !s.is_ok()) {
    // Core names the cell; the node's message gives the point and the map in metres.
    if (s.code == core::StatusCode::kGoalOutsideMap) {
      return WireStatus{wire::GOAL_OUTSIDE_MAP,
                        maps::goal_outside_message(*map, goal.x, goal.y, goal_tolerance)};
    }
    return WireStatus{to_wire_code(s.code), s.message};
  }
  // The final pose takes the goal's orientation when it is a rotation (docs/algorithm.md,
  // section 8).
  const auto& q = job.goal.pose().orientation();
  out.goal_yaw = core::yaw_from_quaternion(q.x(), q.y(), q.z(), q.w());
  if (!out.goal_yaw) {
    const double norm = std::sqrt(q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w());
    out.warning += std::string(out.warning.empty() ? "" : "; ") +
                   "warning: goal orientation ignored: quaternion norm " +
                   maps::short_number(norm) + " is not 1 (the last pose faces along the path)";
  }
  return std::nullopt;
}

}  // namespace

ResolvedRequest resolve_request(const Job& job, const NodeConfig& config, const core::GridMap* map,
                                const std::string& map_topic) {
  ResolvedRequest out;
  std::optional<WireStatus> failure = check_id_and_planner_name(job, out);
  if (!failure) failure = check_frame_id_lengths(job);
  if (!failure) failure = choose_planner(job, config, out);
  if (!failure) failure = locate_endpoints(job, config, map, map_topic, out);
  if (failure) out.status = std::move(*failure);
  return out;
}

ResolvedRequest resolve_leg(const Job& job, const ResolvedRequest& accepted,
                            const NodeConfig& config, const core::GridMap* map,
                            const std::string& map_topic) {
  ResolvedRequest out;
  // In resolve_request's order: the frames' lengths come before the planner is named.
  std::optional<WireStatus> failure = check_frame_id_lengths(job);
  if (!failure) {
    out.planner_name = accepted.planner_name;
    out.options = accepted.options;
    out.planner_warning = accepted.planner_warning;
    out.warning = accepted.planner_warning;
    failure = locate_endpoints(job, config, map, map_topic, out);
  }
  if (failure) out.status = std::move(*failure);
  return out;
}

void RequestQueue::interrupt(Interruption& interruption, const std::string& reason) {
  if (interruption.flag) return;  // the first reason stands
  interruption.reason = reason;
  interruption.flag = true;
}

std::vector<Job> RequestQueue::admit(Job job) {
  std::vector<Job> answer_now;
  auto same_request = [&](const std::string& id, const RequestIdentity& identity) {
    return id == job.id && identity.same_client(job.identity);
  };
  // Room first: a request that is refused replaces and preempts nothing. Waiting requests it
  // would remove (same id, or all with preempt) make room for it.
  size_t staying = 0;
  for (const Job& waiting : queue_)
    staying += !(preempt_ || same_request(waiting.id, waiting.identity));
  if (staying >= capacity_) {
    interrupt(*job.interruption, "request queue is full (requests.queue_capacity = " +
                                     std::to_string(capacity_) + ")");
    answer_now.push_back(std::move(job));
    return answer_now;
  }
  const std::string replaced = "replaced by a newer request with the same id '" +
                               printable(job.id) + "' from the same client";
  const std::string preempted = "preempted by newer request '" + printable(job.id) + "'";
  for (auto it = queue_.begin(); it != queue_.end();) {
    const bool same = same_request(it->id, it->identity);
    if (same || preempt_) {
      interrupt(*it->interruption, same ? replaced : preempted);
      answer_now.push_back(std::move(*it));
      it = queue_.erase(it);
    } else {
      ++it;
    }
  }
  if (current_) {
    const bool same = same_request(current_->id, current_->identity);
    if (same || preempt_) interrupt(*current_->interruption, same ? replaced : preempted);
  }
  queue_.push_back(std::move(job));
  return answer_now;
}

std::optional<Job> RequestQueue::next() {
  if (queue_.empty()) return std::nullopt;
  Job job = std::move(queue_.front());
  queue_.pop_front();
  current_ = Current{job.id, job.identity, job.interruption};
  return job;
}

void RequestQueue::interrupt_current(const std::string& reason) {
  if (current_) interrupt(*current_->interruption, reason);
}

std::vector<Job> RequestQueue::cancel(const std::string& id, const std::string& reason) {
  std::vector<Job> removed;
  for (auto it = queue_.begin(); it != queue_.end();) {
    if (it->id == id) {
      interrupt(*it->interruption, reason);
      removed.push_back(std::move(*it));
      it = queue_.erase(it);
    } else {
      ++it;
    }
  }
  if (current_ && current_->id == id) interrupt(*current_->interruption, reason);
  return removed;
}

}  // namespace vnsba::node
