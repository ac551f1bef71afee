// The planning workers: the only threads that plan. Each takes the next request from the work
// queues (work_queues.hpp), plans it on the active map with its own core::Planner of that map,
// publishes the path on its robot's `plan` topic, answers it (answers.hpp) and publishes its
// debug (debug_publisher.hpp). A request is planned as it was accepted (Job::resolved): its
// planner is not chosen again, and its endpoints are located again only on a newer map than
// the one it was accepted on. A ComputePathThroughPoses goal is planned leg by leg.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "fleet.hpp"
#include "map_input.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/requests.hpp"
#include "vnsba/node/time_source.hpp"

namespace vnsba::node {

class Answers;
class DebugPublisher;
class WorkQueues;

class PlanningWorkers {
 public:
  using Clock = std::chrono::steady_clock;

  PlanningWorkers(const NodeConfig& config, int workers, const Fleet& fleet, WorkQueues& queues,
                  const MapInput& maps, Answers& answers, DebugPublisher& debug,
                  const TimeSource& time);
  PlanningWorkers(const PlanningWorkers&) = delete;
  PlanningWorkers& operator=(const PlanningWorkers&) = delete;

  // `robot`'s plan writer.
  core::Status add_plan_writer(Participant& participant, const Robot& robot);
  void start();
  // After WorkQueues::stop(): each worker answers its robot's queued requests first.
  void join();
  // Once the participant is gone.
  void forget_writers();

  uint64_t plans_ok() const { return plans_ok_; }
  // Readers matched by the `plan` writers.
  size_t plan_readers() const;

 private:
  // One plan (a request, or one leg of a ComputePathThroughPoses goal) on a map.
  struct Leg {
    WireStatus status;
    std::string planner_name;
    core::PlanResult result;
    PathMsg path;          // set when status is OK
    bool planned = false;  // false: refused by its checks (result is empty)
  };

  const NodeConfig& cfg_;
  const int workers_;
  WorkQueues& queues_;
  const MapInput& maps_;
  Answers& answers_;
  DebugPublisher& debug_;
  const TimeSource& time_;
  std::vector<dds::DataWriter*> plan_writers_;  // by Robot::index
  std::vector<std::thread> threads_;
  std::atomic<uint64_t> plans_ok_{0};

  void loop(size_t worker);
  // Plans one job with the worker's planner; `map` is set to the map it plans on (the worker
  // drops its planner when the plan throws).
  void handle(const Robot& robot, Job& job, std::shared_ptr<const ActiveMap>& map, size_t worker);
  // The request's legs on `map`, joined; refused (not planned) when its first leg is.
  Leg plan_legs(const Robot& robot, Job& job, const ActiveMap& map, size_t worker);
  // The request's first leg as it was accepted; located again only on a newer map.
  ResolvedRequest first_leg(const Robot& robot, const Job& job, const ActiveMap& map) const;
  // One leg of `job` as `resolved` says, with the worker's planner of `map`.
  Leg plan_leg(const Robot& robot, Job& job, ResolvedRequest resolved, const ActiveMap& map,
               size_t worker);
  // The path, the answer, the debug and the log line of a planned request.
  void publish(const Robot& robot, const Job& job, Leg& leg, size_t legs, const ActiveMap& map,
               Clock::time_point t0);
};

}  // namespace vnsba::node
