// Run records: JSON round trip, errors naming the key, safe file names, and pictures of runs
// with missing parts (no map, no debug) or data that does not fit the map.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <filesystem>
#include <fstream>

#include "recorder/run_record.hpp"
#include "svg_test_support.hpp"
#include "vnsba/core/map_io.hpp"

namespace vnsba::test {
namespace {

using tools::RunRecord;

RunRecord full_record() {
  RunRecord r;
  r.request_id = "req-1";
  r.request = tools::RequestRecord{"plan_request", "astar", Eigen::Vector2d(0.25, 0.25),
                                   Eigen::Vector2d(1.75, 0.75)};
  tools::StatusRecord s;
  s.code = 0;
  s.code_name = "OK";
  s.planner = "astar";
  s.metrics.length_m = 1.6;
  s.metrics.length_cells = 3.2;
  s.metrics.raw_cost_cells = 3.4;
  s.metrics.turns = 1;
  s.metrics.turn_angle_deg = 45;
  s.metrics.expanded = 9;
  s.metrics.planning_time_us = 12;
  s.map_stamp_sec = 5;
  s.map_stamp_nanosec = 7;
  r.status = s;
  r.path = {{0.25, 0.25}, {1.25, 0.75}, {1.75, 0.75}};
  tools::DebugRecord d;
  d.planner = "astar";
  d.width = 4;
  d.height = 2;
  d.resolution = 0.5;
  d.expanded_forward = {{0, 0}, {1, 0}, {1, 1}};
  d.expanded_backward = {{3, 1}};
  d.meeting_cell = core::Cell{2, 1};
  d.raw_path = {{0, 0}, {1, 1}, {2, 1}, {3, 1}};
  d.pruned_waypoints = {{0.25, 0.25}, {0.75, 0.75}, {1.75, 0.75}};
  r.debug = d;
  tools::MapReference m;
  m.file = "maps/m.yaml";
  m.frame_id = "map";
  m.width = 4;
  m.height = 2;
  m.resolution = 0.5;
  r.map = m;
  return r;
}

TEST(RunRecord, JsonRoundTripKeepsEverything) {
  const RunRecord r = full_record();
  const auto back = tools::run_record_from_json(nlohmann::json::parse(tools::to_json(r).dump()));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(tools::to_json(*back), tools::to_json(r));
  EXPECT_EQ(back->debug->expanded_forward.size(), 3u);
  EXPECT_EQ(back->status->metrics.turns, 1);
  EXPECT_TRUE(std::isnan(back->status->metrics.length_ratio));  // NaN travels as null
  EXPECT_EQ(back->map->file, "maps/m.yaml");
}

TEST(RunRecord, BadFieldsAreNamed) {
  const nlohmann::json good = tools::to_json(full_record());
  struct Case {
    const char* pointer;
    nlohmann::json value;
    const char* named;
  };
  for (const Case& c :
       {Case{"/status/turns", "three", "status.turns"}, Case{"/status/code", 300, "status.code"},
        Case{"/debug/expanded_forward/1", nlohmann::json::array({1}), "debug.expanded_forward[1]"},
        Case{"/path/0", "x", "path[0]"},
        Case{"/map/occupied_threshold", 0, "map.occupied_threshold"},
        Case{"/request", 5, "request"}, Case{"/request_id", nullptr, "request_id"}}) {
    nlohmann::json bad = good;
    bad[nlohmann::json::json_pointer(c.pointer)] = c.value;
    const auto parsed = tools::run_record_from_json(bad);
    ASSERT_FALSE(parsed) << c.pointer;
    EXPECT_NE(parsed.error().message.find(c.named), std::string::npos)
        << c.pointer << ": " << parsed.error().message;
  }
}

TEST(RunRecord, SafeFileStems) {
  EXPECT_EQ(tools::safe_file_stem("goal-3"), "goal-3");
  for (const std::string& id : std::vector<std::string>{"../../etc/passwd", "", ".", "..", "a/b",
                                                        std::string(500, 'x'), "sp ace"}) {
    const std::string stem = tools::safe_file_stem(id);
    EXPECT_FALSE(stem.empty());
    EXPECT_EQ(stem.find('/'), std::string::npos) << id;
    EXPECT_NE(stem.front(), '.') << id;
    EXPECT_LE(stem.size(), 130u) << id;
  }
  // Ids that clean to the same text still get different files.
  EXPECT_NE(tools::safe_file_stem("a/b"), tools::safe_file_stem("a_b"));
  EXPECT_NE(tools::safe_file_stem("a/b"), tools::safe_file_stem("a:b"));
}

// The picture of a record: debug cells where the debug says, the path in cell coordinates.
TEST(RunRecord, PictureOfARecordWithItsMap) {
  const RunRecord r = full_record();
  core::OccupancyGrid grid;
  grid.width = 4;
  grid.height = 2;
  grid.resolution = 0.5;
  grid.data = {0, 0, 0, 0, 0, 0, 0, 0};
  const render::RunPicture p = tools::picture_of(r, &grid);
  EXPECT_EQ(p.expanded_forward.size(), 3u);
  ASSERT_EQ(p.path.size(), 3u);
  EXPECT_NEAR(p.path[1].x(), 2.5, 1e-9);  // 1.25 m at 0.5 m per cell
  EXPECT_NEAR(p.path[1].y(), 1.5, 1e-9);
  ASSERT_TRUE(p.start && p.goal);
  EXPECT_NEAR(p.goal->x(), 3.5, 1e-9);
  EXPECT_EQ(p.status, "OK");
  ASSERT_TRUE(p.metrics.has_value());
}

// Debug data for another grid (the slice changed in between) is not drawn on this one, and a
// record with neither map nor debug still gets a picture of its path.
TEST(RunRecord, MismatchedOrMissingPartsStillDraw) {
  RunRecord r = full_record();
  core::OccupancyGrid other;
  other.width = 8;
  other.height = 8;
  other.resolution = 0.5;
  other.data.assign(64, 0);
  const render::RunPicture p = tools::picture_of(r, &other);
  EXPECT_TRUE(p.expanded_forward.empty());
  EXPECT_EQ(p.path.size(), 3u);

  r.debug.reset();
  r.map.reset();
  const render::RunPicture bare = tools::picture_of(r, nullptr);
  ASSERT_TRUE(bare.map);
  EXPECT_GT(bare.map->width, 0);
  for (const auto& q : bare.path) {
    EXPECT_GE(q.x(), 0);
    EXPECT_LE(q.x(), bare.map->width);
    EXPECT_GE(q.y(), 0);
    EXPECT_LE(q.y(), bare.map->height);
  }
  tinyxml2::XMLDocument doc;
  const std::string svg = render::render_svg(bare);
  ASSERT_EQ(doc.Parse(svg.c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_EQ(data_count(find_id(doc.RootElement(), "final-path")), 3);

  // Absurd debug geometry (a huge grid, NaN resolution) falls back to a frame around the path.
  RunRecord absurd = full_record();
  absurd.map.reset();
  absurd.debug->width = 2000000000;
  absurd.debug->height = 2000000000;
  const render::RunPicture q = tools::picture_of(absurd, nullptr);
  EXPECT_LE(int64_t{q.map->width} * q.map->height, int64_t{4096} * 4096);
  absurd.debug->width = 4;
  absurd.debug->height = 2;
  absurd.debug->resolution = NAN;
  EXPECT_LE(int64_t{tools::picture_of(absurd, nullptr).map->width}, 4096);
}

TEST(RunRecord, RenderRecordFileReadsTheMapBesideIt) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / ("vnsba_record_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir / "maps");
  core::OccupancyGrid grid;
  grid.width = 4;
  grid.height = 2;
  grid.resolution = 0.5;
  grid.data = {0, 0, 100, 0, 0, 0, 0, -1};
  ASSERT_TRUE(core::save_map_server(grid, (dir / "maps" / "m").string()));
  const RunRecord r = full_record();
  std::ofstream(dir / "run.json") << tools::to_json(r).dump(1);
  auto svg = tools::render_record_file((dir / "run.json").string());
  ASSERT_TRUE(svg) << svg.error().message;
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(svg->c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_EQ(decode_runs(find_id(doc.RootElement(), "map-occupied"), 2),
            (std::set<std::pair<int, int>>{{2, 0}}));
  EXPECT_EQ(decode_runs(find_id(doc.RootElement(), "map-unknown"), 2),
            (std::set<std::pair<int, int>>{{3, 1}}));
  EXPECT_EQ(data_count(find_id(doc.RootElement(), "expanded-forward")), 3);

  // Broken files: errors name the file and the problem, never a crash.
  std::ofstream(dir / "broken.json") << "{ not json";
  auto broken = tools::render_record_file((dir / "broken.json").string());
  ASSERT_FALSE(broken);
  EXPECT_NE(broken.error().message.find("broken.json"), std::string::npos);
  nlohmann::json missing_map = tools::to_json(r);
  missing_map["map"]["file"] = "maps/none.yaml";
  std::ofstream(dir / "missing.json") << missing_map.dump();
  auto missing = tools::render_record_file((dir / "missing.json").string());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("map.file"), std::string::npos) << missing.error().message;
  EXPECT_FALSE(tools::render_record_file((dir / "absent.json").string()));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vnsba::test
