// render::Progress with a fake clock: at most one line per second of (fake) time, the count and
// the ETA as the rate so far predicts them, silence when disabled.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "vnsba/render/progress.hpp"

namespace vnsba::test {
namespace {

using std::chrono::milliseconds;
using TimePoint = std::chrono::steady_clock::time_point;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(Progress, AtMostOneLinePerSecondOfFakeTime) {
  TimePoint now{};
  std::ostringstream out;
  render::Progress progress("run", 1000, true, out, [&] { return now; });
  // 1000 steps of 37 ms each: 37 s in all; a line at most once per second.
  for (int done = 1; done <= 1000; ++done) {
    now += milliseconds(37);
    progress.update(done);
  }
  const auto lines = lines_of(out.str());
  const double elapsed_s = 37.0;
  EXPECT_LE(static_cast<double>(lines.size()), elapsed_s);
  // Every second brings a line: at least one per 1.037 s (the step after a second has passed).
  EXPECT_GE(static_cast<double>(lines.size()), elapsed_s / 1.037 - 1.0);
  EXPECT_EQ(progress.lines_printed(), static_cast<int64_t>(lines.size()));
}

TEST(Progress, NothingBeforeTheFirstSecond) {
  TimePoint now{};
  std::ostringstream out;
  render::Progress progress("run", 10, true, out, [&] { return now; });
  for (int done = 1; done <= 10; ++done) {
    now += milliseconds(90);
    progress.update(done);
  }
  progress.finish(10);  // nothing printed before: no final line either
  EXPECT_EQ(out.str(), "");
}

TEST(Progress, LineGivesDoneTotalElapsedAndEta) {
  TimePoint now{};
  std::ostringstream out;
  render::Progress progress("vnsba_plan --scen", 200, true, out, [&] { return now; });
  now += std::chrono::seconds(10);
  progress.update(50);  // a quarter in 10 s: three quarters left take 30 s at that rate
  EXPECT_EQ(out.str(), "vnsba_plan --scen: 50/200 (25.0%), elapsed 10s, ETA 30s\n");
  now += std::chrono::seconds(290);
  progress.update(100);  // half in 300 s: 300 s more
  EXPECT_EQ(lines_of(out.str()).back(),
            "vnsba_plan --scen: 100/200 (50.0%), elapsed 5m00s, ETA 5m00s");
  now += std::chrono::seconds(3600);
  progress.finish(200);
  EXPECT_EQ(lines_of(out.str()).back(),
            "vnsba_plan --scen: 200/200 (100.0%), elapsed 1h05m, ETA 0s");
}

TEST(Progress, FinishAddsNoLineTheLastOneAlreadySaid) {
  TimePoint now{};
  std::ostringstream out;
  render::Progress progress("run", 3, true, out, [&] { return now; });
  now += std::chrono::seconds(2);
  progress.update(3);
  progress.finish(3);
  EXPECT_EQ(lines_of(out.str()).size(), 1u) << out.str();
}

TEST(Progress, EtaUnknownBeforeTheFirstStep) {
  TimePoint now{};
  std::ostringstream out;
  render::Progress progress("run", 4, true, out, [&] { return now; });
  now += std::chrono::seconds(2);
  progress.update(0);
  EXPECT_EQ(out.str(), "run: 0/4 (0.0%), elapsed 2s, ETA ?\n");
}

TEST(Progress, SilentWhenDisabled) {
  TimePoint now{};
  std::ostringstream out;
  render::Progress progress("run", 100, false, out, [&] { return now; });
  for (int done = 1; done <= 100; ++done) {
    now += std::chrono::seconds(2);
    progress.update(done);
  }
  progress.finish(100);
  EXPECT_EQ(out.str(), "");
  EXPECT_EQ(progress.lines_printed(), 0);
}

TEST(Progress, ForcedIsWanted) {
  EXPECT_TRUE(render::progress_wanted(true));
}

TEST(Progress, DurationsAsAPersonReadsThem) {
  EXPECT_EQ(render::format_duration(0.4), "0s");
  EXPECT_EQ(render::format_duration(59.4), "59s");
  EXPECT_EQ(render::format_duration(187.0), "3m07s");
  EXPECT_EQ(render::format_duration(3720.0), "1h02m");
  EXPECT_EQ(render::format_duration(-1.0), "?");
  EXPECT_EQ(render::format_duration(NAN), "?");
}

}  // namespace
}  // namespace vnsba::test
