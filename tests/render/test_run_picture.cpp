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
#include <string>
#include <vector>

#include "svg_test_support.hpp"
#include "temp_dir.hpp"
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

// The caption's lines joined by single spaces (the renderer wraps long lines at spaces).
std::string caption_text(const tinyxml2::XMLElement* root) {
  std::string text;
  const auto* caption = find_id(root, "caption");
  if (caption == nullptr) return text;
  for (auto* t = caption->FirstChildElement("text"); t; t = t->NextSiblingElement("text"))
    text += (text.empty() ? "" : " ") + std::string(t->GetText() ? t->GetText() : "");
  return text;
}

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
  // The rooms map has no unknown or inflated cells: the legend does not list them (see
  // LegendListsExactlyTheLayersDrawn).
  for (const char* label :
       {"occupied", "forward expansions", "backward expansions", "raw grid path", "pruned path",
        "smoothed corners", "meeting cell", "start", "goal"})
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
  // Caption lines wrap at spaces: joined with one they are the caption's text again.
  EXPECT_NE(caption_text(r.root).find("GOAL_OCCUPIED: " + result.status.message), std::string::npos)
      << caption_text(r.root);
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
  const std::string base = (FreshTempDir("render") / "run").string();
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

// ---- Layout: text, legend and axes fit the document and keep off the map and each other ----

// A box in the document's user units (cells), SVG y down.
struct Box {
  double x0, y0, x1, y1;
  bool overlaps(const Box& o) const {
    constexpr double kTouch = 1e-6;  // boxes that only touch do not overlap
    return std::min(x1, o.x1) - std::max(x0, o.x0) > kTouch &&
           std::min(y1, o.y1) - std::max(y0, o.y0) > kTouch;
  }
  bool inside(const Box& o) const {
    constexpr double kSlack = 2e-3;  // the SVG's numbers carry 3 decimals
    return x0 >= o.x0 - kSlack && y0 >= o.y0 - kSlack && x1 <= o.x1 + kSlack && y1 <= o.y1 + kSlack;
  }
};

// An attribute of the element or the nearest ancestor that has it (SVG inheritance).
const char* inherited(const tinyxml2::XMLElement* e, const char* name) {
  for (; e != nullptr; e = e->Parent() ? e->Parent()->ToElement() : nullptr)
    if (const char* v = e->Attribute(name)) return v;
  return nullptr;
}

size_t utf8_chars(const std::string& s) {
  size_t n = 0;
  for (const unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

// The estimated extent of a <text>: the estimate every layout check here rests on. Each
// character is at most 0.6 em wide on average (the sans-serif fonts rsvg picks, DejaVu Sans or
// Liberation Sans, average about 0.55 em over lowercase letters, digits and spaces), glyphs reach
// 0.8 em above the baseline and 0.25 em below it; text-anchor start, middle or end.
Box text_box(const tinyxml2::XMLElement* t) {
  const char* size_attr = inherited(t, "font-size");
  EXPECT_NE(size_attr, nullptr) << "a text without a font size";
  const double size = size_attr ? std::atof(size_attr) : 0.0;
  const double width =
      0.6 * size * static_cast<double>(utf8_chars(t->GetText() ? t->GetText() : ""));
  const char* anchor = inherited(t, "text-anchor");
  const std::string a = anchor ? anchor : "start";
  const double x = t->DoubleAttribute("x"), y = t->DoubleAttribute("y");
  const double x0 = a == "middle" ? x - width / 2 : a == "end" ? x - width : x;
  return {x0, y - 0.8 * size, x0 + width, y + 0.25 * size};
}

void collect_texts(const tinyxml2::XMLElement* e, std::vector<const tinyxml2::XMLElement*>& out) {
  for (auto* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) {
    if (std::string(c->Name()) == "text") out.push_back(c);
    collect_texts(c, out);
  }
}

bool within(const tinyxml2::XMLElement* e, const tinyxml2::XMLElement* group) {
  for (; e != nullptr; e = e->Parent() ? e->Parent()->ToElement() : nullptr)
    if (e == group) return true;
  return false;
}

// Checks the whole layout of a picture of a width x height map.
void expect_layout_fits(const std::string& svg, int width, int height) {
  Rendered r;
  r.svg = svg;
  ASSERT_TRUE(r.parse());
  double vx, vy, vw, vh;
  ASSERT_EQ(std::sscanf(r.root->Attribute("viewBox"), "%lf %lf %lf %lf", &vx, &vy, &vw, &vh), 4);
  const Box view{vx, vy, vx + vw, vy + vh};
  // The pixel size keeps the viewBox's aspect ratio (nothing is stretched or cut by it).
  EXPECT_NEAR(r.root->DoubleAttribute("width") / r.root->DoubleAttribute("height"), vw / vh,
              1e-3 * vw / vh);
  const Box map{0, 0, static_cast<double>(width), static_cast<double>(height)};
  EXPECT_TRUE(map.inside(view));

  std::vector<const tinyxml2::XMLElement*> texts;
  collect_texts(r.root, texts);
  ASSERT_FALSE(texts.empty());
  // A picture with nothing to explain (an empty map) has no legend.
  const auto* legend = find_id(r.root, "legend");
  const auto* legend_rect = find_id(r.root, "legend-box");
  EXPECT_EQ(legend == nullptr, legend_rect == nullptr);
  Box legend_box{0, 0, 0, 0};
  if (legend_rect != nullptr) {
    legend_box = {legend_rect->DoubleAttribute("x"), legend_rect->DoubleAttribute("y"),
                  legend_rect->DoubleAttribute("x") + legend_rect->DoubleAttribute("width"),
                  legend_rect->DoubleAttribute("y") + legend_rect->DoubleAttribute("height")};
    EXPECT_TRUE(legend_box.inside(view)) << "legend box outside the document";
    EXPECT_FALSE(legend_box.overlaps(map)) << "legend box over the map";
  }
  std::vector<Box> boxes;
  for (const auto* t : texts) {
    const Box b = text_box(t);
    const std::string text = t->GetText() ? t->GetText() : "";
    EXPECT_TRUE(b.inside(view)) << "text outside the document: '" << text << "' x " << b.x0 << ".."
                                << b.x1 << " y " << b.y0 << ".." << b.y1 << " in " << view.x0
                                << ".." << view.x1 << ", " << view.y0 << ".." << view.y1;
    EXPECT_FALSE(b.overlaps(map)) << "text over the map: '" << text << "'";
    if (within(t, legend))
      EXPECT_TRUE(b.inside(legend_box)) << "legend text outside its box: '" << text << "'";
    else
      EXPECT_FALSE(b.overlaps(legend_box)) << "text over the legend: '" << text << "'";
    for (size_t i = 0; i < boxes.size(); ++i)
      EXPECT_FALSE(b.overlaps(boxes[i]))
          << "'" << text << "' overlaps '" << texts[i]->GetText() << "'";
    boxes.push_back(b);
  }
}

// A random map (a fifth blocked) with a long run across it, every layer and a long title.
render::RunPicture random_run(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  core::OccupancyGrid grid;
  grid.width = width;
  grid.height = height;
  grid.resolution = 0.05;
  grid.origin_x = -12.3;
  grid.origin_y = 4.56;
  grid.data.assign(static_cast<size_t>(width) * height, 0);
  for (auto& v : grid.data) v = std::uniform_real_distribution<>(0, 1)(rng) < 0.2 ? 100 : 0;
  for (int y = 0; y < height; ++y)  // a band of unknown on the right
    if (width > 4) grid.data[static_cast<size_t>(y) * width + width - 1] = -1;
  const core::PlanQuery query{{0, 0}, {width - 1 - (width > 4 ? 1 : 0), height - 1}};
  grid.data[0] = 0;
  grid.data[static_cast<size_t>(query.goal.y) * width + query.goal.x] = 0;
  core::GridBuildOptions build;
  build.allow_unknown = true;
  auto map = std::make_shared<const core::GridMap>(core::GridMap::build(grid, build).value());
  core::PlannerOptions options = core::default_options(core::PlannerKind::kVnsBaStar);
  options.record_expansions = true;
  const core::PlanResult result = core::plan_once(map, query, options);
  auto picture =
      std::make_shared<const render::MapPicture>(render::map_picture(grid, 65, map.get()));
  render::RunPicture run = render::picture_of(picture, query, result);
  run.options = render::path_options(options, &build);
  run.title = "a run with a rather long title that names its map, its robot and its request";
  return run;
}

// The caption used to run off the right edge of tall maps: on a 40 x 800, an 800 x 40 and a
// 1 x 1 map (and a failed run whose message is long) every text and the legend lie inside the
// document, off the map and off each other.
TEST(RunPicture, CaptionLegendAndAxesFitTallWideAndTinyMaps) {
  for (const auto& [w, h] :
       {std::pair{40, 800}, std::pair{800, 40}, std::pair{1, 1}, std::pair{32, 32}}) {
    SCOPED_TRACE(std::to_string(w) + " x " + std::to_string(h));
    render::RunPicture run = random_run(w, h, 11);
    expect_layout_fits(render::render_svg(run), w, h);
    // Whatever the run, and at a fixed scale too.
    run.status = "NO_VALID_PATH";
    run.message = std::string(300, 'x') + " and then a very long explanation of what went wrong";
    run.metrics.reset();
    expect_layout_fits(render::render_svg(run), w, h);
    render::RenderOptions options;
    options.pixels_per_cell = 3;
    expect_layout_fits(render::render_svg(run, options), w, h);
  }
}

// The legend lists exactly the layers that draw something. The oracle: the SVG's own layer
// groups, a group drawing something when it has an element (a path, polyline, rect or circle),
// the final path only when it is stroked (it is invisible under the pruned polyline).
std::set<std::string> drawn_layers(const tinyxml2::XMLElement* root) {
  std::set<std::string> layers;
  for (const char* id : {"map-occupied", "map-unknown", "map-inflated", "expanded-forward",
                         "expanded-backward", "raw-path", "pruned-path", "smoothed-corners",
                         "final-path", "meeting-cell", "start", "goal"}) {
    const auto* group = find_id(root, id);
    EXPECT_NE(group, nullptr) << id;
    const auto* child = group ? group->FirstChildElement() : nullptr;
    if (child == nullptr) continue;
    if (std::string(id) == "final-path" && std::string(child->Attribute("stroke")) == "none")
      continue;
    layers.insert(id);
  }
  for (int level = 1; level <= render::MapPicture::kCostLevels; ++level) {
    const auto* group = find_id(root, "map-cost-" + std::to_string(level));
    if (group != nullptr && group->FirstChildElement() != nullptr) layers.insert("map-cost");
  }
  return layers;
}

std::set<std::string> legend_layers(const tinyxml2::XMLElement* root) {
  std::set<std::string> layers;
  const auto* legend = find_id(root, "legend");
  if (legend == nullptr) return layers;
  for (auto* t = legend->FirstChildElement("text"); t; t = t->NextSiblingElement("text")) {
    const char* layer = t->Attribute("data-layer");
    EXPECT_NE(layer, nullptr) << t->GetText();
    if (layer) {
      EXPECT_TRUE(layers.insert(layer).second) << "listed twice: " << layer;
    }
  }
  return layers;
}

TEST(RunPicture, LegendListsExactlyTheLayersDrawn) {
  std::vector<std::pair<std::string, render::RunPicture>> runs;
  {
    RoomsRun rooms;
    auto picture = std::make_shared<const render::MapPicture>(render::map_picture(rooms.grid));
    runs.emplace_back("rooms, every search layer",
                      render::picture_of(picture, rooms.query, rooms.result));
    core::PlannerOptions plain = core::default_options(core::PlannerKind::kAStar);
    runs.emplace_back(
        "rooms, astar without smoothing or debug",
        render::picture_of(picture, rooms.query, core::plan_once(rooms.map, rooms.query, plain)));
    render::RunPicture path_only;  // a run record without debug data: the path alone
    path_only.map = picture;
    path_only.path = rooms.result.path;
    runs.emplace_back("path without a polyline", path_only);
  }
  runs.emplace_back("random, unknown and inflated", random_run(40, 30, 5));
  {
    render::RunPicture empty;  // a map without obstacles, nothing on it
    auto map = std::make_shared<render::MapPicture>();
    map->width = 6;
    map->height = 4;
    map->cells.assign(24, render::CellState::kFree);
    empty.map = map;
    runs.emplace_back("an empty map", empty);
    auto costly = std::make_shared<render::MapPicture>(*map);
    costly->cells[3] = render::CellState::kInflated;
    costly->cost_levels.assign(24, 0);
    costly->cost_levels[5] = 2;
    render::RunPicture with_costs;
    with_costs.map = costly;
    with_costs.start = Point2(0.5, 0.5);
    runs.emplace_back("costs and one inflated cell", with_costs);
  }
  std::set<std::string> seen;
  for (const auto& [name, run] : runs) {
    SCOPED_TRACE(name);
    Rendered r;
    r.svg = render::render_svg(run);
    ASSERT_TRUE(r.parse());
    const std::set<std::string> drawn = drawn_layers(r.root);
    EXPECT_EQ(legend_layers(r.root), drawn);
    seen.insert(drawn.begin(), drawn.end());
  }
  // The runs between them exercise every layer, each present in some and absent in others.
  for (const char* layer : {"map-occupied", "map-unknown", "map-inflated", "map-cost",
                            "expanded-forward", "expanded-backward", "raw-path", "pruned-path",
                            "smoothed-corners", "final-path", "meeting-cell", "start", "goal"})
    EXPECT_TRUE(seen.count(layer)) << layer << " never drawn";
}

// Axis ticks: along the bottom and the left edge, a 1, 2 or 5 x 10^k metre step, labels in world
// coordinates (origin + cells * resolution, row 0 at the bottom), increasing by the step, within
// the map's extent, and each tick drawn where its label says.
TEST(RunPicture, AxisTicksAreRoundWorldCoordinates) {
  struct Case {
    int width, height;
    double resolution, origin_x, origin_y;
  };
  for (const Case& c : {Case{487, 187, 0.08, -8.0, -7.52}, Case{40, 800, 0.05, 1000.3, -2.0},
                        Case{800, 40, 1.0, 0.0, 0.0}, Case{1, 1, 0.05, 0.01, 0.02},
                        Case{32, 32, 0.25, -3.1, 2.0}}) {
    SCOPED_TRACE(std::to_string(c.width) + " x " + std::to_string(c.height));
    auto map = std::make_shared<render::MapPicture>();
    map->width = c.width;
    map->height = c.height;
    map->resolution = c.resolution;
    map->origin_x = c.origin_x;
    map->origin_y = c.origin_y;
    map->cells.assign(static_cast<size_t>(c.width) * c.height, render::CellState::kFree);
    render::RunPicture run;
    run.map = map;
    Rendered r;
    r.svg = render::render_svg(run);
    ASSERT_TRUE(r.parse());
    for (const bool x_axis : {true, false}) {
      SCOPED_TRACE(x_axis ? "bottom axis" : "left axis");
      const auto* axis = find_id(r.root, x_axis ? "axis-x" : "axis-y");
      ASSERT_NE(axis, nullptr);
      const double step = axis->DoubleAttribute("data-step");
      ASSERT_GT(step, 0);
      const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
      EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
                  std::abs(mantissa - 5) < 1e-9)
          << "step " << step;
      const double origin = x_axis ? c.origin_x : c.origin_y;
      const double extent = (x_axis ? c.width : c.height) * c.resolution;
      std::vector<double> labels;
      const auto* line = axis->FirstChildElement("line");
      const auto* text = axis->FirstChildElement("text");
      for (; line && text;
           line = line->NextSiblingElement("line"), text = text->NextSiblingElement("text")) {
        const double label = std::atof(text->GetText());
        labels.push_back(label);
        EXPECT_GE(label, origin - 1e-9) << text->GetText();
        EXPECT_LE(label, origin + extent + 1e-9) << text->GetText();
        // The tick's place, back through the picture's scale (resolution metres per cell; the
        // document's y runs down from the map's top row).
        const double cells =
            x_axis ? line->DoubleAttribute("x1") : c.height - line->DoubleAttribute("y1");
        EXPECT_NEAR(origin + cells * c.resolution, label, 1e-3 * c.resolution + 1e-9)
            << text->GetText();
        // Ticks are outside the map, at its edge.
        if (x_axis) {
          EXPECT_NEAR(line->DoubleAttribute("y1"), c.height, 1e-9);
          EXPECT_GT(line->DoubleAttribute("y2"), c.height);
        } else {
          EXPECT_NEAR(line->DoubleAttribute("x2"), 0.0, 1e-9);
          EXPECT_LT(line->DoubleAttribute("x1"), 0.0);
        }
      }
      EXPECT_EQ(line, nullptr);
      EXPECT_EQ(text, nullptr);
      ASSERT_GE(labels.size(), 1u);
      if (extent >= 4 * step) {
        EXPECT_GE(labels.size(), 4u);
      }
      for (size_t i = 1; i < labels.size(); ++i)
        EXPECT_NEAR(labels[i] - labels[i - 1], step, 1e-9 * std::max(1.0, std::abs(labels[i])))
            << "labels increase by the step";
    }
    expect_layout_fits(r.svg, c.width, c.height);
  }
}

// A map so far from 0 that its cells are below the precision of its coordinates (a fuzzed
// record's 9.2e18 m): no tick can be told apart, so there are none, and rendering ends.
TEST(RunPicture, AMapFarFromTheOriginGetsNoTicksInsteadOfEndlessOnes) {
  for (const double origin : {9.2e18, -9.2e18, 1e300}) {
    auto map = std::make_shared<render::MapPicture>();
    map->width = map->height = 20;
    map->resolution = 0.05;
    map->origin_x = origin;
    map->origin_y = 0.0;
    map->cells.assign(400, render::CellState::kFree);
    render::RunPicture run;
    run.map = map;
    Rendered r;
    r.svg = render::render_svg(run);
    ASSERT_TRUE(r.parse()) << origin;
    const auto* axis = find_id(r.root, "axis-x");
    EXPECT_TRUE(axis == nullptr || axis->FirstChildElement("line") == nullptr) << origin;
    EXPECT_NE(find_id(r.root, "axis-y"), nullptr) << "the other axis is unaffected";
  }
}

// The caption names the options that shape the path where they are known, and nothing about
// those that are not.
TEST(RunPicture, CaptionNamesThePlannerOptionsThatShapeThePath) {
  RoomsRun rooms;
  auto picture = std::make_shared<const render::MapPicture>(render::map_picture(rooms.grid));
  render::RunPicture run = render::picture_of(picture, rooms.query, rooms.result);
  Rendered unknown;
  unknown.svg = render::render_svg(run);
  ASSERT_TRUE(unknown.parse());
  for (const char* word : {"neighbourhood", "prune", "smooth", "cost_weight", "radius"})
    EXPECT_EQ(caption_text(unknown.root).find(word), std::string::npos) << word;

  core::PlannerOptions options = core::default_options(core::PlannerKind::kVnsBaStar);
  options.smooth = false;
  options.cost_weight = 2.5;
  core::GridBuildOptions build;
  build.robot_radius = 0.3;
  build.inflation_radius = 0.75;
  run.options = render::path_options(options, &build);
  EXPECT_EQ(run.options.neighborhood, options.neighborhood);
  EXPECT_EQ(run.options.prune, options.prune);
  EXPECT_EQ(run.options.smooth, options.smooth);
  EXPECT_EQ(run.options.cost_weight, options.cost_weight);
  EXPECT_EQ(run.options.robot_radius, build.robot_radius);
  EXPECT_EQ(run.options.inflation_radius, build.inflation_radius);
  Rendered known;
  known.svg = render::render_svg(run);
  ASSERT_TRUE(known.parse());
  const std::string caption = caption_text(known.root);
  for (const std::string& part :
       {std::string(core::to_string(options.neighborhood)) + " neighbourhood",
        std::string("prune on"), std::string("smooth off"), std::string("cost_weight 2.5"),
        std::string("robot radius 0.3 m"), std::string("inflation radius 0.75 m")})
    EXPECT_NE(caption.find(part), std::string::npos) << part << " not in: " << caption;

  // The 8-neighbourhood, no radii (not named when zero), options without a map's build.
  options = core::default_options(core::PlannerKind::kAStar);
  run.options = render::path_options(options);
  known.svg = render::render_svg(run);
  ASSERT_TRUE(known.parse());
  const std::string plain = caption_text(known.root);
  EXPECT_NE(plain.find("8 neighbourhood, prune off, smooth off, cost_weight 0"), std::string::npos)
      << plain;
  EXPECT_EQ(plain.find("radius"), std::string::npos) << plain;
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
