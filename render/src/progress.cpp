#include "vnsba/render/progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <ostream>

namespace vnsba::render {

bool progress_wanted(bool forced) {
  return forced || isatty(STDERR_FILENO) == 1;
}

std::string format_duration(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) return "?";
  const long long s = std::llround(seconds);
  char text[48];
  if (s < 60)
    std::snprintf(text, sizeof text, "%llds", s);
  else if (s < 3600)
    std::snprintf(text, sizeof text, "%lldm%02llds", s / 60, s % 60);
  else
    std::snprintf(text, sizeof text, "%lldh%02lldm", s / 3600, (s % 3600) / 60);
  return text;
}

Progress::Progress(std::string label, int64_t total, bool enabled, std::ostream& out, Clock clock)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      out_(out),
      clock_(std::move(clock)),
      start_(clock_()),
      last_(start_) {}

Progress::Progress(std::string label, int64_t total, bool enabled)
    : Progress(std::move(label), total, enabled, std::cerr) {}

std::string Progress::line(int64_t done, double elapsed_s) const {
  char percent[32] = "";
  if (total_ > 0)
    std::snprintf(percent, sizeof percent, " (%.1f%%)",
                  100.0 * static_cast<double>(done) / static_cast<double>(total_));
  // The rate so far, extrapolated over what is left; unknown before the first step is done.
  const double eta = done > 0 && total_ >= done ? elapsed_s * static_cast<double>(total_ - done) /
                                                      static_cast<double>(done)
                                                : NAN;
  return label_ + ": " + std::to_string(done) + "/" + std::to_string(total_) + percent +
         ", elapsed " + format_duration(elapsed_s) + ", ETA " + format_duration(eta);
}

void Progress::update(int64_t done) {
  if (!enabled_) return;
  const auto now = clock_();
  if (now - last_ < std::chrono::seconds(1)) return;
  last_ = now;
  ++lines_;
  last_done_ = done;
  out_ << line(done, std::chrono::duration<double>(now - start_).count()) << '\n' << std::flush;
}

void Progress::finish(int64_t done) {
  if (!enabled_ || lines_ == 0 || last_done_ == done) return;
  const auto now = clock_();
  ++lines_;
  out_ << line(done, std::chrono::duration<double>(now - start_).count()) << '\n' << std::flush;
}

}  // namespace vnsba::render
