#include "vnsba/render/charts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vnsba/render/svg.hpp"

namespace vnsba::render {
namespace {

// One colour per series, distinguishable in print and for common colour-vision deficiencies
// (Okabe-Ito palette).
constexpr const char* kSeriesColours[] = {"#0072B2", "#E69F00", "#009E73", "#CC79A7",
                                          "#56B4E9", "#D55E00", "#F0E442", "#000000"};

std::string format_value(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", std::clamp(decimals, 0, 6), value);
  return buf;
}

// A "nice" tick step (1, 2 or 5 times a power of ten) for about `ticks` intervals over `span`.
double nice_step(double span, int ticks) {
  if (!(span > 0)) return 1.0;
  const double raw = span / ticks;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * power) return m * power;
  return 10.0 * power;
}

std::string attr(const char* name, const std::string& value) {
  return std::string(name) + "=\"" + xml_escape(value) + "\"";
}

}  // namespace

std::string render_bar_chart_svg(const BarChart& chart) {
  const double plot_left = 70, plot_top = 50, plot_height = 320;
  const double bar_width = 24, bar_gap = 2, group_gap = 36;
  const size_t groups = chart.groups.size(), series = chart.series.size();
  const double group_width = static_cast<double>(series) * (bar_width + bar_gap) - bar_gap;
  const double plot_width =
      std::max(200.0, static_cast<double>(groups) * (group_width + group_gap) + group_gap);
  const double legend_width = 170;
  const double width = plot_left + plot_width + legend_width, height = plot_top + plot_height + 70;
  SvgDocument doc(width, height, width);
  doc.rect(0, 0, width, height, "fill=\"white\"");

  doc.begin_group("title", "font-family=\"sans-serif\" font-size=\"15\" text-anchor=\"middle\"");
  doc.text(plot_left + plot_width / 2, 24, chart.title);
  doc.end_group();

  bool shape_ok = chart.values.size() == groups;
  for (const auto& row : chart.values) shape_ok = shape_ok && row.size() == series;
  if (!shape_ok) {
    doc.text(plot_left, plot_top + 20,
             "bad chart data: values must be " + std::to_string(groups) + " groups x " +
                 std::to_string(series) + " series",
             "font-family=\"sans-serif\" font-size=\"13\" fill=\"#b00\"");
    return doc.str();
  }

  // Value axis: always includes zero, padded by one tick step.
  double low = 0.0, high = 0.0;
  for (const auto& row : chart.values)
    for (const double v : row)
      if (std::isfinite(v)) {
        low = std::min(low, v);
        high = std::max(high, v);
      }
  const double step = nice_step(high - low > 0 ? high - low : 1.0, 6);
  low = std::floor(low / step) * step;
  high = std::ceil(high / step) * step;
  if (high - low < step) high = low + step;
  const auto y_of = [&](double v) { return plot_top + (high - v) / (high - low) * plot_height; };

  doc.begin_group("axes", "font-family=\"sans-serif\" font-size=\"11\" fill=\"#333\"");
  for (double t = low; t <= high + step * 1e-9; t += step) {
    const double y = y_of(t);
    doc.line(plot_left, y, plot_left + plot_width, y,
             std::abs(t) < step * 1e-9 ? "stroke=\"#000\" stroke-width=\"1.2\""
                                       : "stroke=\"#ddd\" stroke-width=\"0.8\"");
    doc.text(plot_left - 6, y + 4, format_value(t, step < 1 ? 1 : 0), "text-anchor=\"end\"");
  }
  doc.line(plot_left, plot_top, plot_left, plot_top + plot_height, "stroke=\"#000\"");
  doc.text(18, plot_top + plot_height / 2, chart.y_label,
           "text-anchor=\"middle\" transform=\"rotate(-90 18 " + fmt(plot_top + plot_height / 2) +
               ")\"");
  for (size_t g = 0; g < groups; ++g) {
    const double x0 = plot_left + group_gap + static_cast<double>(g) * (group_width + group_gap);
    doc.text(x0 + group_width / 2, plot_top + plot_height + 20, chart.groups[g],
             "text-anchor=\"middle\" font-size=\"13\"");
  }
  doc.end_group();

  doc.begin_group("bars", "font-family=\"sans-serif\" font-size=\"9\" text-anchor=\"middle\"");
  const double zero_y = y_of(0.0);
  for (size_t g = 0; g < groups; ++g) {
    const double x0 = plot_left + group_gap + static_cast<double>(g) * (group_width + group_gap);
    for (size_t s = 0; s < series; ++s) {
      const double v = chart.values[g][s];
      const double x = x0 + static_cast<double>(s) * (bar_width + bar_gap);
      if (!std::isfinite(v)) {
        doc.text(x + bar_width / 2, zero_y - 4, "n/a", "fill=\"#777\"");
        continue;
      }
      const double y = y_of(v);
      const std::string colour =
          kSeriesColours[s % (sizeof kSeriesColours / sizeof *kSeriesColours)];
      doc.rect(x, std::min(y, zero_y), bar_width, std::abs(zero_y - y),
               "class=\"bar\" fill=\"" + colour + "\" " + attr("data-group", chart.groups[g]) +
                   " " + attr("data-series", chart.series[s]) + " " +
                   attr("data-value", format_value(v, 6)));
      doc.text(x + bar_width / 2, v >= 0 ? y - 3 : y + 10, format_value(v, chart.value_decimals));
    }
  }
  doc.end_group();

  doc.begin_group("legend", "font-family=\"sans-serif\" font-size=\"12\"");
  const double legend_x = plot_left + plot_width + 20;
  for (size_t s = 0; s < series; ++s) {
    const double y = plot_top + 10 + static_cast<double>(s) * 20;
    const std::string colour = kSeriesColours[s % (sizeof kSeriesColours / sizeof *kSeriesColours)];
    doc.rect(legend_x, y - 10, 12, 12, "fill=\"" + colour + "\"");
    doc.text(legend_x + 18, y, chart.series[s]);
  }
  doc.end_group();
  return doc.str();
}

namespace {

// Light yellow (better) to dark blue (worse): a sequential ramp readable in grey scale.
std::string ramp_colour(double t) {
  t = std::clamp(t, 0.0, 1.0);
  const double from[3] = {255, 247, 188}, to[3] = {8, 48, 107};
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x",
                static_cast<int>(std::lround(from[0] + (to[0] - from[0]) * t)),
                static_cast<int>(std::lround(from[1] + (to[1] - from[1]) * t)),
                static_cast<int>(std::lround(from[2] + (to[2] - from[2]) * t)));
  return buf;
}

}  // namespace

std::string render_heat_map_svg(const HeatMap& map) {
  const double cell = 40, plot_left = 70, plot_top = 50;
  const size_t rows = map.y_ticks.size(), columns = map.x_ticks.size();
  const double plot_width = static_cast<double>(columns) * cell;
  const double plot_height = static_cast<double>(rows) * cell;
  const double width = plot_left + std::max(plot_width, 200.0) + 110;
  const double height = plot_top + plot_height + 60;
  SvgDocument doc(width, height, width);
  doc.rect(0, 0, width, height, "fill=\"white\"");

  doc.begin_group("title", "font-family=\"sans-serif\" font-size=\"15\" text-anchor=\"middle\"");
  doc.text(plot_left + plot_width / 2, 24, map.title);
  doc.end_group();

  bool shape_ok = map.values.size() == rows;
  for (const auto& row : map.values) shape_ok = shape_ok && row.size() == columns;
  if (!shape_ok) {
    doc.text(plot_left, plot_top + 20,
             "bad heat map data: values must be " + std::to_string(rows) + " rows x " +
                 std::to_string(columns) + " columns",
             "font-family=\"sans-serif\" font-size=\"13\" fill=\"#b00\"");
    return doc.str();
  }

  double low = INFINITY, high = -INFINITY;
  for (const auto& row : map.values)
    for (const double v : row)
      if (std::isfinite(v)) {
        low = std::min(low, v);
        high = std::max(high, v);
      }
  // Position of a value on the ramp, 0 = the better end.
  const auto badness = [&](double v) {
    if (!(high > low)) return 0.0;
    const double t = (v - low) / (high - low);
    return map.lower_is_better ? t : 1.0 - t;
  };

  doc.begin_group("cells", "font-family=\"sans-serif\" font-size=\"9\" text-anchor=\"middle\"");
  for (size_t r = 0; r < rows; ++r) {
    for (size_t c = 0; c < columns; ++c) {
      const double v = map.values[r][c];
      const double x = plot_left + static_cast<double>(c) * cell;
      const double y = plot_top + static_cast<double>(rows - 1 - r) * cell;  // row 0 at bottom
      const double t = badness(v);
      doc.rect(x, y, cell, cell,
               "class=\"cell\" fill=\"" + (std::isfinite(v) ? ramp_colour(t) : "#ccc") +
                   "\" stroke=\"white\" stroke-width=\"0.5\" data-row=\"" + std::to_string(r) +
                   "\" data-column=\"" + std::to_string(c) + "\" " +
                   attr("data-value", format_value(v, 6)));
      doc.text(x + cell / 2, y + cell / 2 + 3, format_value(v, map.value_decimals),
               t > 0.55 ? "fill=\"white\"" : "fill=\"black\"");
    }
  }
  doc.end_group();

  if (map.highlight && map.highlight->first >= 0 && map.highlight->second >= 0 &&
      static_cast<size_t>(map.highlight->first) < rows &&
      static_cast<size_t>(map.highlight->second) < columns) {
    doc.begin_group("highlight");
    doc.rect(
        plot_left + map.highlight->second * cell,
        plot_top + static_cast<double>(rows - 1 - static_cast<size_t>(map.highlight->first)) * cell,
        cell, cell, "fill=\"none\" stroke=\"#d00\" stroke-width=\"3\"");
    doc.end_group();
  }

  doc.begin_group("axes", "font-family=\"sans-serif\" font-size=\"11\" fill=\"#333\"");
  for (size_t c = 0; c < columns; ++c)
    doc.text(plot_left + (static_cast<double>(c) + 0.5) * cell, plot_top + plot_height + 16,
             map.x_ticks[c], "text-anchor=\"middle\"");
  for (size_t r = 0; r < rows; ++r)
    doc.text(plot_left - 6, plot_top + (static_cast<double>(rows - 1 - r) + 0.5) * cell + 4,
             map.y_ticks[r], "text-anchor=\"end\"");
  doc.text(plot_left + plot_width / 2, plot_top + plot_height + 38, map.x_label,
           "text-anchor=\"middle\" font-size=\"13\"");
  doc.text(20, plot_top + plot_height / 2, map.y_label,
           "text-anchor=\"middle\" font-size=\"13\" transform=\"rotate(-90 20 " +
               fmt(plot_top + plot_height / 2) + ")\"");
  doc.end_group();

  // Colour scale: the ramp from the best to the worst value, labelled with both.
  doc.begin_group("colour-scale", "font-family=\"sans-serif\" font-size=\"10\"");
  const double scale_x = plot_left + plot_width + 20, steps = 20;
  for (int i = 0; i < static_cast<int>(steps); ++i) {
    const double t = i / (steps - 1);
    doc.rect(scale_x, plot_top + plot_height * i / steps, 14, plot_height / steps + 0.5,
             "fill=\"" + ramp_colour(t) + "\"");
  }
  if (std::isfinite(low)) {
    const double best = map.lower_is_better ? low : high, worst = map.lower_is_better ? high : low;
    doc.text(scale_x + 18, plot_top + 9, format_value(best, map.value_decimals) + " (best)");
    doc.text(scale_x + 18, plot_top + plot_height, format_value(worst, map.value_decimals));
  }
  doc.text(scale_x, plot_top - 8, map.value_label);
  doc.end_group();
  return doc.str();
}

}  // namespace vnsba::render
