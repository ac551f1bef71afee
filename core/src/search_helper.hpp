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
// Every wait inside a search spins (at most kStepSpin), then blocks: on a loaded machine a thread
// whose partner is not running gives its core up instead of burning it. Between searches the
// helper spins briefly, polls with short sleeps for a while, then blocks (kIdle* below).
#pragma once

#include <atomic>
#include <chrono>
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

// Where threads wait for a condition another thread makes true: spin for up to `spin_for`, then
// block. Whoever makes a waited-for condition true then calls notify(), which wakes blocked
// waiters only when there are any (a load of a counter otherwise). With a sequentially consistent
// store (or read-modify-write) before notify(), and conditions that read sequentially consistent,
// no wake-up is lost: a waiter announces itself before it checks the condition the last time,
// under the mutex that notify() takes, and in the single order of those operations either the
// check sees the change or notify() sees the waiter. The searches' per-step hand-over publishes
// with a plain release store instead: a sequentially consistent one drains the store buffer,
// which waits for the other core to give the cache line up (about 200 ns on a 2-core virtual
// machine, as long as an expansion). Its wake-up can be lost only when the store and a waiter's
// announcement cross, after the waiter has spun for its whole spin_for, so a blocked waiter also
// checks again every kRecheck on its own. (No fences, which ThreadSanitizer cannot follow.)
class WaitPoint {
 public:
  template <class Ready>
  void wait(const Ready& ready, std::chrono::nanoseconds spin_for) {
    if (spin(ready, spin_for)) return;
    sleepers_.fetch_add(1, std::memory_order_seq_cst);
    {
      std::unique_lock<std::mutex> lock(mutex_);
      while (!condition_.wait_for(lock, kRecheck, ready)) {
      }
    }
    sleepers_.fetch_sub(1, std::memory_order_relaxed);
  }

  // Spins until `ready` (true) or for `spin_for` (false), reading the clock every 64 pauses.
  template <class Ready>
  static bool spin(const Ready& ready, std::chrono::nanoseconds spin_for) {
    const auto until = std::chrono::steady_clock::now() + spin_for;
    for (uint32_t i = 1;; ++i) {
      if (ready()) return true;
      if (i % 64 == 0 && std::chrono::steady_clock::now() >= until) return false;
      spin_pause();
    }
  }

  // Whether a thread is blocked here (a notify() would make a system call to wake it).
  bool has_sleepers() const { return sleepers_.load(std::memory_order_relaxed) > 0; }

  void notify() {
    if (sleepers_.load(std::memory_order_seq_cst) == 0) return;
    std::lock_guard<std::mutex> lock(mutex_);
    condition_.notify_all();
  }

 private:
  static constexpr std::chrono::microseconds kRecheck{200};
  std::atomic<int> sleepers_{0};
  std::mutex mutex_;
  std::condition_variable condition_;
};

class SearchHelper {
 public:
  // What the helper runs: the backward direction's steps from `from_step` on, until its search
  // ends. `context` is the search.
  using Job = void (*)(void* context, int64_t from_step);

  // How long a wait inside a search spins before it blocks. The partner's next pop is normally a
  // fraction of a microsecond away; one that does not come within this is not running. It must
  // be well above the time a blocked thread takes to wake (about 100 microseconds measured): with
  // 50, one thread's block made its partner block at its next wait, and the two went on taking
  // turns to sleep, 50 times slower than one thread.
  static constexpr std::chrono::microseconds kStepSpin{1000};
  // Between searches the helper spins this long, then polls, sleeping kIdlePollPeriod at a time,
  // for kIdlePollWindow, and only then blocks: waking a blocked thread is a system call that cost
  // the waker 20-30 microseconds and the wakee about 100 (measured on a 2-core virtual machine),
  // which a search that follows another soon does not pay. Polling costs a few microseconds of
  // CPU per period, for the window only.
  static constexpr std::chrono::microseconds kIdleSpin{20};
  static constexpr std::chrono::microseconds kIdlePollPeriod{50};
  static constexpr std::chrono::milliseconds kIdlePollWindow{2};

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
  // Whether the helper is blocked between searches: an offer then costs a system call (see
  // above), so a search offers later, when it has shown it is long.
  bool asleep() const { return waits_.has_sleepers(); }
  // How many jobs were handed off, and how many of them the searching thread took back before
  // the search ended (its partner was not running).
  int64_t hand_offs() const { return hand_offs_; }
  int64_t take_backs() const { return take_backs_; }
  void note_take_back() { ++take_backs_; }

 private:
  enum Phase : int { kIdle, kOffered, kAccepted, kRunning, kWithdrawn, kDone, kQuit };
  void set_phase(Phase phase);
  void wait_for_offer();
  void loop();

  std::atomic<int> phase_{kIdle};
  Job job_ = nullptr;
  void* context_ = nullptr;
  int64_t from_step_ = 0;
  int64_t hand_offs_ = 0;   // the searching thread's
  int64_t take_backs_ = 0;  // likewise
  WaitPoint waits_;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace vnsba::core::detail
