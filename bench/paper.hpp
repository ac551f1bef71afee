// `vnsba_bench paper`: the paper's section 4 on its maps A-D (Tables 2-6, Figures 8-12) plus an
// ablation the paper lacks (each baseline with our pruning and smoothing).
#pragma once

#include <string>
#include <vector>

namespace vnsba::bench {

struct PaperOptions {
  std::string maps_dir;  // holds A.map .. D.map, each with a one-line .map.scen
  std::string out_dir;   // tables (Markdown, CSV) and SVG figures are written here
  int repetitions = 51;  // timed plans per planner and map; the time is their median
};

// The files `run_paper` writes into out_dir (names only), for tools and tests.
std::vector<std::string> paper_output_files();

// (baseline - ours) / baseline in percent, the paper's improvement rate (Table 6). Both zero:
// 0 (no change). Baseline zero and ours not: NaN ("n/a"; the rate is undefined).
double improvement_rate_percent(double baseline, double ours);

// Returns an exit code (common.hpp): 2 for bad input, 1 when a planner fails on a paper map.
int run_paper(const PaperOptions& options);

}  // namespace vnsba::bench
