#include "bench/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bench/common.hpp"
#include "vnsba/render/charts.hpp"
#include "vnsba/render/progress.hpp"
#include "vnsba/render/svg.hpp"

namespace vnsba::bench {
namespace {

constexpr int kSteps = 11;  // 0, 0.1, ..., 1
constexpr int kMiddle = 5;  // index of 0.5

double weight(int index) {
  return index / 10.0;
}

struct Metric {
  const char* key;    // file names
  const char* label;  // tables and charts, with the unit
  int decimals;
};
constexpr Metric kSweepMetrics[] = {{"expanded", "expanded nodes", 0},
                                    {"time", "time (us, median)", 1},
                                    {"length", "length (cells)", 2}};

// values[metric][omega index][eta index]
using Grid = std::vector<std::vector<double>>;

// How many finite values the grid holds.
int finite_count(const Grid& grid) {
  int count = 0;
  for (const auto& row : grid)
    for (const double v : row) count += std::isfinite(v) ? 1 : 0;
  return count;
}

// Rank of value among all finite values of the grid (1 = the lowest), ties sharing the best rank.
int rank_of(const Grid& grid, double value) {
  int below = 0;
  for (const auto& row : grid)
    for (const double v : row)
      if (std::isfinite(v) && v < value) ++below;
  return below + 1;
}

std::pair<int, int> best_cell(const Grid& grid) {
  std::pair<int, int> best{0, 0};
  for (int o = 0; o < kSteps; ++o)
    for (int e = 0; e < kSteps; ++e)
      if (std::isfinite(grid[o][e]) && (!std::isfinite(grid[best.first][best.second]) ||
                                        grid[o][e] < grid[best.first][best.second]))
        best = {o, e};
  return best;
}

std::string pair_name(std::pair<int, int> cell) {
  return format(weight(cell.first), 1) + " / " + format(weight(cell.second), 1);
}

}  // namespace

std::vector<std::string> sweep_map_names() {
  return {"sweep_simple", "sweep_middle", "sweep_bars", "sweep_random"};
}

std::vector<std::string> sweep_output_files() {
  std::vector<std::string> files = {"sweep_tables.md", "sweep_results.csv"};
  for (const auto& map : sweep_map_names())
    for (const auto& metric : kSweepMetrics) files.push_back(map + "_" + metric.key + ".svg");
  return files;
}

int run_sweep(const SweepOptions& options) {
  if (!check_run_options("sweep", options.repetitions, options.maps_dir, options.out_dir))
    return kExitBadInput;

  std::string csv = "map,omega,eta,status,expanded,time_us_median,length,turns,turn_angle_deg\n";
  std::string md;
  md += "### Omega / eta sweep (Table 1, Figure 3)\n\n";
  md +=
      "VNS-BA* in its paper configuration with omega and eta from 0 to 1 in steps of 0.1; time "
      "is the median of " +
      std::to_string(options.repetitions) +
      " plans in microseconds, length the final path's in cells. Rank: the position of the pair "
      "0.5 / 0.5 among the pairs (1 = lowest value; equal values share a rank). The pair 0 / 0 "
      "is left blank: with both weights zero the heuristic vanishes and the planner refuses "
      "it, so 120 pairs are ranked.\n\n";
  MarkdownTable summary({"map", "metric", "best pair (omega / eta)", "best value",
                         "value at 0.5 / 0.5", "rank of 0.5 / 0.5"});
  std::string full_tables;
  // Relative values (value / the map's best) summed over maps, per metric, to find the pair that
  // is best over all four maps together.
  std::vector<Grid> relative_sum(std::size(kSweepMetrics),
                                 Grid(kSteps, std::vector<double>(kSteps, 0.0)));
  bool all_ok = true;

  render::Progress progress("vnsba_bench sweep",
                            static_cast<int64_t>(sweep_map_names().size()) * kSteps * kSteps,
                            render::progress_wanted(options.progress));
  int64_t pairs_done = 0;
  for (const auto& name : sweep_map_names()) {
    const std::string path = options.maps_dir + "/" + name + ".map";
    auto loaded = load_map_with_scenarios(path);
    if (!loaded) {
      std::fprintf(stderr, "vnsba_bench sweep: %s\n", loaded.error().message.c_str());
      return kExitBadInput;
    }
    if (loaded->scenarios.empty()) {
      std::fprintf(stderr, "vnsba_bench sweep: %s.scen has no scenario line\n", path.c_str());
      return kExitBadInput;
    }
    const core::PlanQuery query{loaded->scenarios.front().start, loaded->scenarios.front().goal};
    core::Planner planner(loaded->map);
    std::vector<Grid> values(std::size(kSweepMetrics),
                             Grid(kSteps, std::vector<double>(kSteps, NAN)));
    for (int o = 0; o < kSteps; ++o) {
      for (int e = 0; e < kSteps; ++e) {
        core::PlannerSettings settings;
        settings.omega = weight(o);
        settings.eta = weight(e);
        const core::PlannerOptions plan_options =
            core::make_options(core::PlannerKind::kVnsBaStar, settings);
        const core::PlanResult r = planner.plan(query, plan_options);
        char line[256];
        if (!r.status.is_ok()) {
          // omega = eta = 0 makes the heuristic vanish; the planner refuses it by design
          // (validate() in planner.hpp), so that pair is left blank rather than counted a failure.
          const bool refused_by_design =
              o == 0 && e == 0 && r.status.code == core::StatusCode::kInvalidRequest;
          if (!refused_by_design) all_ok = false;
          if (!refused_by_design)
            std::fprintf(stderr, "%s omega %.1f eta %.1f: %s\n", name.c_str(), weight(o), weight(e),
                         r.status.message.c_str());
          std::snprintf(line, sizeof line, "%s,%.1f,%.1f,%s,,,,,\n", name.c_str(), weight(o),
                        weight(e), std::string(core::to_string(r.status.code)).c_str());
          csv += line;
          continue;
        }
        const double time_us =
            median_plan_time_us(planner, query, plan_options, options.repetitions);
        values[0][o][e] = static_cast<double>(r.metrics.expanded);
        values[1][o][e] = time_us;
        values[2][o][e] = r.metrics.length_cells;
        std::snprintf(line, sizeof line, "%s,%.1f,%.1f,OK,%lld,%.3f,%.6f,%d,%.4f\n", name.c_str(),
                      weight(o), weight(e), static_cast<long long>(r.metrics.expanded), time_us,
                      r.metrics.length_cells, r.metrics.turns, r.metrics.turn_angle_deg);
        csv += line;
      }
      pairs_done += kSteps;  // one row of pairs, repetitions included
      progress.update(pairs_done);
    }
    std::fprintf(stderr, "%s done\n", name.c_str());

    for (size_t m = 0; m < std::size(kSweepMetrics); ++m) {
      const Metric& metric = kSweepMetrics[m];
      const Grid& grid = values[m];
      const auto best = best_cell(grid);
      const double best_value = grid[best.first][best.second];
      summary.add_row({name, metric.label, pair_name(best), format(best_value, metric.decimals),
                       format(grid[kMiddle][kMiddle], metric.decimals),
                       std::to_string(rank_of(grid, grid[kMiddle][kMiddle])) + " of " +
                           std::to_string(finite_count(grid))});
      for (int o = 0; o < kSteps; ++o)
        for (int e = 0; e < kSteps; ++e)
          relative_sum[m][o][e] += best_value > 0 ? grid[o][e] / best_value : NAN;

      render::HeatMap heat;
      heat.title = name + ": " + metric.label;
      heat.x_label = "eta";
      heat.y_label = "omega";
      for (int i = 0; i < kSteps; ++i) {
        heat.x_ticks.push_back(format(weight(i), 1));
        heat.y_ticks.push_back(format(weight(i), 1));
      }
      heat.values = grid;
      heat.value_label = metric.label;
      heat.value_decimals = metric.decimals == 0 ? 0 : 1;
      heat.lower_is_better = true;
      heat.highlight = best;
      if (!write_file_or_report(options.out_dir + "/" + name + "_" + metric.key + ".svg",
                                render::render_heat_map_svg(heat)))
        return kExitBadInput;

      // The full grid as a table: rows omega, columns eta.
      full_tables += "**" + name + ": " + metric.label + "** (rows omega, columns eta)\n\n";
      std::vector<std::string> headers = {"omega \\ eta"};
      for (int e = 0; e < kSteps; ++e) headers.push_back(format(weight(e), 1));
      MarkdownTable table(headers);
      for (int o = 0; o < kSteps; ++o) {
        std::vector<std::string> cells = {format(weight(o), 1)};
        for (int e = 0; e < kSteps; ++e) cells.push_back(format(grid[o][e], metric.decimals));
        table.add_row(cells);
      }
      full_tables += table.str() + "\n";
    }
  }

  md += summary.str() + "\n";
  md +=
      "Over all four maps together (each value divided by its map's best, summed; 4.00 would be "
      "best on every map):\n\n";
  MarkdownTable together(
      {"metric", "best pair (omega / eta)", "its sum", "sum at 0.5 / 0.5", "rank of 0.5 / 0.5"});
  progress.finish(pairs_done);
  for (size_t m = 0; m < std::size(kSweepMetrics); ++m) {
    const auto best = best_cell(relative_sum[m]);
    together.add_row({kSweepMetrics[m].label, pair_name(best),
                      format(relative_sum[m][best.first][best.second], 2),
                      format(relative_sum[m][kMiddle][kMiddle], 2),
                      std::to_string(rank_of(relative_sum[m], relative_sum[m][kMiddle][kMiddle])) +
                          " of " + std::to_string(finite_count(relative_sum[m]))});
  }
  md += together.str() + "\n";
  md += "Heat maps (best pair outlined in red):\n\n";
  MarkdownTable links({"map", "expanded", "time", "length"});
  for (const auto& name : sweep_map_names()) {
    std::vector<std::string> cells = {name};
    for (const auto& metric : kSweepMetrics) {
      const std::string file = name + "_" + metric.key + ".svg";
      cells.push_back("[svg](" + file + ")");
    }
    links.add_row(cells);
  }
  md += links.str() + "\n";
  md +=
      "The full 11 x 11 grids are in [sweep_full_tables](sweep_tables.md#full-grids) and "
      "[sweep_results.csv](sweep_results.csv).\n\n";

  const std::string tables_file = md + "### Full grids\n\n" + full_tables;
  if (!write_file_or_report(options.out_dir + "/sweep_results.csv", csv) ||
      !write_file_or_report(options.out_dir + "/sweep_tables.md", tables_file))
    return kExitBadInput;
  std::fputs(md.c_str(), stdout);
  return all_ok ? kExitOk : kExitFailure;
}

}  // namespace vnsba::bench
