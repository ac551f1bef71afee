#include "vnsba/render/svg.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>

namespace vnsba::render {

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        // Control characters other than tab/newline are not allowed in XML 1.0 at all.
        if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r')
          out += '?';
        else
          out += c;
    }
  }
  return out;
}

std::string fmt(double value) {
  if (!std::isfinite(value)) return "0";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", value);
  std::string s(buf);
  // Trim trailing zeros and a trailing point: "12.500" -> "12.5", "3.000" -> "3".
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  if (s == "-0" || s.empty()) s = "0";
  return s;
}

SvgDocument::SvgDocument(double width, double height, double pixel_width)
    : width_(width), height_(height), pixel_width_(pixel_width) {
  body_.reserve(1 << 16);
}

SvgDocument::SvgDocument(double min_x, double min_y, double width, double height,
                         double pixel_width)
    : SvgDocument(width, height, pixel_width) {
  min_x_ = min_x;
  min_y_ = min_y;
}

static void append_attributes(std::string& out, std::string_view attributes) {
  if (!attributes.empty()) {
    out += ' ';
    out += attributes;
  }
}

void SvgDocument::begin_group(std::string_view id, std::string_view attributes) {
  body_ += "<g id=\"";
  body_ += xml_escape(id);
  body_ += '"';
  append_attributes(body_, attributes);
  body_ += ">\n";
  ++open_groups_;
}

void SvgDocument::end_group() {
  if (open_groups_ == 0) return;  // unbalanced call: ignore rather than write broken XML
  body_ += "</g>\n";
  --open_groups_;
}

void SvgDocument::rect(double x, double y, double w, double h, std::string_view attributes) {
  body_ += "<rect x=\"" + fmt(x) + "\" y=\"" + fmt(y) + "\" width=\"" + fmt(w) + "\" height=\"" +
           fmt(h) + '"';
  append_attributes(body_, attributes);
  body_ += "/>\n";
}

void SvgDocument::circle(double cx, double cy, double r, std::string_view attributes) {
  body_ += "<circle cx=\"" + fmt(cx) + "\" cy=\"" + fmt(cy) + "\" r=\"" + fmt(r) + '"';
  append_attributes(body_, attributes);
  body_ += "/>\n";
}

void SvgDocument::line(double x1, double y1, double x2, double y2, std::string_view attributes) {
  body_ += "<line x1=\"" + fmt(x1) + "\" y1=\"" + fmt(y1) + "\" x2=\"" + fmt(x2) + "\" y2=\"" +
           fmt(y2) + '"';
  append_attributes(body_, attributes);
  body_ += "/>\n";
}

void SvgDocument::polyline(const std::vector<core::Point2>& points, std::string_view attributes) {
  if (points.size() < 2) return;
  body_ += "<polyline points=\"";
  for (size_t i = 0; i < points.size(); ++i) {
    if (i) body_ += ' ';
    body_ += fmt(points[i].x());
    body_ += ',';
    body_ += fmt(points[i].y());
  }
  body_ += '"';
  append_attributes(body_, attributes);
  body_ += "/>\n";
}

void SvgDocument::path(std::string_view data, std::string_view attributes) {
  if (data.empty()) return;
  body_ += "<path d=\"";
  body_ += data;
  body_ += '"';
  append_attributes(body_, attributes);
  body_ += "/>\n";
}

void SvgDocument::text(double x, double y, std::string_view content, std::string_view attributes) {
  body_ += "<text x=\"" + fmt(x) + "\" y=\"" + fmt(y) + '"';
  append_attributes(body_, attributes);
  body_ += '>';
  body_ += xml_escape(content);
  body_ += "</text>\n";
}

void SvgDocument::raw(std::string_view markup) {
  body_ += markup;
}

std::string SvgDocument::str() const {
  const double pixel_height = width_ > 0 ? pixel_width_ * height_ / width_ : pixel_width_;
  std::string out;
  out.reserve(body_.size() + 512);
  out += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + fmt(pixel_width_) +
         "\" height=\"" + fmt(pixel_height) + "\" viewBox=\"" + fmt(min_x_) + ' ' + fmt(min_y_) +
         ' ' + fmt(width_) + ' ' + fmt(height_) + "\">\n";
  out += body_;
  for (int i = 0; i < open_groups_; ++i) out += "</g>\n";  // never emit unbalanced markup
  out += "</svg>\n";
  return out;
}

core::Status write_text_file(const std::string& path, std::string_view content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return core::Status::error(core::StatusCode::kInvalidRequest, "cannot write " + path);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.flush();
  if (!out) return core::Status::error(core::StatusCode::kInvalidRequest, "write failed: " + path);
  return core::Status::ok();
}

}  // namespace vnsba::render
