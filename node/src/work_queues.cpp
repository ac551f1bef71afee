#include "work_queues.hpp"

#include <algorithm>
#include <utility>

namespace vnsba::node {

WorkQueues::WorkQueues(const NodeConfig& config, const Fleet& fleet) : fleet_(fleet) {
  queues_.reserve(fleet.size());
  for (size_t i = 0; i < fleet.size(); ++i)
    queues_.emplace_back(static_cast<size_t>(config.queue_capacity), config.preempt);
}

std::vector<Job> WorkQueues::admit(const Robot& robot, Job job) {
  std::vector<Job> canceled;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    RequestQueue& queue = queues_[robot.index];
    canceled = queue.admit(std::move(job));
    peak_ = std::max(peak_.load(), queue.waiting());
  }
  work_.notify_one();
  return canceled;
}

std::vector<Job> WorkQueues::cancel(const Robot& robot, const std::vector<std::string>& ids,
                                    const std::string& reason) {
  std::vector<Job> removed;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const std::string& id : ids) {
    std::vector<Job> jobs = queues_[robot.index].cancel(id, reason);
    for (Job& job : jobs) removed.push_back(std::move(job));
  }
  return removed;
}

const Robot* WorkQueues::robot_with_work() {
  for (size_t i = 0; i < queues_.size(); ++i) {
    const size_t r = (next_robot_ + i) % queues_.size();
    const RequestQueue& queue = queues_[r];
    if (queue.waiting() > 0 && !queue.planning()) {
      next_robot_ = r + 1;  // the next search starts after it: no robot starves the others
      return &fleet_[r];
    }
  }
  return nullptr;
}

std::optional<WorkQueues::Turn> WorkQueues::next() {
  std::unique_lock<std::mutex> lock(mutex_);
  const Robot* robot = nullptr;
  work_.wait(lock, [&] {
    robot = robot_with_work();
    return robot != nullptr || stopping_;
  });
  if (robot == nullptr) return std::nullopt;
  RequestQueue& queue = queues_[robot->index];
  Turn turn{robot, std::move(*queue.next())};
  if (stopping_) queue.interrupt_current(stop_reason_);
  return turn;
}

void WorkQueues::finish(const Robot& robot) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queues_[robot.index].finish_current();
  }
  work_.notify_all();  // this robot's next request may wait for a worker
}

std::string WorkQueues::interruption(const Job& job) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return job.interruption->flag ? job.interruption->reason : std::string();
}

void WorkQueues::stop(const std::string& reason) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    stop_reason_ = reason;
    for (RequestQueue& queue : queues_) queue.interrupt_current(reason);
  }
  work_.notify_all();
}

}  // namespace vnsba::node
