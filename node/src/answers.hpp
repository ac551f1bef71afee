// A request's one answer, whatever its interface: a PlanStatus on its robot's plan_status topic
// (held by the replier until its requester can read it), or a Nav2 action goal's result; and a
// report about a slice (SUBJECT_MAP) on every robot's status topic. Every answer given tells
// the intake that the robot owes one less.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "action_server.hpp"
#include "fleet.hpp"
#include "vnsba/node/requests.hpp"

namespace vnsba::node {

class Replier;
class RequestIntake;

class Answers {
 public:
  Answers(const Fleet& fleet, Replier& replier, RequestIntake& intake);
  Answers(const Answers&) = delete;
  Answers& operator=(const Answers&) = delete;

  // `job`'s one answer, on its robot's status topic or its action. `endpoints` and `map`, when
  // given, are the start and goal the plan used (see to_status_msg).
  void answer(const Robot& robot, const Job& job, const WireStatus& status,
              const std::string& planner = "", const core::Metrics* metrics = nullptr,
              const TimeMsg& map_stamp = TimeMsg(), PathMsg path = PathMsg(),
              const core::Endpoints* endpoints = nullptr, const core::GridMap* map = nullptr);
  // An action goal refused before it became a request (Nav2's own codes: no poses, too many):
  // EXECUTING, then ended with `outcome`.
  void abort_goal(const Robot& robot, ActionServer& server, const GoalUuid& id,
                  ActionOutcome outcome);
  // A report about a slice (SUBJECT_MAP), on every robot's status topic.
  void report_map(const WireStatus& status, const TimeMsg& map_stamp);

  // Request statuses and action results given (not map reports).
  uint64_t published() const { return published_; }

 private:
  const Fleet& fleet_;
  Replier& replier_;
  RequestIntake& intake_;
  std::atomic<uint64_t> published_{0};

  // An action goal's one result, instead of a plan_status.
  void finish_action(const Robot& robot, const Job& job, const WireStatus& status,
                     const core::Metrics* metrics, PathMsg path);
};

}  // namespace vnsba::node
