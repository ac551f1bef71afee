// Shared helpers of the vnsba_bench subcommands: loading a map with its scenarios, timing plans,
// simple statistics and Markdown tables. Units: cells for lengths, microseconds for times.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/core/status.hpp"
#include "vnsba/maps/map_io.hpp"

namespace vnsba::bench {

// Exit codes of every subcommand: 0 success, 1 a measurement failed (a planner found no path
// where it must, a mismatch), 2 bad input (missing folder, bad map file, unknown name).
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

// A Moving AI map with its scenarios (`<map>.scen` beside it) and the planning map built from it.
struct LoadedMap {
  std::string name;  // file name without ".map"
  core::OccupancyGrid grid;
  std::shared_ptr<const core::GridMap> map;
  std::vector<maps::MovingAiScenario> scenarios;
};

// Loads `map_path` and `map_path + ".scen"`; the status message names the file at fault.
core::Expected<LoadedMap> load_map_with_scenarios(const std::string& map_path);

// The `.map` files in a folder that have a `.map.scen` beside them, sorted by name. An error
// names the folder when it does not exist or holds no such pair.
core::Expected<std::vector<std::string>> list_scenario_maps(const std::string& folder);

// "astar,vns_bastar" -> planners; an unknown name is an error naming it and the valid names.
core::Expected<std::vector<core::PlannerKind>> parse_planner_list(const std::string& list);

// The paper's name for a planner (Tables 2-6): "A*", "improved A*", "BA*", "improved BA*",
// "VNS-BA*".
std::string paper_name(core::PlannerKind kind);

// Scenario indices to run: all, or `limit` spread evenly over the file (it is sorted by
// bucket, i.e. by optimal length, so every length band stays represented).
std::vector<size_t> pick_scenarios(size_t count, int limit);

// One plan, timed around Planner::plan on a steady clock in nanoseconds (the core's own
// planning_time_us has a resolution of 1 us, too coarse for 20 x 20 maps), and the CPU time the
// whole process spent over the same call (process_cpu_time_us, read just outside the steady
// clock's two reads, so the wall time is measured as before): every thread's, which is the
// plan's own CPU time while no other thread of the process runs (vnsba_bench runs none). Below
// the wall time where the plan was preempted: a sign of a busy machine.
struct TimedPlan {
  core::PlanResult result;
  double time_us = 0.0;
  double cpu_time_us = 0.0;
};
TimedPlan timed_plan(core::Planner& planner, const core::PlanQuery& query,
                     const core::PlannerOptions& options);

// CPU time consumed by all threads of this process so far (CLOCK_PROCESS_CPUTIME_ID), in
// microseconds.
double process_cpu_time_us();

// Median wall time of `repetitions` plans of the same query (after one warm-up plan, so the
// search state is allocated), in microseconds. Debug data and the length ratio are switched off
// for the timed runs, as they are not part of planning.
double median_plan_time_us(core::Planner& planner, const core::PlanQuery& query,
                           core::PlannerOptions options, int repetitions);

// Statistics over a sample; NaN for an empty one.
double mean(const std::vector<double>& values);
double median(std::vector<double> values);
// Nearest-rank percentile, p in [0, 100].
double percentile(std::vector<double> values, double p);
// The headline of a speed comparison: the median over queries of times[i] / reference_times[i]
// (query i planned by both). Not the ratio of the two medians, which pairs unrelated queries.
// Pairs with a non-finite time or a reference time <= 0 are left out; NaN when none is left.
double median_of_ratios(const std::vector<double>& times,
                        const std::vector<double>& reference_times);

// printf-style number formatting for tables ("n/a" for NaN).
std::string format(double value, int decimals);

// A Markdown (GitHub) table.
class MarkdownTable {
 public:
  explicit MarkdownTable(std::vector<std::string> headers) : headers_(std::move(headers)) {}
  void add_row(std::vector<std::string> cells) { rows_.push_back(std::move(cells)); }
  std::string str() const;

 private:
  std::vector<std::string> headers_;
  std::vector<std::vector<std::string>> rows_;
};

// Creates the folder (and parents); the status names it on failure.
core::Status ensure_directory(const std::string& folder);

// The checks `paper` and `sweep` share before they run: repetitions >= 1, an existing maps
// folder, an output folder that exists or can be made. Prints what is wrong, naming the option,
// as "vnsba_bench <command>: ..." and returns false.
bool check_run_options(const char* command, int repetitions, const std::string& maps_dir,
                       const std::string& out_dir);

// Writes text to a file; prints the failure naming the file and returns false.
bool write_file_or_report(const std::string& path, const std::string& content);

}  // namespace vnsba::bench
