// vnsba_bench: offline measurements of the planners.
//
//   vnsba_bench optimality [--maps DIR]   every Moving AI scenario in DIR through A*: its path
//                                         cost must equal the published optimum; prints a table
//                                         per map and exits 1 on any mismatch.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "vnsba/core/map_io.hpp"
#include "vnsba/core/planner.hpp"

namespace {

using namespace vnsba::core;

int run_optimality(const std::string& dir) {
  if (!std::filesystem::is_directory(dir)) {
    std::fprintf(stderr, "no such folder: %s\n", dir.c_str());
    return 2;
  }
  std::vector<std::filesystem::path> maps;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".map") maps.push_back(entry.path());
  std::sort(maps.begin(), maps.end());
  std::printf("%-18s %10s %12s %12s %10s %10s\n", "map", "scenarios", "max_abs_err", "max_rel_err",
              "mismatch", "time_s");
  size_t total = 0, total_mismatch = 0;
  for (const auto& path : maps) {
    auto grid = load_movingai_map(path.string());
    auto scenarios = load_movingai_scenarios(path.string() + ".scen");
    if (!grid || !scenarios) {
      std::fprintf(stderr, "%s\n", (!grid ? grid.error() : scenarios.error()).message.c_str());
      return 2;
    }
    auto built = GridMap::build(*grid);
    if (!built) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), built.error().message.c_str());
      return 2;
    }
    Planner planner(std::make_shared<const GridMap>(std::move(built).value()));
    const PlannerOptions options = default_options(PlannerKind::kAStar);
    double max_abs = 0.0, max_rel = 0.0;
    size_t mismatch = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& s : *scenarios) {
      const PlanResult r = planner.plan({s.start, s.goal}, options);
      const double err =
          r.status.is_ok() ? std::abs(r.metrics.raw_cost_cells - s.optimal_length) : INFINITY;
      max_abs = std::max(max_abs, err);
      max_rel = std::max(max_rel, err / std::max(1.0, s.optimal_length));
      // Relative 1e-6, or the printed precision where the file prints fewer digits.
      if (!(err <= std::max(1e-6 * s.optimal_length, s.optimal_resolution))) {
        ++mismatch;
        std::fprintf(stderr, "%s line %d: %s, cost %.8f, optimum %.8f\n", path.filename().c_str(),
                     s.line, std::string(to_string(r.status.code)).c_str(),
                     r.metrics.raw_cost_cells, s.optimal_length);
      }
    }
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%-18s %10zu %12.2e %12.2e %10zu %10.2f\n", path.stem().c_str(), scenarios->size(),
                max_abs, max_rel, mismatch, secs);
    total += scenarios->size();
    total_mismatch += mismatch;
  }
  std::printf("total: %zu scenarios on %zu maps, %zu mismatches\n", total, maps.size(),
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
  CLI11_PARSE(app, argc, argv);
  if (optimality->parsed()) return run_optimality(maps_dir);
  return 2;
}
