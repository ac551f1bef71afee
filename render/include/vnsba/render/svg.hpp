// A minimal SVG document builder: the one place that writes SVG markup and escapes text.
//
// Used by the run renderer (maps, expansions, paths) and by the benchmark charts. Coordinates
// are in the document's user units; callers choose what a unit means (the run renderer uses one
// unit per grid cell, charts use pixels).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/status.hpp"

namespace vnsba::render {

// Escapes &, <, >, " and ' for use in SVG text and attribute values.
std::string xml_escape(std::string_view text);

// Formats a coordinate compactly (at most 3 decimals, no trailing zeros, "-0" -> "0").
std::string fmt(double value);

class SvgDocument {
 public:
  // width/height: the document's size in user units; pixel_width: the rendered width in px
  // (height follows the aspect ratio).
  SvgDocument(double width, double height, double pixel_width);
  // A document whose viewBox starts at (min_x, min_y) instead of the origin (content left of
  // and above the origin, like axis labels around a map drawn from (0, 0)).
  SvgDocument(double min_x, double min_y, double width, double height, double pixel_width);

  // Opens <g id="..." ...attributes>; attributes is raw markup like `fill="#ccc"` (escaped by
  // the caller where it holds text). Every begin_group needs an end_group.
  void begin_group(std::string_view id, std::string_view attributes = {});
  void end_group();

  void rect(double x, double y, double w, double h, std::string_view attributes = {});
  void circle(double cx, double cy, double r, std::string_view attributes = {});
  void line(double x1, double y1, double x2, double y2, std::string_view attributes = {});
  // An open polyline through the points (nothing is written for fewer than 2 points).
  void polyline(const std::vector<core::Point2>& points, std::string_view attributes = {});
  // A <path d="..."> with raw path data (for merged cell runs: "M x y h w v 1 h -w z ...").
  void path(std::string_view data, std::string_view attributes = {});
  void text(double x, double y, std::string_view content, std::string_view attributes = {});
  // Raw markup (definitions, patterns). The caller is responsible for its validity.
  void raw(std::string_view markup);

  // The complete document (closes nothing for the caller: groups must be balanced).
  std::string str() const;

 private:
  std::string body_;
  double min_x_ = 0.0;
  double min_y_ = 0.0;
  double width_;
  double height_;
  double pixel_width_;
  int open_groups_ = 0;
};

// Writes text to a file (whole, replacing it); the status names the path on failure.
core::Status write_text_file(const std::string& path, std::string_view content);

}  // namespace vnsba::render
