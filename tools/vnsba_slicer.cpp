// vnsba_slicer: OctoMap 3D maps -> 2D slices, to a map_server file or onto the bus.
//
//   vnsba_slicer FILE.bt|FILE.ot [--z-min A] [--z-max B] [--resolution R]
//                [--bounds XMIN,YMIN,XMAX,YMAX] [--out map.pgm]
//   vnsba_slicer FILE.bt --publish [--watch] [--config FILE] [--domain N]
//   vnsba_slicer --subscribe [--config FILE] [--domain N]
//
// Band, resolution and speckle removal default to the config's `slicer` section; the flags
// override them, and errors name the flag or the config key a value came from. With --publish
// the slice goes out on the slice topic (transient local, so a node started later still gets it)
// and the slicer stays up to serve it until SIGINT/SIGTERM; --watch republishes when the file
// changes. --subscribe slices every binary octomap_msgs/Octomap
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
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/process.hpp"
#include "vnsba/node/security.hpp"

namespace {

using namespace vnsba;

constexpr int kBadInput = 2;
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

// The file's modification time; file_time_type::min() when it cannot be read (e.g. mid-rename).
std::filesystem::file_time_type modified(const std::string& path) {
  std::error_code ec;
  const auto t = std::filesystem::last_write_time(path, ec);
  return ec ? std::filesystem::file_time_type::min() : t;
}

// Slicing errors start with what was sliced (the file, or "the received octomap").
core::Expected<core::OccupancyGrid> slice_tree(const octomap::OcTree& tree,
                                               const maps::SliceOptions& options,
                                               const std::string& source) {
  auto sliced = maps::slice_octree(tree, options);
  if (!sliced)
    return core::Status::error(sliced.error().code, source + ": " + sliced.error().message);
  return sliced;
}

core::Expected<core::OccupancyGrid> slice_file(const std::string& path,
                                               const maps::SliceOptions& options) {
  auto tree = maps::load_octree(path);
  if (!tree) return tree.error();
  return slice_tree(**tree, options, path);
}

void log_slice(const core::OccupancyGrid& g, const std::string& source) {
  size_t occupied = 0, free_cells = 0;
  for (int8_t v : g.data) {
    occupied += v == core::kOccupancyOccupied;
    free_cells += v == core::kOccupancyFree;
  }
  spdlog::info(
      "slice of {}: {} x {} cells at {} m, origin ({:.3f}, {:.3f}) m; {} occupied, {} free, {} "
      "unknown",
      source, g.width, g.height, g.resolution, g.origin_x, g.origin_y, occupied, free_cells,
      g.data.size() - occupied - free_cells);
}

}  // namespace

int main(int argc, char** argv) {
  node::init_logging("vnsba_slicer");
  CLI::App app{"vnsba_slicer: OctoMap 3D maps to 2D occupancy slices"};
  std::string input, out, config_path = "";
  std::optional<double> z_min, z_max, resolution;
  int domain = -1;
  bool publish = false, watch = false, subscribe = false, speckles = false;
  std::vector<double> bounds;
  app.add_option("file", input, "OctoMap file (.bt binary tree or .ot full tree)");
  app.add_option("--z-min", z_min, "lower bound of the height band, metres");
  app.add_option("--z-max", z_max, "upper bound of the height band, metres");
  app.add_option("--resolution", resolution,
                 "metres per cell: the leaf size or a whole multiple (0 = leaf size)");
  app.add_option("--bounds", bounds,
                 "x_min,y_min,x_max,y_max in metres (default: the tree's bounds)")
      ->expected(4)
      ->delimiter(',');
  app.add_flag("--remove-speckles", speckles, "turn isolated occupied cells free");
  app.add_option("--out", out, "write a ROS map_server map: OUT (.pgm) and its .yaml");
  app.add_flag("--publish", publish, "publish the slice on the slice topic and keep serving it");
  app.add_flag("--watch", watch, "with --publish: republish when the file changes");
  app.add_flag("--subscribe", subscribe, "slice the binary octomaps received on the octomap topic");
  app.add_option("--config", config_path, vnsba::node::kConfigOptionHelp);
  app.add_option("--domain", domain, "DDS domain id 0..232 (overrides domain_id)");
  CLI11_PARSE(app, argc, argv);

  if (subscribe == !input.empty()) {
    spdlog::error("give either an OctoMap file or --subscribe (not both, not neither)");
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
  const auto loaded = node::load_config_or_report(config_path, domain);
  if (!loaded) return kBadInput;
  const node::NodeConfig& config = *loaded;

  maps::SliceOptions options;
  options.z_min = z_min.value_or(config.slicer.z_min);
  options.z_max = z_max.value_or(config.slicer.z_max);
  options.resolution = resolution.value_or(config.slicer.resolution);
  options.remove_speckles = speckles || config.slicer.remove_speckles;
  options.max_cells = config.map.max_cells;
  // Errors name where each value came from: the flag, or the config key (and its file).
  const std::string in_config = " in " + config_path;
  options.names.z_min = z_min ? "--z-min" : "slicer.z_min" + in_config;
  options.names.z_max = z_max ? "--z-max" : "slicer.z_max" + in_config;
  options.names.resolution = resolution ? "--resolution" : "slicer.resolution" + in_config;
  options.names.bounds = "--bounds";
  options.names.max_cells = "map.max_cells" + in_config;
  if (!bounds.empty())
    options.bounds = maps::SliceBounds{bounds[0], bounds[1], bounds[2], bounds[3]};

  // File mode: slice once (errors are final), write it if asked.
  std::optional<core::OccupancyGrid> slice;
  if (!input.empty()) {
    auto sliced = slice_file(input, options);
    if (!sliced) {
      spdlog::error("{}", sliced.error().message);
      return kBadInput;
    }
    slice = std::move(sliced).value();
    log_slice(*slice, input);
    if (!out.empty()) {
      const std::string stem = std::filesystem::path(out).replace_extension().string();
      auto written = maps::save_map_server(*slice, stem, config.map.occupied_threshold);
      if (!written) {
        spdlog::error("{}", written.error().message);
        return kBadInput;
      }
      spdlog::info("wrote {}.pgm and {}", stem, *written);
    }
    if (!publish) return 0;
  }

  // Bus mode. Signals are blocked before DDS starts its threads and taken in the loop below.
  const node::StopSignals stop;

  auto participant = node::Participant::create(
      config.domain_id, "vnsba_slicer", nullptr, config.localhost_only,
      node::with_default_enclave(config.security, node::kSlicerEnclave));
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
      spdlog::error("could not publish the slice on '{}'", slice_topic_name);
      return;
    }
    spdlog::info("published the slice on '{}' (domain {})", slice_topic_name, config.domain_id);
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

  auto last_change = input.empty() ? std::filesystem::file_time_type::min() : modified(input);
  for (;;) {
    if (const auto received = stop.wait_for(std::chrono::milliseconds(200))) {
      spdlog::info("{} received: stopping", node::StopSignals::name(*received));
      break;
    }
    if (watch) {
      const auto now = modified(input);
      if (now != std::filesystem::file_time_type::min() && now != last_change) {
        last_change = now;
        auto sliced = slice_file(input, options);
        if (sliced) {
          log_slice(*sliced, input);
          publish_slice(*sliced);
        } else {
          // A file caught mid-write, or broken: keep serving the last good slice.
          // The message names the file.
          spdlog::warn("changed but cannot be sliced: {}; the last slice stays published",
                       sliced.error().message);
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
      log_slice(*sliced, "the received octomap");
      publish_slice(*sliced);
    }
  }
  bus.shutdown();
  return 0;
}
