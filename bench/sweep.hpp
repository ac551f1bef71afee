// `vnsba_bench sweep`: VNS-BA*'s weights omega and eta from 0 to 1 in steps of 0.1 on the four
// maps of the paper's Figure 3 (its Table 1): expanded nodes, planning time and path length per
// pair, as Markdown/CSV tables and SVG heat maps, and where the pair 0.5 / 0.5 ranks.
#pragma once

#include <string>
#include <vector>

namespace vnsba::bench {

struct SweepOptions {
  std::string maps_dir;  // holds sweep_simple, sweep_middle, sweep_bars, sweep_random (.map/.scen)
  std::string out_dir;
  int repetitions = 21;   // timed plans per pair; the time is their median
  bool progress = false;  // progress lines on stderr also when it is not a terminal
};

std::vector<std::string> sweep_map_names();
std::vector<std::string> sweep_output_files();

int run_sweep(const SweepOptions& options);

}  // namespace vnsba::bench
