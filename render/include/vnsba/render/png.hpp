// SVG to PNG in-process (librsvg and cairo), so a tool writes a picture a browser-less user can
// open, without a converter installed.
#pragma once

#include <string>
#include <string_view>

#include "vnsba/core/status.hpp"

namespace vnsba::render {

// PNGs larger than this many pixels (4 bytes each while drawn) are refused rather than
// allocating gigabytes: 8192 x 8192.
inline constexpr double kMaxPngPixels = 8192.0 * 8192.0;

// The PNG (file bytes) of an SVG document, `ceil(width)` x `ceil(height)` pixels for the
// document's width and height attributes (px; without them, its viewBox size). Errors
// (kInvalidRequest) say what librsvg or cairo reported: an SVG that does not parse, one without
// a size, one over kMaxPngPixels.
core::Expected<std::string> svg_to_png(std::string_view svg);

// svg_to_png written to `path`; every error names the path.
core::Status write_png_file(const std::string& path, std::string_view svg);

}  // namespace vnsba::render
