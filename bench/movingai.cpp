#include "bench/movingai.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "bench/common.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/render/progress.hpp"

namespace vnsba::bench {
namespace {

const std::vector<std::string> kClasses = {"game", "maze", "room", "random", "street"};

std::string class_of_source_folder(const std::string& folder) {
  if (folder == "mazes" || folder == "maze") return "maze";
  if (folder == "rooms" || folder == "room") return "room";
  if (folder == "random") return "random";
  if (folder == "cities" || folder == "street") return "street";
  return "game";  // dao, bg512, sc1, wc3maps512, da2, ...: commercial game maps
}

std::string class_of_name(const std::string& name) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower.find("maze") != std::string::npos) return "maze";
  if (lower.find("room") != std::string::npos) return "room";
  if (lower.find("random") != std::string::npos) return "random";
  // Street maps are named <City>_<n>_<size>, e.g. Berlin_0_256.
  const auto last = name.rfind('_');
  if (last != std::string::npos && name.find('_') < last &&
      std::isupper(static_cast<unsigned char>(name[0]))) {
    const std::string size = name.substr(last + 1, name.find('.', last) - last - 1);
    if (size == "256" || size == "512" || size == "1024") return "street";
  }
  return "game";
}

// A planner in one configuration: its paper one, or (baselines) with pruning and smoothing.
struct Configuration {
  core::PlannerKind planner;
  bool post_processed = false;
  std::string name() const {
    return std::string(core::to_string(planner)) + (post_processed ? "+prune+smooth" : "");
  }
  std::string label() const {
    return paper_name(planner) + (post_processed ? " +prune+smooth" : "") + " (`" + name() + "`)";
  }
  core::PlannerOptions options() const {
    core::PlannerSettings settings;
    if (post_processed) settings.prune = settings.smooth = true;
    return core::make_options(planner, settings);
  }
};

struct Run {
  std::string map_class;
  size_t configuration = 0;  // index into the run's configurations
  size_t query = 0;          // the scenario's index over the whole run (the same for every
                             // configuration): pairs plans of one query
  bool ok = false;
  double length_ratio = NAN;  // final length / the scenario's optimum
  double raw_ratio = NAN;     // grid path cost / the scenario's optimum
  double turns = NAN;
  double turn_angle_deg = NAN;
  double clearance_cells = NAN;  // the final path's clearance (+inf on a map without obstacles)
  double expanded = NAN;
  double time_us = NAN;  // wall
};

// 64-bit FNV-1a, fed value by value (the bytes of each, so the bits of a double count).
class Fnv1a {
 public:
  template <class T>
  void add(const T& value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    for (const unsigned char b : bytes) hash_ = (hash_ ^ b) * 1099511628211ull;
  }
  void add(const core::Cell& cell) {
    add(cell.x);
    add(cell.y);
  }
  void add(const core::Point2& point) {
    add(point.x());
    add(point.y());
  }
  template <class T>
  void add_all(const std::vector<T>& values) {
    add(static_cast<uint64_t>(values.size()));
    for (const T& v : values) add(v);
  }
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(hash_));
    return buf;
  }

 private:
  uint64_t hash_ = 14695981039346656037ull;
};

template <class T>
std::string hash_of(const std::vector<T>& values) {
  Fnv1a h;
  h.add_all(values);
  return h.hex();
}

// The CSV columns of a plan's outputs beyond its metrics (kMovingAiCsvHeader): the expansions
// from `recorded` (the same query planned with record_expansions on), the rest from `timed`.
std::string output_columns(const core::PlanResult& timed, const core::PlanResult& recorded) {
  Fnv1a expansions;
  expansions.add_all(recorded.expanded_forward);
  expansions.add_all(recorded.expanded_backward);
  const std::string meeting = timed.meeting_cell ? std::to_string(timed.meeting_cell->x) + ":" +
                                                       std::to_string(timed.meeting_cell->y)
                                                 : std::string();
  return std::to_string(recorded.expanded_forward.size()) + "," +
         std::to_string(recorded.expanded_backward.size()) + "," + meeting + "," +
         hash_of(timed.raw_path) + "," + hash_of(timed.waypoints) + "," + hash_of(timed.path) +
         "," + expansions.hex();
}

// Whether two plans of one query agree on everything but the expansion lists and the time.
bool same_outputs(const core::PlanResult& a, const core::PlanResult& b) {
  return a.status.code == b.status.code && a.raw_path == b.raw_path && a.waypoints == b.waypoints &&
         a.path == b.path && a.meeting_cell == b.meeting_cell &&
         a.metrics.expanded == b.metrics.expanded;
}

}  // namespace

std::string movingai_map_class(const std::string& maps_dir, const std::string& map_file_name) {
  std::ifstream manifest(maps_dir + "/MANIFEST.tsv");
  std::string line;
  while (std::getline(manifest, line)) {
    std::stringstream fields(line);
    std::string local_file, bytes, hash, repo, source_path;
    if (!std::getline(fields, local_file, '\t') || local_file != map_file_name) continue;
    std::getline(fields, bytes, '\t');
    std::getline(fields, hash, '\t');
    std::getline(fields, repo, '\t');
    std::getline(fields, source_path, '\t');
    // "maps/<folder>/<file>": the folder names the benchmark set.
    const std::filesystem::path source(source_path);
    if (source.has_parent_path())
      return class_of_source_folder(source.parent_path().filename().string());
  }
  return class_of_name(map_file_name);
}

// Per class and over all classes: VNS-BA*'s and JPS's time against A*'s, as the median over
// queries of (its time / A*'s time on the same query), the headline, and as the ratio of the
// median times beside it; and every configuration's cost per expansion (its total time / its
// total expansions, in nanoseconds). Times and expansions of failed plans count too: they were
// spent.
std::string speed_summary(const std::vector<Run>& runs,
                          const std::vector<Configuration>& configurations) {
  auto index_of = [&](core::PlannerKind kind) -> std::optional<size_t> {
    for (size_t c = 0; c < configurations.size(); ++c)
      if (configurations[c].planner == kind && !configurations[c].post_processed) return c;
    return std::nullopt;
  };
  const auto astar = index_of(core::PlannerKind::kAStar);
  const std::pair<const char*, std::optional<size_t>> against_astar[] = {
      {"VNS-BA*", index_of(core::PlannerKind::kVnsBaStar)},
      {"JPS", index_of(core::PlannerKind::kJps)}};
  std::vector<std::string> headers = {"class"};
  for (const auto& [name, index] : against_astar) {
    if (!astar || !index) continue;
    headers.push_back(std::string(name) + " / A* time, median of per-query ratios");
    headers.push_back(std::string(name) + " / A*, ratio of median times");
  }
  for (const auto& c : configurations) headers.push_back(c.name() + " ns / expansion");
  MarkdownTable table(headers);
  std::vector<std::string> classes = kClasses;
  classes.push_back("all");
  for (const std::string& map_class : classes) {
    std::vector<std::vector<double>> time(configurations.size());
    std::vector<double> total_us(configurations.size(), 0.0), total_expanded(configurations.size());
    // query -> time per configuration
    std::map<size_t, std::vector<double>> time_of_query;
    for (const Run& r : runs) {
      if (map_class != "all" && r.map_class != map_class) continue;
      time[r.configuration].push_back(r.time_us);
      total_us[r.configuration] += r.time_us;
      total_expanded[r.configuration] += r.expanded;
      auto& times = time_of_query[r.query];
      times.resize(configurations.size(), NAN);
      times[r.configuration] = r.time_us;
    }
    if (time[0].empty()) continue;
    std::vector<std::string> row = {map_class};
    for (const auto& [name, index] : against_astar) {
      if (!astar || !index) continue;
      std::vector<double> planner_times, astar_times;
      for (const auto& [query, times] : time_of_query) {
        planner_times.push_back(times[*index]);
        astar_times.push_back(times[*astar]);
      }
      row.push_back(format(median_of_ratios(planner_times, astar_times), 3));
      row.push_back(format(median(time[*index]) / median(time[*astar]), 3));
    }
    for (size_t c = 0; c < configurations.size(); ++c)
      row.push_back(
          format(total_expanded[c] > 0 ? 1000.0 * total_us[c] / total_expanded[c] : NAN, 0));
    table.add_row(row);
  }
  return "**Speed.** VNS-BA*'s and JPS's planning time against A*'s on the same queries: the "
         "headline is the median over queries of (the planner's time / A*'s time on that query); "
         "the ratio of the two median times is beside it, named so (it can differ a lot: the "
         "median query of one planner need not be the other's). Then each configuration's cost "
         "per expansion (total planning time / total expanded nodes, ns; post-processing "
         "included where it is on).\n\n" +
         table.str() + "\n";
}

int run_movingai(const MovingAiOptions& options) {
  auto maps = list_scenario_maps(options.maps_dir);
  if (!maps) {
    std::fprintf(stderr, "vnsba_bench movingai: --maps: %s\n", maps.error().message.c_str());
    return kExitBadInput;
  }
  if (options.max_scenarios < 0) {
    std::fprintf(stderr, "vnsba_bench movingai: --max-scenarios must be >= 0, got %d\n",
                 options.max_scenarios);
    return kExitBadInput;
  }
  const std::vector<core::PlannerKind> planners =
      options.planners.empty() ? core::all_planner_kinds() : options.planners;
  std::vector<Configuration> configurations;
  for (const auto kind : planners) configurations.push_back({kind, false});
  if (options.with_post_processing)
    for (const auto kind : planners)
      if (kind != core::PlannerKind::kVnsBaStar) configurations.push_back({kind, true});

  // The plans to come, for the progress line: the scenario files alone are read here (the maps
  // load one at a time below); a file that does not load counts 0 and fails below.
  int64_t plans_total = 0;
  for (const std::string& path : *maps)
    if (const auto scenarios = maps::load_movingai_scenarios(path + ".scen"))
      plans_total += static_cast<int64_t>(
          pick_scenarios(scenarios->size(), options.max_scenarios).size() * configurations.size());
  render::Progress progress("vnsba_bench movingai", plans_total,
                            render::progress_wanted(options.progress));
  int64_t plans_done = 0;

  if (options.csv) std::printf("%s\n", kMovingAiCsvHeader);
  std::vector<Run> runs;
  size_t plans_disagreeing = 0;  // --csv: second plans of a query with other outputs
  std::map<std::string, std::vector<std::string>> maps_of_class;
  size_t scenario_total = 0;
  for (const std::string& path : *maps) {
    auto loaded = load_map_with_scenarios(path);
    if (!loaded) {
      std::fprintf(stderr, "vnsba_bench movingai: %s\n", loaded.error().message.c_str());
      return kExitBadInput;
    }
    const std::string file_name = std::filesystem::path(path).filename().string();
    const std::string map_class = movingai_map_class(options.maps_dir, file_name);
    maps_of_class[map_class].push_back(loaded->name);
    core::Planner planner(loaded->map);
    const auto picked = pick_scenarios(loaded->scenarios.size(), options.max_scenarios);
    scenario_total += picked.size();
    for (size_t c = 0; c < configurations.size(); ++c) {
      const core::PlannerOptions plan_options = configurations[c].options();
      core::PlannerOptions record_options = plan_options;
      record_options.record_expansions = true;
      const std::string planner_name = configurations[c].name();
      // Warm-up: the first plan allocates this map's search state. The longest query (the file
      // is sorted by length), so that no timed plan grows it: with the shortest, the first
      // configuration of a map paid the growth and a second, identical one ran 3 % faster per
      // query.
      if (!picked.empty()) {
        const auto& s = loaded->scenarios[picked.back()];
        planner.plan({s.start, s.goal}, plan_options);
      }
      for (size_t k = 0; k < picked.size(); ++k) {
        const maps::MovingAiScenario& s = loaded->scenarios[picked[k]];
        const TimedPlan timed = timed_plan(planner, {s.start, s.goal}, plan_options);
        const core::Metrics& m = timed.result.metrics;
        Run run{map_class, c, scenario_total - picked.size() + k};
        run.ok = timed.result.status.is_ok();
        if (run.ok) {
          if (s.optimal_length > 0) {
            run.length_ratio = m.length_cells / s.optimal_length;
            run.raw_ratio = m.raw_cost_cells / s.optimal_length;
          }
          run.turns = m.turns;
          run.turn_angle_deg = m.turn_angle_deg;
          run.clearance_cells = m.clearance_m / loaded->map->resolution();
        }
        run.expanded = static_cast<double>(m.expanded);
        run.time_us = timed.time_us;
        runs.push_back(run);
        progress.update(++plans_done);
        if (options.csv) {
          // The expansions of each search, from the same query planned again (untimed, after
          // the timed plan so that it does not warm the caches for it).
          const core::PlanResult recorded = planner.plan({s.start, s.goal}, record_options);
          if (!same_outputs(timed.result, recorded)) {
            ++plans_disagreeing;
            std::fprintf(stderr,
                         "vnsba_bench movingai: %s line %d, %s: a second plan of the query (with "
                         "record_expansions) gave other outputs than the first\n",
                         loaded->name.c_str(), s.line, planner_name.c_str());
          }
          const std::string status(core::to_string(timed.result.status.code));
          char metrics[256];
          if (run.ok)
            std::snprintf(metrics, sizeof metrics, "%.8f,%.8f,%.8f,%d,%.4f,%lld,%.4f",
                          s.optimal_length, m.raw_cost_cells, m.length_cells, m.turns,
                          m.turn_angle_deg, static_cast<long long>(m.expanded), m.clearance_m);
          else
            std::snprintf(metrics, sizeof metrics, "%.8f,,,,,%lld,", s.optimal_length,
                          static_cast<long long>(m.expanded));
          std::printf("%s,%d,%s,%s,%s,%s,%.3f,%.3f,%.3f\n", loaded->name.c_str(), s.line,
                      planner_name.c_str(), status.c_str(), metrics,
                      output_columns(timed.result, recorded).c_str(), m.search_time_us,
                      timed.time_us, timed.cpu_time_us);
        }
      }
    }
    // Progress on stderr in both modes (the CSV goes to stdout): one line per map done.
    if (options.csv) std::fflush(stdout);
    std::fprintf(stderr, "%s (%s): %zu scenarios x %zu configurations\n", loaded->name.c_str(),
                 map_class.c_str(), picked.size(), configurations.size());
  }
  progress.finish(plans_done);
  if (options.csv) {
    if (plans_disagreeing == 0) return kExitOk;
    std::fprintf(stderr,
                 "vnsba_bench movingai: %zu plans gave other outputs when planned again (above)\n",
                 plans_disagreeing);
    return kExitFailure;
  }

  std::string md = "### Moving AI benchmarks, per map class\n\n";
  md += std::to_string(scenario_total) + " scenarios on " + std::to_string(maps->size()) + " maps" +
        (options.max_scenarios > 0 ? " (at most " + std::to_string(options.max_scenarios) +
                                         " per map, spread evenly over each scenario file)"
                                   : " (every scenario)") +
        ", each planner in its paper configuration" +
        (options.with_post_processing
             ? std::string(" and each baseline also with VNS-BA*'s pruning and smoothing")
             : std::string()) +
        ", one plan per scenario. Ratio: final path "
        "length / the scenario's published optimum (8-connected, no corner cutting); raw ratio: "
        "the grid path's cost before pruning and smoothing / that optimum; clearance: the final "
        "path's smallest distance to an obstacle cell, in cells (1 m on these maps). Means over "
        "the successful plans (clearance: those on maps with obstacles); time in microseconds "
        "(search plus post-processing).\n\n";
  for (const auto& map_class : kClasses) {
    if (maps_of_class.count(map_class) == 0) continue;
    std::string names;
    for (const auto& n : maps_of_class[map_class]) names += (names.empty() ? "" : ", ") + n;
    md += "**" + map_class + "** (" + names + ")\n\n";
    MarkdownTable table({"planner", "plans", "success", "length ratio", "raw ratio", "turns",
                         "turn angle (deg)", "clearance (cells)", "expanded", "time median (us)",
                         "time p95 (us)"});
    for (size_t c = 0; c < configurations.size(); ++c) {
      size_t count = 0, ok = 0;
      std::vector<double> ratio, raw, turns, angle, clearance, expanded, time;
      for (const Run& r : runs) {
        if (r.map_class != map_class || r.configuration != c) continue;
        ++count;
        if (!r.ok) continue;
        ++ok;
        if (std::isfinite(r.length_ratio)) ratio.push_back(r.length_ratio);
        if (std::isfinite(r.raw_ratio)) raw.push_back(r.raw_ratio);
        turns.push_back(r.turns);
        angle.push_back(r.turn_angle_deg);
        if (std::isfinite(r.clearance_cells)) clearance.push_back(r.clearance_cells);
        expanded.push_back(r.expanded);
        time.push_back(r.time_us);
      }
      table.add_row(
          {configurations[c].label(), std::to_string(count),
           format(count ? 100.0 * static_cast<double>(ok) / static_cast<double>(count) : NAN, 1) +
               " %",
           format(mean(ratio), 4), format(mean(raw), 4), format(mean(turns), 1),
           format(mean(angle), 0), format(mean(clearance), 2), format(mean(expanded), 0),
           format(median(time), 0), format(percentile(time, 95), 0)});
    }
    md += table.str() + "\n";
  }
  md += speed_summary(runs, configurations);
  std::fputs(md.c_str(), stdout);
  return kExitOk;
}

}  // namespace vnsba::bench
