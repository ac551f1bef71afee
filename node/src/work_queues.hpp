// Every robot's request queue (requests.hpp's RequestQueue) under one lock, and the planning
// workers' turns: a worker takes the oldest request of a robot that has one waiting and none
// being planned, the robots in turn, so that no robot starves the others. No DDS.
#pragma once

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "fleet.hpp"
#include "vnsba/node/requests.hpp"

namespace vnsba::node {

class WorkQueues {
 public:
  WorkQueues(const NodeConfig& config, const Fleet& fleet);
  WorkQueues(const WorkQueues&) = delete;
  WorkQueues& operator=(const WorkQueues&) = delete;

  // Queues a request resolve_request accepted (RequestQueue::admit) and wakes a worker.
  // Returns the requests to answer CANCELED now (their interruption's reason says why).
  std::vector<Job> admit(const Robot& robot, Job job);
  // `robot`'s requests with these ids, canceled by their client (RequestQueue::cancel): the
  // waiting ones are returned, to be answered CANCELED now; the one being planned is flagged.
  std::vector<Job> cancel(const Robot& robot, const std::vector<std::string>& ids,
                          const std::string& reason);

  // A worker's next request and its robot; waits for one. nullopt once stopping and none is
  // left that this worker can take (a robot being planned that still has requests waiting is
  // drained by its own worker). Taken while stopping, a request is interrupted at once.
  struct Turn {
    const Robot* robot;
    Job job;
  };
  std::optional<Turn> next();
  // The request `robot` was planning has been answered: its next one may be taken.
  void finish(const Robot& robot);
  // Why `job` was interrupted (its CANCELED message), read under the lock; "" when it was not.
  std::string interruption(const Job& job) const;

  // Interrupts every request being planned with `reason`, and every one taken from now on.
  void stop(const std::string& reason);

  // The most requests ever waiting at once in one robot's queue.
  size_t peak() const { return peak_; }

 private:
  const Fleet& fleet_;
  mutable std::mutex mutex_;
  std::condition_variable work_;
  std::vector<RequestQueue> queues_;  // by Robot::index, under mutex_
  size_t next_robot_ = 0;             // where the next search for work starts, under mutex_
  bool stopping_ = false;             // under mutex_
  std::string stop_reason_;
  std::atomic<size_t> peak_{0};
  // A robot with a waiting request and none being planned (round robin), or null; under mutex_.
  const Robot* robot_with_work();
};

}  // namespace vnsba::node
