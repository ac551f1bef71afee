// Issue 31 (item 5): the node fed a map over the bus and vnsba_plan reading the map's file must
// plan the same paths. The node's side is what its users publish: for a map_server file, the
// OccupancyGrid Nav2's map_server makes of it, and for an OctoMap, vnsba_slicer's slice. The
// other side is the library calls vnsba_plan makes on the file (maps::load_map_file,
// core::GridMap::build with the config's map section, the options of its planner section
// (PlannerConfig::options: make_options, or for planner.name auto core::make_auto_options), a
// PlanQuery holding the exact requested points), not its printed line.
//
// The map_server side is an oracle written here from Nav2's rules (nav2_map_server map_io.cpp,
// loadMapYaml and loadMapFromFile), not the maps library's loader: the node's users run Nav2's
// map_server, and whether maps/ reads files as that publishes them is one of the things tested.
// Nav2 reads images through GraphicsMagick (16-bit quanta): an 8-bit sample s is the quantum
// 257 s, a 16-bit one itself, so the shade is s / maxval for the maxvals 255 and 65535 that
// map_saver and image editors write; other maxvals are rescaled to quanta with rounding, which
// this oracle does not model (such files are left out, with a message).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "bus_client.hpp"
#include "temp_dir.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_file.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/node/planner_node.hpp"

namespace vnsba::test {
namespace {

namespace fs = std::filesystem;
using node::OccupancyGridMsg;

// --- The oracle: the OccupancyGrid Nav2's map_server publishes for a map_server file. ---

struct Image {
  int width = 0, height = 0;
  uint32_t maxval = 0;
  std::vector<uint32_t> samples;  // top row first, as stored
};

// A P2 or P5 PGM, as Netpbm defines it (comments from '#' to the end of a line in the header,
// one whitespace byte before P5's samples, 16-bit samples big-endian).
std::optional<Image> read_image(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  size_t at = 0;
  auto token = [&]() {
    for (;;) {
      while (at < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[at]))) ++at;
      if (at >= bytes.size() || bytes[at] != '#') break;
      at = bytes.find('\n', at);
      if (at == std::string::npos) at = bytes.size();
    }
    const size_t begin = at;
    while (at < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[at]))) ++at;
    return bytes.substr(begin, at - begin);
  };
  const std::string magic = token();
  if (magic != "P2" && magic != "P5") return std::nullopt;
  Image image;
  image.width = std::stoi(token());
  image.height = std::stoi(token());
  image.maxval = static_cast<uint32_t>(std::stoul(token()));
  const size_t count = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  if (magic == "P2") {
    for (size_t i = 0; i < count; ++i) image.samples.push_back(std::stoul(token()));
    return image;
  }
  ++at;  // the one whitespace byte after maxval
  const size_t bytes_per_sample = image.maxval > 255 ? 2 : 1;
  if (bytes.size() < at + count * bytes_per_sample) return std::nullopt;
  for (size_t i = 0; i < count; ++i) {
    const auto byte = [&](size_t k) { return static_cast<unsigned char>(bytes[at + k]); };
    image.samples.push_back(bytes_per_sample == 1 ? byte(i) : (byte(2 * i) << 8) | byte(2 * i + 1));
  }
  return image;
}

// loadMapYaml + loadMapFromFile: `why_not` says why a file is left out.
std::optional<OccupancyGridMsg> map_server_publishes(const fs::path& yaml, std::string* why_not) {
  const YAML::Node doc = YAML::LoadFile(yaml.string());
  fs::path image_path = doc["image"].as<std::string>();
  if (image_path.is_relative()) image_path = yaml.parent_path() / image_path;
  const double resolution = doc["resolution"].as<double>();
  const auto origin = doc["origin"].as<std::vector<double>>();
  const double free_thresh = doc["free_thresh"].as<double>();
  const double occupied_thresh = doc["occupied_thresh"].as<double>();
  const std::string mode = doc["mode"] ? doc["mode"].as<std::string>() : "trinary";
  bool negate = false;
  try {
    negate = doc["negate"].as<int>() != 0;
  } catch (const YAML::Exception&) {
    negate = doc["negate"].as<bool>();
  }
  const std::optional<Image> image = read_image(image_path);
  if (!image) {
    *why_not = image_path.string() + " is not a PGM";
    return std::nullopt;
  }
  if (image->maxval != 255 && image->maxval != 65535) {
    *why_not = image_path.string() + " has maxval " + std::to_string(image->maxval) +
               " (GraphicsMagick's rescaling of it is not modelled)";
    return std::nullopt;
  }
  OccupancyGridMsg msg;
  msg.header().frame_id("map");
  msg.info().resolution(static_cast<float>(resolution));  // float32 in MapMetaData
  msg.info().width(static_cast<uint32_t>(image->width));
  msg.info().height(static_cast<uint32_t>(image->height));
  msg.info().origin().position().x(origin.at(0));
  msg.info().origin().position().y(origin.at(1));
  msg.info().origin().orientation().z(std::sin(origin.at(2) / 2));  // orientationAroundZAxis
  msg.info().origin().orientation().w(std::cos(origin.at(2) / 2));
  msg.data().resize(image->samples.size());
  for (int y = 0; y < image->height; ++y) {
    for (int x = 0; x < image->width; ++x) {
      const uint32_t sample = image->samples[static_cast<size_t>(y) * image->width + x];
      const double quantum = image->maxval == 255 ? sample * 257.0 : sample;
      const double shade = quantum / 65535.0;  // scaleQuantumToDouble
      const double occ = negate ? shade : 1.0 - shade;
      int cell = -1;
      if (mode == "raw") {
        const double percent = std::round(shade * 255);
        cell = percent >= 0 && percent <= 100 ? static_cast<int>(percent) : -1;
      } else if (occupied_thresh < occ) {
        cell = 100;
      } else if (occ < free_thresh) {
        cell = 0;
      } else if (mode == "scale") {
        cell = static_cast<int>(
            std::rint((occ - free_thresh) / (occupied_thresh - free_thresh) * 100.0));
      }
      msg.data()[static_cast<size_t>(image->width) * (image->height - y - 1) + x] =
          static_cast<int8_t>(cell);
    }
  }
  return msg;
}

// --- vnsba_plan's side: its library calls on the file. ---

core::PlannerOptions vnsba_plan_options(const node::NodeConfig& config) {
  core::PlannerOptions options = config.planner.options();
  core::drop_unsupported_costs(options);
  return options;
}

maps::SliceOptions vnsba_plan_slice(const node::NodeConfig& config) {
  maps::SliceOptions slice;
  slice.z_min = config.slicer.z_min;
  slice.z_max = config.slicer.z_max;
  slice.resolution = config.slicer.resolution;
  slice.remove_speckles = config.slicer.remove_speckles;
  return slice;
}

node::NodeConfig default_config() {
  node::ConfigResult loaded = node::load_config(VNSBA_CONFIG_DIR "/default.yaml");
  EXPECT_TRUE(loaded.config.has_value());
  return loaded.config.has_value() ? *loaded.config : node::default_config().config.value();
}

// --- The loader against the oracle, cell by cell (no DDS). ---

void write_pgm(const fs::path& path, bool ascii, int width, int height, uint32_t maxval,
               const std::vector<uint32_t>& samples) {
  std::ofstream out(path, std::ios::binary);
  out << (ascii ? "P2" : "P5") << "\n# made by test_map_parity\n"
      << width << " " << height << "\n"
      << maxval << "\n";
  for (const uint32_t s : samples) {
    if (ascii)
      out << s << "\n";
    else if (maxval > 255)
      out << static_cast<char>(s >> 8) << static_cast<char>(s & 0xff);
    else
      out << static_cast<char>(s);
  }
}

// What vnsba_plan reads of `yaml` and what the node makes of map_server's message for it must be
// one grid: size, resolution, origin and every value.
void expect_same_grid(const fs::path& yaml) {
  SCOPED_TRACE(yaml.string());
  std::string why_not;
  std::optional<OccupancyGridMsg> published = map_server_publishes(yaml, &why_not);
  ASSERT_TRUE(published) << why_not;
  const node::SliceCheck received = node::from_slice_msg(std::move(*published), "map", 1 << 24);
  ASSERT_TRUE(received.status.ok()) << received.status.message;
  const auto read = maps::load_map_server(yaml.string());
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(received.grid.width, read->width);
  EXPECT_EQ(received.grid.height, read->height);
  EXPECT_EQ(received.grid.resolution, read->resolution);
  EXPECT_EQ(received.grid.origin_x, read->origin_x);
  EXPECT_EQ(received.grid.origin_y, read->origin_y);
  ASSERT_EQ(received.grid.data.size(), read->data.size());
  int shown = 0;
  for (size_t i = 0; i < read->data.size(); ++i) {
    if (received.grid.data[i] != read->data[i] && shown++ < 5) {
      ADD_FAILURE() << "cell " << i << ": map_server publishes " << int{received.grid.data[i]}
                    << ", vnsba_plan reads " << int{read->data[i]};
    }
  }
  EXPECT_EQ(shown, 0) << "cells that differ";
}

TEST(MapParity, VnsbaPlanReadsEveryMapServerFileAsMapServerPublishesIt) {
  const fs::path dir = FreshTempDir("map_parity_modes");
  // Every 8-bit sample, and a 16-bit ramp (every 97th value); resolutions that are not floats.
  std::vector<uint32_t> eight(256), sixteen;
  for (uint32_t s = 0; s < 256; ++s) eight[s] = s;
  for (uint32_t s = 0; s <= 65535; s += 97) sixteen.push_back(s);
  while (sixteen.size() % 16 != 0) sixteen.push_back(65535);
  const char* const kResolutions[] = {"0.05", "0.1", "0.025", "0.3"};  // metres
  int maps = 0;
  for (const bool ascii : {false, true}) {
    for (const uint32_t maxval : {255u, 65535u}) {
      const std::vector<uint32_t>& samples = maxval == 255 ? eight : sixteen;
      const std::string image =
          std::string(ascii ? "p2_" : "p5_") + std::to_string(maxval) + ".pgm";
      write_pgm(dir / image, ascii, 16, static_cast<int>(samples.size() / 16), maxval, samples);
      for (const char* mode : {"trinary", "scale", "raw"}) {
        for (const char* negate : {"0", "1", "true"}) {
          for (const char* thresholds : {"occupied_thresh: 0.65\nfree_thresh: 0.196\n",
                                         "occupied_thresh: 0.75\nfree_thresh: 0.25\n",
                                         "occupied_thresh: 0.9\nfree_thresh: 0.1\n"}) {
            const fs::path yaml = dir / ("map" + std::to_string(maps++) + ".yaml");
            std::ofstream(yaml) << "image: " << image << "\nmode: " << mode
                                << "\nnegate: " << negate << "\n"
                                << thresholds << "resolution: " << kResolutions[maps % 4]
                                << "\norigin: [-12.3, 4.05, 0]\n";
            expect_same_grid(yaml);
          }
        }
      }
    }
  }
  // The repository's map_server fixtures of 8 and 16 bits, with the keys Nav2 requires and
  // maps/ defaults (thresholds, negate) added where they leave them out.
  for (const char* fixture : {"map_server/p5_8bit.yaml", "map_server/p5_16bit.yaml"}) {
    const fs::path source = fs::path(VNSBA_FIXTURE_DIR) / fixture;
    YAML::Node doc = YAML::LoadFile(source.string());
    doc["image"] = (source.parent_path() / doc["image"].as<std::string>()).string();
    if (!doc["occupied_thresh"]) doc["occupied_thresh"] = "0.65";
    if (!doc["free_thresh"]) doc["free_thresh"] = "0.196";
    if (!doc["negate"]) doc["negate"] = "0";
    const fs::path yaml = dir / source.filename();
    std::ofstream(yaml) << doc << "\n";
    expect_same_grid(yaml);
  }
}

// --- The node on the bus against vnsba_plan on the file. ---

class NodeAgainstVnsbaPlan {
 public:
  NodeAgainstVnsbaPlan() : config_(make_config()), node_(config_), client_(config_) {}
  ~NodeAgainstVnsbaPlan() { node_.stop(); }

  bool start() {
    const core::Status s = node_.start();
    EXPECT_TRUE(s.is_ok()) << s.message;
    return s.is_ok() && client_.wait_for_match(node_);
  }

  // Publishes `published` to the node, reads `file` as vnsba_plan does, and plans the same
  // queries on both: free cells spread over the map, each point at a random place in its cell,
  // and points on cell edges. Length and clearance must agree to 1 mm.
  void compare(const std::string& label, OccupancyGridMsg published, const std::string& file) {
    SCOPED_TRACE(label);
    const uint64_t accepted = node_.stats().maps_accepted;
    client_.publish_slice_msg(std::move(published));
    const auto grid = maps::load_map_file(file, vnsba_plan_slice(config_));
    ASSERT_TRUE(grid) << grid.error().message;
    auto built = core::GridMap::build(*grid, config_.map);
    ASSERT_TRUE(built) << built.error().message;
    const auto map = std::make_shared<const core::GridMap>(std::move(built).value());
    core::Planner planner(map);
    const core::PlannerOptions options = vnsba_plan_options(config_);
    const auto end = std::chrono::steady_clock::now() + 20s;
    while (node_.stats().maps_accepted == accepted && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(10ms);
    ASSERT_GT(node_.stats().maps_accepted, accepted) << "the node did not accept the map";

    std::vector<core::Cell> free_cells;
    for (int32_t y = 0; y < map->height(); ++y)
      for (int32_t x = 0; x < map->width(); ++x)
        if (map->free(core::Cell{x, y})) free_cells.push_back({x, y});
    ASSERT_GE(free_cells.size(), 2u);
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> fraction(0.0, 1.0);
    auto pick = [&](bool on_edge) {
      const core::Cell c =
          free_cells[std::uniform_int_distribution<size_t>(0, free_cells.size() - 1)(rng)];
      // Metres, as a user types them: on the cell's lower-left edges, or anywhere inside it.
      const double fx = on_edge ? 0.0 : fraction(rng), fy = on_edge ? 0.0 : fraction(rng);
      return Eigen::Vector2d(map->origin_x() + (c.x + fx) * map->resolution(),
                             map->origin_y() + (c.y + fy) * map->resolution());
    };
    int planned = 0, compared = 0;
    for (int attempt = 0; attempt < 200 && planned < 8; ++attempt) {
      const Eigen::Vector2d s = pick(attempt % 4 == 3), g = pick(attempt % 4 == 2);
      const auto start_cell = map->world_to_cell(s.x(), s.y());
      const auto goal_cell = map->world_to_cell(g.x(), g.y());
      if (!start_cell || !goal_cell) continue;
      const core::PlanQuery query(*start_cell, *goal_cell, map->world_to_grid(s.x(), s.y()),
                                  map->world_to_grid(g.x(), g.y()));
      const core::PlanResult expected = planner.plan(query, options);
      // Mostly plans that succeed (the comparison that matters); a few refusals must agree too.
      if (!expected.status.is_ok() && compared - planned >= 2) continue;
      ++compared;
      planned += expected.status.is_ok();
      char where[160];
      std::snprintf(where, sizeof where, "(%.17g, %.17g) -> (%.17g, %.17g)", s.x(), s.y(), g.x(),
                    g.y());
      SCOPED_TRACE(where);
      const std::string id = label + "-" + std::to_string(attempt);
      const auto identity = client_.publish_request(id, s.x(), s.y(), g.x(), g.y());
      const auto status = client_.wait_status_for(identity, 30s);
      ASSERT_TRUE(status) << "no status for " << id;
      ASSERT_EQ(status->code_name(), core::to_string(expected.status.code)) << status->message();
      if (!expected.status.is_ok()) continue;
      EXPECT_NEAR(status->length_m(), expected.metrics.length_m, 1e-3);
      if (std::isinf(expected.metrics.clearance_m))
        EXPECT_TRUE(std::isinf(status->clearance_m()));
      else
        EXPECT_NEAR(status->clearance_m(), expected.metrics.clearance_m, 1e-3);
    }
    EXPECT_GE(planned, 4) << "too few plans found to compare";
  }

  const node::NodeConfig& config() const { return config_; }

 private:
  static node::NodeConfig make_config() {
    node::NodeConfig cfg = default_config();
    const node::NodeConfig bus = test_config("parity");
    cfg.domain_id = bus.domain_id;
    cfg.topics = bus.topics;
    return cfg;
  }
  node::NodeConfig config_;
  node::PlannerNode node_;
  BusClient client_;
};

// The demo scene, sliced as vnsba_slicer and vnsba_plan slice it (config/default.yaml's band, at
// the tree's leaf size, 0.08 m), and its cells saved as map_server maps of 0.05 m and 0.1 m (the
// scene's leaf is 0.08 m, so the slicer cannot cut it at those resolutions; a map_saver file
// of an office at 0.05 m is what the user published).
TEST(MapParity, TheNodeOnTheBusPlansTheDemoSceneAsVnsbaPlanDoes) {
  NodeAgainstVnsbaPlan parity;
  ASSERT_TRUE(parity.start());
  const std::string scene = VNSBA_CONFIG_DIR "/scenes/geb079.bt";
  const auto slice = maps::load_map_file(scene, vnsba_plan_slice(parity.config()));
  ASSERT_TRUE(slice) << slice.error().message;
  // vnsba_slicer --publish: its slice as a message.
  parity.compare("slicer", node::to_slice_msg(*slice, "map", node::now_msg()), scene);
  const fs::path dir = FreshTempDir("map_parity_scene");
  for (const double resolution : {0.05, 0.1}) {
    core::OccupancyGrid cells = *slice;
    cells.resolution = resolution;
    cells.origin_x = -12.35;  // metres, an origin map_saver could write
    cells.origin_y = -7.65;
    const std::string stem = (dir / ("geb079_" + std::to_string(resolution))).string();
    const auto yaml = maps::save_map_server(cells, stem, parity.config().map.occupied_threshold);
    ASSERT_TRUE(yaml) << yaml.error().message;
    std::string why_not;
    auto published = map_server_publishes(*yaml, &why_not);
    ASSERT_TRUE(published) << why_not;
    parity.compare("map_server " + std::to_string(resolution), std::move(*published), *yaml);
  }
}

// Every map_server map (a .yaml whose image is a .pgm) under the shared data folder.
TEST(MapParity, TheNodeOnTheBusPlansTheSharedMapServerMapsAsVnsbaPlanDoes) {
  std::vector<fs::path> found;
  std::error_code error;
  for (auto it = fs::recursive_directory_iterator(VNSBA_DATA_DIR, error);
       !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
    if (it->path().extension() != ".yaml") continue;
    try {
      const YAML::Node doc = YAML::LoadFile(it->path().string());
      if (doc["image"] && fs::path(doc["image"].as<std::string>()).extension() == ".pgm")
        found.push_back(it->path());
    } catch (const YAML::Exception&) {
      // Not a map_server file.
    }
  }
  if (found.empty())
    GTEST_SKIP() << "no map_server map (.yaml with a .pgm image) under " << VNSBA_DATA_DIR;
  NodeAgainstVnsbaPlan parity;
  ASSERT_TRUE(parity.start());
  for (const fs::path& yaml : found) {
    std::string why_not;
    auto published = map_server_publishes(yaml, &why_not);
    if (!published) {
      std::cout << "[ SKIPPED  ] " << yaml << ": " << why_not << "\n";
      continue;
    }
    parity.compare(yaml.filename().string(), std::move(*published), yaml.string());
  }
}

}  // namespace
}  // namespace vnsba::test
