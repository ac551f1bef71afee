// Reading pictures back for tests: parse the SVG with tinyxml2 and decode its layers into cells
// and points, so tests compare the picture's geometry with the run it shows; read a PNG's header.
#pragma once

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "vnsba/core/geometry.hpp"

namespace vnsba::test {

// The 4-byte big-endian unsigned integer at byte `at` of `bytes` (PNG's byte order).
inline uint32_t big_endian(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  for (size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
  return v;
}

// The element with this id anywhere under `e`, or nullptr.
inline const tinyxml2::XMLElement* find_id(const tinyxml2::XMLElement* e, const std::string& id) {
  if (e == nullptr) return nullptr;
  const char* own = e->Attribute("id");
  if (own != nullptr && id == own) return e;
  for (auto* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement())
    if (auto* found = find_id(c, id)) return found;
  return nullptr;
}

inline long data_count(const tinyxml2::XMLElement* group) {
  const char* v = group ? group->Attribute("data-count") : nullptr;
  return v ? std::strtol(v, nullptr, 10) : -1;
}

// Cells drawn by a layer group: its <path> elements hold row runs "M x y h w m dx dy h w ...",
// horizontal strokes through the middle of SVG row y - 0.5, which is map row H - y - 0.5.
inline std::set<std::pair<int, int>> decode_runs(const tinyxml2::XMLElement* group,
                                                 int map_height) {
  std::set<std::pair<int, int>> cells;
  if (group == nullptr) return cells;
  for (auto* p = group->FirstChildElement("path"); p != nullptr;
       p = p->NextSiblingElement("path")) {
    const std::string data = p->Attribute("d") ? p->Attribute("d") : "";
    double px = 0, py = 0;
    size_t i = 0;
    auto number = [&]() {
      char* end = nullptr;
      const double v = std::strtod(data.c_str() + i, &end);
      i = static_cast<size_t>(end - data.c_str());
      while (i < data.size() && data[i] == ' ') ++i;
      return v;
    };
    while (i < data.size()) {
      const char cmd = data[i++];
      if (cmd == 'M' || cmd == 'm') {
        const double x = number(), y = number();
        px = cmd == 'M' ? x : px + x;
        py = cmd == 'M' ? y : py + y;
      } else if (cmd == 'h') {
        const double w = number();
        const int row = static_cast<int>(std::lround(map_height - py - 0.5));
        for (int k = 0; k < static_cast<int>(std::lround(w)); ++k)
          cells.insert({static_cast<int>(std::lround(px)) + k, row});
        px += w;
      } else {
        ADD_FAILURE() << "unexpected path command '" << cmd << "' in " << data.substr(0, 80);
        break;
      }
    }
  }
  return cells;
}

// The points of every <polyline> in a group, converted back to cell coordinates (y up).
inline std::vector<std::vector<core::Point2>> decode_polylines(const tinyxml2::XMLElement* group,
                                                               int map_height) {
  std::vector<std::vector<core::Point2>> out;
  if (group == nullptr) return out;
  for (auto* p = group->FirstChildElement("polyline"); p != nullptr;
       p = p->NextSiblingElement("polyline")) {
    std::string text = p->Attribute("points") ? p->Attribute("points") : "";
    for (char& c : text)
      if (c == ',') c = ' ';
    std::istringstream in(text);
    std::vector<core::Point2> points;
    double x, y;
    while (in >> x >> y) points.emplace_back(x, map_height - y);
    out.push_back(points);
  }
  return out;
}

}  // namespace vnsba::test
