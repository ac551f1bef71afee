// The SVG renderer: every layer present and named, its geometry equal to the run it shows,
// valid XML whatever the text, bounded file size, and a real rasteriser can draw it.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <set>

#include "svg_test_support.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/render/run_picture.hpp"
#include "vnsba/render/svg.hpp"

namespace vnsba::test {
namespace {

using core::Cell;
using core::Point2;

std::shared_ptr<const core::GridMap> rooms_map(core::OccupancyGrid* grid_out = nullptr) {
  auto grid = maps::load_movingai_map(VNSBA_FIXTURE_DIR "/maps/rooms_32.map");
  EXPECT_TRUE(grid) << grid.error().message;
  if (grid_out) *grid_out = *grid;
  return std::make_shared<const core::GridMap>(core::GridMap::build(*grid).value());
}

struct Rendered {
  std::string svg;
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLElement* root = nullptr;
  bool parse() {
    const bool ok = doc.Parse(svg.c_str(), svg.size()) == tinyxml2::XML_SUCCESS;
    root = doc.RootElement();
    return ok && root != nullptr && std::string(root->Name()) == "svg";
  }
};

std::set<std::pair<int, int>> as_set(const std::vector<Cell>& cells) {
  std::set<std::pair<int, int>> out;
  for (const Cell& c : cells) out.insert({c.x, c.y});
  return out;
}

void expect_same_points(const std::vector<Point2>& drawn, const std::vector<Point2>& expected,
                        const char* what) {
  ASSERT_EQ(drawn.size(), expected.size()) << what;
  for (size_t i = 0; i < drawn.size(); ++i)
    EXPECT_LE((drawn[i] - expected[i]).norm(), 1e-3) << what << " point " << i;
}

// A VNS-BA* run across the rooms map, with expansions recorded.
struct RoomsRun {
  core::OccupancyGrid grid;
  std::shared_ptr<const core::GridMap> map = rooms_map(&grid);
  core::PlanQuery query{{2, 2}, {29, 13}};
  core::PlanResult result;
  RoomsRun() {
    core::PlannerOptions options = core::default_options(core::PlannerKind::kVnsBaStar);
    options.record_expansions = true;
    result = core::plan_once(map, query, options);
  }
};

TEST(RunPicture, HasEveryLayerTheLegendScaleBarAndCaption) {
  RoomsRun run;
  ASSERT_TRUE(run.result.status.is_ok()) << run.result.status.message;
  auto picture = std::make_shared<const render::MapPicture>(render::map_picture(run.grid));
  render::RunPicture rp = render::picture_of(picture, run.query, run.result);
  rp.title = "rooms";
  Rendered r;
  r.svg = render::render_svg(rp);
  ASSERT_TRUE(r.parse());
  for (const char* id : {"map-occupied", "map-unknown", "map-inflated", "expanded-forward",
                         "expanded-backward", "raw-path", "pruned-path", "smoothed-corners",
                         "meeting-cell", "start", "goal", "legend", "scale-bar", "caption"})
    EXPECT_NE(find_id(r.root, id), nullptr) << "missing layer " << id;
  std::set<std::string> legend;
  for (auto* t = find_id(r.root, "legend")->FirstChildElement("text"); t;
       t = t->NextSiblingElement("text"))
    legend.insert(t->GetText());
  for (const char* label :
       {"occupied", "unknown", "forward expansions", "backward expansions", "raw grid path",
        "pruned path", "smoothed corners", "meeting cell", "start", "goal"})
    EXPECT_TRUE(legend.count(label)) << "legend lacks " << label;
  std::string caption;
  for (auto* t = find_id(r.root, "caption")->FirstChildElement("text"); t;
       t = t->NextSiblingElement("text"))
    caption += std::string(t->GetText()) + "\n";
  EXPECT_NE(caption.find("vns_bastar"), std::string::npos) << caption;
  EXPECT_NE(caption.find("OK"), std::string::npos) << caption;
  EXPECT_NE(caption.find("turns " + std::to_string(run.result.metrics.turns)), std::string::npos)
      << caption;
  EXPECT_NE(caption.find("expanded " + std::to_string(run.result.metrics.expanded)),
            std::string::npos)
      << caption;
  // The clearance beside length and turns, in metres.
  ASSERT_TRUE(std::isfinite(run.result.metrics.clearance_m));
  char clearance[64];
  std::snprintf(clearance, sizeof clearance, " cells), clearance %.2f m, turns ",
                run.result.metrics.clearance_m);
  EXPECT_NE(caption.find(clearance), std::string::npos) << clearance << " not in: " << caption;
  // The scale bar's length is a round number of metres and its drawn length matches it.
  const auto* bar = find_id(r.root, "scale-bar");
  const double metres = bar->DoubleAttribute("data-metres");
  const double cells = bar->DoubleAttribute("data-cells");
  EXPECT_GT(metres, 0);
  EXPECT_NEAR(cells, metres / run.grid.resolution, 1e-3);
  const auto* line = bar->FirstChildElement("line");
  ASSERT_NE(line, nullptr);
  EXPECT_NEAR(line->DoubleAttribute("x2") - line->DoubleAttribute("x1"), cells, 1e-3);
}

// The clearance is left out of the caption when NaN and says so when infinite (no obstacle).
TEST(RunPicture, CaptionClearanceOmittedWhenNaNAndInfWithoutObstacles) {
  RoomsRun run;
  ASSERT_TRUE(run.result.status.is_ok()) << run.result.status.message;
  auto picture = std::make_shared<const render::MapPicture>(render::map_picture(run.grid));
  render::RunPicture rp = render::picture_of(picture, run.query, run.result);
  rp.metrics->clearance_m = std::numeric_limits<double>::quiet_NaN();
  std::string svg = render::render_svg(rp);
  EXPECT_EQ(svg.find("clearance"), std::string::npos);
  EXPECT_NE(svg.find("turns " + std::to_string(run.result.metrics.turns)), std::string::npos);
  rp.metrics->clearance_m = std::numeric_limits<double>::infinity();
  svg = render::render_svg(rp);
  EXPECT_NE(svg.find("clearance inf (no obstacle), turns"), std::string::npos);
}

// A query's requested points (what tolerance measures from) are where start and goal are drawn.
TEST(RunPicture, StartAndGoalAtTheQuerysRequestedPoints) {
  RoomsRun run;
  auto picture = std::make_shared<const render::MapPicture>(render::map_picture(run.grid));
  core::PlanQuery query = run.query;
  query.start_point = Point2(2.2, 2.9);
  query.goal_point = Point2(29.75, 13.1);
  const render::RunPicture rp = render::picture_of(picture, query, run.result);
  ASSERT_TRUE(rp.start && rp.goal);
  EXPECT_EQ(*rp.start, *query.start_point);
  EXPECT_EQ(*rp.goal, *query.goal_point);
  const render::RunPicture centres = render::picture_of(picture, run.query, run.result);
  EXPECT_EQ(*centres.start, core::cell_centre(run.query.start));
}

TEST(RunPicture, GeometryEqualsTheRun) {
  RoomsRun run;
  ASSERT_TRUE(run.result.status.is_ok());
  const int h = run.grid.height;
  auto picture = std::make_shared<const render::MapPicture>(render::map_picture(run.grid));
  Rendered r;
  r.svg = render::render_svg(render::picture_of(picture, run.query, run.result));
  ASSERT_TRUE(r.parse());

  std::set<std::pair<int, int>> occupied;
  for (int y = 0; y < run.grid.height; ++y)
    for (int x = 0; x < run.grid.width; ++x)
      if (run.grid.at(x, y) >= 65) occupied.insert({x, y});
  const auto* occupied_layer = find_id(r.root, "map-occupied");
  EXPECT_EQ(decode_runs(occupied_layer, h), occupied);
  EXPECT_EQ(data_count(occupied_layer), static_cast<long>(occupied.size()));
  EXPECT_EQ(data_count(find_id(r.root, "map-unknown")), 0);

  for (const auto& [id, cells] : {std::pair{"expanded-forward", &run.result.expanded_forward},
                                  std::pair{"expanded-backward", &run.result.expanded_backward}}) {
    ASSERT_FALSE(cells->empty()) << id;
    const auto* layer = find_id(r.root, id);
    EXPECT_EQ(decode_runs(layer, h), as_set(*cells)) << id;
    EXPECT_EQ(data_count(layer), static_cast<long>(as_set(*cells).size())) << id;
  }
  auto raw = decode_polylines(find_id(r.root, "raw-path"), h);
  ASSERT_EQ(raw.size(), 1u);
  expect_same_points(raw[0], core::cell_centres(run.result.raw_path), "raw path");
  auto pruned = decode_polylines(find_id(r.root, "pruned-path"), h);
  ASSERT_EQ(pruned.size(), 1u);
  expect_same_points(pruned[0], run.result.waypoints, "pruned path");
  auto final_path = decode_polylines(find_id(r.root, "final-path"), h);
  ASSERT_EQ(final_path.size(), 1u);
  expect_same_points(final_path[0], run.result.path, "final path");

  const auto* start = find_id(r.root, "start")->FirstChildElement("circle");
  ASSERT_NE(start, nullptr);
  EXPECT_NEAR(start->DoubleAttribute("cx"), run.query.start.x + 0.5, 1e-3);
  EXPECT_NEAR(h - start->DoubleAttribute("cy"), run.query.start.y + 0.5, 1e-3);
  const auto* goal = find_id(r.root, "goal")->FirstChildElement("circle");
  ASSERT_NE(goal, nullptr);
  EXPECT_NEAR(goal->DoubleAttribute("cx"), run.query.goal.x + 0.5, 1e-3);
  ASSERT_TRUE(run.result.meeting_cell.has_value());
  const auto* meeting = find_id(r.root, "meeting-cell")->FirstChildElement("rect");
  ASSERT_NE(meeting, nullptr);
  EXPECT_NEAR(meeting->DoubleAttribute("x"), run.result.meeting_cell->x, 1e-3);
  EXPECT_NEAR(h - meeting->DoubleAttribute("y") - 1.0, run.result.meeting_cell->y, 1e-3);
}

// The smoothed corners are exactly the stretches where the final path leaves the pruned
// polyline: none without smoothing, one per smoothed turn with it.
TEST(RunPicture, SmoothedCornersAreWhereThePathLeavesThePolyline) {
  RoomsRun run;
  const int h = run.grid.height;
  auto picture = std::make_shared<const render::MapPicture>(render::map_picture(run.grid));
  for (const bool smooth : {false, true}) {
    core::PlannerOptions options = core::default_options(core::PlannerKind::kVnsBaStar);
    options.smooth = smooth;
    const core::PlanResult result = core::plan_once(run.map, run.query, options);
    ASSERT_TRUE(result.status.is_ok());
    ASSERT_GT(result.metrics.turns, 0) << "the query must turn for this test to mean anything";
    Rendered r;
    r.svg = render::render_svg(render::picture_of(picture, run.query, result));
    ASSERT_TRUE(r.parse());
    const auto* layer = find_id(r.root, "smoothed-corners");
    const auto stretches = decode_polylines(layer, h);
    if (!smooth) {
      EXPECT_TRUE(stretches.empty());
      continue;
    }
    EXPECT_GE(static_cast<int>(stretches.size()), 1);
    EXPECT_LE(static_cast<int>(stretches.size()), result.metrics.turns);
    for (const auto& s : stretches) {
      ASSERT_GE(s.size(), 3u);
      // Each stretch starts and ends near a waypoint's segment and bends by the turn there:
      // its middle lies off the polyline.
      double farthest = 0;
      for (const Point2& p : s) {
        double nearest = INFINITY;
        for (size_t k = 0; k + 1 < result.waypoints.size(); ++k) {
          const Point2 a = result.waypoints[k], b = result.waypoints[k + 1];
          const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
          nearest = std::min(nearest, (p - (a + t * (b - a))).norm());
        }
        farthest = std::max(farthest, nearest);
      }
      EXPECT_GT(farthest, 1e-4);
    }
  }
}

TEST(RunPicture, UnknownAndInflatedCellsAreTheirOwnLayers) {
  // 12 x 8: a block of unknown on the left, one occupied cell inflated by 1 m at 1 m cells.
  core::OccupancyGrid grid;
  grid.width = 12;
  grid.height = 8;
  grid.data.assign(96, 0);
  for (int y = 2; y < 6; ++y)
    for (int x = 0; x < 3; ++x) grid.data[y * 12 + x] = -1;
  grid.data[4 * 12 + 8] = 100;
  core::GridBuildOptions options;
  options.robot_radius = 1.0;
  options.allow_unknown = true;
  auto built = core::GridMap::build(grid, options);
  ASSERT_TRUE(built);
  const render::MapPicture picture = render::map_picture(grid, 65, &built.value());
  std::set<std::pair<int, int>> inflated;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 12; ++x)
      if (grid.at(x, y) == 0 && built->blocked(x, y)) inflated.insert({x, y});
  ASSERT_EQ(inflated.size(), 4u);  // the 4-neighbours within 1 m of the occupied centre
  render::RunPicture run;
  run.map = std::make_shared<const render::MapPicture>(picture);
  Rendered r;
  r.svg = render::render_svg(run);
  ASSERT_TRUE(r.parse());
  EXPECT_EQ(decode_runs(find_id(r.root, "map-inflated"), 8), inflated);
  EXPECT_EQ(decode_runs(find_id(r.root, "map-unknown"), 8).size(), 12u);
  EXPECT_EQ(decode_runs(find_id(r.root, "map-occupied"), 8),
            (std::set<std::pair<int, int>>{{8, 4}}));
}

// The cost gradient is drawn as kCostLevels layers under the map, each cell in the band of its
// cost (GridMap::cost, the oracle); the legend names it only where a map has costs.
TEST(RunPicture, CellCostsAreDrawnInBandsUnderTheMap) {
  core::OccupancyGrid grid;
  grid.width = 16;
  grid.height = 9;
  grid.data.assign(16 * 9, 0);
  for (int y = 0; y < 9; ++y) grid.data[y * 16 + 3] = 100;  // a wall at x = 3
  grid.data[4 * 16 + 12] = 40;                              // a graded cost of 0.4
  core::GridBuildOptions options;
  options.robot_radius = 1.0;
  options.inflation_radius = 6.0;
  options.cost_scaling_factor = 0.5;
  auto built = core::GridMap::build(grid, options);
  ASSERT_TRUE(built);
  ASSERT_TRUE(built->has_costs());
  const render::MapPicture picture = render::map_picture(grid, 65, &built.value());
  std::set<std::pair<int, int>> band[render::MapPicture::kCostLevels + 1];
  for (int y = 0; y < 9; ++y) {
    for (int x = 0; x < 16; ++x) {
      const double cost = built->blocked(x, y) ? 0.0 : built->cost({x, y});
      if (cost <= 0.0) continue;
      int level = 1;
      while (level < render::MapPicture::kCostLevels &&
             cost > static_cast<double>(level) / render::MapPicture::kCostLevels)
        ++level;
      band[level].insert({x, y});
    }
  }
  render::RunPicture run;
  run.map = std::make_shared<const render::MapPicture>(picture);
  Rendered r;
  r.svg = render::render_svg(run);
  ASSERT_TRUE(r.parse());
  size_t drawn = 0;
  for (int level = 1; level <= render::MapPicture::kCostLevels; ++level) {
    SCOPED_TRACE(level);
    EXPECT_EQ(decode_runs(find_id(r.root, ("map-cost-" + std::to_string(level)).c_str()), 9),
              band[level]);
    drawn += band[level].size();
  }
  EXPECT_GT(drawn, 20u);
  EXPECT_EQ(band[2].count({12, 4}), 1u) << "the graded cell (0.4) is in the second band";
  EXPECT_NE(r.svg.find("cell cost"), std::string::npos);
  // A binary map (no graded values, no gradient): no cost layer, no legend entry.
  grid.data[4 * 16 + 12] = 0;
  auto binary = core::GridMap::build(grid, core::GridBuildOptions{});
  ASSERT_TRUE(binary);
  ASSERT_FALSE(binary->has_costs());
  render::RunPicture plain;
  plain.map =
      std::make_shared<const render::MapPicture>(render::map_picture(grid, 65, &binary.value()));
  const std::string svg = render::render_svg(plain);
  EXPECT_EQ(svg.find("map-cost-"), std::string::npos);
  EXPECT_EQ(svg.find("cell cost"), std::string::npos);
}

TEST(RunPicture, FailedRunShowsStartGoalAndTheMessage) {
  RoomsRun run;
  const core::PlanQuery blocked{{2, 2}, {0, 0}};  // the goal is in the outer wall
  const core::PlanResult result =
      core::plan_once(run.map, blocked, core::default_options(core::PlannerKind::kVnsBaStar));
  ASSERT_EQ(result.status.code, core::StatusCode::kGoalOccupied);
  auto picture = std::make_shared<const render::MapPicture>(render::map_picture(run.grid));
  Rendered r;
  r.svg = render::render_svg(render::picture_of(picture, blocked, result));
  ASSERT_TRUE(r.parse());
  EXPECT_EQ(data_count(find_id(r.root, "start")), 1);
  EXPECT_EQ(data_count(find_id(r.root, "goal")), 1);
  EXPECT_EQ(data_count(find_id(r.root, "pruned-path")), 0);
  EXPECT_NE(r.svg.find("GOAL_OCCUPIED: " + render::xml_escape(result.status.message)),
            std::string::npos);
}

TEST(RunPicture, AnyTextStaysValidXml) {
  render::RunPicture run;
  auto map = std::make_shared<render::MapPicture>();
  map->width = 3;
  map->height = 2;
  map->cells.assign(6, render::CellState::kFree);
  run.map = map;
  run.title = "a<b>&\"c\"'d'\x01\x1f";
  run.planner = "</svg>";
  run.status = "NO_VALID_PATH";
  run.message = "]]> <!-- & -->";
  run.path = {{0.5, 0.5}, {NAN, 1.0}, {2.5, 1.5}};  // a non-finite point is left out
  Rendered r;
  r.svg = render::render_svg(run);
  ASSERT_TRUE(r.parse()) << r.svg.substr(0, 2000);
  EXPECT_EQ(decode_polylines(find_id(r.root, "final-path"), 2)[0].size(), 2u);
  // A picture with no map at all is still a document.
  render::RunPicture empty;
  Rendered e;
  e.svg = render::render_svg(empty);
  EXPECT_TRUE(e.parse());
}

// Merged runs keep a 1000 x 1000 map with 200,000 scattered expansions (the worst case: no two
// adjacent) and a 35 % random obstacle field under 10 MB.
TEST(RunPicture, LargeMapWithManyExpansionsStaysSmall) {
  std::mt19937 rng(7);
  auto map = std::make_shared<render::MapPicture>();
  map->width = map->height = 1000;
  map->resolution = 0.05;
  map->cells.resize(1000000);
  for (auto& c : map->cells)
    c = std::uniform_real_distribution<>(0, 1)(rng) < 0.35 ? render::CellState::kOccupied
                                                           : render::CellState::kFree;
  render::RunPicture run;
  run.map = map;
  for (int i = 0; i < 200000; ++i) {
    const Cell c{(i % 500) * 2, (i / 500) * 2};  // every other cell of every other row
    (i % 2 ? run.expanded_backward : run.expanded_forward).push_back(c);
  }
  const std::string svg = render::render_svg(run);
  EXPECT_LT(svg.size(), size_t{10} << 20) << svg.size() << " bytes";
  Rendered r;
  r.svg = svg;
  ASSERT_TRUE(r.parse());
  EXPECT_EQ(data_count(find_id(r.root, "expanded-forward")) +
                data_count(find_id(r.root, "expanded-backward")),
            200000);
}

TEST(RunPicture, RsvgConvertRendersItToPng) {
  RoomsRun run;
  auto picture = std::make_shared<const render::MapPicture>(render::map_picture(run.grid));
  const std::string svg = render::render_svg(render::picture_of(picture, run.query, run.result));
  const std::string base = ::testing::TempDir() + "/vnsba_render_" + std::to_string(getpid());
  ASSERT_TRUE(render::write_text_file(base + ".svg", svg).is_ok());
  const std::string command =
      std::string("'") + VNSBA_RSVG_CONVERT + "' '" + base + ".svg' -o '" + base + ".png' 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  std::ifstream png(base + ".png", std::ios::binary);
  unsigned char header[24] = {};
  png.read(reinterpret_cast<char*>(header), sizeof header);
  ASSERT_TRUE(png) << "no PNG written";
  EXPECT_EQ(std::string(reinterpret_cast<char*>(header) + 1, 3), "PNG");
  // IHDR width, big-endian at byte 16: the SVG's pixel width.
  const uint32_t width = (uint32_t{header[16]} << 24) | (uint32_t{header[17]} << 16) |
                         (uint32_t{header[18]} << 8) | header[19];
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(svg.c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_NEAR(width, doc.RootElement()->DoubleAttribute("width"), 1.0);
  std::remove((base + ".svg").c_str());
  std::remove((base + ".png").c_str());
}

TEST(Svg, FormatsNumbersCompactlyAndEscapes) {
  EXPECT_EQ(render::fmt(12.5), "12.5");
  EXPECT_EQ(render::fmt(3.0), "3");
  EXPECT_EQ(render::fmt(-0.0001), "0");
  EXPECT_EQ(render::fmt(NAN), "0");
  EXPECT_EQ(render::xml_escape("<a & 'b'>\""), "&lt;a &amp; &apos;b&apos;&gt;&quot;");
}

}  // namespace
}  // namespace vnsba::test
