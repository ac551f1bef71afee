// vnsba_bench: offline measurements of the planners.
//
//   vnsba_bench optimality [--maps DIR]   every Moving AI scenario in DIR through A*: its path
//                                         cost must equal the published optimum; prints a table
//                                         per map and exits 1 on any mismatch.
//   vnsba_bench paper [--out DIR] [--repetitions N]
//                                         the paper's section 4 on its maps A-D: Tables 2-6,
//                                         Figures 8-12, an ablation (bench/paper.hpp)
//   vnsba_bench sweep [--out DIR] [--repetitions N]
//                                         omega / eta from 0 to 1 on the Figure 3 maps
//   vnsba_bench movingai [--maps DIR] [--planners a,b] [--csv] [--max-scenarios N] [--progress]
//                        [--with-post-processing]
//                                         every planner on Moving AI scenarios, per map class
//   vnsba_bench large [--maps DIR] [--planners a,b] [--sizes 2048,4096] [--queries N] [--progress]
//                     [--memory] [--write-maps DIR]
//                                         planners on grown Moving AI maps (bench/large.hpp):
//                                         interleaved in one process, or --memory: a process per
//                                         map, size and planner with its peak RSS
//
// Exit codes: 0 success, 1 a measurement failed, 2 bad input (the message names it).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/common.hpp"
#include "bench/costs.hpp"
#include "bench/large.hpp"
#include "bench/movingai.hpp"
#include "bench/paper.hpp"
#include "bench/sweep.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/node/command_line.hpp"

namespace {

using namespace vnsba::core;

int run_optimality(const std::string& dir) {
  const auto maps = vnsba::bench::list_scenario_maps(dir);
  if (!maps) {
    std::fprintf(stderr, "vnsba_bench optimality: --maps: %s\n", maps.error().message.c_str());
    return vnsba::bench::kExitBadInput;
  }
  std::printf("%-18s %10s %12s %12s %10s %10s\n", "map", "scenarios", "max_abs_err", "max_rel_err",
              "mismatch", "time_s");
  size_t total = 0, total_mismatch = 0;
  for (const auto& path : *maps) {
    auto loaded = vnsba::bench::load_map_with_scenarios(path);
    if (!loaded) {
      std::fprintf(stderr, "vnsba_bench optimality: %s\n", loaded.error().message.c_str());
      return vnsba::bench::kExitBadInput;
    }
    const auto& scenarios = loaded->scenarios;
    Planner planner(loaded->map);
    const PlannerOptions options = make_options(PlannerKind::kAStar, {});  // the paper's A*
    double max_abs = 0.0, max_rel = 0.0;
    size_t mismatch = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& s : scenarios) {
      const PlanResult r = planner.plan({s.start, s.goal}, options);
      const double err =
          r.status.is_ok() ? std::abs(r.metrics.raw_cost_cells - s.optimal_length) : INFINITY;
      max_abs = std::max(max_abs, err);
      max_rel = std::max(max_rel, err / std::max(1.0, s.optimal_length));
      // Relative 1e-6, or the printed precision where the file prints fewer digits.
      if (!(err <= std::max(1e-6 * s.optimal_length, s.optimal_resolution))) {
        ++mismatch;
        std::fprintf(stderr, "%s line %d: %s, cost %.8f, optimum %.8f\n", loaded->name.c_str(),
                     s.line, std::string(to_string(r.status.code)).c_str(),
                     r.metrics.raw_cost_cells, s.optimal_length);
      }
    }
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%-18s %10zu %12.2e %12.2e %10zu %10.2f\n", loaded->name.c_str(), scenarios.size(),
                max_abs, max_rel, mismatch, secs);
    total += scenarios.size();
    total_mismatch += mismatch;
  }
  std::printf("total: %zu scenarios on %zu maps, %zu mismatches\n", total, maps->size(),
              total_mismatch);
  return total_mismatch == 0 && total > 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vnsba_bench: offline measurements of the VNS-BA* planners"};
  app.require_subcommand(1);
  std::string maps_dir = std::string(VNSBA_DATA_DIR) + "/movingai";
  auto* optimality = app.add_subcommand("optimality", "A* against every Moving AI optimum");
  optimality->add_option("--maps", maps_dir, "folder with .map and .map.scen files");

  // One wording of --progress for every long subcommand: `what` is what it counts.
  auto add_progress_flag = [](CLI::App* subcommand, bool& flag, const std::string& what) {
    subcommand->add_flag("--progress", flag,
                         what +
                             " done / total, elapsed and ETA on stderr at most once a second, "
                             "also when stderr is not a terminal (on a terminal: always)");
  };
  vnsba::bench::PaperOptions paper_options;
  paper_options.maps_dir = VNSBA_PAPER_MAPS_DIR;
  paper_options.out_dir = "vnsba_bench_paper";
  auto* paper = app.add_subcommand("paper", "the paper's Tables 2-6 and Figures 8-12 on maps A-D");
  paper->add_option("--maps", paper_options.maps_dir, "folder with the paper maps A-D")
      ->capture_default_str();
  paper->add_option("--out", paper_options.out_dir, "folder for tables and figures")
      ->capture_default_str();
  paper
      ->add_option("--repetitions", paper_options.repetitions,
                   "timed plans per planner and map (the median is reported)")
      ->capture_default_str();

  vnsba::bench::SweepOptions sweep_options;
  sweep_options.maps_dir = VNSBA_PAPER_MAPS_DIR;
  sweep_options.out_dir = "vnsba_bench_sweep";
  auto* sweep = app.add_subcommand("sweep", "omega and eta from 0 to 1 on the Figure 3 maps");
  sweep->add_option("--maps", sweep_options.maps_dir, "folder with the sweep_* maps")
      ->capture_default_str();
  sweep->add_option("--out", sweep_options.out_dir, "folder for tables and heat maps")
      ->capture_default_str();
  sweep
      ->add_option("--repetitions", sweep_options.repetitions,
                   "timed plans per pair (the median is reported)")
      ->capture_default_str();
  add_progress_flag(sweep, sweep_options.progress, "omega/eta pairs");

  vnsba::bench::MovingAiOptions movingai_options;
  movingai_options.maps_dir = maps_dir;
  std::string planner_list;
  auto* movingai =
      app.add_subcommand("movingai", "every planner on Moving AI scenarios, per map class");
  movingai->add_option("--maps", movingai_options.maps_dir, "folder with .map and .map.scen files")
      ->capture_default_str();
  movingai->add_option("--planners", planner_list, "comma-separated planner names (default: all)");
  movingai->add_flag("--csv", movingai_options.csv,
                     "one row per scenario and planner instead of the summary");
  movingai->add_flag("--with-post-processing", movingai_options.with_post_processing,
                     "also run each baseline with VNS-BA*'s pruning and smoothing");
  movingai
      ->add_option("--max-scenarios", movingai_options.max_scenarios,
                   "at most N scenarios per map, spread over the file (0: all)")
      ->capture_default_str();
  add_progress_flag(movingai, movingai_options.progress, "plans");

  vnsba::bench::LargeOptions large_options;
  large_options.maps_dir = maps_dir;
  std::string large_planner_list;
  auto* large = app.add_subcommand(
      "large", "astar, jps and vns_bastar on 2048 and 4096 cells square slices, p50 and p95");
  large->add_option("--maps", large_options.maps_dir, "folder with the Moving AI maps")
      ->capture_default_str();
  large->add_option("--planners", large_planner_list,
                    "comma-separated planner names (default: astar,jps,vns_bastar)");
  large->add_option("--sizes", large_options.sizes, "cells a side, multiples of 512")
      ->capture_default_str();
  large->add_option("--queries", large_options.queries, "queries per map and size")
      ->capture_default_str();
  add_progress_flag(large, large_options.progress, "plans");
  large->add_flag("--memory", large_options.memory,
                  "one child process per map, size and planner: times and each child's peak RSS "
                  "(the default mode runs the planners interleaved in one process, times only)");
  large->add_option("--write-maps", large_options.write_maps_dir,
                    "write the grown maps and their queries as Moving AI .map and .map.scen files "
                    "to this folder (<map>-<size>.map), instead of planning");
  // The memory mode's children: the bench started again for one map (see bench/large.hpp).
  large->add_option("--memory-child", large_options.memory_child_map)->group("");

  vnsba::bench::CostsOptions costs_options;
  costs_options.maps_dir = maps_dir;
  costs_options.scene_path = VNSBA_SCENE_PATH;
  costs_options.slice_paths = {std::string(VNSBA_DATA_DIR) + "/octomap/fr_078_tidyup.bt"};
  std::string costs_planner_list;
  auto* costs = app.add_subcommand(
      "costs",
      "the default configuration (planner.name: auto) with and without costs, the cost-aware "
      "planners auto could run against astar, and binary against cost-aware against cost-aware "
      "+ relax planning per planner (config/paper.yaml against default.yaml's robot, without "
      "and with the relax smoother) on the demo scene, held-in OctoMap slices and the Moving AI "
      "maps");
  costs->add_option("--maps", costs_options.maps_dir, "folder with the Moving AI maps")
      ->capture_default_str();
  costs
      ->add_option("--scene", costs_options.scene_path,
                   "the demo scene, an OctoMap .bt file (its routes, and the first slice)")
      ->capture_default_str();
  costs
      ->add_option("--slices", costs_options.slice_paths,
                   "more held-in OctoMap .bt files, sliced like the scene, for random queries "
                   "(comma-separated; a missing file is skipped with a message)")
      ->delimiter(',')
      ->capture_default_str();
  costs
      ->add_option("--slice-queries", costs_options.slice_queries,
                   "seeded random queries per slice (0: the demo's routes only)")
      ->capture_default_str();
  costs->add_option("--seed", costs_options.seed, "seed of the slices' random queries")
      ->capture_default_str();
  costs
      ->add_option("--min-distance", costs_options.min_query_distance,
                   "metres between a random query's start and goal, at least")
      ->capture_default_str();
  costs->add_option("--planners", costs_planner_list,
                    "comma-separated planner names (default: all)");
  costs
      ->add_option("--max-scenarios", costs_options.max_scenarios,
                   "at most N scenarios per Moving AI map, spread over the file (0: all)")
      ->capture_default_str();
  add_progress_flag(costs, costs_options.progress, "Moving AI part: queries");
  costs
      ->add_option("--repetitions", costs_options.repetitions,
                   "timed plans per scene or slice query and side (the median is reported)")
      ->capture_default_str();

  // A bad command line exits 2 (vnsba::node::kExitUsage, bench's kExitBadInput), naming it.
  if (const auto exit_code = vnsba::node::parse_command_line(app, argc, argv)) return *exit_code;
  if (optimality->parsed()) return run_optimality(maps_dir);
  if (paper->parsed()) return vnsba::bench::run_paper(paper_options);
  if (sweep->parsed()) return vnsba::bench::run_sweep(sweep_options);
  // --planners of `command` into `planners` (left empty when not given); false after printing
  // what is wrong.
  auto read_planners = [](const char* command, const std::string& list,
                          std::vector<vnsba::core::PlannerKind>& planners) {
    if (list.empty()) return true;
    auto kinds = vnsba::bench::parse_planner_list(list);
    if (!kinds) {
      std::fprintf(stderr, "vnsba_bench %s: %s\n", command, kinds.error().message.c_str());
      return false;
    }
    planners = std::move(kinds).value();
    return true;
  };
  if (movingai->parsed()) {
    if (!read_planners("movingai", planner_list, movingai_options.planners))
      return vnsba::bench::kExitBadInput;
    return vnsba::bench::run_movingai(movingai_options);
  }
  if (large->parsed()) {
    if (!read_planners("large", large_planner_list, large_options.planners))
      return vnsba::bench::kExitBadInput;
    return vnsba::bench::run_large(large_options);
  }
  if (costs->parsed()) {
    if (!read_planners("costs", costs_planner_list, costs_options.planners))
      return vnsba::bench::kExitBadInput;
    return vnsba::bench::run_costs(costs_options);
  }
  return vnsba::bench::kExitBadInput;
}
