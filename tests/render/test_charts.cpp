// The benchmark charts parse as XML, draw one bar per finite value and one cell per heat-map
// value, and escape their text.
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <string>

#include "vnsba/render/charts.hpp"

namespace vnsba::test {
namespace {

const tinyxml2::XMLElement* find_id(const tinyxml2::XMLElement* e, const std::string& id) {
  if (e == nullptr) return nullptr;
  if (const char* own = e->Attribute("id"); own != nullptr && id == own) return e;
  for (auto* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement())
    if (auto* found = find_id(c, id)) return found;
  return nullptr;
}

int count_class(const tinyxml2::XMLElement* group, const std::string& element,
                const std::string& css_class) {
  int count = 0;
  if (group == nullptr) return count;
  for (auto* e = group->FirstChildElement(element.c_str()); e != nullptr;
       e = e->NextSiblingElement(element.c_str()))
    if (const char* c = e->Attribute("class"); c != nullptr && css_class == c) ++count;
  return count;
}

TEST(Charts, GroupedBarChartHasOneBarPerFiniteValue) {
  render::BarChart chart;
  chart.title = "overall <improvement> & \"rate\"";
  chart.y_label = "%";
  chart.groups = {"map A", "map B", "map C"};
  chart.series = {"A*", "improved A*", "BA*", "improved BA*"};
  chart.values = {{10, 20, -5, 3}, {40, NAN, 12.5, 0}, {-30, 1, 2, 3}};
  const std::string svg = render::render_bar_chart_svg(chart);
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(svg.c_str()), tinyxml2::XML_SUCCESS) << svg.substr(0, 300);
  const auto* root = doc.RootElement();
  ASSERT_STREQ(root->Name(), "svg");
  const auto* bars = find_id(root, "bars");
  ASSERT_NE(bars, nullptr);
  EXPECT_EQ(count_class(bars, "rect", "bar"), 11);  // 12 values, one NaN
  // Bars carry their data; a negative value's bar hangs below the zero line, same scale.
  double height_40 = 0, height_minus_30 = 0;
  for (auto* e = bars->FirstChildElement("rect"); e != nullptr; e = e->NextSiblingElement("rect")) {
    const double v = e->DoubleAttribute("data-value");
    if (v == 40) height_40 = e->DoubleAttribute("height");
    if (v == -30) height_minus_30 = e->DoubleAttribute("height");
  }
  EXPECT_GT(height_40, 0);
  EXPECT_NEAR(height_minus_30 / height_40, 0.75, 0.01);
  const auto* title = find_id(root, "title");
  ASSERT_NE(title, nullptr);
  EXPECT_STREQ(title->FirstChildElement("text")->GetText(), "overall <improvement> & \"rate\"");
  EXPECT_NE(find_id(root, "legend"), nullptr);
}

TEST(Charts, BadShapeGivesAValidDocumentWithoutBars) {
  render::BarChart chart;
  chart.groups = {"a", "b"};
  chart.series = {"x"};
  chart.values = {{1.0}};  // one group short
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(render::render_bar_chart_svg(chart).c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_EQ(find_id(doc.RootElement(), "bars"), nullptr);

  render::HeatMap heat;
  heat.x_ticks = {"0", "1"};
  heat.y_ticks = {"0"};
  heat.values = {{1.0}};
  ASSERT_EQ(doc.Parse(render::render_heat_map_svg(heat).c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_EQ(find_id(doc.RootElement(), "cells"), nullptr);
}

TEST(Charts, HeatMapHasOneCellPerValueRowZeroAtTheBottom) {
  render::HeatMap heat;
  heat.title = "sweep_simple: expanded nodes";
  heat.x_label = "eta";
  heat.y_label = "omega";
  for (int i = 0; i <= 10; ++i) {
    heat.x_ticks.push_back(std::to_string(i));
    heat.y_ticks.push_back(std::to_string(i));
  }
  heat.values.assign(11, std::vector<double>(11, 0.0));
  for (int r = 0; r <= 10; ++r)
    for (int c = 0; c <= 10; ++c) heat.values[r][c] = r * 100 + c;
  heat.values[0][0] = NAN;
  heat.highlight = std::make_pair(5, 5);
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(render::render_heat_map_svg(heat).c_str()), tinyxml2::XML_SUCCESS);
  const auto* cells = find_id(doc.RootElement(), "cells");
  ASSERT_NE(cells, nullptr);
  EXPECT_EQ(count_class(cells, "rect", "cell"), 121);
  double y_row0 = -1, y_row10 = -1;
  for (auto* e = cells->FirstChildElement("rect"); e != nullptr;
       e = e->NextSiblingElement("rect")) {
    if (e->IntAttribute("data-column") != 3) continue;
    if (e->IntAttribute("data-row") == 0) y_row0 = e->DoubleAttribute("y");
    if (e->IntAttribute("data-row") == 10) {
      y_row10 = e->DoubleAttribute("y");
      EXPECT_DOUBLE_EQ(e->DoubleAttribute("data-value"), 1003);
    }
  }
  EXPECT_GT(y_row0, y_row10) << "row 0 must be drawn at the bottom";
  EXPECT_NE(find_id(doc.RootElement(), "highlight"), nullptr);
  EXPECT_NE(find_id(doc.RootElement(), "colour-scale"), nullptr);
}

}  // namespace
}  // namespace vnsba::test
