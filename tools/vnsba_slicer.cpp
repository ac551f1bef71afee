// vnsba_slicer: any map file vnsba_plan reads -> the 2D map the node plans on, to a map_server
// file or onto the bus. OctoMaps are sliced; 2D maps are published as they are.
//
//   vnsba_slicer FILE.bt|FILE.ot [--z-min A] [--z-max B] [--resolution R]
//                [--bounds XMIN,YMIN,XMAX,YMAX] [--remove-speckles] [--out map.pgm]
//   vnsba_slicer FILE.map|FILE.yaml|FILE.pgm [--out map.pgm]
//   vnsba_slicer FILE --publish [--watch] [--config FILE] [--domain N] [--namespace NS]
//   vnsba_slicer --subscribe [--config FILE] [--domain N] [--namespace NS]
//
// Files are read by maps::load_map_file, as vnsba_plan reads them: a Moving AI map has 1 m
// cells and origin (0, 0), a map_server map its YAML's resolution and origin and map_server's
// values (trinary 100 / 0 / -1, scale mode's graded 1..99 too). Band, resolution and speckle
// removal (OctoMaps only: given with a 2D map they are refused by name) default to the config's
// `slicer` section; the flags override them, and errors name the flag or the config key a value
// came from. With --publish the map goes out on the slice topic (transient local, so a node
// started later still gets it) and the slicer stays up to serve it until SIGINT/SIGTERM; --watch
// republishes when the file changes. --subscribe slices every binary octomap_msgs/Octomap
// it receives on the `octomap` topic and publishes the result.
//
// Exit codes: 0 done (or stopped by a signal), 2 bad arguments, config, file or slice options,
// 1 DDS failure.
#include <octomap/OcTree.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <mutex>
#include <optional>

#include "nav_msgs/msg/OccupancyGridPubSubTypes.h"
#include "octomap_msgs/msg/OctomapPubSubTypes.h"
#include "vnsba/maps/map_file.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/node/command_line.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/process.hpp"
#include "vnsba/node/security.hpp"

namespace {

using namespace vnsba;

constexpr int kBadInput = node::kExitUsage;
constexpr int kDdsFailure = 1;

// Newest tree received on the bus, handed from the DDS listener to the main loop.
class TreeSlot : public node::dds::DataReaderListener {
 public:
  void on_data_available(node::dds::DataReader* reader) override {
    node::OctomapMsg msg;
    node::dds::SampleInfo info;
    // Nothing escapes a DDS thread: a tree that cannot be taken (memory) is logged and lost.
    try {
      while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
        if (!info.valid_data) continue;
        std::lock_guard<std::mutex> lock(mutex_);
        pending_ = std::move(msg);
        msg = node::OctomapMsg();
      }
    } catch (const std::exception& e) {
      spdlog::error("an octomap sample was lost: {}", e.what());
    }
  }
  std::optional<node::OctomapMsg> take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<node::OctomapMsg> out = std::move(pending_);
    pending_.reset();
    return out;
  }

 private:
  std::mutex mutex_;
  std::optional<node::OctomapMsg> pending_;
};

// The files a map is read from, whose changes --watch follows: the file given and, for a map_server
// map, the .yaml and .pgm of the same name beside it (map_saver's pair).
std::vector<std::string> watched_files(const std::string& path) {
  std::vector<std::string> files = {path};
  if (maps::map_file_kind(path) == maps::MapFileKind::kMapServer) {
    for (const char* extension : {".yaml", ".pgm"}) {
      std::string sibling = std::filesystem::path(path).replace_extension(extension).string();
      if (sibling != path) files.push_back(std::move(sibling));
    }
  }
  return files;
}

// The files' modification times; file_time_type::min() for one that cannot be read (e.g.
// mid-rename).
std::vector<std::filesystem::file_time_type> modified(const std::vector<std::string>& paths) {
  std::vector<std::filesystem::file_time_type> times;
  for (const std::string& path : paths) {
    std::error_code ec;
    const auto t = std::filesystem::last_write_time(path, ec);
    times.push_back(ec ? std::filesystem::file_time_type::min() : t);
  }
  return times;
}

// Slicing errors start with what was sliced (here "the received octomap"; files are named by
// maps::load_map_file).
core::Expected<core::OccupancyGrid> slice_tree(const octomap::OcTree& tree,
                                               const maps::SliceOptions& options,
                                               const std::string& source) {
  auto sliced = maps::slice_octree(tree, options);
  if (!sliced)
    return core::Status::error(sliced.error().code, source + ": " + sliced.error().message);
  return sliced;
}

// A map file as the node would plan on it: an OctoMap sliced, a 2D map as it is. A 2D map larger
// than the node's map.max_cells is refused here, as the node would refuse it (a slice is held to
// the limit by the slicing itself).
core::Expected<core::OccupancyGrid> load_file(const std::string& path,
                                              const maps::SliceOptions& options) {
  auto grid = maps::load_map_file(path, options);
  if (!grid) return grid;
  const int64_t cells = int64_t{grid->width} * grid->height;
  if (maps::map_file_kind(path) != maps::MapFileKind::kOctoMap && cells > options.max_cells) {
    return core::Status::error(core::StatusCode::kInvalidMap,
                               path + ": " + std::to_string(grid->width) + " x " +
                                   std::to_string(grid->height) + " = " + std::to_string(cells) +
                                   " cells, over " + options.names.max_cells + " (" +
                                   std::to_string(options.max_cells) + " cells)");
  }
  return grid;
}

// `what` is "slice" (of an OctoMap) or "map" (a 2D map as it is).
void log_grid(const core::OccupancyGrid& g, const char* what, const std::string& source) {
  size_t occupied = 0, free_cells = 0, unknown = 0;
  for (int8_t v : g.data) {
    occupied += v == core::kOccupancyOccupied;
    free_cells += v == core::kOccupancyFree;
    unknown += v < 0;
  }
  const size_t graded = g.data.size() - occupied - free_cells - unknown;
  spdlog::info(
      "{} of {}: {} x {} cells at {} m, origin ({:.3f}, {:.3f}) m; {} occupied, {} free, {} "
      "unknown{}",
      what, source, g.width, g.height, g.resolution, g.origin_x, g.origin_y, occupied, free_cells,
      unknown, graded == 0 ? "" : fmt::format(", {} graded (1..99)", graded));
}

// --out: the map as map_saver saves what is published (trinary). Refuses to overwrite the files
// the map is read from; warns about graded cells that the trinary file turns unknown.
bool write_out(const core::OccupancyGrid& grid, const std::string& out,
               const std::vector<std::string>& inputs, int occupied_threshold) {
  const std::string stem = std::filesystem::path(out).replace_extension().string();
  for (const std::string& written : {stem + ".pgm", stem + ".yaml"}) {
    for (const std::string& input : inputs) {
      std::error_code ec;
      if (std::filesystem::equivalent(written, input, ec) && !ec) {
        spdlog::error("--out {}: would overwrite {}, which the map is read from", out, written);
        return false;
      }
    }
  }
  auto saved = maps::save_map_server(grid, stem, occupied_threshold);
  if (!saved) {
    spdlog::error("--out {}: {}", out, saved.error().message);
    return false;
  }
  // Graded values (map_server's scale mode) between map_saver's free and occupied ranges become
  // unknown in a trinary file: read it back and say how many.
  if (auto back = maps::load_map_server(*saved); back && back->data.size() == grid.data.size()) {
    size_t turned_unknown = 0;
    for (size_t i = 0; i < grid.data.size(); ++i)
      turned_unknown += grid.data[i] >= 0 && back->data[i] < 0;
    if (turned_unknown > 0)
      spdlog::warn(
          "{}.pgm: {} cells with graded values are written as unknown, as map_saver's trinary "
          "file does (the published map keeps their values)",
          stem, turned_unknown);
  }
  spdlog::info("wrote {}.pgm and {}", stem, *saved);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  node::init_logging("vnsba_slicer");
  CLI::App app{
      "vnsba_slicer: map files (OctoMaps sliced, 2D maps as they are) to the 2D occupancy map "
      "the node plans on"};
  std::string input, out, config_path = "";
  std::optional<double> z_min, z_max, resolution;
  int domain = -1;
  bool publish = false, watch = false, subscribe = false, speckles = false;
  std::vector<double> bounds;
  app.add_option("file", input,
                 "map file: .bt/.ot (OctoMap, sliced), .map (Moving AI), .yaml/.pgm (map_server)");
  // The slicing options: for OctoMaps (files and --subscribe) only.
  const std::vector<CLI::Option*> slice_only = {
      app.add_option("--z-min", z_min, "OctoMap: lower bound of the height band, metres"),
      app.add_option("--z-max", z_max, "OctoMap: upper bound of the height band, metres"),
      app.add_option("--resolution", resolution,
                     "OctoMap: metres per cell, the leaf size or a whole multiple (0 = leaf size)"),
      app.add_option("--bounds", bounds,
                     "OctoMap: x_min,y_min,x_max,y_max in metres (default: the tree's bounds)")
          ->expected(4)
          ->delimiter(','),
      app.add_flag("--remove-speckles", speckles, "OctoMap: turn isolated occupied cells free")};
  app.add_option("--out", out,
                 "write what is published as a ROS map_server map (trinary, as map_saver does): "
                 "OUT (.pgm) and its .yaml");
  app.add_flag("--publish", publish, "publish the map on the slice topic and keep serving it");
  app.add_flag("--watch", watch, "with --publish: republish when the file changes");
  app.add_flag("--subscribe", subscribe, "slice the binary octomaps received on the octomap topic");
  app.add_option("--config", config_path, vnsba::node::kConfigOptionHelp);
  app.add_option("--domain", domain,
                 "DDS domain id 0..232 (overrides ROS_DOMAIN_ID and domain_id)");
  std::optional<std::string> ros_namespace;
  app.add_option("--namespace", ros_namespace, node::kNamespaceOptionHelp);
  std::optional<std::string> participant_profile;
  app.add_option("--participant-profile", participant_profile, node::kParticipantProfileOptionHelp);
  if (const auto exit_code = node::parse_command_line(app, argc, argv)) return *exit_code;

  if (subscribe == !input.empty()) {
    spdlog::error("give either a map file or --subscribe (not both, not neither)");
    return kBadInput;
  }
  if (!publish && !subscribe && out.empty()) {
    spdlog::error("nothing to do: give --out FILE.pgm and/or --publish");
    return kBadInput;
  }
  if (watch && !publish) {
    spdlog::error("--watch needs --publish");
    return kBadInput;
  }
  // A 2D map is published as it is: a slicing option given with one is a mistake, not a no-op.
  const maps::MapFileKind kind = maps::map_file_kind(input);
  if (kind == maps::MapFileKind::kMovingAi || kind == maps::MapFileKind::kMapServer)
    for (const CLI::Option* option : slice_only)
      if (option->count() > 0) {
        spdlog::error("{}: only for OctoMap files (.bt, .ot), not {}, a 2D map published as it is",
                      option->get_name(), input);
        return kBadInput;
      }
  const auto loaded =
      node::load_config_or_report(config_path, domain, ros_namespace, participant_profile);
  if (!loaded) return kBadInput;
  const node::NodeConfig& config = *loaded;

  maps::SliceOptions options;
  options.z_min = z_min.value_or(config.slicer.z_min);
  options.z_max = z_max.value_or(config.slicer.z_max);
  options.resolution = resolution.value_or(config.slicer.resolution);
  options.remove_speckles = speckles || config.slicer.remove_speckles;
  options.max_cells = config.map.max_cells;
  // Errors name where each value came from: the flag, or the config key (and its file).
  std::string config_name = config_path;
  if (config_name.empty())
    if (auto found = node::find_default_config()) config_name = *found;
  const std::string in_config = " in " + config_name;
  options.names.z_min =
      node::value_source(z_min.has_value(), "--z-min", "slicer.z_min", config_name);
  options.names.z_max =
      node::value_source(z_max.has_value(), "--z-max", "slicer.z_max", config_name);
  options.names.resolution =
      node::value_source(resolution.has_value(), "--resolution", "slicer.resolution", config_name);
  options.names.bounds = "--bounds";
  options.names.max_cells = "map.max_cells" + in_config;
  if (!bounds.empty())
    options.bounds = maps::SliceBounds{bounds[0], bounds[1], bounds[2], bounds[3]};
  const bool two_d = kind == maps::MapFileKind::kMovingAi || kind == maps::MapFileKind::kMapServer;
  const char* what = two_d ? "map" : "slice";
  const std::vector<std::string> inputs =
      input.empty() ? std::vector<std::string>{} : watched_files(input);

  // File mode: read once (errors are final), write it if asked.
  std::optional<core::OccupancyGrid> slice;
  if (!input.empty()) {
    auto grid = load_file(input, options);
    if (!grid) {
      spdlog::error("{}", grid.error().message);
      return kBadInput;
    }
    slice = std::move(grid).value();
    log_grid(*slice, what, input);
    if (!out.empty() && !write_out(*slice, out, inputs, config.map.occupied_threshold))
      return kBadInput;
    if (!publish) return 0;
  }

  // Bus mode. Signals are blocked before DDS starts its threads and taken in the loop below.
  const node::StopSignals stop;

  auto participant =
      node::Participant::create_configured(config, "vnsba_slicer", node::kSlicerEnclave);
  if (!participant) {
    spdlog::error("{}", participant.error().message);
    return kDdsFailure;
  }
  auto& bus = **participant;
  const std::string slice_topic_name = node::dds_topic_name(config, config.topics.projected_map);
  auto slice_topic = bus.topic<nav_msgs::msg::dds_::OccupancyGrid_PubSubType>(slice_topic_name);
  if (!slice_topic) {
    spdlog::error("{}", slice_topic.error().message);
    return kDdsFailure;
  }
  auto writer = bus.writer(*slice_topic, node::writer_qos(node::TopicQos::kLatched, true));
  if (!writer) {
    spdlog::error("{}", writer.error().message);
    return kDdsFailure;
  }
  auto publish_slice = [&](const core::OccupancyGrid& grid) {
    node::OccupancyGridMsg msg = node::to_slice_msg(grid, config.frame_id, node::now_msg());
    if (!(*writer)->write(&msg)) {
      spdlog::error("could not publish the {} on '{}'", what, slice_topic_name);
      return;
    }
    spdlog::info("published the {} on '{}' (domain {})", what, slice_topic_name, config.domain_id);
  };

  TreeSlot trees;
  if (subscribe) {
    const std::string tree_topic_name = node::dds_topic_name(config, config.topics.octomap);
    auto tree_topic = bus.topic<octomap_msgs::msg::dds_::Octomap_PubSubType>(tree_topic_name);
    if (!tree_topic) {
      spdlog::error("{}", tree_topic.error().message);
      return kDdsFailure;
    }
    auto reader = bus.reader(*tree_topic, node::reader_qos(node::TopicQos::kLatched), &trees);
    if (!reader) {
      spdlog::error("{}", reader.error().message);
      return kDdsFailure;
    }
    spdlog::info("slicing the octomaps on '{}' (domain {})", tree_topic_name, config.domain_id);
  }
  if (slice) publish_slice(*slice);

  auto last_change = modified(inputs);
  for (;;) {
    if (const auto received = stop.wait_for(std::chrono::milliseconds(200))) {
      spdlog::info("{} received: stopping", node::StopSignals::name(*received));
      break;
    }
    if (watch) {
      const auto now = modified(inputs);
      if (now.front() != std::filesystem::file_time_type::min() && now != last_change) {
        last_change = now;
        auto grid = load_file(input, options);
        if (grid) {
          log_grid(*grid, what, input);
          publish_slice(*grid);
        } else {
          // A file caught mid-write, or broken: keep serving the last good map.
          // The message names the file.
          spdlog::warn("changed but cannot be read: {}; the last {} stays published",
                       grid.error().message, what);
        }
      }
    }
    if (auto msg = trees.take()) {
      node::TreeCheck check = node::from_octomap_msg(*msg);
      if (!check.status.ok()) {
        spdlog::error("octomap rejected: {}", check.status.message);
        continue;
      }
      auto sliced = slice_tree(*check.tree, options, "the received octomap");
      if (!sliced) {
        spdlog::error("{}", sliced.error().message);
        continue;
      }
      log_grid(*sliced, "slice", "the received octomap");
      publish_slice(*sliced);
    }
  }
  bus.shutdown();
  return 0;
}
