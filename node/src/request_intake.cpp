#include "request_intake.hpp"

namespace vnsba::node {

RequestIntake::RequestIntake(const NodeConfig& config, const Fleet& fleet)
    : room_(static_cast<size_t>(config.queue_capacity) + kAnswerBacklog) {
  for (size_t i = 0; i < fleet.size(); ++i) robots_.push_back(std::make_unique<Backlog>());
}

IntakeInputs& RequestIntake::inputs(const Robot& robot) {
  return robots_.at(robot.index)->inputs;
}

void RequestIntake::taken(const Robot& robot) {
  ++robots_[robot.index]->unanswered;
}

void RequestIntake::answered(const Robot& robot) {
  --robots_[robot.index]->unanswered;
}

bool RequestIntake::may_take(const Robot& robot) {
  if (refusing_) return true;  // answered at once, and everything must be taken
  Backlog& backlog = *robots_[robot.index];
  if (backlog.unanswered < room_) return true;
  backlog.paused = true;
  // Answers that went out between the check and the flag found it unset: look again.
  if (backlog.unanswered < room_) {
    backlog.paused = false;
    return true;
  }
  return false;
}

void RequestIntake::resume(const Robot& robot) {
  Backlog& backlog = *robots_[robot.index];
  if (!backlog.paused) return;
  if (backlog.unanswered >= room_) return;
  backlog.paused = false;
  wake();
}

void RequestIntake::wake() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = true;
  }
  wake_.notify_one();
}

void RequestIntake::take_inputs() {
  for (const auto& backlog : robots_)
    for (const auto& [listener, reader] : backlog->inputs) listener->take_available(reader);
}

void RequestIntake::start() {
  thread_ = std::thread([this] { loop(); });
}

void RequestIntake::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return pending_ || stopping_; });
    if (!pending_) return;  // stopping, and nothing arrived since the last pass
    pending_ = false;
    lock.unlock();
    take_inputs();
    lock.lock();
  }
}

void RequestIntake::stop() {
  // What the readers still hold (taken by the DDS threads as it comes, or left by a paused
  // robot) is taken and answered CANCELED, then the readers go: nothing the bus delivered goes
  // unanswered.
  refusing_ = true;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    pending_ = true;  // one last pass, whatever the backlog
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  take_inputs();  // what came during that pass (DDS threads only wake the intake: no deadlock)
}

void RequestIntake::forget_readers() {
  for (const auto& backlog : robots_) backlog->inputs.clear();
}

}  // namespace vnsba::node
