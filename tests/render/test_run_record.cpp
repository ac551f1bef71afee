// Run records: JSON round trip, errors naming the key, safe file names, and pictures of runs
// with missing parts (no map, no debug) or data that does not fit the map.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "svg_test_support.hpp"
#include "temp_dir.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/records/open_runs.hpp"
#include "vnsba/records/run_record.hpp"

namespace vnsba::test {
namespace {

using records::RunRecord;

RunRecord full_record() {
  RunRecord r;
  r.request_id = "req-1";
  r.request = records::RequestRecord{"plan_request", "astar", Eigen::Vector2d(0.25, 0.25),
                                     Eigen::Vector2d(1.75, 0.75)};
  records::StatusRecord s;
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
  s.metrics.clearance_m = 0.25;
  s.map_stamp_sec = 5;
  s.map_stamp_nanosec = 7;
  r.status = s;
  r.path = {{0.25, 0.25}, {1.25, 0.75}, {1.75, 0.75}};
  records::DebugRecord d;
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
  records::MapReference m;
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
  const auto back =
      records::run_record_from_json(nlohmann::json::parse(records::to_json(r).dump()));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(records::to_json(*back), records::to_json(r));
  EXPECT_EQ(back->debug->expanded_forward.size(), 3u);
  EXPECT_EQ(back->status->metrics.turns, 1);
  EXPECT_TRUE(std::isnan(back->status->metrics.length_ratio));  // NaN travels as null
  EXPECT_EQ(back->status->metrics.clearance_m, 0.25);
  EXPECT_EQ(back->map->file, "maps/m.yaml");
}

// write_json (the recorder's and vnsba_plan's record files) is to_json's document: the same JSON
// once parsed, for a record with every list, empty lists, strings that hold a list's key, and
// values to_json writes as null. Issue 31: its text takes at most 2 bytes for each byte of the
// cells it writes (to_json(r).dump(1) took about 27 for 8).
TEST(RunRecord, WriteJsonIsToJsonsDocumentInAboutTheBytesOfItsCells) {
  RunRecord r = full_record();
  r.request_id = "\"path\": [] \"raw_path\": []";
  r.status->message = "\"expanded_forward\": []";
  r.status->metrics.length_ratio = std::numeric_limits<double>::quiet_NaN();
  r.path.push_back({std::numeric_limits<double>::infinity(), 0.1 + 0.2});
  r.debug->expanded_backward.clear();
  for (const RunRecord& record : {r, RunRecord{}}) {
    std::ostringstream text;
    records::write_json(text, record);
    const nlohmann::json parsed = nlohmann::json::parse(text.str(), nullptr, false);
    ASSERT_FALSE(parsed.is_discarded()) << text.str();
    EXPECT_EQ(parsed, records::to_json(record)) << text.str();
  }

  RunRecord large = full_record();
  large.debug->width = large.debug->height = 1024;
  large.debug->expanded_forward.clear();
  for (int32_t y = 0; y < 1024; ++y)
    for (int32_t x = 0; x < 1024; ++x) large.debug->expanded_forward.push_back({x, y});
  std::ostringstream text;
  records::write_json(text, large);
  const size_t cell_bytes = large.debug->expanded_forward.size() * sizeof(core::Cell);
  EXPECT_LE(text.str().size(), 2 * cell_bytes);
  EXPECT_EQ(nlohmann::json::parse(text.str()), records::to_json(large));
}

// The cost gradient's settings travel with the map reference; a record written before they
// existed reads as no gradient (inflation_radius 0) with the default scaling.
TEST(RunRecord, CostGradientRoundTripsAndOlderRecordsHaveNone) {
  RunRecord r = full_record();
  r.map->inflation_radius = 0.55;
  r.map->cost_scaling_factor = 2.5;
  auto back = records::run_record_from_json(nlohmann::json::parse(records::to_json(r).dump()));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->map->inflation_radius, 0.55);
  EXPECT_EQ(back->map->cost_scaling_factor, 2.5);
  EXPECT_EQ(back->map->build_options().inflation_radius, 0.55);
  nlohmann::json older = records::to_json(r);
  older["map"].erase("inflation_radius");
  older["map"].erase("cost_scaling_factor");
  back = records::run_record_from_json(older);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->map->inflation_radius, 0.0);
  EXPECT_EQ(back->map->cost_scaling_factor, core::GridBuildOptions{}.cost_scaling_factor);
}

// map.inflate_unknown travels with the map reference (a redraw builds the grid the node planned
// on); a record written before the key existed reads true: unknown cells were inflated then.
TEST(RunRecord, InflateUnknownRoundTripsAndOlderRecordsInflated) {
  RunRecord r = full_record();
  for (const bool inflate : {false, true}) {
    r.map->inflate_unknown = inflate;
    const auto back =
        records::run_record_from_json(nlohmann::json::parse(records::to_json(r).dump()));
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->map->inflate_unknown, inflate);
    EXPECT_EQ(back->map->build_options().inflate_unknown, inflate);
  }
  r.map->inflate_unknown = false;
  nlohmann::json older = records::to_json(r);
  older["map"].erase("inflate_unknown");
  const auto back = records::run_record_from_json(older);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->map->inflate_unknown);
  // set_build_options is build_options' inverse.
  records::MapReference ref;
  core::GridBuildOptions options;
  options.occupied_threshold = 70;
  options.allow_unknown = true;
  options.inflate_unknown = true;
  options.robot_radius = 0.3;
  options.inflation_radius = 0.8;
  options.cost_scaling_factor = 1.5;
  ref.set_build_options(options);
  const core::GridBuildOptions again = ref.build_options();
  EXPECT_EQ(again.occupied_threshold, 70);
  EXPECT_TRUE(again.allow_unknown);
  EXPECT_TRUE(again.inflate_unknown);
  EXPECT_EQ(again.robot_radius, 0.3);
  EXPECT_EQ(again.inflation_radius, 0.8);
  EXPECT_EQ(again.cost_scaling_factor, 1.5);
}

// The clearance: metres, "inf" for a map without obstacles, null for NaN; a record written before
// it existed reads NaN and still draws (without a clearance in the caption).
TEST(RunRecord, ClearanceRoundTripsAndOlderRecordsReadNaN) {
  RunRecord r = full_record();
  EXPECT_EQ(records::to_json(r)["status"]["clearance_m"], 0.25);
  r.status->metrics.clearance_m = std::numeric_limits<double>::infinity();
  nlohmann::json j = records::to_json(r);
  EXPECT_EQ(j["status"]["clearance_m"], "inf");
  auto back = records::run_record_from_json(nlohmann::json::parse(j.dump()));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(std::isinf(back->status->metrics.clearance_m));
  EXPECT_GT(back->status->metrics.clearance_m, 0.0);

  r.status->metrics.clearance_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(records::to_json(r)["status"]["clearance_m"].is_null());
  j = records::to_json(full_record());
  j["status"].erase("clearance_m");  // an older record
  back = records::run_record_from_json(j);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(std::isnan(back->status->metrics.clearance_m));
  EXPECT_EQ(back->status->metrics.turns, 1);
  const render::RunPicture picture = records::picture_of(*back, nullptr);
  ASSERT_TRUE(picture.metrics.has_value());
  const std::string svg = render::render_svg(picture);
  EXPECT_NE(svg.find("turns 1"), std::string::npos);
  EXPECT_EQ(svg.find("clearance"), std::string::npos);
  // The record's clearance reaches the caption.
  const std::string with = render::render_svg(records::picture_of(full_record(), nullptr));
  EXPECT_NE(with.find("clearance 0.25 m"), std::string::npos);

  for (const nlohmann::json& bad : {nlohmann::json("wide"), nlohmann::json::array({1})}) {
    j["status"]["clearance_m"] = bad;
    const auto parsed = records::run_record_from_json(j);
    ASSERT_FALSE(parsed) << bad;
    EXPECT_NE(parsed.error().message.find("status.clearance_m"), std::string::npos)
        << parsed.error().message;
  }
}

// The planner options travel with the record and reach the caption; a record written before
// they existed (no "options"), or with some of them, names only what it has: missing means "not
// recorded", never a guessed default.
TEST(RunRecord, PlannerOptionsRoundTripAndOlderRecordsNameNone) {
  const auto caption_of = [](const RunRecord& record) {
    tinyxml2::XMLDocument doc;
    const std::string svg = render::render_svg(records::picture_of(record, nullptr));
    EXPECT_EQ(doc.Parse(svg.c_str()), tinyxml2::XML_SUCCESS);
    std::string text;
    for (auto* t = find_id(doc.RootElement(), "caption")->FirstChildElement("text"); t;
         t = t->NextSiblingElement("text"))
      text += (text.empty() ? "" : " ") + std::string(t->GetText());
    return text;
  };
  RunRecord r = full_record();
  core::PlannerOptions options = core::default_options(core::PlannerKind::kAStar);
  options.prune = true;
  options.cost_weight = 4;
  r.options = records::options_record(options);
  r.map->robot_radius = 0.2;
  nlohmann::json j = records::to_json(r);
  EXPECT_EQ(j["options"]["neighborhood"], "8");
  auto back = records::run_record_from_json(nlohmann::json::parse(j.dump()));
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_TRUE(back->options.has_value());
  EXPECT_EQ(back->options->neighborhood, options.neighborhood);
  EXPECT_EQ(back->options->prune, true);
  EXPECT_EQ(back->options->smooth, false);
  EXPECT_EQ(back->options->cost_weight, 4.0);
  EXPECT_EQ(records::to_json(*back), j);
  std::string caption = caption_of(*back);
  EXPECT_NE(
      caption.find("8 neighbourhood, prune on, smooth off, cost_weight 4, robot radius 0.2 m"),
      std::string::npos)
      << caption;

  // The relax smoother is recorded, read back, named in the caption, and its path so labelled.
  {
    RunRecord relaxed = full_record();
    relaxed.debug->pruned_waypoints = {relaxed.path.front(), relaxed.path.back()};  // path leaves
    core::PlannerOptions relax_options = options;
    relax_options.smoother = core::PathSmoother::kRelax;
    relaxed.options = records::options_record(relax_options);
    const nlohmann::json rj = records::to_json(relaxed);
    EXPECT_EQ(rj["options"]["smoother"], "relax");
    const auto relaxed_back = records::run_record_from_json(nlohmann::json::parse(rj.dump()));
    ASSERT_TRUE(relaxed_back) << relaxed_back.error().message;
    EXPECT_EQ(relaxed_back->options->smoother, core::PathSmoother::kRelax);
    EXPECT_NE(caption_of(*relaxed_back).find("smooth off, smoother relax, cost_weight 4"),
              std::string::npos)
        << caption_of(*relaxed_back);
    const std::string svg = render::render_svg(records::picture_of(*relaxed_back, nullptr));
    EXPECT_NE(svg.find("relaxed path"), std::string::npos);
    EXPECT_EQ(svg.find("smoothed corners"), std::string::npos);
    nlohmann::json bad = rj;
    bad["options"]["smoother"] = "spline";
    const auto refused = records::run_record_from_json(bad);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("options.smoother"), std::string::npos)
        << refused.error().message;
  }

  // An older record: no options, no radii.
  nlohmann::json older = records::to_json(full_record());
  older.erase("options");
  back = records::run_record_from_json(older);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_FALSE(back->options.has_value());
  caption = caption_of(*back);
  for (const char* word : {"neighbourhood", "prune", "smooth", "cost_weight", "radius"})
    EXPECT_EQ(caption.find(word), std::string::npos) << word << " in: " << caption;

  // Some options recorded: those alone are named.
  j["options"].erase("smooth");
  j["options"].erase("neighborhood");
  back = records::run_record_from_json(j);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_FALSE(back->options->smooth.has_value());
  EXPECT_FALSE(back->options->neighborhood.has_value());
  caption = caption_of(*back);
  EXPECT_NE(caption.find("prune on"), std::string::npos) << caption;
  EXPECT_EQ(caption.find("smooth"), std::string::npos) << caption;
  EXPECT_EQ(caption.find("neighbourhood"), std::string::npos) << caption;

  // Bad values are named.
  for (const auto& [key, value] :
       {std::pair{"neighborhood", nlohmann::json("9")}, std::pair{"prune", nlohmann::json(1)},
        std::pair{"cost_weight", nlohmann::json(-1)}, std::pair{"smooth", nlohmann::json("on")}}) {
    nlohmann::json bad = records::to_json(r);
    bad["options"][key] = value;
    const auto parsed = records::run_record_from_json(bad);
    ASSERT_FALSE(parsed) << key;
    EXPECT_NE(parsed.error().message.find(std::string("options.") + key), std::string::npos)
        << parsed.error().message;
  }
}

TEST(RunRecord, BadFieldsAreNamed) {
  const nlohmann::json good = records::to_json(full_record());
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
    const auto parsed = records::run_record_from_json(bad);
    ASSERT_FALSE(parsed) << c.pointer;
    EXPECT_NE(parsed.error().message.find(c.named), std::string::npos)
        << c.pointer << ": " << parsed.error().message;
  }
}

TEST(RunRecord, SafeFileStems) {
  EXPECT_EQ(records::safe_file_stem("goal-3"), "goal-3");
  for (const std::string& id : std::vector<std::string>{"../../etc/passwd", "", ".", "..", "a/b",
                                                        std::string(500, 'x'), "sp ace"}) {
    const std::string stem = records::safe_file_stem(id);
    EXPECT_FALSE(stem.empty());
    EXPECT_EQ(stem.find('/'), std::string::npos) << id;
    EXPECT_NE(stem.front(), '.') << id;
    EXPECT_LE(stem.size(), 130u) << id;
  }
  // Ids that clean to the same text still get different files.
  EXPECT_NE(records::safe_file_stem("a/b"), records::safe_file_stem("a_b"));
  EXPECT_NE(records::safe_file_stem("a/b"), records::safe_file_stem("a:b"));
}

// The picture of a record: debug cells where the debug says, the path in cell coordinates.
TEST(RunRecord, PictureOfARecordWithItsMap) {
  const RunRecord r = full_record();
  core::OccupancyGrid grid;
  grid.width = 4;
  grid.height = 2;
  grid.resolution = 0.5;
  grid.data = {0, 0, 0, 0, 0, 0, 0, 0};
  const render::RunPicture p = records::picture_of(r, &grid);
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
  const render::RunPicture p = records::picture_of(r, &other);
  EXPECT_TRUE(p.expanded_forward.empty());
  EXPECT_EQ(p.path.size(), 3u);

  r.debug.reset();
  r.map.reset();
  const render::RunPicture bare = records::picture_of(r, nullptr);
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
  const render::RunPicture q = records::picture_of(absurd, nullptr);
  EXPECT_LE(int64_t{q.map->width} * q.map->height, int64_t{4096} * 4096);
  absurd.debug->width = 4;
  absurd.debug->height = 2;
  absurd.debug->resolution = NAN;
  EXPECT_LE(int64_t{records::picture_of(absurd, nullptr).map->width}, 4096);
}

TEST(RunRecord, RenderRecordFileReadsTheMapBesideIt) {
  const std::filesystem::path dir = FreshTempDir("record");
  std::filesystem::create_directories(dir / "maps");
  core::OccupancyGrid grid;
  grid.width = 4;
  grid.height = 2;
  grid.resolution = 0.5;
  grid.data = {0, 0, 100, 0, 0, 0, 0, -1};
  ASSERT_TRUE(maps::save_map_server(grid, (dir / "maps" / "m").string()));
  const RunRecord r = full_record();
  std::ofstream(dir / "run.json") << records::to_json(r).dump(1);
  auto svg = records::render_record_file((dir / "run.json").string());
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
  auto broken = records::render_record_file((dir / "broken.json").string());
  ASSERT_FALSE(broken);
  EXPECT_NE(broken.error().message.find("broken.json"), std::string::npos);
  nlohmann::json missing_map = records::to_json(r);
  missing_map["map"]["file"] = "maps/none.yaml";
  std::ofstream(dir / "missing.json") << missing_map.dump();
  auto missing = records::render_record_file((dir / "missing.json").string());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("map.file"), std::string::npos) << missing.error().message;
  EXPECT_FALSE(records::render_record_file((dir / "absent.json").string()));
  std::filesystem::remove_all(dir);
}

// A record whose geometry cannot be drawn is refused with the JSON field named, and no picture is
// made: a negative or null resolution, no cells, an absurd size, a null origin, a bad robot
// radius, debug cells outside the debug grid. With the map file beside it and without. A null
// (to_json's NaN) is said to be null, naming its field.
TEST(RunRecord, RenderRefusesGeometryItCannotDraw) {
  const std::filesystem::path dir = FreshTempDir("bad_geometry");
  std::filesystem::create_directories(dir / "maps");
  core::OccupancyGrid grid;
  grid.width = 4;
  grid.height = 2;
  grid.resolution = 0.5;
  grid.data = {0, 0, 100, 0, 0, 0, 0, 0};
  ASSERT_TRUE(maps::save_map_server(grid, (dir / "maps" / "m").string()));
  RunRecord base = full_record();
  base.map->robot_radius = 0.5;      // one cell: the obstacle's neighbours are drawn inflated
  base.map->inflation_radius = 1.5;  // and the cells beyond them carry costs
  struct Case {
    const char* pointer;
    nlohmann::json value;
    std::string named;  // in the message
  };
  const std::vector<Case> cases = {
      {"/map/resolution", -0.5, "map: resolution must be finite and > 0"},
      {"/map/resolution", nullptr, "map.resolution is null"},
      {"/map/resolution", 0, "map: resolution"},
      {"/map/width", 0, "map: width must be > 0"},
      {"/map/origin", nlohmann::json::array({nullptr, 0}), "map.origin[0] is null"},
      {"/map/robot_radius", -1, "map: robot_radius"},
      {"/map/robot_radius", nullptr, "map.robot_radius is null"},
      {"/map/inflation_radius", -1, "map: inflation_radius"},
      {"/map/inflation_radius", 0.25, "map: inflation_radius"},  // below robot_radius
      {"/map/cost_scaling_factor", nullptr, "map.cost_scaling_factor is null"},
      {"/debug/resolution", -1, "debug: resolution must be finite and > 0"},
      {"/debug/resolution", nullptr, "debug.resolution is null"},
      {"/debug/height", 0, "debug: height must be > 0"},
      {"/debug/origin", nlohmann::json::array({0, nullptr}), "debug.origin[1] is null"},
      {"/map/inflation_radius", nullptr, "map.inflation_radius is null"},
      {"/debug/expanded_forward/1", nlohmann::json::array({4, 0}),
       "debug.expanded_forward[1] = [4, 0] is outside the debug grid"},
      {"/debug/expanded_backward/0", nlohmann::json::array({0, -1}), "debug.expanded_backward[0]"},
      {"/debug/raw_path/2", nlohmann::json::array({9, 9}), "debug.raw_path[2]"},
      {"/debug/meeting_cell", nlohmann::json::array({0, 2}), "debug.meeting_cell"},
  };
  for (const bool with_file : {true, false}) {
    RunRecord r = base;
    if (!with_file) r.map->file.clear();
    const nlohmann::json good = records::to_json(r);
    std::ofstream(dir / "good.json") << good.dump(1);
    const auto drawn = records::render_record_file((dir / "good.json").string());
    ASSERT_TRUE(drawn) << drawn.error().message;
    if (with_file) {
      // The record's robot radius reaches the planning map the picture is drawn from.
      tinyxml2::XMLDocument doc;
      ASSERT_EQ(doc.Parse(drawn->c_str()), tinyxml2::XML_SUCCESS);
      EXPECT_GT(data_count(find_id(doc.RootElement(), "map-inflated")), 0);
      // And its cost gradient: the free cells 1-1.5 m from the obstacle.
      int64_t costly = 0;
      for (int level = 1; level <= 4; ++level)
        costly +=
            data_count(find_id(doc.RootElement(), ("map-cost-" + std::to_string(level)).c_str()));
      EXPECT_GT(costly, 0);
    }
    for (const Case& c : cases) {
      SCOPED_TRACE(std::string(c.pointer) + (with_file ? " with the map file" : " without it"));
      nlohmann::json bad = good;
      bad[nlohmann::json::json_pointer(c.pointer)] = c.value;
      const std::filesystem::path path = dir / "bad.json";
      std::ofstream(path) << bad.dump(1);
      const auto svg = records::render_record_file(path.string());
      ASSERT_FALSE(svg) << bad[nlohmann::json::json_pointer(c.pointer)];
      EXPECT_EQ(svg.error().message.rfind(path.string() + ": ", 0), 0u) << svg.error().message;
      EXPECT_NE(svg.error().message.find(c.named), std::string::npos) << svg.error().message;
      // Issue 31: a null was reported as the NaN it reads as ("got nan").
      EXPECT_EQ(svg.error().message.find("nan"), std::string::npos) << svg.error().message;
    }
  }
  // An absurd size is refused before any cell is allocated.
  nlohmann::json absurd = records::to_json(base);
  absurd["map"]["file"] = "";
  absurd["map"]["width"] = absurd["map"]["height"] = 2000000000;
  std::ofstream(dir / "absurd.json") << absurd.dump();
  const auto huge = records::render_record_file((dir / "absurd.json").string());
  ASSERT_FALSE(huge);
  EXPECT_NE(huge.error().message.find("map: width x height"), std::string::npos)
      << huge.error().message;
  std::filesystem::remove_all(dir);
}

// --- Open runs: what the recorder holds until a run is complete, bounded in bytes. ---

records::DebugRecord debug_of(size_t cells) {
  records::DebugRecord d;
  d.width = d.height = 1000;
  d.resolution = 0.1;
  d.expanded_forward.assign(cells, core::Cell{1, 2});
  return d;
}

size_t sum_of_bytes(const records::OpenRuns& runs, const std::vector<std::string>& ids) {
  size_t sum = 0;
  for (const std::string& id : ids)
    if (const records::OpenRun* run = runs.find(id)) sum += run->bytes;
  return sum;
}

// Twice the cap of debug data goes in: the bytes held never pass the cap, the debug data of the
// oldest runs goes first (the runs themselves stay, to be written without it), and every drop
// names the run and the bytes it freed, in the totals too.
TEST(OpenRuns, DebugDataPastTheByteCapIsDroppedOldestFirstAndReported) {
  const size_t cells_per_run = 25000;
  const size_t debug_bytes = cells_per_run * sizeof(core::Cell);
  const size_t cap = 5 * debug_bytes;  // room for fewer than five runs with their overheads
  records::OpenRuns runs(1000, cap);
  std::vector<std::string> ids;
  std::vector<records::DroppedPart> drops;
  for (int i = 0; i < 10; ++i) {
    ids.push_back("run-" + std::to_string(i));
    const auto dropped = runs.update(
        ids.back(), [&](records::OpenRun& run) { run.record.debug = debug_of(cells_per_run); });
    drops.insert(drops.end(), dropped.begin(), dropped.end());
    EXPECT_LE(runs.bytes(), cap) << ids.back();
    EXPECT_EQ(runs.bytes(), sum_of_bytes(runs, ids)) << ids.back();
  }
  EXPECT_EQ(runs.size(), 10u);  // every run is still open
  ASSERT_GE(drops.size(), 5u);  // at least half the debug data did not fit
  size_t freed = 0;
  for (size_t k = 0; k < drops.size(); ++k) {
    EXPECT_EQ(drops[k].request_id, ids[k]) << "oldest first";
    EXPECT_FALSE(drops[k].whole_run);
    EXPECT_GE(drops[k].bytes, debug_bytes);
    EXPECT_NE(drops[k].reason.find(std::to_string(cap) + " bytes"), std::string::npos)
        << drops[k].reason;
    EXPECT_FALSE(runs.find(ids[k])->record.debug.has_value());
    freed += drops[k].bytes;
  }
  EXPECT_TRUE(runs.find(ids.back())->record.debug.has_value());  // the newest kept theirs
  EXPECT_EQ(runs.dropped().debug, drops.size());
  EXPECT_EQ(runs.dropped().runs, 0u);
  EXPECT_EQ(runs.dropped().bytes, freed);

  // One debug message larger than the cap on its own is dropped at once; its run stays.
  const auto alone = runs.update("huge", [&](records::OpenRun& run) {
    run.record.debug = debug_of(cap / sizeof(core::Cell) + 1);
  });
  ASSERT_FALSE(alone.empty());
  EXPECT_EQ(alone.back().request_id, "huge");
  EXPECT_GT(alone.back().bytes, cap);
  EXPECT_LE(runs.bytes(), cap);
  ASSERT_NE(runs.find("huge"), nullptr);
  EXPECT_FALSE(runs.find("huge")->record.debug.has_value());

  // Writing the runs out releases their bytes.
  const auto taken = runs.take([](const records::OpenRun&) { return true; });
  EXPECT_EQ(taken.size(), 11u);
  EXPECT_EQ(runs.bytes(), 0u);
  EXPECT_EQ(runs.size(), 0u);
}

// When debug data is not what holds the bytes (here long paths), whole runs go, oldest first;
// past the count limit too.
TEST(OpenRuns, WholeRunsGoWhenDebugDataIsNotEnoughOrTooManyAreOpen) {
  const size_t path_bytes = 10000 * sizeof(Eigen::Vector2d);
  records::OpenRuns by_bytes(1000, 3 * path_bytes);
  std::vector<records::DroppedPart> drops;
  for (int i = 0; i < 6; ++i) {
    const auto d = by_bytes.update("p" + std::to_string(i), [&](records::OpenRun& run) {
      run.record.path.assign(10000, Eigen::Vector2d(1, 2));
    });
    drops.insert(drops.end(), d.begin(), d.end());
    EXPECT_LE(by_bytes.bytes(), 3 * path_bytes);
  }
  ASSERT_FALSE(drops.empty());
  EXPECT_TRUE(drops.front().whole_run);
  EXPECT_EQ(drops.front().request_id, "p0");
  EXPECT_EQ(by_bytes.find("p0"), nullptr);
  EXPECT_NE(by_bytes.find("p5"), nullptr);
  EXPECT_EQ(by_bytes.dropped().runs, drops.size());

  records::OpenRuns by_count(3, size_t{1} << 30);
  for (const char* id : {"a", "b", "c"})
    EXPECT_TRUE(by_count.update(id, [](records::OpenRun&) {}).empty());
  const auto d = by_count.update("d", [](records::OpenRun&) {});
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].request_id, "a");
  EXPECT_TRUE(d[0].whole_run);
  EXPECT_NE(d[0].reason.find("more than 3 open runs"), std::string::npos) << d[0].reason;
  EXPECT_EQ(by_count.size(), 3u);
  // Changing an open run opens nothing and drops nothing.
  EXPECT_TRUE(by_count.update("b", [](records::OpenRun&) {}).empty());
}

}  // namespace
}  // namespace vnsba::test
