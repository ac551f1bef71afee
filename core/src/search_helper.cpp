#include "search_helper.hpp"

namespace vnsba::core::detail {

SearchHelper::SearchHelper() : thread_([this] { loop(); }) {}

SearchHelper::~SearchHelper() {
  set_phase(kQuit);  // only ever destroyed between searches: the helper is idle
  thread_.join();
}

void SearchHelper::set_phase(Phase phase) {
  phase_.store(phase, std::memory_order_seq_cst);
  waits_.notify();
}

void SearchHelper::offer(Job job, void* context) {
  job_ = job;
  context_ = context;
  set_phase(kOffered);  // publishes job_ and context_ with it
}

void SearchHelper::hand_off(int64_t from_step) {
  from_step_ = from_step;
  ++hand_offs_;
  set_phase(kRunning);
}

void SearchHelper::finish() {
  int phase = phase_.load(std::memory_order_acquire);
  if (phase == kRunning || phase == kDone) {
    waits_.wait([&] { return phase_.load(std::memory_order_seq_cst) == kDone; }, kStepSpin);
    phase_.store(kIdle, std::memory_order_relaxed);  // the helper waits for kOffered or kQuit
    return;
  }
  // Not handed off: take the offer back before the helper accepts it, or withdraw it after.
  int expected = kOffered;
  if (phase_.compare_exchange_strong(expected, kIdle, std::memory_order_seq_cst)) return;
  set_phase(kWithdrawn);
  waits_.wait([&] { return phase_.load(std::memory_order_seq_cst) == kIdle; }, kStepSpin);
}

void SearchHelper::wait_for_offer() {
  auto offered = [&] {
    const int phase = phase_.load(std::memory_order_seq_cst);
    return phase == kOffered || phase == kQuit;
  };
  if (WaitPoint::spin(offered, kIdleSpin)) return;
  const auto until = std::chrono::steady_clock::now() + kIdlePollWindow;
  while (std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(kIdlePollPeriod);
    if (offered()) return;
  }
  waits_.wait(offered, std::chrono::nanoseconds{0});
}

void SearchHelper::loop() {
  for (;;) {
    wait_for_offer();
    int expected = kOffered;
    if (!phase_.compare_exchange_strong(expected, kAccepted, std::memory_order_seq_cst)) {
      if (expected == kQuit) return;
      continue;  // taken back before it was accepted
    }
    waits_.notify();  // the search may be waiting in finish()
    waits_.wait(
        [&] {
          const int phase = phase_.load(std::memory_order_seq_cst);
          return phase == kRunning || phase == kWithdrawn;
        },
        kStepSpin);
    if (phase_.load(std::memory_order_acquire) == kRunning) {
      job_(context_, from_step_);
      set_phase(kDone);
    } else {
      set_phase(kIdle);
    }
  }
}

}  // namespace vnsba::core::detail
