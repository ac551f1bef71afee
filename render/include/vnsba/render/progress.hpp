// Progress of a long run on stderr: "LABEL: done/total (P%), elapsed T, ETA T" at most once a
// second, so a user of a run that takes minutes (vnsba_bench movingai, vnsba_plan --scen) sees
// that it moves and when it ends, and a log is not flooded.
//
// The clock and the stream are injectable so that tests drive fake time instead of sleeping.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>

namespace vnsba::render {

// Whether progress lines are wanted: `forced` (a tool's --progress flag), or stderr is a terminal
// (a redirected stderr, a test or a CI log, gets none unless asked for).
bool progress_wanted(bool forced);

// Seconds as a person reads them: "42s", "3m07s", "1h02m" (negative or NaN: "?").
std::string format_duration(double seconds);

class Progress {
 public:
  using Clock = std::function<std::chrono::steady_clock::time_point()>;

  // `total` steps; silent when `enabled` is false. Elapsed time counts from construction.
  Progress(
      std::string label, int64_t total, bool enabled, std::ostream& out,
      Clock clock = [] { return std::chrono::steady_clock::now(); });
  // Writes to std::cerr with the steady clock.
  Progress(std::string label, int64_t total, bool enabled);

  // `done` steps of `total` are complete. Prints a line when at least one second has passed
  // since the start and since the last line (the first line comes after one second, so a run
  // shorter than that prints nothing).
  void update(int64_t done);
  // The run is over: a last line with the final count, only if a line was printed before (a
  // reader of the earlier lines learns how it ended) and the last one had another count.
  void finish(int64_t done);

  // The line for `done` steps after `elapsed_s` seconds (no newline): what update() prints.
  std::string line(int64_t done, double elapsed_s) const;
  int64_t lines_printed() const { return lines_; }

 private:
  std::string label_;
  int64_t total_;
  bool enabled_;
  std::ostream& out_;
  Clock clock_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_;
  int64_t lines_ = 0;
  int64_t last_done_ = -1;  // the count of the last line printed
};

}  // namespace vnsba::render
