// `vnsba_bench large`: planners on slices of 2048 x 2048 and 4096 x 4096 cells, built from real
// Moving AI maps, per query p50 and p95. An office slice at 5 cm a cell is that large (200 m
// across), and that is where an exact planner's time matters.
//
// Two ways to make a large map from a 512 x 512 one, both keeping its character:
//   scaled: every cell becomes a k x k block (k = size / 512): the same building or city at a
//           finer resolution (Boston_0_512 as a street map, 16room_000 as an indoor floor);
//   tiled:  the map repeated k x k times (random512-20-0: its edges are not walled, so the
//           copies join into one large random field).
// Queries: the map's scenarios spread over its file, endpoints moved to the centre of their
// block (scaled), or from a scenario's start in the first copy to its goal in the last (tiled).
//
// Three modes:
//   interleaved (default): every planner in one process, query by query, so that a slow moment
//           of the machine hits every planner alike; times only (the process holds every map).
//   memory (--memory): one child process per map, size and planner (the bench binary itself,
//           started again with a hidden option), each building its map and running the same
//           queries with its planner only, so that its peak RSS is that planner's alone. The
//           parent prints times and memory (docs/benchmarks.md says what each column is).
//   write maps (--write-maps DIR): the grown maps and their queries as Moving AI .map and
//           .map.scen files, for other programs (a reference JPS) to run the same queries.
#pragma once

#include <string>
#include <vector>

#include "vnsba/core/planner.hpp"

namespace vnsba::bench {

// A map grown to `factor` times its side (see above): scaled (every cell a factor x factor
// block) or tiled (factor x factor copies); 5 cm cells, as an office slice's.
enum class Growth { kScaled, kTiled };
core::OccupancyGrid grow_grid(const core::OccupancyGrid& source, int factor, Growth growth);

struct LargeOptions {
  std::string maps_dir;
  std::vector<core::PlannerKind> planners;  // empty: astar, jps, vns_bastar
  std::vector<int> sizes = {2048, 4096};    // cells a side, each a multiple of 512
  int queries = 20;                         // per map and size
  // Progress on stderr (plans done / total, elapsed, ETA, at most once a second) even when stderr
  // is not a terminal; on a terminal it is always shown.
  bool progress = false;
  // The memory mode (see above).
  bool memory = false;
  // Set in a memory mode child only (a hidden option): the one map (a source map's name, as
  // "16room_000") it runs, with the one size and the one planner it is given; it prints its
  // figures as one line on stdout for the parent.
  std::string memory_child_map;
  // Not empty: write the grown maps and queries to this folder instead of planning.
  std::string write_maps_dir;
};

int run_large(const LargeOptions& options);

}  // namespace vnsba::bench
