#include "bench/paper.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "bench/common.hpp"
#include "vnsba/render/charts.hpp"
#include "vnsba/render/run_picture.hpp"
#include "vnsba/render/svg.hpp"

namespace vnsba::bench {
namespace {

using core::PlannerKind;

struct PaperMap {
  const char* name;  // file stem and table label
  const char* size;  // "20 x 20"
  int table;         // the paper's table number
  int figure;        // the paper's figure number
};

constexpr PaperMap kPaperMaps[] = {{"A", "20 x 20", 2, 8},
                                   {"B", "40 x 40", 3, 9},
                                   {"C", "60 x 60", 4, 10},
                                   {"D", "80 x 80", 5, 11}};

// A planner in one configuration: the paper's, or a baseline with our post-processing, or
// VNS-BA*'s search alone.
enum class Config { kPaper, kPostProcessed, kSearchOnly };

const char* config_name(Config config) {
  switch (config) {
    case Config::kPaper:
      return "paper";
    case Config::kPostProcessed:
      return "+prune+smooth";
    case Config::kSearchOnly:
      return "search only";
  }
  return "?";
}

// What a configuration sets; the rest is the planner's paper configuration (core::make_options).
core::PlannerSettings settings_for(Config config) {
  core::PlannerSettings settings;
  if (config == Config::kPostProcessed) settings.prune = settings.smooth = true;
  if (config == Config::kSearchOnly) settings.prune = settings.smooth = false;
  return settings;
}

struct Row {
  std::string map;
  PlannerKind planner;
  Config config;
  core::PlanResult result;  // one plan with the expansions recorded and the length ratio
  double time_us = NAN;     // median over the repetitions
};

// The five metrics of Table 6, in its order.
struct MetricDef {
  const char* name;
  double (*get)(const Row&);
};
const MetricDef kMetrics[] = {
    {"length", [](const Row& r) { return r.result.metrics.length_cells; }},
    {"turns", [](const Row& r) { return static_cast<double>(r.result.metrics.turns); }},
    {"turn angle", [](const Row& r) { return r.result.metrics.turn_angle_deg; }},
    {"expanded", [](const Row& r) { return static_cast<double>(r.result.metrics.expanded); }},
    {"time", [](const Row& r) { return r.time_us; }},
};

// The paper's four baselines: Table 6, Figure 12 and the check of its claims compare against
// these only (jps is not one of them).
std::vector<PlannerKind> baselines() {
  std::vector<PlannerKind> out;
  for (const auto kind : core::all_planner_kinds())
    if (kind != PlannerKind::kVnsBaStar && kind != PlannerKind::kJps) out.push_back(kind);
  return out;
}

// Every other planner, jps included: the comparison with post-processed baselines.
std::vector<PlannerKind> all_baselines() {
  std::vector<PlannerKind> out;
  for (const auto kind : core::all_planner_kinds())
    if (kind != PlannerKind::kVnsBaStar) out.push_back(kind);
  return out;
}

// The arithmetic mean of the available rates (the paper's "overall optimization rate").
double overall(const std::vector<double>& rates) {
  std::vector<double> finite;
  for (const double r : rates)
    if (std::isfinite(r)) finite.push_back(r);
  return mean(finite);
}

std::string percent(double value) {
  return std::isfinite(value) ? format(value, 1) + " %" : "n/a";
}

}  // namespace

std::vector<std::string> paper_output_files() {
  std::vector<std::string> files = {"paper_tables.md", "paper_results.csv",
                                    "figure12_overall_improvement.svg"};
  for (const auto& m : kPaperMaps)
    for (const auto kind : core::all_planner_kinds()) {
      char name[96];
      std::snprintf(name, sizeof name, "figure%02d_%s_%s.svg", m.figure, m.name,
                    std::string(core::to_string(kind)).c_str());
      files.push_back(name);
    }
  return files;
}

double improvement_rate_percent(double baseline, double ours) {
  if (baseline == 0.0) return ours == 0.0 ? 0.0 : NAN;
  return 100.0 * (baseline - ours) / baseline;
}

int run_paper(const PaperOptions& options) {
  if (!check_run_options("paper", options.repetitions, options.maps_dir, options.out_dir))
    return kExitBadInput;

  std::vector<Row> rows;
  std::map<std::string, core::PlanQuery> queries;
  bool all_ok = true;
  for (const auto& paper_map : kPaperMaps) {
    const std::string path = options.maps_dir + "/" + paper_map.name + ".map";
    auto loaded = load_map_with_scenarios(path);
    if (!loaded) {
      std::fprintf(stderr, "vnsba_bench paper: %s\n", loaded.error().message.c_str());
      return kExitBadInput;
    }
    if (loaded->scenarios.empty()) {
      std::fprintf(stderr, "vnsba_bench paper: %s.scen has no scenario line\n", path.c_str());
      return kExitBadInput;
    }
    const core::PlanQuery query{loaded->scenarios.front().start, loaded->scenarios.front().goal};
    queries[paper_map.name] = query;
    core::Planner planner(loaded->map);
    const auto picture_map =
        std::make_shared<const render::MapPicture>(render::map_picture(*loaded->map));
    std::fprintf(stderr, "map %s (%s): ", paper_map.name, paper_map.size);
    for (const auto kind : core::all_planner_kinds()) {
      std::vector<Config> configs = {Config::kPaper};
      configs.push_back(kind == PlannerKind::kVnsBaStar ? Config::kSearchOnly
                                                        : Config::kPostProcessed);
      for (const Config config : configs) {
        core::PlannerSettings measured = settings_for(config);
        measured.record_expansions = config == Config::kPaper;  // for the figures
        measured.compute_length_ratio = true;
        Row row{paper_map.name, kind, config, {}, NAN};
        row.result = planner.plan(query, core::make_options(kind, measured));
        if (!row.result.status.is_ok()) {
          all_ok = false;
          std::fprintf(stderr, "\n%s on map %s (%s): %s: %s\n",
                       std::string(core::to_string(kind)).c_str(), paper_map.name,
                       config_name(config),
                       std::string(core::to_string(row.result.status.code)).c_str(),
                       row.result.status.message.c_str());
        } else {
          row.time_us = median_plan_time_us(
              planner, query, core::make_options(kind, settings_for(config)), options.repetitions);
        }
        if (config == Config::kPaper) {
          render::RunPicture picture = render::picture_of(picture_map, query, row.result);
          picture.options = render::path_options(core::make_options(kind, measured));
          picture.title = std::string("map ") + paper_map.name + " (figure " +
                          std::to_string(paper_map.figure) + ")";
          char name[96];
          std::snprintf(name, sizeof name, "figure%02d_%s_%s.svg", paper_map.figure, paper_map.name,
                        std::string(core::to_string(kind)).c_str());
          if (!write_file_or_report(options.out_dir + "/" + name, render::render_svg(picture)))
            return kExitBadInput;
        }
        rows.push_back(std::move(row));
      }
      std::fprintf(stderr, "%s ", std::string(core::to_string(kind)).c_str());
    }
    std::fprintf(stderr, "\n");
  }

  const auto find = [&](const std::string& map, PlannerKind kind, Config config) -> const Row& {
    for (const Row& r : rows)
      if (r.map == map && r.planner == kind && r.config == config) return r;
    std::abort();  // every (map, planner, config) was run above
  };

  // --- CSV: every run. ---
  std::string csv =
      "map,planner,config,status,length,raw_cost,optimal_ratio,turns,turn_angle_deg,expanded,"
      "time_us_median,repetitions\n";
  for (const Row& r : rows) {
    const auto& m = r.result.metrics;
    char line[512];
    std::snprintf(line, sizeof line, "%s,%s,%s,%s,%.6f,%.6f,%.6f,%d,%.4f,%lld,%.3f,%d\n",
                  r.map.c_str(), std::string(core::to_string(r.planner)).c_str(),
                  config_name(r.config), std::string(core::to_string(r.result.status.code)).c_str(),
                  m.length_cells, m.raw_cost_cells, m.length_ratio, m.turns, m.turn_angle_deg,
                  static_cast<long long>(m.expanded), r.time_us, options.repetitions);
    csv += line;
  }

  // --- Tables 2-5. ---
  std::string md;
  md += "### Tables 2-5: the five planners on maps A-D\n\n";
  md +=
      "Length in cells (1 cell = 1 m here), final path (after smoothing where it is on); ratio: "
      "that length / the optimal 8-connected grid cost (A*); turn angle: total, in degrees; "
      "time: median of " +
      std::to_string(options.repetitions) +
      " plans, microseconds, search plus post-processing.\n\n";
  for (const auto& paper_map : kPaperMaps) {
    md += "**Table " + std::to_string(paper_map.table) + ": map " + paper_map.name + " (" +
          paper_map.size + ")** (figure " + std::to_string(paper_map.figure) + ")\n\n";
    MarkdownTable table({"planner", "length", "ratio to optimal", "turns", "turn angle (deg)",
                         "expanded", "time (us)"});
    for (const auto kind : core::all_planner_kinds()) {
      const Row& r = find(paper_map.name, kind, Config::kPaper);
      const auto& m = r.result.metrics;
      if (!r.result.status.is_ok()) {
        table.add_row({paper_name(kind), std::string(core::to_string(r.result.status.code)), "", "",
                       "", "", ""});
        continue;
      }
      table.add_row({paper_name(kind), format(m.length_cells, 2), format(m.length_ratio, 3),
                     std::to_string(m.turns), format(m.turn_angle_deg, 1),
                     std::to_string(m.expanded), format(r.time_us, 1)});
    }
    md += table.str() + "\n";
  }

  // --- Table 6 and Figure 12. ---
  md +=
      "### Table 6: improvement rate of VNS-BA* over each baseline, (baseline - ours) / "
      "baseline\n\n";
  md +=
      "Positive: VNS-BA* is better (shorter, fewer turns, less turning, fewer expansions, "
      "faster). Overall: the arithmetic mean of the five rates (the paper's \"arithmetic mean "
      "method\", section 4); a rate that is undefined (baseline 0, ours not) is left out of "
      "the mean and shown as n/a.\n\n";
  MarkdownTable table6(
      {"map", "baseline", "length", "turns", "turn angle", "expanded", "time", "overall"});
  render::BarChart figure12;
  figure12.title = "Figure 12: overall improvement rate of VNS-BA* per map";
  figure12.y_label = "overall improvement rate (%)";
  for (const auto kind : baselines()) figure12.series.push_back(paper_name(kind));
  // rates[map][baseline][metric], for the claims below.
  std::map<std::string, std::map<PlannerKind, std::vector<double>>> rates;
  for (const auto& paper_map : kPaperMaps) {
    figure12.groups.push_back(std::string("map ") + paper_map.name);
    figure12.values.emplace_back();
    const Row& ours = find(paper_map.name, PlannerKind::kVnsBaStar, Config::kPaper);
    for (const auto kind : baselines()) {
      const Row& base = find(paper_map.name, kind, Config::kPaper);
      std::vector<double>& r = rates[paper_map.name][kind];
      std::vector<std::string> cells = {paper_map.name, paper_name(kind)};
      for (const auto& metric : kMetrics) {
        const bool ok = ours.result.status.is_ok() && base.result.status.is_ok();
        r.push_back(ok ? improvement_rate_percent(metric.get(base), metric.get(ours)) : NAN);
        cells.push_back(percent(r.back()));
      }
      const double total = overall(r);
      cells.push_back("**" + percent(total) + "**");
      table6.add_row(cells);
      figure12.values.back().push_back(total);
    }
  }
  md += table6.str() + "\n";
  md += "Figure 12: [figure12_overall_improvement.svg](figure12_overall_improvement.svg)\n\n";
  if (!write_file_or_report(options.out_dir + "/figure12_overall_improvement.svg",
                            render::render_bar_chart_svg(figure12)))
    return kExitBadInput;

  // --- The paper's claims against these numbers. ---
  const auto range_of = [&](size_t metric, const std::vector<std::string>& maps,
                            const std::vector<PlannerKind>& against) {
    double low = INFINITY, high = -INFINITY;
    for (const auto& map : maps)
      for (const auto kind : against) {
        const double v = rates[map][kind][metric];
        if (!std::isfinite(v)) continue;
        low = std::min(low, v);
        high = std::max(high, v);
      }
    return std::make_pair(low, high);
  };
  const std::vector<std::string> all_maps = {"A", "B", "C", "D"};
  const std::vector<PlannerKind> unidirectional = {PlannerKind::kAStar,
                                                   PlannerKind::kWeightedAStar};
  const std::vector<PlannerKind> bidirectional = {PlannerKind::kBidirectionalAStar,
                                                  PlannerKind::kAlternatingBidirectionalAStar};
  const auto yes_no = [](bool holds) { return holds ? "yes" : "**no**"; };
  md += "### The paper's claims, checked on these runs\n\n";
  MarkdownTable claims({"claim (paper, section 4)", "these runs", "reproduced here"});
  {
    const auto [low, high] = range_of(1, all_maps, baselines());
    claims.add_row(
        {"turns down by more than 40 % on every map, against every baseline (max 80.96 %)",
         "from " + percent(low) + " to " + percent(high), yes_no(low > 40.0)});
  }
  {
    const auto [low, high] = range_of(2, all_maps, baselines());
    claims.add_row({"total turn angle down by 28.44 % to 83.53 %",
                    "from " + percent(low) + " to " + percent(high), yes_no(low >= 28.0)});
  }
  {
    const auto [low, high] = range_of(4, all_maps, unidirectional);
    claims.add_row({"planning time better than the unidirectional planners (A*, improved A*)",
                    "from " + percent(low) + " to " + percent(high), yes_no(low > 0.0)});
  }
  {
    const auto [low, high] = range_of(4, all_maps, bidirectional);
    claims.add_row({"\"some improvement\" in time over the bidirectional ones (BA*, improved BA*)",
                    "from " + percent(low) + " to " + percent(high), yes_no(low > 0.0)});
  }
  {
    double low = INFINITY;
    std::string per_map;
    for (const std::string map : {"B", "C", "D"}) {
      double map_low = INFINITY;
      for (const auto kind : baselines()) map_low = std::min(map_low, overall(rates[map][kind]));
      per_map += (per_map.empty() ? "" : ", ") + map + ": " + percent(map_low);
      low = std::min(low, map_low);
    }
    claims.add_row({"overall improvement above 30 % on maps B, C and D (lowest per map)", per_map,
                    yes_no(low > 30.0)});
  }
  {
    const auto [low_a, high_a] = range_of(3, {"A"}, baselines());
    const auto [low_d, high_d] = range_of(3, {"D"}, baselines());
    claims.add_row({"expansions: negative on the simple map, improving as maps grow",
                    "map A from " + percent(low_a) + " to " + percent(high_a) + "; map D from " +
                        percent(low_d) + " to " + percent(high_d),
                    yes_no(low_a < 0.0 && low_d > low_a)});
  }
  {
    const auto [low, high] = range_of(0, all_maps, baselines());
    claims.add_row(
        {"path length (the paper reports gains; A* is optimal on the grid, but "
         "pruning and smoothing cut corners)",
         "from " + percent(low) + " to " + percent(high), yes_no(low >= 0.0)});
  }
  md += claims.str() + "\n";

  // --- Ablation: how much of the turn reduction is post-processing? ---
  md += "### Ablation: the baselines with our pruning and smoothing, VNS-BA* without them\n\n";
  md +=
      "\"paper\": the configuration of Tables 2-5; \"+prune+smooth\": the same search followed "
      "by the polyline pruning and corner smoothing of VNS-BA*; \"search only\": VNS-BA*'s "
      "8-11-13 bidirectional search with neither.\n\n";
  MarkdownTable ablation({"map", "planner", "configuration", "length", "ratio to optimal", "turns",
                          "turn angle (deg)", "expanded", "time (us)"});
  for (const auto& paper_map : kPaperMaps)
    for (const auto kind : core::all_planner_kinds())
      for (const Config config :
           {Config::kPaper,
            kind == PlannerKind::kVnsBaStar ? Config::kSearchOnly : Config::kPostProcessed}) {
        const Row& r = find(paper_map.name, kind, config);
        const auto& m = r.result.metrics;
        ablation.add_row({paper_map.name, paper_name(kind), config_name(config),
                          format(m.length_cells, 2), format(m.length_ratio, 3),
                          std::to_string(m.turns), format(m.turn_angle_deg, 1),
                          std::to_string(m.expanded), format(r.time_us, 1)});
      }
  md += ablation.str() + "\n";
  md +=
      "Improvement rate of VNS-BA* over the post-processed baselines (same formula as Table 6):"
      "\n\n";
  MarkdownTable fair({"map", "baseline +prune+smooth", "length", "turns", "turn angle", "expanded",
                      "time", "overall"});
  for (const auto& paper_map : kPaperMaps) {
    const Row& ours = find(paper_map.name, PlannerKind::kVnsBaStar, Config::kPaper);
    for (const auto kind : all_baselines()) {
      const Row& base = find(paper_map.name, kind, Config::kPostProcessed);
      std::vector<double> r;
      std::vector<std::string> cells = {paper_map.name, paper_name(kind)};
      for (const auto& metric : kMetrics) {
        r.push_back(improvement_rate_percent(metric.get(base), metric.get(ours)));
        cells.push_back(percent(r.back()));
      }
      cells.push_back("**" + percent(overall(r)) + "**");
      fair.add_row(cells);
    }
  }
  md += fair.str() + "\n";

  md +=
      "Figures 8-11 (expansions: forward search yellow, backward blue; paths black, smoothed "
      "corners red):\n\n";
  MarkdownTable figures({"map", "A*", "improved A*", "BA*", "improved BA*", "VNS-BA*"});
  for (const auto& paper_map : kPaperMaps) {
    std::vector<std::string> cells = {std::string(paper_map.name)};
    for (const auto kind : core::all_planner_kinds()) {
      char name[96];
      std::snprintf(name, sizeof name, "figure%02d_%s_%s.svg", paper_map.figure, paper_map.name,
                    std::string(core::to_string(kind)).c_str());
      cells.push_back(std::string("[svg](") + name + ")");
    }
    figures.add_row(cells);
  }
  md += figures.str();

  if (!write_file_or_report(options.out_dir + "/paper_results.csv", csv) ||
      !write_file_or_report(options.out_dir + "/paper_tables.md", md))
    return kExitBadInput;
  std::fputs(md.c_str(), stdout);
  return all_ok ? kExitOk : kExitFailure;
}

}  // namespace vnsba::bench
