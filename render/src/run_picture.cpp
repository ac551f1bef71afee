#include "vnsba/render/run_picture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "vnsba/render/svg.hpp"

namespace vnsba::render {

using core::Cell;
using core::Point2;

namespace {
// The cost levels of a planning map's free cells (MapPicture::cost_levels); empty without costs.
std::vector<uint8_t> cost_levels_of(const core::GridMap& map) {
  std::vector<uint8_t> levels;
  if (!map.has_costs()) return levels;
  levels.assign(static_cast<size_t>(map.cell_count()), 0);
  for (int32_t y = 0; y < map.height(); ++y) {
    for (int32_t x = 0; x < map.width(); ++x) {
      const core::Cell c{x, y};
      if (map.blocked(c)) continue;
      const double cost = map.cost(c);
      if (cost > 0.0)
        levels[static_cast<size_t>(y) * map.width() + x] =
            static_cast<uint8_t>(std::clamp(std::ceil(cost * MapPicture::kCostLevels), 1.0,
                                            static_cast<double>(MapPicture::kCostLevels)));
    }
  }
  return levels;
}
}  // namespace

MapPicture map_picture(const core::OccupancyGrid& grid, int occupied_threshold,
                       const core::GridMap* planning_map) {
  MapPicture picture;
  picture.width = std::max(0, grid.width);
  picture.height = std::max(0, grid.height);
  picture.resolution = grid.resolution;
  picture.origin_x = grid.origin_x;
  picture.origin_y = grid.origin_y;
  const size_t cells = static_cast<size_t>(picture.width) * static_cast<size_t>(picture.height);
  picture.cells.assign(cells, CellState::kFree);
  if (grid.data.size() != cells) return picture;  // malformed grid: an empty (free) picture
  const bool use_planning_map = planning_map != nullptr && planning_map->width() == picture.width &&
                                planning_map->height() == picture.height;
  for (int32_t y = 0; y < picture.height; ++y) {
    for (int32_t x = 0; x < picture.width; ++x) {
      // The map's own value decides occupied and unknown (drawn even where the planner was
      // allowed into unknown space); the planning map adds what inflation blocked.
      CellState state = core::classify_value(grid.at(x, y), occupied_threshold, false);
      if (state == CellState::kFree && use_planning_map && planning_map->blocked(x, y))
        state = CellState::kInflated;
      picture.cells[static_cast<size_t>(y) * picture.width + x] = state;
    }
  }
  if (use_planning_map) picture.cost_levels = cost_levels_of(*planning_map);
  return picture;
}

MapPicture map_picture(const core::GridMap& map) {
  MapPicture picture;
  picture.width = map.width();
  picture.height = map.height();
  picture.resolution = map.resolution();
  picture.origin_x = map.origin_x();
  picture.origin_y = map.origin_y();
  picture.cells.resize(static_cast<size_t>(map.cell_count()));
  for (int32_t y = 0; y < map.height(); ++y)
    for (int32_t x = 0; x < map.width(); ++x)
      picture.cells[static_cast<size_t>(y) * map.width() + x] = map.layer({x, y});
  picture.cost_levels = cost_levels_of(map);
  return picture;
}

RunPicture picture_of(std::shared_ptr<const MapPicture> map, const core::PlanQuery& query,
                      const core::PlanResult& result) {
  RunPicture run;
  run.map = std::move(map);
  // The requested points where the query carries them (tolerance measures from them).
  run.start = query.start_point.value_or(core::cell_centre(query.start));
  run.goal = query.goal_point.value_or(core::cell_centre(query.goal));
  run.expanded_forward = result.expanded_forward;
  run.expanded_backward = result.expanded_backward;
  run.meeting_cell = result.meeting_cell;
  run.raw_path = result.raw_path;
  run.waypoints = result.waypoints;
  run.path = result.path;
  run.planner = std::string(core::to_string(result.planner));
  run.status = std::string(core::to_string(result.status.code));
  run.message = result.status.message;
  if (result.status.is_ok()) run.metrics = result.metrics;
  return run;
}

namespace {

// Colours of the paper's figures where it has them.
constexpr std::string_view kOccupiedColour = "#7f7f7f";
constexpr std::string_view kUnknownColour = "#d7dbe8";
constexpr std::string_view kInflatedColour = "#c4c4c4";
// Cell costs: one hue, each level more opaque (the highest level at 0.6).
constexpr std::string_view kCostColour = "#e07b00";
constexpr double kCostOpacityPerLevel = 0.15;
constexpr std::string_view kForwardColour = "#f2d21b";
constexpr std::string_view kBackwardColour = "#4a90d9";
constexpr std::string_view kSmoothedColour = "#e01010";
constexpr std::string_view kMeetingColour = "#b000b0";
constexpr std::string_view kStartColour = "#e01010";
constexpr std::string_view kGoalColour = "#10a010";

// Cell rows are drawn as horizontal strokes of width 1 through the row's middle: "M x y h w"
// then relative moves to the next run. One run costs about 8 bytes, so a 1000 x 1000 random map
// (about 250,000 runs per layer) stays near 2 MB.
class RunPath {
 public:
  explicit RunPath(int32_t map_height) : map_height_(map_height) {}
  // A run of `length` cells starting at cell (x, y); runs must come in increasing y, then x.
  void add(int32_t x, int32_t y, int32_t length) {
    const double svg_y = map_height_ - y - 0.5;
    char buf[64];
    if (data_.empty())
      std::snprintf(buf, sizeof buf, "M%d %sh%d", x, fmt(svg_y).c_str(), length);
    else
      std::snprintf(buf, sizeof buf, "m%d %sh%d", x - pen_x_, fmt(svg_y - pen_y_).c_str(), length);
    data_ += buf;
    pen_x_ = x + length;
    pen_y_ = svg_y;
  }
  const std::string& data() const { return data_; }

 private:
  int32_t map_height_;
  std::string data_;
  int32_t pen_x_ = 0;
  double pen_y_ = 0.0;
};

// Merges the cells for which `in_layer(x, y)` holds into row runs; returns the cell count.
template <class InLayer>
int64_t merged_runs(int32_t width, int32_t height, InLayer in_layer, RunPath& out) {
  int64_t count = 0;
  for (int32_t y = 0; y < height; ++y) {
    int32_t x = 0;
    while (x < width) {
      if (!in_layer(x, y)) {
        ++x;
        continue;
      }
      const int32_t begin = x;
      while (x < width && in_layer(x, y)) ++x;
      out.add(begin, y, x - begin);
      count += x - begin;
    }
  }
  return count;
}

// The cells of a list as a bitmap (cells outside the map are dropped: bad debug data must not
// draw outside the picture).
std::vector<uint8_t> cell_mask(const MapPicture& map, const std::vector<Cell>& cells) {
  std::vector<uint8_t> mask(static_cast<size_t>(map.width) * map.height, 0);
  for (const Cell& c : cells)
    if (c.x >= 0 && c.y >= 0 && c.x < map.width && c.y < map.height)
      mask[static_cast<size_t>(c.y) * map.width + c.x] = 1;
  return mask;
}

bool finite_point(const Point2& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y());
}

double distance_to_segment(const Point2& p, const Point2& a, const Point2& b) {
  const Point2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

// The stretches of `path` that leave the pruned polyline (the smoothed corners), each with one
// on-polyline point on either side so they join the black segments. Corners so close that their
// splines share an end point are drawn as one stretch. Straight stretches lie on
// the polyline; the walk follows the segments in order, so this is linear in the path length.
std::vector<std::vector<Point2>> smoothed_stretches(const std::vector<Point2>& path,
                                                    const std::vector<Point2>& polyline) {
  std::vector<std::vector<Point2>> stretches;
  if (path.size() < 2) return stretches;
  if (polyline.size() < 2) return stretches;
  constexpr double kOnPolyline = 1e-6;  // cells
  std::vector<uint8_t> off(path.size(), 0);
  size_t segment = 0;
  const size_t segments = polyline.size() - 1;
  for (size_t i = 0; i < path.size(); ++i) {
    double best = INFINITY;
    size_t best_segment = segment;
    for (size_t j = segment; j < std::min(segments, segment + 3); ++j) {
      const double d = distance_to_segment(path[i], polyline[j], polyline[j + 1]);
      if (d < best) {
        best = d;
        best_segment = j;
      }
    }
    if (best <= kOnPolyline)
      segment = best_segment;
    else
      off[i] = 1;
  }
  // The spline interpolates P2 and P3 (ALGORITHM.md section 5), so a corner touches the
  // polyline at single samples between its off-polyline parts: bridge those one-sample gaps so
  // each smoothed corner is one stretch.
  std::vector<uint8_t> bridged = off;
  for (size_t k = 1; k + 1 < path.size(); ++k)
    if (!off[k] && off[k - 1] && off[k + 1]) bridged[k] = 1;
  off.swap(bridged);
  size_t i = 0;
  while (i < path.size()) {
    if (!off[i]) {
      ++i;
      continue;
    }
    const size_t begin = i > 0 ? i - 1 : i;
    while (i < path.size() && off[i]) ++i;
    const size_t end = i < path.size() ? i : path.size() - 1;  // inclusive
    stretches.emplace_back(path.begin() + static_cast<std::ptrdiff_t>(begin),
                           path.begin() + static_cast<std::ptrdiff_t>(end) + 1);
  }
  return stretches;
}

std::string format_number(const char* format, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

// A round scale-bar length (1, 2 or 5 times a power of ten) close to `target` metres.
double nice_length(double target) {
  if (!(target > 0) || !std::isfinite(target)) return 1.0;
  const double power = std::pow(10.0, std::floor(std::log10(target)));
  for (const double step : {5.0, 2.0, 1.0})
    if (step * power <= target) return step * power;
  return power;
}

struct LegendItem {
  std::string_view label;
  std::string swatch;  // markup drawn in a 1 x 1 box at (0, 0), scaled by the legend
};

}  // namespace

std::string render_svg(const RunPicture& run, const RenderOptions& options) {
  static const MapPicture kEmptyMap{};
  const MapPicture& map = run.map ? *run.map : kEmptyMap;
  const int32_t width = std::max(map.width, 1);
  const int32_t height = std::max(map.height, 1);
  const bool map_valid =
      map.width > 0 && map.height > 0 &&
      map.cells.size() == static_cast<size_t>(map.width) * static_cast<size_t>(map.height);

  const double ppc = options.pixels_per_cell > 0
                         ? options.pixels_per_cell
                         : std::clamp(1000.0 / std::max(width, height), 0.05, 60.0);
  // Sizes of text and strokes are fixed in pixels and converted to cells (the document's unit).
  const double px = 1.0 / ppc;
  const double font = 14 * px;
  const double line_height = 1.6 * font;
  const double margin = 8 * px;

  // Legend layout: items flow left to right, wrapping at the map's width.
  const double swatch = font;
  std::vector<LegendItem> legend;
  if (options.legend) {
    legend = {
        {"occupied",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kOccupiedColour) + "\"/>"},
        {"unknown",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kUnknownColour) + "\"/>"},
        {"inflated",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kInflatedColour) + "\"/>"},
        {"cell cost", "<rect width=\"0.5\" height=\"1\" fill=\"" + std::string(kCostColour) +
                          "\" fill-opacity=\"" + std::to_string(kCostOpacityPerLevel) +
                          "\"/><rect x=\"0.5\" width=\"0.5\" height=\"1\" fill=\"" +
                          std::string(kCostColour) + "\" fill-opacity=\"" +
                          std::to_string(kCostOpacityPerLevel * MapPicture::kCostLevels) + "\"/>"},
        {"forward expansions",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kForwardColour) + "\"/>"},
        {"backward expansions",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kBackwardColour) + "\"/>"},
        {"raw grid path",
         "<line x1=\"0\" y1=\"0.5\" x2=\"1\" y2=\"0.5\" stroke=\"#000\" stroke-width=\"0.08\"/>"},
        {"pruned path",
         "<line x1=\"0\" y1=\"0.5\" x2=\"1\" y2=\"0.5\" stroke=\"#000\" stroke-width=\"0.2\"/>"},
        {"smoothed corners", "<line x1=\"0\" y1=\"0.5\" x2=\"1\" y2=\"0.5\" stroke=\"" +
                                 std::string(kSmoothedColour) + "\" stroke-width=\"0.2\"/>"},
        {"meeting cell",
         "<rect x=\"0.1\" y=\"0.1\" width=\"0.8\" height=\"0.8\" fill=\"none\" stroke=\"" +
             std::string(kMeetingColour) + "\" stroke-width=\"0.2\"/>"},
        {"start",
         "<circle cx=\"0.5\" cy=\"0.5\" r=\"0.4\" fill=\"" + std::string(kStartColour) + "\"/>"},
        {"goal",
         "<circle cx=\"0.5\" cy=\"0.5\" r=\"0.4\" fill=\"" + std::string(kGoalColour) + "\"/>"},
    };
  }
  // The cost tint is explained only where a map has costs (the paper's pictures have none).
  if (map.cost_levels.empty())
    legend.erase(std::remove_if(legend.begin(), legend.end(),
                                [](const LegendItem& item) { return item.label == "cell cost"; }),
                 legend.end());
  struct Placed {
    double x, y;
  };
  std::vector<Placed> legend_places;
  double legend_height = 0;
  {
    double x = 0, y = 0;
    const double char_width = 0.6 * font;
    for (const LegendItem& item : legend) {
      const double item_width = swatch + 0.5 * font + char_width * item.label.size() + font;
      if (x > 0 && x + item_width > width) {
        x = 0;
        y += line_height;
      }
      legend_places.push_back({x, y});
      x += item_width;
    }
    if (!legend.empty()) legend_height = y + line_height;
  }

  // Caption lines.
  std::vector<std::string> caption;
  if (options.caption) {
    std::string head = run.title.empty() ? std::string("run") : run.title;
    if (!run.planner.empty()) head += " | planner " + run.planner;
    head += " | " + run.status;
    if (!run.message.empty() && run.status != "OK") head += ": " + run.message;
    caption.push_back(head);
    if (run.metrics) {
      const core::Metrics& m = *run.metrics;
      std::string line = "length " + format_number("%.2f", m.length_m) + " m (" +
                         format_number("%.2f", m.length_cells) + " cells), " +
                         (std::isnan(m.clearance_m) ? std::string()
                          : std::isinf(m.clearance_m)
                              ? std::string("clearance inf (no obstacle), ")
                              : "clearance " + format_number("%.2f", m.clearance_m) + " m, ") +
                         "turns " + std::to_string(m.turns) + ", turn angle " +
                         format_number("%.1f", m.turn_angle_deg) + " deg, expanded " +
                         std::to_string(m.expanded) + ", time " +
                         format_number("%.3f", m.planning_time_us / 1000.0) + " ms";
      if (std::isfinite(m.length_ratio))
        line += ", length / optimal " + format_number("%.3f", m.length_ratio);
      caption.push_back(line);
    }
    caption.push_back("map " + std::to_string(map.width) + " x " + std::to_string(map.height) +
                      " cells at " + format_number("%g", map.resolution) + " m, origin (" +
                      format_number("%g", map.origin_x) + ", " + format_number("%g", map.origin_y) +
                      ") m");
  }
  const double scale_bar_height = 2.2 * font;
  const double below = margin + scale_bar_height + legend_height +
                       line_height * static_cast<double>(caption.size()) + margin;
  const double doc_height = height + below;
  SvgDocument svg(width, doc_height, width * ppc);
  svg.rect(0, 0, width, doc_height, "fill=\"#ffffff\"");

  const auto svg_y = [&](double y) { return height - y; };  // world rows up, SVG rows down
  const auto flip = [&](const std::vector<Point2>& points) {
    std::vector<Point2> out;
    out.reserve(points.size());
    for (const Point2& p : points)
      if (finite_point(p)) out.emplace_back(p.x(), svg_y(p.y()));
    return out;
  };
  const std::string crisp = "fill=\"none\" stroke-width=\"1\" shape-rendering=\"crispEdges\"";

  // Cell costs, under everything else.
  if (map_valid && !map.cost_levels.empty() && map.cost_levels.size() == map.cells.size()) {
    for (int level = 1; level <= MapPicture::kCostLevels; ++level) {
      RunPath runs(height);
      const int64_t count = merged_runs(
          map.width, map.height,
          [&](int32_t x, int32_t y) { return map.cost_level(x, y) == level; }, runs);
      svg.begin_group("map-cost-" + std::to_string(level),
                      "data-count=\"" + std::to_string(count) + "\"");
      svg.path(runs.data(), crisp + " stroke-opacity=\"" +
                                std::to_string(kCostOpacityPerLevel * level) + "\" stroke=\"" +
                                std::string(kCostColour) + "\"");
      svg.end_group();
    }
  }
  // Map layers.
  for (const auto& [id, state, colour] :
       {std::tuple{"map-occupied", CellState::kOccupied, kOccupiedColour},
        std::tuple{"map-unknown", CellState::kUnknown, kUnknownColour},
        std::tuple{"map-inflated", CellState::kInflated, kInflatedColour}}) {
    RunPath runs(height);
    const int64_t count =
        map_valid ? merged_runs(
                        map.width, map.height,
                        [&](int32_t x, int32_t y) { return map.at(x, y) == state; }, runs)
                  : 0;
    svg.begin_group(id, "data-count=\"" + std::to_string(count) + "\"");
    svg.path(runs.data(), crisp + " stroke=\"" + std::string(colour) + "\"");
    svg.end_group();
  }
  // Expansions, semi-transparent so cells closed by both searches show both colours.
  for (const auto& [id, cells, colour] :
       {std::tuple{"expanded-forward", &run.expanded_forward, kForwardColour},
        std::tuple{"expanded-backward", &run.expanded_backward, kBackwardColour}}) {
    RunPath runs(height);
    int64_t count = 0;
    if (map_valid && !cells->empty()) {
      const std::vector<uint8_t> mask = cell_mask(map, *cells);
      count = merged_runs(
          map.width, map.height,
          [&](int32_t x, int32_t y) { return mask[static_cast<size_t>(y) * map.width + x] != 0; },
          runs);
    }
    svg.begin_group(id, "data-count=\"" + std::to_string(count) + "\"");
    svg.path(runs.data(),
             crisp + " stroke-opacity=\"0.75\" stroke=\"" + std::string(colour) + "\"");
    svg.end_group();
  }
  // A light grid on small maps, as in the paper's figures.
  if (map_valid && ppc >= 12) {
    std::string data;
    for (int32_t x = 0; x <= map.width; ++x)
      data += "M" + std::to_string(x) + " 0v" + std::to_string(map.height);
    for (int32_t y = 0; y <= map.height; ++y)
      data += "M0 " + std::to_string(y) + "h" + std::to_string(map.width);
    svg.begin_group("grid-lines");
    svg.path(data, "fill=\"none\" stroke=\"#d0d0d0\" stroke-width=\"" + fmt(0.6 * px) + "\"");
    svg.end_group();
  }
  svg.rect(0, 0, width, height, "fill=\"none\" stroke=\"#000\" stroke-width=\"" + fmt(px) + "\"");

  // Paths.
  const std::vector<Point2> raw = flip(core::cell_centres(run.raw_path));
  svg.begin_group("raw-path", "data-count=\"" + std::to_string(raw.size()) + "\"");
  svg.polyline(raw, "fill=\"none\" stroke=\"#000\" stroke-width=\"" + fmt(1.2 * px) +
                        "\" stroke-dasharray=\"" + fmt(4 * px) + "," + fmt(3 * px) + "\"");
  svg.end_group();
  const std::vector<Point2> pruned = flip(run.waypoints);
  svg.begin_group("pruned-path", "data-count=\"" + std::to_string(pruned.size()) + "\"");
  svg.polyline(pruned, "fill=\"none\" stroke=\"#000\" stroke-linejoin=\"round\" stroke-width=\"" +
                           fmt(3 * px) + "\"");
  svg.end_group();
  const auto stretches = smoothed_stretches(flip(run.path), pruned);
  size_t smoothed_points = 0;
  for (const auto& s : stretches) smoothed_points += s.size();
  svg.begin_group("smoothed-corners", "data-count=\"" + std::to_string(smoothed_points) +
                                          "\" data-stretches=\"" +
                                          std::to_string(stretches.size()) + "\"");
  for (const auto& s : stretches)
    svg.polyline(s, "fill=\"none\" stroke=\"" + std::string(kSmoothedColour) +
                        "\" stroke-linecap=\"round\" stroke-width=\"" + fmt(3 * px) + "\"");
  svg.end_group();
  // The final path itself, invisible, so tools can read its exact geometry back.
  const std::vector<Point2> final_path = flip(run.path);
  svg.begin_group("final-path", "data-count=\"" + std::to_string(final_path.size()) + "\"");
  svg.polyline(final_path, "fill=\"none\" stroke=\"none\"");
  svg.end_group();

  // Markers, sized in pixels but at least most of a cell so they stay visible on small maps.
  const double marker = std::max(6 * px, 0.35);
  svg.begin_group("meeting-cell", run.meeting_cell ? "data-count=\"1\"" : "data-count=\"0\"");
  if (run.meeting_cell)
    svg.rect(run.meeting_cell->x, svg_y(run.meeting_cell->y + 1.0), 1, 1,
             "fill=\"none\" stroke=\"" + std::string(kMeetingColour) + "\" stroke-width=\"" +
                 fmt(std::max(2.5 * px, 0.12)) + "\"");
  svg.end_group();
  for (const auto& [id, point, colour] : {std::tuple{"start", &run.start, kStartColour},
                                          std::tuple{"goal", &run.goal, kGoalColour}}) {
    const bool shown = point->has_value() && finite_point(**point);
    svg.begin_group(id, shown ? "data-count=\"1\"" : "data-count=\"0\"");
    if (shown)
      svg.circle(
          (*point)->x(), svg_y((*point)->y()), marker,
          "fill=\"" + std::string(colour) + "\" stroke=\"#000\" stroke-width=\"" + fmt(px) + "\"");
    svg.end_group();
  }

  // Scale bar: a round length near a fifth of the map's width, in metres.
  double y = height + margin;
  {
    const double resolution =
        map.resolution > 0 && std::isfinite(map.resolution) ? map.resolution : 1.0;
    const double metres = nice_length(0.2 * width * resolution);
    const double cells = metres / resolution;
    const std::string stroke = "stroke=\"#000\" stroke-width=\"" + fmt(2 * px) + "\"";
    svg.begin_group("scale-bar", "data-metres=\"" + format_number("%g", metres) +
                                     "\" data-cells=\"" + fmt(cells) + "\"");
    svg.line(0, y + font * 0.5, cells, y + font * 0.5, stroke);
    svg.line(0, y, 0, y + font, stroke);
    svg.line(cells, y, cells, y + font, stroke);
    svg.text(cells + 0.5 * font, y + font, format_number("%g", metres) + " m",
             "font-family=\"sans-serif\" font-size=\"" + fmt(font) + "\"");
    svg.end_group();
    y += scale_bar_height;
  }
  if (!legend.empty()) {
    svg.begin_group("legend", "font-family=\"sans-serif\" font-size=\"" + fmt(font) + "\"");
    for (size_t i = 0; i < legend.size(); ++i) {
      const double lx = legend_places[i].x;
      const double ly = y + legend_places[i].y;
      svg.raw("<g transform=\"translate(" + fmt(lx) + " " + fmt(ly) + ") scale(" + fmt(swatch) +
              ")\">" + legend[i].swatch + "</g>\n");
      svg.text(lx + swatch + 0.4 * font, ly + 0.85 * font, legend[i].label);
    }
    svg.end_group();
    y += legend_height;
  }
  if (!caption.empty()) {
    svg.begin_group("caption", "font-family=\"sans-serif\" font-size=\"" + fmt(font) + "\"");
    for (const std::string& line : caption) {
      svg.text(0, y + font, line);
      y += line_height;
    }
    svg.end_group();
  }
  return svg.str();
}

}  // namespace vnsba::render
