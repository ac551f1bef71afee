#include "bench/large.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bench/common.hpp"
#include "vnsba/core/planner_options.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/render/progress.hpp"

extern char** environ;  // what posix_spawn passes on to a memory mode child

namespace vnsba::bench {

namespace {

constexpr int kSourceSize = 512;  // cells a side of every source map

struct LargeMapSpec {
  const char* name;       // Moving AI map, kSourceSize a side
  const char* map_class;  // as `vnsba_bench movingai` names it
  Growth growth;
};
constexpr LargeMapSpec kLargeMaps[] = {
    {"Boston_0_512", "street", Growth::kScaled},
    {"16room_000", "room", Growth::kScaled},
    {"random512-20-0", "random", Growth::kTiled},
};

// A scenario's query on the grown map (see large.hpp).
core::PlanQuery grown_query(const maps::MovingAiScenario& s, int factor, Growth growth,
                            int32_t source_width, int32_t source_height) {
  if (growth == Growth::kScaled) {
    auto centre = [&](const core::Cell& c) {
      return core::Cell{c.x * factor + factor / 2, c.y * factor + factor / 2};
    };
    return {centre(s.start), centre(s.goal)};
  }
  const core::Cell last_copy{(factor - 1) * source_width, (factor - 1) * source_height};
  return {s.start, {s.goal.x + last_copy.x, s.goal.y + last_copy.y}};
}

struct Sample {
  std::vector<double> time_us;
  std::vector<double> expanded;
  int failures = 0;
};

const LargeMapSpec* find_map_spec(const std::string& name) {
  for (const LargeMapSpec& spec : kLargeMaps)
    if (name == spec.name) return &spec;
  return nullptr;
}

// "16room_000 (room, scaled)": a table's map column.
std::string map_label(const LargeMapSpec& spec) {
  return std::string(spec.name) + " (" + spec.map_class + ", " +
         (spec.growth == Growth::kScaled ? "scaled" : "tiled") + ")";
}

std::vector<core::PlannerKind> planners_or_default(const LargeOptions& options) {
  return options.planners.empty()
             ? std::vector<core::PlannerKind>{core::PlannerKind::kAStar, core::PlannerKind::kJps,
                                              core::PlannerKind::kVnsBaStar}
             : options.planners;
}

// The checks every mode makes first; prints what is wrong, naming the option.
bool check_large_options(const LargeOptions& options) {
  if (options.queries < 1) {
    std::fprintf(stderr, "vnsba_bench large: --queries must be >= 1, got %d\n", options.queries);
    return false;
  }
  for (const int size : options.sizes) {
    if (size < kSourceSize || size % kSourceSize != 0 || size > 16384) {
      std::fprintf(
          stderr, "vnsba_bench large: --sizes: %d is not a multiple of %d cells from %d to 16384\n",
          size, kSourceSize, kSourceSize);
      return false;
    }
  }
  return true;
}

// The source map of `spec` with its scenarios, kSourceSize cells a side; prints what is wrong
// (naming the file) and returns nothing.
std::optional<LoadedMap> load_source_map(const std::string& maps_dir, const LargeMapSpec& spec) {
  auto loaded = load_map_with_scenarios(maps_dir + "/" + spec.name + ".map");
  if (!loaded) {
    std::fprintf(stderr, "vnsba_bench large: %s\n", loaded.error().message.c_str());
    return std::nullopt;
  }
  if (loaded->grid.width != kSourceSize || loaded->grid.height != kSourceSize) {
    std::fprintf(stderr, "vnsba_bench large: %s is %d x %d cells, expected %d x %d\n", spec.name,
                 loaded->grid.width, loaded->grid.height, kSourceSize, kSourceSize);
    return std::nullopt;
  }
  return std::move(loaded).value();
}

// The source grown to `size` cells a side and built as the planners' map; prints what is wrong
// and returns null.
std::shared_ptr<const core::GridMap> build_grown_map(const LoadedMap& source,
                                                     const LargeMapSpec& spec, int size) {
  core::GridBuildOptions build;
  build.max_cells = int64_t{size} * size;
  auto built = core::GridMap::build(grow_grid(source.grid, size / kSourceSize, spec.growth), build);
  if (!built) {
    std::fprintf(stderr, "vnsba_bench large: %s at %d: %s\n", spec.name, size,
                 built.error().message.c_str());
    return nullptr;
  }
  return std::make_shared<const core::GridMap>(std::move(built).value());
}

// The picked scenarios of `source` as queries on its map grown to `size` cells a side.
std::vector<core::PlanQuery> grown_queries(const LoadedMap& source, const LargeMapSpec& spec,
                                           int size, int limit) {
  std::vector<core::PlanQuery> queries;
  for (const size_t i : pick_scenarios(source.scenarios.size(), limit))
    queries.push_back(grown_query(source.scenarios[i], size / kSourceSize, spec.growth,
                                  source.grid.width, source.grid.height));
  return queries;
}

// ---- Memory mode --------------------------------------------------------------------------

// The line a memory mode child prints on stdout, then key=value fields.
constexpr const char* kChildLinePrefix = "vnsba_bench_large_memory_child";

// A field of /proc/self/status in KiB ("VmRSS": resident now, "VmHWM": the peak resident set
// of this process image), -1 when it cannot be read. VmHWM rather than getrusage's ru_maxrss:
// Linux carries ru_maxrss over an exec from the image before it (the parent's, for a child of
// posix_spawn), VmHWM belongs to this image alone.
int64_t proc_status_kib(const char* field) {
  std::ifstream status("/proc/self/status");
  const std::string key = std::string(field) + ":";
  for (std::string line; std::getline(status, line);)
    if (line.rfind(key, 0) == 0) return std::stoll(line.substr(key.size()));
  return -1;
}

// Lowers VmHWM to the current RSS ("5" into /proc/self/clear_refs, Linux 4.0 on), so that the
// next read of VmHWM is the peak of what runs after this call; false when the kernel refuses.
bool reset_peak_rss() {
  std::ofstream clear_refs("/proc/self/clear_refs");
  clear_refs << "5";
  clear_refs.flush();
  return clear_refs.good();
}

// A memory mode child: one map, one size, one planner (the parent passes exactly one of each).
// Prints its figures on stdout as one line (kChildLinePrefix, then key=value fields).
int run_memory_child(const LargeOptions& options) {
  const LargeMapSpec* spec = find_map_spec(options.memory_child_map);
  if (spec == nullptr || options.sizes.size() != 1 || options.planners.size() != 1) {
    std::fprintf(stderr,
                 "vnsba_bench large: a memory child runs one known map, one size and one planner "
                 "(map '%s', %zu sizes, %zu planners)\n",
                 options.memory_child_map.c_str(), options.sizes.size(), options.planners.size());
    return kExitBadInput;
  }
  // Before any map: the program, its libraries and the C++ runtime.
  const int64_t baseline_kib = proc_status_kib("VmRSS");
  const int size = options.sizes.front();
  std::shared_ptr<const core::GridMap> map;
  std::vector<core::PlanQuery> queries;
  {
    // The 512 x 512 source (and its own small GridMap) goes out of scope before the search:
    // only the grown map stays, as a node holds only its slice's.
    const std::optional<LoadedMap> source = load_source_map(options.maps_dir, *spec);
    if (!source) return kExitBadInput;
    map = build_grown_map(*source, *spec, size);
    if (!map) return kExitBadInput;
    queries = grown_queries(*source, *spec, size, options.queries);
  }
  // The planner and what it reads of the map beyond the cells (prepare: VNS-BA*'s obstacle
  // density table), as the node makes them when a map goes live: map memory, not search.
  core::Planner planner(map);
  const core::PlannerOptions planner_options = core::make_options(options.planners.front(), {});
  planner.prepare(planner_options);
  const int64_t build_peak_kib = proc_status_kib("VmHWM");
  const int64_t map_rss_kib = proc_status_kib("VmRSS");
  const bool peak_was_reset = reset_peak_rss();
  Sample sample;
  std::string found;  // '1' or '0' per query, for the parent to compare the planners
  for (const core::PlanQuery& q : queries) {
    const TimedPlan timed = timed_plan(planner, q, planner_options);
    sample.time_us.push_back(timed.time_us);
    sample.expanded.push_back(static_cast<double>(timed.result.metrics.expanded));
    found += timed.result.status.is_ok() ? '1' : '0';
    if (!timed.result.status.is_ok()) ++sample.failures;
  }
  const int64_t end_peak_kib = proc_status_kib("VmHWM");
  // With the reset, end_peak_kib is the peak of the planner and its queries alone.
  const int64_t search_peak_kib = peak_was_reset ? end_peak_kib : -1;
  const int64_t peak_kib = std::max(build_peak_kib, end_peak_kib);
  std::printf(
      "%s queries=%zu failed=%d p50_us=%.3f p95_us=%.3f expanded_p50=%.0f baseline_kib=%lld "
      "map_bytes=%zu map_rss_kib=%lld build_peak_kib=%lld search_peak_kib=%lld peak_kib=%lld "
      "found=%s\n",
      kChildLinePrefix, queries.size(), sample.failures, median(sample.time_us),
      percentile(sample.time_us, 95), median(sample.expanded), static_cast<long long>(baseline_kib),
      map->bytes(), static_cast<long long>(map_rss_kib), static_cast<long long>(build_peak_kib),
      static_cast<long long>(search_peak_kib), static_cast<long long>(peak_kib), found.c_str());
  return kExitOk;
}

struct ChildRun {
  int exit_code = 0;   // the child's; 128 + signal when a signal ended it
  std::string output;  // its stdout (its stderr goes to ours)
};

// This very program again (/proc/self/exe) with `args` (args[0] is its name), its stdout read
// through a pipe. posix_spawn rather than fork: no copy of this process's pages, whatever it
// holds. exit_code -1: it could not be started (errno's message printed).
ChildRun run_self(const std::vector<std::string>& args) {
  ChildRun run;
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) {
    std::fprintf(stderr, "vnsba_bench large: pipe: %s\n", std::strerror(errno));
    run.exit_code = -1;
    return run;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[1]);
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(pipe_fds[1]);
  if (spawned != 0) {
    std::fprintf(stderr, "vnsba_bench large: cannot start /proc/self/exe: %s\n",
                 std::strerror(spawned));
    close(pipe_fds[0]);
    run.exit_code = -1;
    return run;
  }
  char buffer[4096];
  for (ssize_t n; (n = read(pipe_fds[0], buffer, sizeof buffer)) != 0;) {
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    run.output.append(buffer, static_cast<size_t>(n));
  }
  close(pipe_fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return run;
}

// The key=value fields of a child's line; empty when its output has none.
std::map<std::string, std::string> child_fields(const std::string& output) {
  std::map<std::string, std::string> fields;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(kChildLinePrefix, 0) != 0) continue;
    std::istringstream words(line.substr(std::strlen(kChildLinePrefix)));
    for (std::string word; words >> word;)
      if (const size_t eq = word.find('='); eq != std::string::npos)
        fields[word.substr(0, eq)] = word.substr(eq + 1);
  }
  return fields;
}

std::string mib(double kib) {
  return kib < 0 ? "n/a" : format(kib / 1024.0, 1);
}

int run_memory(const LargeOptions& options) {
  const std::vector<core::PlannerKind> planners = planners_or_default(options);
  MarkdownTable table({"map", "cells", "planner", "queries", "failed", "time p50 (ms)",
                       "time p95 (ms)", "expanded p50", "baseline RSS (MiB)", "GridMap (MiB)",
                       "RSS with map (MiB)", "search (MiB)", "peak RSS (MiB)",
                       "peak bytes / cell"});
  int exit_code = kExitOk;
  // A worse outcome replaces a milder one: bad input (2) over a failed measurement (1).
  auto fail = [&exit_code](int code) {
    if (code == kExitBadInput || exit_code == kExitOk) exit_code = code;
  };
  for (const LargeMapSpec& spec : kLargeMaps) {
    for (const int size : options.sizes) {
      std::optional<std::string> first_found;  // the first planner's, for the others to match
      for (const core::PlannerKind planner : planners) {
        const std::string planner_name(core::to_string(planner));
        std::fprintf(stderr, "%s at %d x %d, %s: a child process\n", spec.name, size, size,
                     planner_name.c_str());
        const ChildRun run =
            run_self({"vnsba_bench", "large", "--maps", options.maps_dir, "--sizes",
                      std::to_string(size), "--queries", std::to_string(options.queries),
                      "--planners", planner_name, "--memory-child", spec.name});
        auto fields = child_fields(run.output);
        if (run.exit_code != 0 || fields.count("peak_kib") == 0) {
          std::fprintf(stderr, "vnsba_bench large --memory: %s at %d with %s: the child %s %d\n",
                       spec.name, size, planner_name.c_str(),
                       run.exit_code > 128 ? "was ended by signal" : "exited",
                       run.exit_code > 128 ? run.exit_code - 128 : run.exit_code);
          fail(run.exit_code == kExitBadInput ? kExitBadInput : kExitFailure);
          continue;
        }
        // Every planner here is complete: all find a path or none does (see run_interleaved).
        if (!first_found) first_found = fields["found"];
        if (fields["found"] != *first_found) {
          std::fprintf(stderr,
                       "vnsba_bench large --memory: %s at %d: %s finds paths for queries %s, "
                       "the first planner for %s\n",
                       spec.name, size, planner_name.c_str(), fields["found"].c_str(),
                       first_found->c_str());
          fail(kExitFailure);
        }
        auto number = [&fields](const char* key) { return std::stod(fields[key]); };
        const double cells = double(size) * size;
        const double search_peak_kib = number("search_peak_kib");
        table.add_row({map_label(spec), std::to_string(size) + "²", planner_name, fields["queries"],
                       fields["failed"], format(number("p50_us") / 1000.0, 2),
                       format(number("p95_us") / 1000.0, 2), fields["expanded_p50"],
                       mib(number("baseline_kib")), mib(number("map_bytes") / 1024.0),
                       mib(number("map_rss_kib")),
                       search_peak_kib < 0 ? "n/a" : mib(search_peak_kib - number("map_rss_kib")),
                       mib(number("peak_kib")), format(number("peak_kib") * 1024.0 / cells, 1)});
      }
    }
  }
  std::printf(
      "**Large maps, memory.** One process per map, size and planner, each building its map and "
      "planning the same queries with its planner only; times as in the interleaved table, RSS "
      "from the child's /proc/self/status (MiB = 2^20 bytes).\n\n%s\n",
      table.str().c_str());
  return exit_code;
}

// ---- Writing the grown maps -----------------------------------------------------------------

// `map` as a Moving AI .map ('@' blocked, '.' free; the top row first, as the loader reads it).
std::string movingai_map_text(const core::GridMap& map) {
  std::string text = "type octile\nheight " + std::to_string(map.height()) + "\nwidth " +
                     std::to_string(map.width()) + "\nmap\n";
  text.reserve(text.size() + static_cast<size_t>(map.cell_count() + map.height()));
  for (int32_t y = map.height() - 1; y >= 0; --y) {
    for (int32_t x = 0; x < map.width(); ++x) text += map.blocked(x, y) ? '@' : '.';
    text += '\n';
  }
  return text;
}

// The grown maps and queries as `<source>-<size>.map` and `.map.scen` (version 1, tab-separated,
// file rows counted from the top). A scenario's optimal length is our jps's grid path cost
// (exact: octile moves, no corner cutting, as Moving AI's); 0 for a query with no path (a
// tiled map's two copies may not be joined).
int write_grown_maps(const LargeOptions& options) {
  if (const core::Status made = ensure_directory(options.write_maps_dir); !made.is_ok()) {
    std::fprintf(stderr, "vnsba_bench large: --write-maps: %s\n", made.message.c_str());
    return kExitBadInput;
  }
  for (const LargeMapSpec& spec : kLargeMaps) {
    const std::optional<LoadedMap> source = load_source_map(options.maps_dir, spec);
    if (!source) return kExitBadInput;
    for (const int size : options.sizes) {
      const std::shared_ptr<const core::GridMap> map = build_grown_map(*source, spec, size);
      if (!map) return kExitBadInput;
      const std::string name = std::string(spec.name) + "-" + std::to_string(size) + ".map";
      const std::string path = options.write_maps_dir + "/" + name;
      if (!write_file_or_report(path, movingai_map_text(*map))) return kExitBadInput;
      core::Planner planner(map);
      const core::PlannerOptions jps = core::make_options(core::PlannerKind::kJps, {});
      std::string scen = "version 1\n";
      int bucket = 0;
      for (const core::PlanQuery& q : grown_queries(*source, spec, size, options.queries)) {
        const core::PlanResult r = planner.plan(q, jps);
        char line[256];
        std::snprintf(line, sizeof line, "%d\t%s\t%d\t%d\t%d\t%d\t%d\t%d\t%.8f\n", bucket++,
                      name.c_str(), map->width(), map->height(), q.start.x,
                      map->height() - 1 - q.start.y, q.goal.x, map->height() - 1 - q.goal.y,
                      r.status.is_ok() ? r.metrics.raw_cost_cells : 0.0);
        scen += line;
      }
      if (!write_file_or_report(path + ".scen", scen)) return kExitBadInput;
      std::fprintf(stderr, "wrote %s and its .scen\n", path.c_str());
    }
  }
  return kExitOk;
}

}  // namespace

// The source grid grown to `factor` times its side, either way (see large.hpp). Resolution and
// origin are irrelevant to planning in cells; the slice is given 5 cm cells, as an office's.
core::OccupancyGrid grow_grid(const core::OccupancyGrid& source, int factor, Growth growth) {
  core::OccupancyGrid g;
  g.width = source.width * factor;
  g.height = source.height * factor;
  g.resolution = 0.05;
  g.data.resize(static_cast<size_t>(g.width) * g.height);
  for (int32_t y = 0; y < g.height; ++y)
    for (int32_t x = 0; x < g.width; ++x)
      g.data[static_cast<size_t>(y) * g.width + x] =
          growth == Growth::kScaled ? source.at(x / factor, y / factor)
                                    : source.at(x % source.width, y % source.height);
  return g;
}

namespace {

// Every planner in this one process, query by query (see large.hpp).
int run_interleaved(const LargeOptions& options) {
  const std::vector<core::PlannerKind> planners = planners_or_default(options);
  std::vector<std::string> headers = {"map",    "cells",         "planner",       "queries",
                                      "failed", "time p50 (ms)", "time p95 (ms)", "expanded p50"};
  const bool with_astar =
      std::find(planners.begin(), planners.end(), core::PlannerKind::kAStar) != planners.end();
  if (with_astar) headers.push_back("p50 / A*'s");
  MarkdownTable table(headers);
  bool all_ok = true;
  // The plans to come, for the progress line (a scenario file that does not load counts 0 and
  // fails below).
  int64_t plans_total = 0;
  for (const LargeMapSpec& spec : kLargeMaps)
    if (const auto scenarios =
            maps::load_movingai_scenarios(options.maps_dir + "/" + spec.name + ".map.scen"))
      plans_total +=
          static_cast<int64_t>(pick_scenarios(scenarios->size(), options.queries).size() *
                               planners.size() * options.sizes.size());
  render::Progress progress("vnsba_bench large", plans_total,
                            render::progress_wanted(options.progress));
  int64_t plans_done = 0;
  for (const LargeMapSpec& spec : kLargeMaps) {
    const std::optional<LoadedMap> loaded = load_source_map(options.maps_dir, spec);
    if (!loaded) return kExitBadInput;
    for (const int size : options.sizes) {
      const int factor = size / kSourceSize;
      const std::shared_ptr<const core::GridMap> map = build_grown_map(*loaded, spec, size);
      if (!map) return kExitBadInput;
      core::Planner planner(map);
      // As the node does when a map goes live: what a planner reads beyond the cells.
      for (const core::PlannerKind kind : planners) planner.prepare(core::make_options(kind, {}));
      const std::vector<core::PlanQuery> queries =
          grown_queries(*loaded, spec, size, options.queries);
      std::fprintf(stderr, "%s %s x%d (%d x %d): %zu queries\n", spec.name,
                   spec.growth == Growth::kScaled ? "scaled" : "tiled", factor, size, size,
                   queries.size());
      std::vector<Sample> samples(planners.size());
      // Interleaved by query, so that a slow moment of the machine hits every planner alike.
      for (const core::PlanQuery& q : queries) {
        std::vector<bool> found;
        for (size_t p = 0; p < planners.size(); ++p) {
          const TimedPlan timed = timed_plan(planner, q, core::make_options(planners[p], {}));
          samples[p].time_us.push_back(timed.time_us);
          samples[p].expanded.push_back(static_cast<double>(timed.result.metrics.expanded));
          found.push_back(timed.result.status.is_ok());
          if (!found.back()) ++samples[p].failures;
          progress.update(++plans_done);
        }
        // Every planner here is complete: all find a path or none does (a tiled query's two
        // copies may not be connected). Anything else is a planner's failure.
        if (std::adjacent_find(found.begin(), found.end(), std::not_equal_to<>()) != found.end()) {
          std::fprintf(stderr, "vnsba_bench large: planners disagree on (%d, %d) -> (%d, %d)\n",
                       q.start.x, q.start.y, q.goal.x, q.goal.y);
          all_ok = false;
        }
      }
      double astar_p50 = NAN;
      for (size_t p = 0; p < planners.size(); ++p)
        if (planners[p] == core::PlannerKind::kAStar) astar_p50 = median(samples[p].time_us);
      for (size_t p = 0; p < planners.size(); ++p) {
        const Sample& s = samples[p];
        std::vector<std::string> row = {map_label(spec),
                                        std::to_string(size) + "²",
                                        std::string(core::to_string(planners[p])),
                                        std::to_string(s.time_us.size()),
                                        std::to_string(s.failures),
                                        format(median(s.time_us) / 1000.0, 2),
                                        format(percentile(s.time_us, 95) / 1000.0, 2),
                                        format(median(s.expanded), 0)};
        if (with_astar) row.push_back(format(median(s.time_us) / astar_p50, 4));
        table.add_row(row);
      }
    }
  }
  progress.finish(plans_done);
  std::printf(
      "**Large maps.** Planning time per query (search and each planner's paper "
      "configuration of pruning and smoothing), p50 and p95 over the same queries, "
      "planners interleaved query by query.\n\n%s\n",
      table.str().c_str());
  return all_ok ? kExitOk : kExitFailure;
}

}  // namespace

int run_large(const LargeOptions& options) {
  if (!check_large_options(options)) return kExitBadInput;
  if (!options.write_maps_dir.empty()) return write_grown_maps(options);
  if (!options.memory_child_map.empty()) return run_memory_child(options);
  if (options.memory) return run_memory(options);
  return run_interleaved(options);
}

}  // namespace vnsba::bench
