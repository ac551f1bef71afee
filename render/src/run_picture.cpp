#include "vnsba/render/run_picture.hpp"

#include <algorithm>
#include <cctype>
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
  // The spline interpolates P2 and P3 (docs/algorithm.md section 5), so a corner touches the
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

// The smallest round step (1, 2 or 5 times a power of ten) of at least `minimum`.
double nice_step_at_least(double minimum) {
  if (!(minimum > 0) || !std::isfinite(minimum)) return 1.0;
  const double power = std::pow(10.0, std::floor(std::log10(minimum)));
  for (const double step : {1.0, 2.0, 5.0, 10.0})
    if (step * power >= minimum * (1 - 1e-12)) return step * power;
  return 10.0 * power;
}

// The next round step after `step` (1 -> 2 -> 5 -> 10).
double next_nice_step(double step) {
  return nice_step_at_least(step * 1.5);
}

// Characters of UTF-8 text (continuation bytes do not count), what the layout measures.
size_t char_count(std::string_view text) {
  size_t n = 0;
  for (const char c : text)
    if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) ++n;
  return n;
}

// Cuts UTF-8 text after `chars` characters.
size_t byte_offset_of_char(std::string_view text, size_t chars) {
  size_t n = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) {
      if (n == chars) return i;
      ++n;
    }
  }
  return text.size();
}

// Splits a caption line into lines of at most `max_chars` characters, at spaces where it can
// (a word longer than a line is cut).
std::vector<std::string> wrap(const std::string& line, size_t max_chars) {
  std::vector<std::string> out;
  max_chars = std::max<size_t>(max_chars, 1);
  std::string_view rest = line;
  while (char_count(rest) > max_chars) {
    const size_t limit = byte_offset_of_char(rest, max_chars);
    // Between the caption's items (", " before a word, not inside "(x, y)") where one ends in
    // the line, else at a space.
    size_t cut = rest.rfind(", ", limit - 1);
    while (cut != std::string_view::npos && cut > 0 && cut + 2 < rest.size() &&
           (std::isdigit(static_cast<unsigned char>(rest[cut + 2])) || rest[cut + 2] == '-'))
      cut = rest.rfind(", ", cut - 1);
    if (cut != std::string_view::npos && cut > 0) {
      out.emplace_back(rest.substr(0, cut + 1));
      rest.remove_prefix(cut + 2);
      continue;
    }
    cut = rest.rfind(' ', limit);
    if (cut == std::string_view::npos || cut == 0) {
      out.emplace_back(rest.substr(0, limit));
      rest.remove_prefix(limit);
    } else {
      out.emplace_back(rest.substr(0, cut));
      rest.remove_prefix(cut + 1);
    }
  }
  if (!rest.empty() || out.empty()) out.emplace_back(rest);
  return out;
}

// Ticks along one edge of the map: a round step in metres, the world coordinates of the ticks
// within [origin, origin + cells * resolution] and their places in cells from the map's corner.
struct Tick {
  double value;     // metres
  double position;  // cells from the map's lower (or left) edge
  std::string label;
};
struct Axis {
  double step = 0.0;  // metres
  std::vector<Tick> ticks;
  double widest = 0.0;  // the widest label, characters
};

Axis axis_with_step(double origin, int32_t cells, double resolution, double step) {
  Axis axis;
  axis.step = step;
  const double end = origin + cells * resolution;
  // Decimals enough to tell ticks apart: 0 for steps of 1 m and more, 1 for 0.5 m, 2 for 0.02 m.
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  const double first = std::ceil(origin / step - 1e-9);
  const double last = std::floor(end / step + 1e-9);
  constexpr double kMaxTicks = 1000;  // a step too small for the map is refused by the caller
  if (!(last - first < kMaxTicks)) return axis;
  // Far from 0 (a record with x = 9e18 m) consecutive multiples of the step are one double:
  // there is no tick to tell apart, and counting with `++k` would never end.
  if (!(first + 1.0 > first)) return axis;
  const int64_t count = static_cast<int64_t>(last - first) + 1;
  for (int64_t i = 0; i < count; ++i) {
    double value = (first + static_cast<double>(i)) * step;
    if (std::abs(value) < 1e-9 * step) value = 0.0;  // no "-0"
    Tick tick{value, (value - origin) / resolution, {}};
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
    tick.label = buf;
    // A value that rounds to zero is "0", never "-0.0".
    if (tick.label[0] == '-' && tick.label.find_first_not_of("0.", 1) == std::string::npos)
      tick.label.erase(0, 1);
    tick.position = std::clamp(tick.position, 0.0, static_cast<double>(cells));
    axis.widest = std::max(axis.widest, static_cast<double>(char_count(tick.label)));
    axis.ticks.push_back(std::move(tick));
  }
  return axis;
}

// The axis with the smallest round step whose ticks lie `spacing(axis)` cells apart or more (a
// function of the widest label on the x axis, of the font height on the y axis); where that
// leaves fewer than two ticks (a narrow map), the smallest with `minimum(axis)`.
template <class Spacing, class Minimum>
Axis choose_axis(double origin, int32_t cells, double resolution, Spacing spacing,
                 Minimum minimum) {
  if (!std::isfinite(origin) || !(resolution > 0) || !std::isfinite(resolution) || cells <= 0)
    return {};
  const auto smallest = [&](auto&& enough) -> Axis {
    // Start where at most ~500 ticks could fit, then widen until labels do not crowd.
    double step = nice_step_at_least(cells * resolution / 500.0);
    for (int attempt = 0; attempt < 40; ++attempt, step = next_nice_step(step)) {
      Axis axis = axis_with_step(origin, cells, resolution, step);
      if (axis.ticks.empty() && cells * resolution / step >= 1000) continue;
      if (step / resolution >= enough(axis)) return axis;
    }
    return {};
  };
  Axis axis = smallest(spacing);
  if (axis.ticks.size() < 2) {
    Axis denser = smallest(minimum);
    if (denser.ticks.size() > axis.ticks.size()) axis = std::move(denser);
  }
  return axis;
}

struct LegendItem {
  std::string_view label;
  std::string_view layer;  // the layer group it explains ("map-cost" for every cost level)
  std::string swatch;      // markup drawn in a 1 x 1 box at (0, 0), scaled by the legend
};

// One layer's drawn markup and its group, prepared before the layout so that the legend can
// list only what is drawn.
struct Layer {
  std::string id;
  std::string group_attributes;
  std::string markup;
  bool drawn() const { return !markup.empty(); }
};

}  // namespace

PathOptions path_options(const core::PlannerOptions& planner, const core::GridBuildOptions* build) {
  PathOptions o;
  o.neighborhood = planner.neighborhood;
  o.prune = planner.prune;
  o.smooth = planner.smooth;
  o.smoother = planner.smoother;
  o.cost_weight = planner.cost_weight;
  if (build != nullptr) {
    o.robot_radius = build->robot_radius;
    o.inflation_radius = build->inflation_radius;
  }
  return o;
}

std::string render_svg(const RunPicture& run, const RenderOptions& options) {
  static const MapPicture kEmptyMap{};
  const MapPicture& map = run.map ? *run.map : kEmptyMap;
  const int32_t width = std::max(map.width, 1);
  const int32_t height = std::max(map.height, 1);
  const bool map_valid =
      map.width > 0 && map.height > 0 &&
      map.cells.size() == static_cast<size_t>(map.width) * static_cast<size_t>(map.height);
  const double resolution =
      map.resolution > 0 && std::isfinite(map.resolution) ? map.resolution : 1.0;

  const double ppc = options.pixels_per_cell > 0
                         ? options.pixels_per_cell
                         : std::clamp(1000.0 / std::max(width, height), 0.05, 60.0);
  // Sizes of text and strokes are fixed in pixels and converted to cells (the document's unit).
  const double px = 1.0 / ppc;
  const double font = 14 * px;
  const double line_height = 1.6 * font;
  const double margin = 8 * px;
  const double char_width = kCharWidthEm * font;

  const auto svg_y = [&](double y) { return height - y; };  // world rows up, SVG rows down
  const auto flip = [&](const std::vector<Point2>& points) {
    std::vector<Point2> out;
    out.reserve(points.size());
    for (const Point2& p : points)
      if (finite_point(p)) out.emplace_back(p.x(), svg_y(p.y()));
    return out;
  };
  const std::string crisp = "fill=\"none\" stroke-width=\"1\" shape-rendering=\"crispEdges\"";
  const auto count_attribute = [](int64_t count) {
    return "data-count=\"" + std::to_string(count) + "\"";
  };
  const auto path_markup = [](const std::string& data, const std::string& attributes) {
    return data.empty() ? std::string() : "<path d=\"" + data + "\" " + attributes + "/>\n";
  };
  const auto polyline_markup = [](const std::vector<Point2>& points,
                                  const std::string& attributes) {
    if (points.size() < 2) return std::string();
    std::string out = "<polyline points=\"";
    for (size_t i = 0; i < points.size(); ++i) {
      if (i) out += ' ';
      out += fmt(points[i].x()) + "," + fmt(points[i].y());
    }
    return out + "\" " + attributes + "/>\n";
  };

  // Every layer, before the layout: the legend lists the ones with something drawn.
  std::vector<Layer> under;  // cost levels, map layers, expansions (under the grid lines)
  if (map_valid && !map.cost_levels.empty() && map.cost_levels.size() == map.cells.size()) {
    for (int level = 1; level <= MapPicture::kCostLevels; ++level) {
      RunPath runs(height);
      const int64_t count = merged_runs(
          map.width, map.height,
          [&](int32_t x, int32_t y) { return map.cost_level(x, y) == level; }, runs);
      under.push_back(
          {"map-cost-" + std::to_string(level), count_attribute(count),
           path_markup(runs.data(), crisp + " stroke-opacity=\"" +
                                        std::to_string(kCostOpacityPerLevel * level) +
                                        "\" stroke=\"" + std::string(kCostColour) + "\"")});
    }
  }
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
    under.push_back({id, count_attribute(count),
                     path_markup(runs.data(), crisp + " stroke=\"" + std::string(colour) + "\"")});
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
    under.push_back({id, count_attribute(count),
                     path_markup(runs.data(), crisp + " stroke-opacity=\"0.75\" stroke=\"" +
                                                  std::string(colour) + "\"")});
  }
  std::vector<Layer> over;  // paths and markers
  const std::vector<Point2> raw = flip(core::cell_centres(run.raw_path));
  over.push_back({"raw-path", count_attribute(static_cast<int64_t>(raw.size())),
                  polyline_markup(raw, "fill=\"none\" stroke=\"#000\" stroke-width=\"" +
                                           fmt(1.2 * px) + "\" stroke-dasharray=\"" + fmt(4 * px) +
                                           "," + fmt(3 * px) + "\"")});
  const std::vector<Point2> pruned = flip(run.waypoints);
  over.push_back({"pruned-path", count_attribute(static_cast<int64_t>(pruned.size())),
                  polyline_markup(pruned,
                                  "fill=\"none\" stroke=\"#000\" stroke-linejoin=\"round\" "
                                  "stroke-width=\"" +
                                      fmt(3 * px) + "\"")});
  const std::vector<Point2> final_path = flip(run.path);
  const auto stretches = smoothed_stretches(final_path, pruned);
  {
    size_t smoothed_points = 0;
    std::string markup;
    for (const auto& s : stretches) {
      smoothed_points += s.size();
      markup += polyline_markup(s, "fill=\"none\" stroke=\"" + std::string(kSmoothedColour) +
                                       "\" stroke-linecap=\"round\" stroke-width=\"" + fmt(3 * px) +
                                       "\"");
    }
    over.push_back({"smoothed-corners",
                    count_attribute(static_cast<int64_t>(smoothed_points)) + " data-stretches=\"" +
                        std::to_string(stretches.size()) + "\"",
                    markup});
  }
  // The final path itself, so tools can read its exact geometry back: invisible under the
  // pruned polyline and its corners, drawn (thin black) when there is no polyline to show it
  // (a run record without debug data).
  const bool path_alone = pruned.size() < 2 && final_path.size() >= 2;
  over.push_back({"final-path", count_attribute(static_cast<int64_t>(final_path.size())),
                  polyline_markup(final_path, path_alone ? "fill=\"none\" stroke=\"#000\" "
                                                           "stroke-linejoin=\"round\" "
                                                           "stroke-width=\"" +
                                                               fmt(2 * px) + "\""
                                                         : "fill=\"none\" stroke=\"none\"")});
  // Markers, sized in pixels but at least most of a cell so they stay visible on small maps.
  const double marker = std::max(6 * px, 0.35);
  {
    std::string markup;
    if (run.meeting_cell) {
      markup = "<rect x=\"" + fmt(run.meeting_cell->x) + "\" y=\"" +
               fmt(svg_y(run.meeting_cell->y + 1.0)) +
               "\" width=\"1\" height=\"1\" fill=\"none\" stroke=\"" + std::string(kMeetingColour) +
               "\" stroke-width=\"" + fmt(std::max(2.5 * px, 0.12)) + "\"/>\n";
    }
    over.push_back({"meeting-cell", count_attribute(run.meeting_cell ? 1 : 0), markup});
  }
  for (const auto& [id, point, colour] : {std::tuple{"start", &run.start, kStartColour},
                                          std::tuple{"goal", &run.goal, kGoalColour}}) {
    const bool shown = point->has_value() && finite_point(**point);
    std::string markup;
    if (shown)
      markup = "<circle cx=\"" + fmt((*point)->x()) + "\" cy=\"" + fmt(svg_y((*point)->y())) +
               "\" r=\"" + fmt(marker) + "\" fill=\"" + std::string(colour) +
               "\" stroke=\"#000\" stroke-width=\"" + fmt(px) + "\"/>\n";
    over.push_back({id, count_attribute(shown ? 1 : 0), markup});
  }
  const auto drawn = [&](std::string_view layer) {
    for (const auto* list : {&under, &over})
      for (const Layer& l : *list)
        if (l.drawn() &&
            (l.id == layer || (layer == "map-cost" && l.id.rfind("map-cost-", 0) == 0)))
          return true;
    return false;
  };

  // The legend: what is drawn, in drawing order.
  const double swatch = font;
  std::vector<LegendItem> legend;
  if (options.legend) {
    const std::vector<LegendItem> all = {
        {"occupied", "map-occupied",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kOccupiedColour) + "\"/>"},
        {"unknown", "map-unknown",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kUnknownColour) + "\"/>"},
        {"inflated", "map-inflated",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kInflatedColour) + "\"/>"},
        {"cell cost", "map-cost",
         "<rect width=\"0.5\" height=\"1\" fill=\"" + std::string(kCostColour) +
             "\" fill-opacity=\"" + std::to_string(kCostOpacityPerLevel) +
             "\"/><rect x=\"0.5\" width=\"0.5\" height=\"1\" fill=\"" + std::string(kCostColour) +
             "\" fill-opacity=\"" + std::to_string(kCostOpacityPerLevel * MapPicture::kCostLevels) +
             "\"/>"},
        {"forward expansions", "expanded-forward",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kForwardColour) + "\"/>"},
        {"backward expansions", "expanded-backward",
         "<rect width=\"1\" height=\"1\" fill=\"" + std::string(kBackwardColour) + "\"/>"},
        {"raw grid path", "raw-path",
         "<line x1=\"0\" y1=\"0.5\" x2=\"1\" y2=\"0.5\" stroke=\"#000\" stroke-width=\"0.08\" "
         "stroke-dasharray=\"0.3,0.2\"/>"},
        {"pruned path", "pruned-path",
         "<line x1=\"0\" y1=\"0.5\" x2=\"1\" y2=\"0.5\" stroke=\"#000\" stroke-width=\"0.2\"/>"},
        {run.options.smoother == core::PathSmoother::kRelax ? "relaxed path" : "smoothed corners",
         "smoothed-corners",
         "<line x1=\"0\" y1=\"0.5\" x2=\"1\" y2=\"0.5\" stroke=\"" + std::string(kSmoothedColour) +
             "\" stroke-width=\"0.2\"/>"},
        {"path", "final-path",
         "<line x1=\"0\" y1=\"0.5\" x2=\"1\" y2=\"0.5\" stroke=\"#000\" stroke-width=\"0.14\"/>"},
        {"meeting cell", "meeting-cell",
         "<rect x=\"0.1\" y=\"0.1\" width=\"0.8\" height=\"0.8\" fill=\"none\" stroke=\"" +
             std::string(kMeetingColour) + "\" stroke-width=\"0.2\"/>"},
        {"start", "start",
         "<circle cx=\"0.5\" cy=\"0.5\" r=\"0.4\" fill=\"" + std::string(kStartColour) + "\"/>"},
        {"goal", "goal",
         "<circle cx=\"0.5\" cy=\"0.5\" r=\"0.4\" fill=\"" + std::string(kGoalColour) + "\"/>"},
    };
    for (const LegendItem& item : all)
      if (item.layer == "final-path" ? path_alone : drawn(item.layer)) legend.push_back(item);
  }

  // Axes: ticks in metres, world coordinates (origin + cells * resolution), along the bottom
  // and the left edge, each step the smallest round one whose labels do not crowd.
  const double axis_font = 12 * px;
  const double tick_length = 5 * px;
  const double tick_gap = 3 * px;
  Axis axis_x, axis_y;
  if (options.axes) {
    // A label and 1.5 em between labels, at least 0.6 em on a narrow map.
    axis_x = choose_axis(
        map.origin_x, width, resolution,
        [&](const Axis& a) { return (a.widest * kCharWidthEm + 1.5) * axis_font; },
        [&](const Axis& a) { return (a.widest * kCharWidthEm + 0.6) * axis_font; });
    // Labels are 1.05 em high: 2 em apart leave a gap of about one.
    const auto rows = [&](const Axis&) { return 2.0 * axis_font; };
    axis_y = choose_axis(map.origin_y, height, resolution, rows, rows);
  }
  double widest_y_label = 0;
  for (const Tick& t : axis_y.ticks)
    widest_y_label = std::max(widest_y_label, char_count(t.label) * kCharWidthEm * axis_font);
  // Left of the map: the y labels (right-aligned before their ticks), and half of the first x
  // label (centred on its tick); right of it half of the last x label.
  double left = margin;
  if (!axis_y.ticks.empty()) left += tick_length + tick_gap + widest_y_label;
  double right_extent = width + margin;
  for (const Tick& t : axis_x.ticks) {
    const double half = 0.5 * char_count(t.label) * kCharWidthEm * axis_font;
    left = std::max(left, half - t.position + margin);
    right_extent = std::max(right_extent, t.position + half + margin);
  }
  // Above: half a y label's height over the top tick.
  const double top = margin + (axis_y.ticks.empty() ? 0.0 : 0.5 * axis_font);
  const double doc_width = std::max(left + right_extent, kMinTextWidthPx * px);
  const double text_left = -left + margin;
  const double text_right = doc_width - left - margin;
  const double text_width = text_right - text_left;

  // Below the map: the x axis, the scale bar, the legend in a box, the caption.
  double y = height + margin;
  if (!axis_x.ticks.empty()) y = height + tick_length + tick_gap + 1.05 * axis_font + margin;
  const double scale_bar_top = y;
  const double scale_bar_height = 2.2 * font;
  y += scale_bar_height;

  const double pad = 6 * px;
  struct Placed {
    double x, y;
  };
  std::vector<Placed> legend_places;
  double legend_box_width = 0;
  double legend_box_height = 0;
  const double legend_top = y;
  if (!legend.empty()) {
    double x = 0, row = 0;
    for (const LegendItem& item : legend) {
      const double label_width = char_width * static_cast<double>(char_count(item.label));
      const double item_width = swatch + 0.4 * font + label_width;
      if (x > 0 && x + font + item_width > text_width - 2 * pad) {
        x = 0;
        row += line_height;
      } else if (x > 0) {
        x += font;  // an em between entries
      }
      legend_places.push_back({text_left + pad + x, legend_top + pad + row});
      x += item_width;
      legend_box_width = std::max(legend_box_width, x + 2 * pad);
    }
    legend_box_height = row + 1.2 * font + 2 * pad;
    y += legend_box_height + margin;
  }

  // Caption lines, wrapped to the document's width.
  std::vector<std::string> caption;
  if (options.caption) {
    std::vector<std::string> lines;
    std::string head = run.title.empty() ? std::string("run") : run.title;
    if (!run.planner.empty()) head += " | planner " + run.planner;
    head += " | " + run.status;
    if (!run.message.empty() && run.status != "OK") head += ": " + run.message;
    lines.push_back(head);
    // The options that shape the path, those recorded only.
    std::vector<std::string> shaping;
    const PathOptions& o = run.options;
    if (o.neighborhood)
      shaping.push_back(std::string(core::to_string(*o.neighborhood)) + " neighbourhood");
    if (o.prune) shaping.push_back(std::string("prune ") + (*o.prune ? "on" : "off"));
    if (o.smooth) shaping.push_back(std::string("smooth ") + (*o.smooth ? "on" : "off"));
    // none is the paper's pipeline: named only when a smoother ran.
    if (o.smoother == core::PathSmoother::kRelax) shaping.push_back("smoother relax");
    if (o.cost_weight) shaping.push_back("cost_weight " + format_number("%g", *o.cost_weight));
    if (o.robot_radius && *o.robot_radius > 0)
      shaping.push_back("robot radius " + format_number("%g", *o.robot_radius) + " m");
    if (o.inflation_radius && *o.inflation_radius > 0)
      shaping.push_back("inflation radius " + format_number("%g", *o.inflation_radius) + " m");
    if (!shaping.empty()) {
      std::string line = "options: ";
      for (size_t i = 0; i < shaping.size(); ++i) line += (i ? ", " : "") + shaping[i];
      lines.push_back(line);
    }
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
      lines.push_back(line);
    }
    lines.push_back("map " + std::to_string(map.width) + " x " + std::to_string(map.height) +
                    " cells at " + format_number("%g", map.resolution) + " m, origin (" +
                    format_number("%g", map.origin_x) + ", " + format_number("%g", map.origin_y) +
                    ") m");
    const size_t max_chars = static_cast<size_t>(std::max(1.0, text_width / char_width));
    for (const std::string& line : lines)
      for (std::string& part : wrap(line, max_chars)) caption.push_back(std::move(part));
  }
  const double caption_top = y;
  y += line_height * static_cast<double>(caption.size());
  const double doc_bottom = y + margin;

  SvgDocument svg(-left, -top, doc_width, top + doc_bottom, doc_width * ppc);
  svg.rect(-left, -top, doc_width, top + doc_bottom, "fill=\"#ffffff\"");
  const auto emit = [&](const Layer& layer) {
    svg.begin_group(layer.id, layer.group_attributes);
    svg.raw(layer.markup);
    svg.end_group();
  };
  for (const Layer& layer : under) emit(layer);
  // A light grid on small maps, as in the paper's figures.
  if (map_valid && ppc >= 12) {
    std::string data;
    for (int32_t x = 0; x <= map.width; ++x)
      data += "M" + std::to_string(x) + " 0v" + std::to_string(map.height);
    for (int32_t row = 0; row <= map.height; ++row)
      data += "M0 " + std::to_string(row) + "h" + std::to_string(map.width);
    svg.begin_group("grid-lines");
    svg.path(data, "fill=\"none\" stroke=\"#d0d0d0\" stroke-width=\"" + fmt(0.6 * px) + "\"");
    svg.end_group();
  }
  svg.rect(0, 0, width, height, "fill=\"none\" stroke=\"#000\" stroke-width=\"" + fmt(px) + "\"");
  for (const Layer& layer : over) emit(layer);

  // Axes: a tick outside the map's edge and its label beyond it.
  const std::string tick_stroke = "stroke=\"#000\" stroke-width=\"" + fmt(px) + "\"";
  const std::string axis_text = "font-family=\"sans-serif\" font-size=\"" + fmt(axis_font) + "\"";
  if (!axis_x.ticks.empty()) {
    svg.begin_group("axis-x", "data-step=\"" + format_number("%g", axis_x.step) +
                                  "\" text-anchor=\"middle\" " + axis_text);
    for (const Tick& t : axis_x.ticks) {
      svg.line(t.position, height, t.position, height + tick_length, tick_stroke);
      svg.text(t.position, height + tick_length + tick_gap + 0.8 * axis_font, t.label,
               "data-value=\"" + format_number("%.17g", t.value) + "\"");
    }
    svg.end_group();
  }
  if (!axis_y.ticks.empty()) {
    svg.begin_group("axis-y", "data-step=\"" + format_number("%g", axis_y.step) +
                                  "\" text-anchor=\"end\" " + axis_text);
    for (const Tick& t : axis_y.ticks) {
      const double ty = svg_y(t.position);
      svg.line(-tick_length, ty, 0, ty, tick_stroke);
      // Baseline 0.3 em below the tick: the digits' middle on it.
      svg.text(-tick_length - tick_gap, ty + 0.3 * axis_font, t.label,
               "data-value=\"" + format_number("%.17g", t.value) + "\"");
    }
    svg.end_group();
  }

  // Scale bar: a round length near a fifth of the map's width (of the text's on a narrow map,
  // where a fifth of the map would be a few pixels), in metres.
  {
    const double metres = nice_length(0.2 * std::max<double>(width, text_width) * resolution);
    const double cells = metres / resolution;
    const double x0 = text_left;
    const double by = scale_bar_top;
    const std::string stroke = "stroke=\"#000\" stroke-width=\"" + fmt(2 * px) + "\"";
    svg.begin_group("scale-bar", "data-metres=\"" + format_number("%g", metres) +
                                     "\" data-cells=\"" + fmt(cells) + "\"");
    svg.line(x0, by + font * 0.5, x0 + cells, by + font * 0.5, stroke);
    svg.line(x0, by, x0, by + font, stroke);
    svg.line(x0 + cells, by, x0 + cells, by + font, stroke);
    svg.text(x0 + cells + 0.5 * font, by + font, format_number("%g", metres) + " m",
             "font-family=\"sans-serif\" font-size=\"" + fmt(font) + "\"");
    svg.end_group();
  }
  if (!legend.empty()) {
    svg.begin_group("legend", "font-family=\"sans-serif\" font-size=\"" + fmt(font) + "\"");
    svg.rect(
        text_left, legend_top, legend_box_width, legend_box_height,
        "id=\"legend-box\" fill=\"#ffffff\" stroke=\"#808080\" stroke-width=\"" + fmt(px) + "\"");
    for (size_t i = 0; i < legend.size(); ++i) {
      const double lx = legend_places[i].x;
      const double ly = legend_places[i].y + 0.1 * font;
      svg.raw("<g transform=\"translate(" + fmt(lx) + " " + fmt(ly) + ") scale(" + fmt(swatch) +
              ")\">" + legend[i].swatch + "</g>\n");
      svg.text(lx + swatch + 0.4 * font, ly + 0.85 * font, legend[i].label,
               "data-layer=\"" + std::string(legend[i].layer) + "\"");
    }
    svg.end_group();
  }
  if (!caption.empty()) {
    svg.begin_group("caption", "font-family=\"sans-serif\" font-size=\"" + fmt(font) + "\"");
    double line_top = caption_top;
    for (const std::string& line : caption) {
      svg.text(text_left, line_top + font, line);
      line_top += line_height;
    }
    svg.end_group();
  }
  return svg.str();
}

}  // namespace vnsba::render
