// Requests, goal_pose goals and action goals taken from the bus (issue 31). One intake thread
// takes them from every robot's readers (take_listener.hpp says why not the DDS threads), as long
// as that robot's answers keep pace: a robot that owes more than requests.queue_capacity +
// kAnswerBacklog answers (requests queued, planned, waiting for a map, held for the requester's
// reader, or waiting for room in the status writer's history) is not taken from until answers go
// out, so the bus holds the rest, not the node.
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "fleet.hpp"
#include "node_readers.hpp"

namespace vnsba::node {

// Answers a robot may owe at once beyond its queue: statuses planned but not yet handed to DDS
// (held for a requester's reader, or waiting for room in the status writer's history). Past
// queue_capacity + this, the node stops taking that robot's requests until answers go out.
inline constexpr size_t kAnswerBacklog = 1024;

class RequestIntake {
 public:
  RequestIntake(const NodeConfig& config, const Fleet& fleet);
  RequestIntake(const RequestIntake&) = delete;
  RequestIntake& operator=(const RequestIntake&) = delete;

  // `robot`'s readers the intake takes from (NodeReaders::add, add_action_server).
  IntakeInputs& inputs(const Robot& robot);

  // A request of `robot` was taken: it is owed an answer until answered() (its status handed
  // to DDS, or its action result stored).
  void taken(const Robot& robot);
  void answered(const Robot& robot);
  // Whether `robot` may take another request now; marks it paused if not. Always, once
  // refusing (see stop()).
  bool may_take(const Robot& robot);
  // Wakes the intake for `robot` if it is paused and has room again (replier thread).
  void resume(const Robot& robot);
  // Something arrived (a listener, on a DDS thread) or a robot has room again: take.
  void wake();

  void start();
  // From here on every request taken is answered CANCELED at once (refusing()) and every
  // robot is taken from whatever its backlog; the thread makes one last pass and ends, then
  // what came during that pass is taken here. The readers are deleted after this.
  void stop();
  bool refusing() const { return refusing_; }
  // After the readers are gone.
  void forget_readers();

 private:
  struct Backlog {
    // Requests taken whose answer is owed (see taken()).
    std::atomic<size_t> unanswered{0};
    std::atomic<bool> paused{false};
    IntakeInputs inputs;
  };
  const size_t room_;                             // requests.queue_capacity + kAnswerBacklog
  std::vector<std::unique_ptr<Backlog>> robots_;  // by Robot::index
  std::atomic<bool> refusing_{false};

  std::mutex mutex_;
  std::condition_variable wake_;
  bool pending_ = false;   // under mutex_
  bool stopping_ = false;  // under mutex_
  std::thread thread_;
  void loop();
  // Takes what every robot's readers hold (as far as may_take allows).
  void take_inputs();
};

}  // namespace vnsba::node
