// `vnsba_bench movingai`: every planner on the scenarios of the Moving AI maps in a folder,
// summarised per map class (game, maze, room, random, street), or one CSV row per scenario and
// planner with --csv.
#pragma once

#include <string>
#include <vector>

#include "vnsba/core/planner.hpp"

namespace vnsba::bench {

struct MovingAiOptions {
  std::string maps_dir;
  std::vector<core::PlannerKind> planners;  // empty = all
  bool csv = false;
  int max_scenarios = 0;  // per map; 0 = all. Picks scenarios evenly over the file (all buckets)
  // Also run each baseline with VNS-BA*'s pruning and smoothing (named "<planner>+prune+smooth"),
  // to separate what the search gains from what post-processing gains.
  bool with_post_processing = false;
  // Progress on stderr (plans done / total, elapsed, ETA, at most once a second) even when stderr
  // is not a terminal; on a terminal it is always shown.
  bool progress = false;
};

// The CSV header (one row per scenario and planner follows it). clearance_m is the final path's
// core::Metrics::clearance_m ("inf" on a map without obstacles; empty, like the other metrics of
// the path, when the plan failed). Then what proves two runs identical beyond the metrics
// (bench/compare_outputs.sh): the closed cells of each search (expanded_forward,
// expanded_backward; 0 backward for a unidirectional planner) and a hash of their order
// (expansions_hash), from a second, untimed plan of the query with record_expansions on (the
// timed plan records nothing; the two plans must agree on everything else, or the run fails);
// the cell where a bidirectional search met (meeting_cell, "x:y", empty otherwise); hashes of the
// grid path (raw_path_hash), the pruned waypoints (waypoints_hash) and the final path
// (path_hash), 64-bit FNV-1a of their cells or coordinates' bits, in hex. The times stay last:
// search_time_us (core::Metrics::search_time_us: the search alone, no endpoint checks, path
// metrics or post-processing, as a reference search that builds no path is timed), time_us
// (wall, steady clock around Planner::plan) and cpu_time_us (the process's CPU time over the same
// call: below time_us where the plan was preempted, a sign of a busy machine);
// compare_outputs.sh drops every *time_us column by name.
constexpr const char* kMovingAiCsvHeader =
    "map,scenario,planner,status,optimal,raw_cost,length,turns,turn_angle_deg,expanded,"
    "clearance_m,expanded_forward,expanded_backward,meeting_cell,raw_path_hash,waypoints_hash,"
    "path_hash,expansions_hash,search_time_us,time_us,cpu_time_us";

// The map's class from the folder's MANIFEST.tsv (its source path: dao, bg512, sc1 -> game;
// mazes -> maze; rooms -> room; random -> random; cities, street -> street) or, without one,
// from the name.
std::string movingai_map_class(const std::string& maps_dir, const std::string& map_file_name);

int run_movingai(const MovingAiOptions& options);

}  // namespace vnsba::bench
