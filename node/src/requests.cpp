#include "vnsba/node/requests.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace vnsba::node {

namespace {

std::string too_long(const char* field, size_t bytes, size_t limit) {
  return std::string(field) + ": " + std::to_string(bytes) + " bytes, longer than the limit of " +
         std::to_string(limit) + " bytes";
}

// Metres to the millimetre, as map bounds are given; %g beyond 1e9 m, so that any magnitude
// fits (a fixed 96-byte buffer once cut 1e300 off mid-number).
std::string metres(double v) {
  char text[64];
  std::snprintf(text, sizeof(text), std::abs(v) < 1e9 ? "%.3f" : "%.6g", v);
  return text;
}

std::string format_position(const char* which, double x, double y) {
  return std::string(which) + " (" + metres(x) + ", " + metres(y) + ") m";
}

std::string describe_world_bounds(const core::GridMap& map) {
  const Eigen::Vector2d lo = map.grid_to_world({0, 0});
  const Eigen::Vector2d hi = map.grid_to_world({double(map.width()), double(map.height())});
  return "[" + metres(lo.x()) + ", " + metres(hi.x()) + "] x [" + metres(lo.y()) + ", " +
         metres(hi.y()) + "] m";
}

}  // namespace

std::string echoed_id(const std::string& id) {
  return id.size() <= kMaxIdBytes ? id : id.substr(0, kMaxIdBytes);
}

ResolvedRequest resolve_request(const Job& job, const NodeConfig& config,
                                const core::GridMap* map) {
  ResolvedRequest out;
  auto fail = [&](uint8_t code, std::string message) {
    out.status = {code, std::move(message)};
    return out;
  };
  if (job.id.size() > kMaxIdBytes)
    return fail(wire::INVALID_REQUEST, too_long("id", job.id.size(), kMaxIdBytes));
  if (job.id.empty()) return fail(wire::INVALID_REQUEST, "id: must not be empty");
  if (job.planner.size() > kMaxPlannerNameBytes) {
    return fail(wire::INVALID_REQUEST,
                too_long("planner", job.planner.size(), kMaxPlannerNameBytes));
  }
  const std::pair<const char*, const PoseStampedMsg*> poses[] = {{"start", &job.start},
                                                                 {"goal", &job.goal}};
  for (const auto& [field, pose] : poses) {
    const size_t bytes = pose->header().frame_id().size();
    if (bytes > kMaxFrameIdBytes) {
      return fail(wire::INVALID_REQUEST, too_long((std::string(field) + ".header.frame_id").c_str(),
                                                  bytes, kMaxFrameIdBytes));
    }
  }
  core::PlannerKind kind = config.planner.kind;
  if (!job.planner.empty()) {
    const auto requested = core::planner_kind_from_string(job.planner);
    if (!requested) {
      std::string known;
      for (core::PlannerKind k : core::all_planner_kinds())
        known += (known.empty() ? "" : ", ") + std::string(core::to_string(k));
      return fail(wire::INVALID_REQUEST, "planner: unknown planner '" + printable(job.planner) +
                                             "' (known: " + known + ")");
    }
    kind = *requested;
  }
  // Every configured planner key, whichever planner runs; the rest is that planner's paper
  // configuration.
  out.options = config.planner.options(kind);
  out.planner_name = std::string(core::to_string(out.options.planner));
  if (!job.missing_start.empty()) return fail(wire::INVALID_REQUEST, job.missing_start);
  const PoseCheck start = check_pose(job.start, "start", config.frame_id);
  if (!start.status.ok()) return fail(start.status.code, start.status.message);
  const PoseCheck goal = check_pose(job.goal, "goal", config.frame_id);
  if (!goal.status.ok()) return fail(goal.status.code, goal.status.message);
  if (map == nullptr) {
    return fail(wire::NO_MAP, "no map has been accepted yet (slices arrive on '" +
                                  dds_topic_name(config, config.topics.projected_map) + "')");
  }
  const auto start_cell = map->world_to_cell(start.x, start.y);
  if (!start_cell) {
    return fail(wire::START_OUTSIDE_MAP, format_position("start", start.x, start.y) +
                                             " is outside the map " + describe_world_bounds(*map));
  }
  const auto goal_cell = map->world_to_cell(goal.x, goal.y);
  if (!goal_cell) {
    return fail(wire::GOAL_OUTSIDE_MAP, format_position("goal", goal.x, goal.y) +
                                            " is outside the map " + describe_world_bounds(*map));
  }
  out.query = {*start_cell, *goal_cell};
  if (core::Status s = core::check_query(*map, out.query, out.options); !s.is_ok())
    return fail(to_wire_code(s.code), s.message);
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

}  // namespace vnsba::node
