// A second thread for a planner's bidirectional search (internal; docs/algorithm.md section 3,
// "two threads"), and the waits the two threads of one search use.
//
// A Planner with vns_threads 2 owns one SearchHelper for its lifetime: the thread is made at the
// first such plan and reused by every later one (no thread per plan). A search starts on the
// calling thread alone, both directions in strict alternation, and offers the backward direction
// to the helper; the helper accepts when it is running, and the search then hands the backward
// direction over at the next step boundary. So the helper's wake-up time overlaps the search
// instead of delaying it, and a search that ends before the helper is awake never waits for it.
//
// Every wait spins briefly, then blocks: on a loaded machine a thread whose partner is not
// running gives its core up instead of burning it.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace vnsba::core::detail {

// The CPU's spin-loop hint (a pause of a few dozen cycles that frees the core's pipeline for its
// sibling hardware thread); nothing where the architecture has none.
inline void spin_pause() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__) || defined(__arm__)
  asm volatile("yield");
#endif
}

// Where threads wait for a condition another thread makes true: spin up to `spins` times, then
// block. Whoever makes a waited-for condition true does so with a sequentially consistent store
// (or read-modify-write) and then calls notify(), which wakes blocked waiters only when there are
// any (a load of a counter otherwise); the condition reads its atomics sequentially consistent
// too. Lost wake-ups are impossible: a waiter announces itself before it checks the condition the
// last time, under the mutex that notify() takes, and in the single order of those sequentially
// consistent operations either the waiter's check sees the change or notify() sees the waiter.
// (Plain loads and stores on x86; no fences, which ThreadSanitizer cannot follow.)
class WaitPoint {
 public:
  template <class Ready>
  void wait(const Ready& ready, int spins) {
    for (int i = 0; i < spins; ++i) {
      if (ready()) return;
      spin_pause();
    }
    sleepers_.fetch_add(1, std::memory_order_seq_cst);
    {
      std::unique_lock<std::mutex> lock(mutex_);
      condition_.wait(lock, ready);
    }
    sleepers_.fetch_sub(1, std::memory_order_relaxed);
  }

  void notify() {
    if (sleepers_.load(std::memory_order_seq_cst) == 0) return;
    std::lock_guard<std::mutex> lock(mutex_);
    condition_.notify_all();
  }

 private:
  std::atomic<int> sleepers_{0};
  std::mutex mutex_;
  std::condition_variable condition_;
};

class SearchHelper {
 public:
  // What the helper runs: the backward direction's steps from `from_step` on, until its search
  // ends. `context` is the search.
  using Job = void (*)(void* context, int64_t from_step);

  // Spins of a wait inside a search (the partner's next pop is normally a fraction of a
  // microsecond away): about 10 to 50 microseconds, by the CPU's pause.
  static constexpr int kStepSpins = 1000;

  SearchHelper();
  ~SearchHelper();
  SearchHelper(const SearchHelper&) = delete;
  SearchHelper& operator=(const SearchHelper&) = delete;

  // The waits of the search the helper works on (both threads use this one).
  WaitPoint& wait_point() { return waits_; }

  // Offers `job` for the search in progress; the caller then calls accepted() between its steps,
  // hand_off() once it is true, and finish() before the search returns, in every case.
  void offer(Job job, void* context);
  bool accepted() const { return phase_.load(std::memory_order_acquire) == kAccepted; }
  // The helper runs the job from `from_step`; everything the caller wrote before is visible to it.
  void hand_off(int64_t from_step);
  // Returns once the helper no longer touches the search: the job has returned (after a
  // hand-off) or the offer is withdrawn (the helper never started it).
  void finish();
  // How many jobs were handed off.
  int64_t hand_offs() const { return hand_offs_; }

 private:
  enum Phase : int { kIdle, kOffered, kAccepted, kRunning, kWithdrawn, kDone, kQuit };
  void set_phase(Phase phase);
  void loop();

  std::atomic<int> phase_{kIdle};
  Job job_ = nullptr;
  void* context_ = nullptr;
  int64_t from_step_ = 0;
  int64_t hand_offs_ = 0;  // the searching thread's
  WaitPoint waits_;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace vnsba::core::detail
