// How the command-line tools print numbers on their result lines (one place, so that scripts
// read vnsba_plan's and vnsba_send_goal's lines alike).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace vnsba::render {

// Metres to the millimetre ("0.412"), and "nan" (no path) and "inf" (a clearance on a map without
// obstacles) as such.
inline std::string format_metres(double metres) {
  if (std::isnan(metres)) return "nan";
  if (std::isinf(metres)) return metres > 0 ? "inf" : "-inf";
  char text[64];
  std::snprintf(text, sizeof text, "%.3f", metres);
  return text;
}

}  // namespace vnsba::render
