#include "bench/common.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "vnsba/core/planner_registry.hpp"
#include "vnsba/render/svg.hpp"

namespace vnsba::bench {

using core::Expected;
using core::Status;
using core::StatusCode;

Expected<LoadedMap> load_map_with_scenarios(const std::string& map_path) {
  auto grid = maps::load_movingai_map(map_path);
  if (!grid) return grid.error();
  auto scenarios = maps::load_movingai_scenarios(map_path + ".scen");
  if (!scenarios) return scenarios.error();
  auto built = core::GridMap::build(*grid);
  if (!built) return Status::error(built.error().code, map_path + ": " + built.error().message);
  LoadedMap loaded;
  loaded.name = std::filesystem::path(map_path).stem().string();
  loaded.grid = std::move(grid).value();
  loaded.map = std::make_shared<const core::GridMap>(std::move(built).value());
  loaded.scenarios = std::move(scenarios).value();
  return loaded;
}

Expected<std::vector<std::string>> list_scenario_maps(const std::string& folder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    return Status::error(StatusCode::kInvalidRequest, "no such folder: " + folder);
  std::vector<std::string> maps;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    if (entry.path().extension() != ".map") continue;
    if (std::filesystem::exists(entry.path().string() + ".scen", ec))
      maps.push_back(entry.path().string());
  }
  if (ec) return Status::error(StatusCode::kInvalidRequest, folder + ": " + ec.message());
  if (maps.empty())
    return Status::error(StatusCode::kInvalidRequest,
                         "no .map file with a .map.scen beside it in " + folder);
  std::sort(maps.begin(), maps.end());
  return maps;
}

Expected<std::vector<core::PlannerKind>> parse_planner_list(const std::string& list) {
  std::vector<core::PlannerKind> kinds;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    if (name.empty()) continue;
    const auto kind = core::planner_kind_from_string(name);
    if (!kind) {
      std::string valid;
      for (const auto k : core::all_planner_kinds())
        valid += (valid.empty() ? "" : ", ") + std::string(core::to_string(k));
      return Status::error(StatusCode::kInvalidRequest,
                           "unknown planner '" + name + "' in --planners (valid: " + valid + ")");
    }
    if (std::find(kinds.begin(), kinds.end(), *kind) == kinds.end()) kinds.push_back(*kind);
  }
  if (kinds.empty())
    return Status::error(StatusCode::kInvalidRequest, "--planners names no planner");
  return kinds;
}

std::string paper_name(core::PlannerKind kind) {
  if (const core::PlannerDescriptor* planner = kind.descriptor())
    return std::string(planner->paper_name);
  return std::string(core::to_string(kind));
}

std::vector<size_t> pick_scenarios(size_t count, int limit) {
  std::vector<size_t> picked;
  if (limit <= 0 || static_cast<size_t>(limit) >= count) {
    for (size_t i = 0; i < count; ++i) picked.push_back(i);
    return picked;
  }
  for (size_t i = 0; i < static_cast<size_t>(limit); ++i)
    picked.push_back(i * count / static_cast<size_t>(limit));
  return picked;
}

double process_cpu_time_us() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return 1e6 * static_cast<double>(now.tv_sec) + 1e-3 * static_cast<double>(now.tv_nsec);
}

TimedPlan timed_plan(core::Planner& planner, const core::PlanQuery& query,
                     const core::PlannerOptions& options) {
  // The CPU clock is read outside the steady clock's reads: its system call stays out of the
  // wall time, which is measured exactly as before it was added.
  const double cpu_started = process_cpu_time_us();
  const auto started = std::chrono::steady_clock::now();
  TimedPlan timed{planner.plan(query, options), 0.0, 0.0};
  const auto ended = std::chrono::steady_clock::now();
  timed.cpu_time_us = process_cpu_time_us() - cpu_started;
  timed.time_us = std::chrono::duration<double, std::micro>(ended - started).count();
  return timed;
}

double median_plan_time_us(core::Planner& planner, const core::PlanQuery& query,
                           core::PlannerOptions options, int repetitions) {
  options.record_expansions = false;
  options.compute_length_ratio = false;
  planner.plan(query, options);  // warm-up: allocates the search state, warms the caches
  std::vector<double> times;
  times.reserve(static_cast<size_t>(std::max(repetitions, 1)));
  for (int i = 0; i < std::max(repetitions, 1); ++i)
    times.push_back(timed_plan(planner, query, options).time_us);
  return median(std::move(times));
}

double mean(const std::vector<double>& values) {
  if (values.empty()) return NAN;
  double sum = 0.0;
  for (const double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

double median(std::vector<double> values) {
  if (values.empty()) return NAN;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  const double lower =
      *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

double median_of_ratios(const std::vector<double>& times,
                        const std::vector<double>& reference_times) {
  std::vector<double> ratios;
  for (size_t i = 0; i < std::min(times.size(), reference_times.size()); ++i)
    if (std::isfinite(times[i]) && std::isfinite(reference_times[i]) && reference_times[i] > 0.0)
      ratios.push_back(times[i] / reference_times[i]);
  return median(std::move(ratios));
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  // Nearest rank: the smallest value with at least p % of the sample at or below it.
  const double rank =
      std::ceil(std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(values.size()));
  const size_t index = rank < 1 ? 0 : static_cast<size_t>(rank) - 1;
  return values[std::min(index, values.size() - 1)];
}

std::string format(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

std::string MarkdownTable::str() const {
  std::string out = "|";
  for (const auto& h : headers_) out += " " + h + " |";
  out += "\n|";
  for (size_t i = 0; i < headers_.size(); ++i) out += i == 0 ? "---|" : "---:|";
  out += "\n";
  for (const auto& row : rows_) {
    out += "|";
    for (const auto& cell : row) out += " " + cell + " |";
    out += "\n";
  }
  return out;
}

Status ensure_directory(const std::string& folder) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec || !std::filesystem::is_directory(folder))
    return Status::error(StatusCode::kInvalidRequest,
                         "cannot create folder " + folder + (ec ? ": " + ec.message() : ""));
  return Status::ok();
}

bool check_run_options(const char* command, int repetitions, const std::string& maps_dir,
                       const std::string& out_dir) {
  if (repetitions < 1) {
    std::fprintf(stderr, "vnsba_bench %s: --repetitions must be >= 1, got %d\n", command,
                 repetitions);
    return false;
  }
  if (!std::filesystem::is_directory(maps_dir)) {
    std::fprintf(stderr, "vnsba_bench %s: --maps: no such folder: %s\n", command, maps_dir.c_str());
    return false;
  }
  if (const auto s = ensure_directory(out_dir); !s.is_ok()) {
    std::fprintf(stderr, "vnsba_bench %s: --out: %s\n", command, s.message.c_str());
    return false;
  }
  return true;
}

bool write_file_or_report(const std::string& path, const std::string& content) {
  const Status s = render::write_text_file(path, content);
  if (!s.is_ok()) std::fprintf(stderr, "vnsba_bench: %s\n", s.message.c_str());
  return s.is_ok();
}

}  // namespace vnsba::bench
