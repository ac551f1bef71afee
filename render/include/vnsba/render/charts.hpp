// Benchmark charts as SVG: a grouped bar chart (the paper's Figure 12) and a heat map (its
// omega/eta sweep, Figure 3 / Table 1). Built on SvgDocument; units are pixels.
//
//   BarChart chart;
//   chart.groups = {"A", "B"};  chart.series = {"astar", "bidirectional_astar"};
//   chart.values = {{12.5, 30.1}, {40.0, -3.2}};        // [group][series], percent
//   write_text_file("fig12.svg", render_bar_chart_svg(chart));
//
// Group ids, fixed for tools and tests: "title", "axes", "bars" (one <rect class="bar"> per
// finite value, with data-group, data-series and data-value), "legend"; a heat map has "cells"
// (one <rect class="cell"> per value, data-row, data-column, data-value) and "colour-scale".
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vnsba::render {

struct BarChart {
  std::string title;
  std::string y_label;                      // e.g. "overall improvement rate (%)"
  std::vector<std::string> groups;          // one cluster of bars per group (e.g. maps)
  std::vector<std::string> series;          // one bar per series in every group (e.g. baselines)
  std::vector<std::vector<double>> values;  // [group][series]; NaN = no bar (shown as "n/a")
  int value_decimals = 1;                   // labels printed above (or below) each bar
};

// Bars grow up from zero for positive values and down for negative ones; the value axis always
// includes zero. Bad shapes (values not groups x series) give a chart with an error caption,
// never a crash.
std::string render_bar_chart_svg(const BarChart& chart);

struct HeatMap {
  std::string title;
  std::string x_label;                      // e.g. "eta"
  std::string y_label;                      // e.g. "omega"
  std::vector<std::string> x_ticks;         // one per column, left to right
  std::vector<std::string> y_ticks;         // one per row, bottom to top
  std::vector<std::vector<double>> values;  // [row][column], row 0 at the bottom; NaN = no data
  std::string value_label;                  // what a cell's value is, with its unit
  bool lower_is_better = true;              // colours: the better end is light, the worse dark
  int value_decimals = 0;                   // digits printed in each cell
  std::optional<std::pair<int, int>> highlight;  // (row, column) outlined, e.g. the best pair
};

// Colours run linearly between the finite minimum and maximum of the values.
std::string render_heat_map_svg(const HeatMap& map);

}  // namespace vnsba::render
