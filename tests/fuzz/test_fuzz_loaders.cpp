// Fuzz stage for every loader (issue 13): Moving AI maps and scenarios, map_server YAML + PGM,
// OctoMap files and message data, run records, node configs.
//
// Each loader gets VNSBA_FUZZ_ITERATIONS inputs (default kDefaultIterations), each a real file
// (a seed) changed by mutator.hpp, written to a temp file and read back by the loader. For every
// input the test asserts what the project promises: the loader returns (a crash, a sanitizer
// report or a hang fails the test through ASan/UBSan and the ctest timeout), an error has a
// message that names the file or the field at fault, and a value is self-consistent. Where an
// independent reading of the format is short (Moving AI, PGM, the OctoMap header, the config's
// keys), a value is also compared with what the file says, so that "silently does the wrong
// thing" fails too.
//
// Reproducing: the base seed (VNSBA_FUZZ_SEED) is printed; VNSBA_FUZZ_ITERATION=I runs only
// input I, and a failing input is saved under VNSBA_FUZZ_OUT_DIR/<folder>/<loader>-seed-S-
// iteration-I/ (<folder> is the loader without its "_data" suffix): in the build folder, not
// under TMPDIR, so it outlives the run (tools/test.sh removes its TMPDIR). Copy such a folder to
// tests/fixtures/fuzz/<folder>/ to keep it as a regression input: FuzzRegression replays every
// folder there with the same checks. An input that kills the process is not saved there: the
// inputs follow from the seed, so the test run again (tools/test.sh prints the command) dies on
// it again and leaves its scratch directory, named in its output, with the input and ITERATION.
#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <octomap/OcTreeStamped.h>
#include <sys/resource.h>
#include <tinyxml2.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "fuzz/mutator.hpp"
#include "temp_dir.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"
#include "vnsba/node/config.hpp"
#include "vnsba/node/security.hpp"
#include "vnsba/records/run_record.hpp"

// A loader that allocates without bound on some input (yaml-cpp 0.7's LoadAll does on a
// document that starts with ',') must fail this test, not take the machine's memory with it:
// under ASan the process aborts past 2 GB resident (ASAN_OPTIONS still overrides it); elsewhere
// an address-space limit turns the allocation into std::bad_alloc.
#if defined(__SANITIZE_ADDRESS__)
extern "C" const char* __asan_default_options() {
  return "hard_rss_limit_mb=2048";
}
#else
[[maybe_unused]] const bool kAddressSpaceLimited = [] {
  constexpr rlim_t kLimit = rlim_t{2} << 30;
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur <= kLimit) return false;
  limit.rlim_cur = kLimit;
  return setrlimit(RLIMIT_AS, &limit) == 0;
}();
#endif

namespace vnsba::fuzz {
namespace {

namespace fs = std::filesystem;
using core::OccupancyGrid;

// A few thousand inputs per loader: about 5-40 s per loader under ASan on one core.
constexpr uint64_t kDefaultIterations = 3000;
constexpr uint64_t kDefaultSeed = 20240613;
// Report this many failing inputs of a loader in full; the first ones say it all.
constexpr int kMaxReportedFailures = 8;

// ---------------------------------------------------------------------------------------------
// Settings, files

struct Settings {
  uint64_t seed = kDefaultSeed;
  uint64_t iterations = kDefaultIterations;
  std::optional<uint64_t> only_iteration;  // VNSBA_FUZZ_ITERATION: replay one input
};

// A whole unsigned decimal number, or nullopt.
std::optional<uint64_t> parse_u64(const char* text) {
  if (text == nullptr || *text == '\0') return std::nullopt;
  uint64_t value = 0;
  const char* end = text + std::strlen(text);
  const auto [ptr, ec] = std::from_chars(text, end, value);
  if (ec != std::errc() || ptr != end) return std::nullopt;
  return value;
}

// Reads the environment; a set but malformed variable fails the test rather than silently
// running with the default (a typo in a long-run command would otherwise go unnoticed).
::testing::AssertionResult read_settings(Settings* s) {
  for (const auto& [name, out] : {std::pair<const char*, uint64_t*>{"VNSBA_FUZZ_SEED", &s->seed},
                                  {"VNSBA_FUZZ_ITERATIONS", &s->iterations}}) {
    const char* text = std::getenv(name);
    if (text == nullptr) continue;
    const auto value = parse_u64(text);
    if (!value) return ::testing::AssertionFailure() << name << "='" << text << "' is not a number";
    *out = *value;
  }
  if (const char* text = std::getenv("VNSBA_FUZZ_ITERATION")) {
    s->only_iteration = parse_u64(text);
    if (!s->only_iteration) {
      return ::testing::AssertionFailure()
             << "VNSBA_FUZZ_ITERATION='" << text << "' is not a number";
    }
  }
  return ::testing::AssertionSuccess();
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A new file each time: ext4 flushes a file that is truncated and rewritten to disk when it is
// closed (auto_da_alloc), which made the driver wait on the disk for every input.
void write_bytes(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  fs::remove(path);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

fs::path fixture(const std::string& relative) {
  return fs::path(VNSBA_FIXTURE_DIR) / relative;
}
fs::path data_dir() {
  return fs::path(VNSBA_DATA_DIR);
}
fs::path config_dir() {
  return fs::path(VNSBA_CONFIG_DIR);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A message that is only a C++ library's exception text ("basic_string::substr", "stoi",
// "std::bad_alloc") has escaped a loader's own checks: it names no field.
bool leaked_exception(const std::string& message) {
  for (const char* marker : {"basic_string", "basic_string_view", "std::", "stoi", "stod", "stoul",
                             "vector::", "bad_alloc", "out_of_range"}) {
    if (contains(message, marker)) return true;
  }
  return false;
}

// The checks shared by every loader's error: a message, naming what was read, and not a leaked
// library exception.
void check_error_message(const std::string& message, const std::string& must_name,
                         std::vector<std::string>* problems) {
  if (message.empty()) {
    problems->push_back("an error with an empty message");
    return;
  }
  if (!must_name.empty() && !contains(message, must_name)) {
    problems->push_back("the error does not name '" + must_name + "': " + message);
  }
  if (leaked_exception(message)) {
    problems->push_back("the error is a library exception's text, naming no field: " + message);
  }
}

// ---------------------------------------------------------------------------------------------
// Independent readings of the formats (oracles). None of them calls the loader under test.

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// Lines without "\n" or "\r\n"; a final newline does not start another line.
std::vector<std::string> text_lines(const std::string& text) {
  std::vector<std::string> out;
  for (size_t begin = 0; begin < text.size();) {
    size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(begin, end - begin);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    out.push_back(line);
    begin = end + 1;
  }
  return out;
}

std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  std::string word;
  for (const char c : line) {
    if (is_space(c)) {
      if (!word.empty()) out.push_back(word);
      word.clear();
    } else {
      word.push_back(c);
    }
  }
  if (!word.empty()) out.push_back(word);
  return out;
}

// A base-10 integer with an optional sign ('+' as YAML and the loaders allow), in [lo, hi].
std::optional<int64_t> strict_int(const std::string& s, int64_t lo, int64_t hi) {
  size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  if (i == s.size()) return std::nullopt;
  for (size_t j = i; j < s.size(); ++j) {
    if (s[j] < '0' || s[j] > '9') return std::nullopt;
  }
  size_t first = i;  // leading zeros do not count against the digits strtoll can hold
  while (first + 1 < s.size() && s[first] == '0') ++first;
  if (s.size() - first > 18) return std::nullopt;  // beyond every range checked here
  const int64_t value = std::strtoll(s.substr(first).c_str(), nullptr, 10) * (s[0] == '-' ? -1 : 1);
  if (value < lo || value > hi) return std::nullopt;
  return value;
}

// No minus sign (PGM header fields and samples; a '+' does not change the number read).
std::optional<int64_t> digits(const std::string& s, int64_t lo, int64_t hi) {
  if (s.empty() || s[0] == '-') return std::nullopt;
  return strict_int(s, lo, hi);
}

// A whole decimal number read by strtod (C locale), or nullopt.
std::optional<double> strict_double(const std::string& s) {
  if (s.empty() || is_space(s[0])) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size()) return std::nullopt;
  return value;
}

constexpr int64_t kMaxSide = 100000;  // map_io.cpp's limit of cells per side

// Moving AI .map as the benchmark's README describes it: the occupancy the file means, or why
// it is malformed.
std::optional<OccupancyGrid> read_movingai_map(const std::string& text, std::string* why) {
  const std::vector<std::string> lines = text_lines(text);
  auto fail = [&](const std::string& w) {
    *why = w;
    return std::nullopt;
  };
  if (lines.size() < 4) return fail("fewer than 4 header lines");
  if (words(lines[0]) != std::vector<std::string>{"type", "octile"}) return fail("line 1");
  const auto h = words(lines[1]), w = words(lines[2]);
  if (h.size() != 2 || h[0] != "height" || w.size() != 2 || w[0] != "width") return fail("sides");
  const auto height = strict_int(h[1], 1, kMaxSide), width = strict_int(w[1], 1, kMaxSide);
  if (!height || !width) return fail("height or width is not in 1..100000");
  if (words(lines[3]) != std::vector<std::string>{"map"}) return fail("line 4 is not 'map'");
  if (lines.size() < 4 + static_cast<size_t>(*height)) return fail("too few rows");
  OccupancyGrid grid;
  grid.width = static_cast<int32_t>(*width);
  grid.height = static_cast<int32_t>(*height);
  grid.data.resize(static_cast<size_t>(*width * *height));
  for (int64_t row = 0; row < *height; ++row) {
    const std::string& cells = lines[4 + row];
    if (static_cast<int64_t>(cells.size()) != *width) return fail("row length");
    for (int64_t x = 0; x < *width; ++x) {
      const char c = cells[x];
      int8_t value = 0;
      if (c == '.' || c == 'G' || c == 'S') {
        value = 0;
      } else if (c == '@' || c == 'O' || c == 'T' || c == 'W') {
        value = 100;
      } else {
        return fail("terrain byte " + std::to_string(static_cast<unsigned char>(c)));
      }
      grid.data[(*height - 1 - row) * *width + x] = value;  // the top line is the top row
    }
  }
  for (size_t i = 4 + *height; i < lines.size(); ++i) {
    if (!words(lines[i]).empty()) return fail("extra row");
  }
  return grid;
}

// One unit of the last printed digit of a decimal number: 10^-(digits after the point), shifted
// by the exponent where there is one ("1.5e+3" is printed to the hundreds). nullopt when that
// unit is no normal double (hundreds of decimals): no tolerance a comparison could use.
std::optional<double> printed_unit(const std::string& token) {
  const size_t e = token.find_first_of("eE");
  const std::string mantissa = token.substr(0, e);
  const size_t point = mantissa.find('.');
  const auto after =
      point == std::string::npos ? 0.0 : static_cast<double>(mantissa.size() - point - 1);
  double exponent = 0;
  if (e != std::string::npos) {
    const auto parsed = strict_int(token.substr(e + 1), -100000, 100000);
    if (!parsed) return std::nullopt;
    exponent = static_cast<double>(*parsed);
  }
  const double unit = std::pow(10.0, exponent - after);
  if (!std::isfinite(unit) || unit < std::numeric_limits<double>::min()) return std::nullopt;
  return unit;
}

std::optional<std::vector<maps::MovingAiScenario>> read_movingai_scenarios(const std::string& text,
                                                                           std::string* why) {
  const std::vector<std::string> lines = text_lines(text);
  auto fail = [&](const std::string& w) {
    *why = w;
    return std::nullopt;
  };
  if (lines.empty()) return fail("empty");
  const auto header = words(lines[0]);
  if (header.size() != 2 || header[0] != "version" || (header[1] != "1" && header[1] != "1.0")) {
    return fail("version line");
  }
  std::vector<maps::MovingAiScenario> out;
  for (size_t i = 1; i < lines.size(); ++i) {
    const auto cols = words(lines[i]);
    if (cols.empty()) continue;
    if (cols.size() != 9) return fail("line " + std::to_string(i + 1) + ": columns");
    int64_t v[8] = {};
    for (int c : {0, 2, 3, 4, 5, 6, 7}) {
      const auto parsed = strict_int(cols[c], INT32_MIN, INT32_MAX);
      if (!parsed) return fail("line " + std::to_string(i + 1) + ": column " + std::to_string(c));
      v[c] = *parsed;
    }
    if (v[2] < 1 || v[2] > kMaxSide || v[3] < 1 || v[3] > kMaxSide) return fail("map size");
    if (v[4] < 0 || v[4] >= v[2] || v[6] < 0 || v[6] >= v[2] || v[5] < 0 || v[5] >= v[3] ||
        v[7] < 0 || v[7] >= v[3]) {
      return fail("line " + std::to_string(i + 1) + ": endpoint outside the map");
    }
    const auto length = strict_double(cols[8]);
    if (!length || !std::isfinite(*length) || *length < 0.0) return fail("optimal length");
    const auto unit = printed_unit(cols[8]);
    if (!unit) return fail("optimal length printed beyond a double's range of precision");
    maps::MovingAiScenario s;
    s.bucket = static_cast<int>(v[0]);
    s.map_name = cols[1];
    s.map_width = static_cast<int>(v[2]);
    s.map_height = static_cast<int>(v[3]);
    s.start = {static_cast<int32_t>(v[4]), static_cast<int32_t>(v[3] - 1 - v[5])};
    s.goal = {static_cast<int32_t>(v[6]), static_cast<int32_t>(v[3] - 1 - v[7])};
    s.optimal_length = *length;
    s.optimal_resolution = *unit;
    s.line = static_cast<int>(i + 1);
    out.push_back(s);
  }
  return out;
}

// The map_server YAML as the oracle reads it: only plain "key: value" lines and comment lines;
// anything else makes the oracle abstain (nullopt with `why` empty). A file the oracle reads but
// finds invalid gives nullopt with `why` set.
struct MapYaml {
  std::string image;
  double resolution = 0.0;
  double origin_x = 0.0, origin_y = 0.0;
  std::string mode = "trinary";
  bool negate = false;
  double occupied = 0.65, free = 0.196;
};

// The checks of map_io.hpp on what a file gives: required keys, ranges.
std::optional<MapYaml> checked_map_yaml(const MapYaml& y, const std::set<std::string>& seen,
                                        std::string* why) {
  for (const char* key : {"image", "resolution", "origin"}) {
    if (seen.count(key) == 0) {
      *why = std::string("no ") + key;
      return std::nullopt;
    }
  }
  if (y.image.empty()) *why = "image is empty";
  if (!(y.resolution > 0.0)) *why = "resolution <= 0";
  if (!(y.occupied > 0.0 && y.occupied <= 1.0)) *why = "occupied_thresh";
  if (!(y.free >= 0.0 && y.free < y.occupied)) *why = "free_thresh";
  if (y.mode != "trinary" && y.mode != "scale" && y.mode != "raw") *why = "mode";
  if (!why->empty()) return std::nullopt;
  return y;
}

std::optional<MapYaml> read_map_yaml(const std::string& text, std::string* why) {
  MapYaml y;
  std::set<std::string> seen;
  // Any line beyond the plain form makes the verdict yaml-cpp's, even after a line found invalid
  // here (a flow list may go on on the next, indented line).
  const auto abstain = [why] {
    why->clear();
    return std::nullopt;
  };
  for (const std::string& raw : text_lines(text)) {
    const auto first = raw.find_first_not_of(" \t");
    if (first == std::string::npos || raw[first] == '#') continue;
    const size_t colon = raw.find(": ");
    if (first != 0 || colon == std::string::npos) return abstain();
    const std::string key = raw.substr(0, colon), value = raw.substr(colon + 2);
    // Plain YAML scalars only: no quotes, comments, anchors, aliases, tags, block scalars or
    // other indicators yaml-cpp would read as more than text (the yaml-cpp oracle takes those).
    if (key.find_first_not_of("abcdefghijklmnopqrstuvwxyz_") != std::string::npos ||
        value.empty() || value.find_first_of("#\"'\t\r\v\f") != std::string::npos ||
        value.find_first_of('\0') != std::string::npos || is_space(value.back()) ||
        is_space(value.front()) || std::string("&*!|>%@`{").find(value[0]) != std::string::npos ||
        (std::string("-?:").find(value[0]) != std::string::npos &&
         (value.size() == 1 || value[1] == ' ')) ||
        (value[0] == '[' && key != "origin")) {
      return abstain();
    }
    if (!seen.insert(key).second) *why = "duplicate key " + key;
    auto number = [&](double* out) {
      const auto v = strict_double(value);
      if (!v || !std::isfinite(*v)) *why = key + " is not a finite number";
      if (v) *out = *v;
    };
    if (key == "image") y.image = value;
    if (key == "resolution") number(&y.resolution);
    if (key == "occupied_thresh") number(&y.occupied);
    if (key == "free_thresh") number(&y.free);
    if (key == "mode") y.mode = value;
    if (key == "origin") {  // [x, y, yaw], yaw 0 (only axis-aligned grids load)
      std::vector<std::optional<double>> items;
      if (value.size() >= 2 && value.front() == '[' && value.back() == ']') {
        std::string item;
        for (const char c : value.substr(1, value.size() - 2) + ",") {
          if (c != ',') {
            item += c;
            continue;
          }
          const auto ws = words(item);
          // An empty item ("[1, 2, 0,]" is three in YAML), or one with YAML indicators or
          // nesting: the yaml-cpp oracle reads it.
          if (ws.empty() || item.find_first_of("&*!|>%@`{}[]?:") != std::string::npos) {
            return abstain();
          }
          items.push_back(ws.size() == 1 ? strict_double(ws[0]) : std::nullopt);
          item.clear();
        }
      }
      if (items.size() != 3 || !items[0] || !items[1] || !items[2] || !std::isfinite(*items[0]) ||
          !std::isfinite(*items[1]) || *items[2] != 0.0) {
        *why = "origin is not [x, y, 0] with finite numbers";
      } else {
        y.origin_x = *items[0];
        y.origin_y = *items[1];
      }
    }
    if (key == "negate") {
      if (value == "1" || value == "true" || value == "True") {
        y.negate = true;
      } else if (value != "0" && value != "false" && value != "False") {
        *why = "negate";
      }
    }
  }
  if (!why->empty()) return std::nullopt;
  return checked_map_yaml(y, seen, why);
}

// The same reading of a YAML beyond plain lines (quotes, block lists, flow maps, anchors, tags),
// through yaml-cpp's own API and conversions (as<double>, not the loader's parsing): nullopt with
// `why` set when the file is invalid as map_server reads it or yaml-cpp cannot read it.
std::optional<MapYaml> read_map_yaml_cpp(const std::string& text, std::string* why) {
  MapYaml y;
  std::set<std::string> seen;
  try {
    const YAML::Node root = YAML::Load(text);  // one document: Load does not loop as LoadAll
    if (!root.IsMap()) {
      *why = "yaml-cpp reads no map of keys";
      return std::nullopt;
    }
    for (const auto& entry : root) {
      const std::string key = entry.first.as<std::string>();
      const YAML::Node& value = entry.second;
      if (!seen.insert(key).second) {
        *why = "duplicate key " + key;
        return std::nullopt;
      }
      if (key == "image") y.image = value.as<std::string>();
      if (key == "resolution") y.resolution = value.as<double>();
      if (key == "occupied_thresh") y.occupied = value.as<double>();
      if (key == "free_thresh") y.free = value.as<double>();
      if (key == "mode") y.mode = value.as<std::string>();
      if (key == "negate") {
        const std::string v = value.as<std::string>();
        y.negate = v == "1" || v == "true" || v == "True";
        if (!y.negate && v != "0" && v != "false" && v != "False") *why = "negate";
      }
      if (key == "origin") {
        const auto xyz = value.as<std::vector<double>>();
        if (xyz.size() != 3 || xyz[2] != 0.0) *why = "origin is not [x, y, 0]";
        if (xyz.size() == 3) y.origin_x = xyz[0], y.origin_y = xyz[1];
      }
    }
    for (const double v : {y.resolution, y.occupied, y.free, y.origin_x, y.origin_y}) {
      if (!std::isfinite(v)) *why = "a number is not finite";
    }
  } catch (const YAML::Exception& e) {
    *why = std::string("yaml-cpp cannot read or convert it: ") + e.what();
  }
  if (!why->empty()) return std::nullopt;
  return checked_map_yaml(y, seen, why);
}

// A P5 or P2 image as Netpbm defines it (libnetpbm's reading: comments anywhere in the header,
// a comment right after maxval ends the header as its whitespace would), converted with the
// map_server rules of map_io.hpp. nullopt with `why` when malformed.
std::optional<OccupancyGrid> read_pgm(const std::string& text, const MapYaml& y, std::string* why) {
  size_t pos = 0;
  auto token = [&] {
    while (pos < text.size() && (is_space(text[pos]) || text[pos] == '#')) {
      if (text[pos] == '#') {
        while (pos < text.size() && text[pos] != '\n') ++pos;
      } else {
        ++pos;
      }
    }
    const size_t begin = pos;
    while (pos < text.size() && !is_space(text[pos]) && text[pos] != '#') ++pos;
    return text.substr(begin, pos - begin);
  };
  auto fail = [&](const std::string& w) {
    *why = w;
    return std::nullopt;
  };
  if (text.rfind("P5", 0) != 0 && text.rfind("P2", 0) != 0) return fail("magic");
  const std::string magic = token();
  if (magic != "P5" && magic != "P2") return fail("magic");
  const auto width = digits(token(), 1, kMaxSide);
  const auto height = digits(token(), 1, kMaxSide);
  const auto maxval = digits(token(), 1, 65535);
  if (!width || !height || !maxval) return fail("header");
  const int64_t count = *width * *height;
  std::vector<int64_t> samples;
  if (magic == "P5") {
    if (pos >= text.size()) return fail("no raster");
    if (text[pos] == '#') {
      pos = text.find('\n', pos);
      if (pos == std::string::npos) return fail("no raster");
    }
    ++pos;  // the one whitespace byte (or the comment's newline) before the raster
    const int64_t bytes = *maxval > 255 ? 2 : 1;
    if (static_cast<int64_t>(text.size() - pos) < count * bytes) return fail("raster truncated");
    const auto* p = reinterpret_cast<const unsigned char*>(text.data() + pos);
    for (int64_t i = 0; i < count; ++i) {
      samples.push_back(bytes == 1 ? p[i] : p[2 * i] * 256 + p[2 * i + 1]);
    }
  } else {
    for (int64_t i = 0; i < count; ++i) {
      const auto v = digits(token(), 0, 1 << 30);
      if (!v) return fail("sample " + std::to_string(i));
      samples.push_back(*v);
    }
  }
  OccupancyGrid grid;
  grid.width = static_cast<int32_t>(*width);
  grid.height = static_cast<int32_t>(*height);
  grid.resolution = y.resolution;
  grid.data.resize(static_cast<size_t>(count));
  for (int64_t row = 0; row < *height; ++row) {
    for (int64_t x = 0; x < *width; ++x) {
      const int64_t s = samples[row * *width + x];
      if (s > *maxval) return fail("sample above maxval");
      int8_t v = -1;
      // Nav2's map_server (map_io.cpp): raw mode reads the shade on 0..255 (the sample itself
      // in an 8-bit image); scale mode maps the thresholds' gap onto 0..100, ties to even.
      if (y.mode == "raw") {
        const double shade =
            std::round(static_cast<double>(s) / static_cast<double>(*maxval) * 255.0);
        v = shade <= 100 ? static_cast<int8_t>(shade) : int8_t{-1};
      } else {
        const double m = static_cast<double>(*maxval);
        const double p = y.negate ? s / m : (m - s) / m;
        if (p > y.occupied) {
          v = 100;
        } else if (p < y.free) {
          v = 0;
        } else if (y.mode == "scale") {
          v = static_cast<int8_t>(std::rint(100.0 * (p - y.free) / (y.occupied - y.free)));
        }
      }
      grid.data[(*height - 1 - row) * *width + x] = v;  // the image's top row is the top
    }
  }
  return grid;
}

// The occupancy trees liboctomap 1.9 reads, which the OctoMap loaders promise to read.
bool is_occupancy_tree_id(const std::string& id) {
  return id == "OcTree" || id == "ColorOcTree" || id == "OcTreeStamped";
}

// The header of an OctoMap file: id, size and res as the keyword lines give them; nullopt when
// the oracle cannot read it plainly (then only the generic checks apply).
struct OctreeHeader {
  std::string id;
  uint64_t size = 0;
  double res = 0.0;
};

std::optional<OctreeHeader> read_octree_header(const std::string& bytes) {
  std::istringstream in(bytes);
  std::string line;
  if (!std::getline(in, line)) return std::nullopt;
  if (line.rfind("# Octomap OcTree", 0) != 0) return std::nullopt;
  OctreeHeader h;
  bool id = false, size = false, res = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') continue;
    const auto w = words(line);
    if (w.size() == 1 && w[0] == "data") return id && size && res ? std::optional(h) : std::nullopt;
    if (w.size() != 2) return std::nullopt;
    if (w[0] == "id") h.id = w[1], id = true;
    if (w[0] == "size") {
      const auto v = digits(w[1], 0, INT64_MAX / 2);
      if (!v) return std::nullopt;
      h.size = static_cast<uint64_t>(*v);
      size = true;
    }
    if (w[0] == "res") {
      const auto v = strict_double(w[1]);
      if (!v) return std::nullopt;
      h.res = *v;
      res = true;
    }
  }
  return std::nullopt;
}

// The nodes of OcTree::writeBinaryData's layout (per node two bytes of 2-bit child codes, child i
// in bits 2i of the little-endian pair: 0 none, 1 free leaf, 2 occupied leaf, 3 inner node whose
// bytes follow, depth first, children in order), or nullopt when the bytes are not one whole tree
// of at most 16 levels.
bool walk_binary_node(const std::string& data, size_t* pos, int depth, uint64_t* nodes) {
  if (data.size() - *pos < 2) return false;
  const unsigned codes = static_cast<unsigned char>(data[*pos]) |
                         static_cast<unsigned>(static_cast<unsigned char>(data[*pos + 1])) << 8;
  *pos += 2;
  for (int i = 0; i < 8; ++i) {
    const unsigned code = (codes >> (2 * i)) & 3u;
    if (code != 0 && depth >= 16) return false;  // a 16-level tree has no children at depth 16
    *nodes += code != 0;
  }
  for (int i = 0; i < 8; ++i) {
    if (((codes >> (2 * i)) & 3u) == 3u && !walk_binary_node(data, pos, depth + 1, nodes)) {
      return false;
    }
  }
  return true;
}

std::optional<uint64_t> binary_node_count(const std::string& data) {
  size_t pos = 0;
  uint64_t nodes = 1;
  if (!walk_binary_node(data, &pos, 0, &nodes) || pos != data.size()) return std::nullopt;
  return nodes;
}

// ---------------------------------------------------------------------------------------------
// The checks: one per loader, on the files of one input in `dir`. They return the problems
// found (empty: the input was handled as promised) and whether the loader accepted it.

struct Outcome {
  bool loaded = false;
  std::vector<std::string> problems;
};

void check_grid(const OccupancyGrid& g, const std::string& what, std::vector<std::string>* p) {
  if (g.width <= 0 || g.height <= 0) {
    p->push_back(what + ": non-positive size " + std::to_string(g.width) + " x " +
                 std::to_string(g.height));
    return;
  }
  if (g.data.size() != static_cast<size_t>(g.width) * static_cast<size_t>(g.height)) {
    p->push_back(what + ": data.size() " + std::to_string(g.data.size()) + " != width * height");
  }
  if (!std::isfinite(g.resolution) || !(g.resolution > 0.0)) {
    p->push_back(what + ": resolution " + std::to_string(g.resolution) + " not finite > 0");
  }
  if (!std::isfinite(g.origin_x) || !std::isfinite(g.origin_y)) {
    p->push_back(what + ": origin not finite");
  }
  for (size_t i = 0; i < g.data.size(); ++i) {
    if (g.data[i] < -1 || g.data[i] > 100) {
      p->push_back(what + ": data[" + std::to_string(i) + "] = " + std::to_string(g.data[i]) +
                   " outside -1..100");
      break;
    }
  }
}

// Where two grids first differ, or "" when equal in size and data.
std::string grid_difference(const OccupancyGrid& got, const OccupancyGrid& want) {
  if (got.width != want.width || got.height != want.height) {
    return std::to_string(got.width) + " x " + std::to_string(got.height) +
           " cells, the file says " + std::to_string(want.width) + " x " +
           std::to_string(want.height);
  }
  for (size_t i = 0; i < got.data.size() && i < want.data.size(); ++i) {
    if (got.data[i] != want.data[i]) {
      return "cell " + std::to_string(i) + " is " + std::to_string(got.data[i]) +
             ", the file says " + std::to_string(want.data[i]);
    }
  }
  return "";
}

Outcome check_movingai_map(const fs::path& file) {
  Outcome out;
  const auto grid = maps::load_movingai_map(file.string());
  std::string why;
  const auto expected = read_movingai_map(read_bytes(file), &why);
  if (!grid) {
    check_error_message(grid.error().message, file.string(), &out.problems);
    return out;
  }
  out.loaded = true;
  check_grid(*grid, "map", &out.problems);
  if (grid->resolution != 1.0 || grid->origin_x != 0.0 || grid->origin_y != 0.0) {
    out.problems.push_back("resolution/origin are not 1 m at (0, 0)");
  }
  if (!expected) {
    out.problems.push_back("loaded a file that is not a Moving AI map (" + why + ")");
  } else if (const std::string d = grid_difference(*grid, *expected); !d.empty()) {
    out.problems.push_back("loaded the wrong grid: " + d);
  }
  return out;
}

Outcome check_movingai_scenarios(const fs::path& file) {
  Outcome out;
  const auto scenarios = maps::load_movingai_scenarios(file.string());
  std::string why;
  const auto expected = read_movingai_scenarios(read_bytes(file), &why);
  if (!scenarios) {
    check_error_message(scenarios.error().message, file.string(), &out.problems);
    return out;
  }
  out.loaded = true;
  for (const auto& s : *scenarios) {
    const bool inside = s.map_width >= 1 && s.map_height >= 1 && s.start.x >= 0 && s.start.y >= 0 &&
                        s.goal.x >= 0 && s.goal.y >= 0 && s.start.x < s.map_width &&
                        s.goal.x < s.map_width && s.start.y < s.map_height &&
                        s.goal.y < s.map_height;
    if (!inside) out.problems.push_back("line " + std::to_string(s.line) + ": endpoint outside");
    if (!std::isfinite(s.optimal_length) || s.optimal_length < 0.0 ||
        !std::isfinite(s.optimal_resolution) || !(s.optimal_resolution > 0.0)) {
      out.problems.push_back("line " + std::to_string(s.line) +
                             ": optimum not finite >= 0 or its resolution not finite > 0");
    }
  }
  if (!expected) {
    out.problems.push_back("loaded a file that is not a scenario file (" + why + ")");
    return out;
  }
  if (expected->size() != scenarios->size()) {
    out.problems.push_back(std::to_string(scenarios->size()) + " scenarios, the file has " +
                           std::to_string(expected->size()));
    return out;
  }
  for (size_t i = 0; i < expected->size(); ++i) {
    const auto &a = (*scenarios)[i], &b = (*expected)[i];
    const bool same =
        a.bucket == b.bucket && a.map_name == b.map_name && a.map_width == b.map_width &&
        a.map_height == b.map_height && a.start == b.start && a.goal == b.goal &&
        a.line == b.line && a.optimal_length == b.optimal_length &&
        std::abs(a.optimal_resolution - b.optimal_resolution) <= 1e-9 * b.optimal_resolution;
    if (!same) {
      out.problems.push_back("scenario of line " + std::to_string(b.line) +
                             " differs from the file (resolution " +
                             std::to_string(a.optimal_resolution) + ", the file prints to " +
                             std::to_string(b.optimal_resolution) + ")");
      break;
    }
  }
  return out;
}

Outcome check_map_server(const fs::path& yaml) {
  Outcome out;
  const auto grid = maps::load_map_server(yaml.string());
  if (!grid) {
    check_error_message(grid.error().message, yaml.string(), &out.problems);
    return out;
  }
  out.loaded = true;
  check_grid(*grid, "map", &out.problems);
  std::string why;
  const std::string text = read_bytes(yaml);
  auto params = read_map_yaml(text, &why);
  // Beyond plain "key: value" lines the plain oracle abstains and yaml-cpp's reading decides.
  if (!params && why.empty()) params = read_map_yaml_cpp(text, &why);
  if (!params) {
    out.problems.push_back("loaded an invalid YAML (" + why + ")");
    return out;
  }
  if (grid->resolution != params->resolution || grid->origin_x != params->origin_x ||
      grid->origin_y != params->origin_y) {
    out.problems.push_back("resolution or origin differ from the file's");
  }
  const fs::path image = fs::path(params->image).is_absolute() ? fs::path(params->image)
                                                               : yaml.parent_path() / params->image;
  const auto expected = read_pgm(read_bytes(image), *params, &why);
  if (!expected) {
    out.problems.push_back("loaded an invalid PGM (" + why + ")");
  } else if (const std::string d = grid_difference(*grid, *expected); !d.empty()) {
    out.problems.push_back("loaded the wrong grid: " + d);
  }
  return out;
}

// The checks on a tree that loaded: resolution, and slices with the default and an
// all-covering band.
void check_tree(const octomap::OcTree& tree, std::vector<std::string>* p) {
  const double res = tree.getResolution();
  if (!std::isfinite(res) || !(res > 0.0)) p->push_back("tree resolution not finite > 0");
  maps::SliceOptions band;
  band.max_cells = int64_t{1} << 22;  // bounds the time of a slice of a corrupt tree's far leaf
  maps::SliceOptions everything = band;
  everything.z_min = -1e9;
  everything.z_max = 1e9;
  for (const maps::SliceOptions& o : {band, everything}) {
    const auto slice = maps::slice_octree(tree, o);
    if (!slice) {
      check_error_message(slice.error().message, "", p);
      if (slice.error().code == core::StatusCode::kInternalError) {
        p->push_back("slice_octree: internal error: " + slice.error().message);
      }
      continue;
    }
    check_grid(*slice, "slice", p);
    if (slice->resolution != res) p->push_back("slice resolution is not the leaf size");
    for (const int8_t v : slice->data) {
      if (v != -1 && v != 0 && v != 100) {
        p->push_back("slice value " + std::to_string(v) + " is not -1, 0 or 100");
        break;
      }
    }
    // Every leaf overlaps the all-covering band, so a non-empty tree has a known cell.
    if (o.z_min == everything.z_min && tree.size() > 0 &&
        std::all_of(slice->data.begin(), slice->data.end(), [](int8_t v) { return v == -1; })) {
      p->push_back("a slice over all heights of a non-empty tree is all unknown");
    }
  }
}

Outcome check_octree_file(const fs::path& file) {
  Outcome out;
  const auto tree = maps::load_octree(file.string());
  if (!tree) {
    check_error_message(tree.error().message, file.string(), &out.problems);
    return out;
  }
  out.loaded = true;
  if (!*tree) {
    out.problems.push_back("a null tree without an error");
    return out;
  }
  if (const auto h = read_octree_header(read_bytes(file))) {
    if ((*tree)->getResolution() != h->res) {
      out.problems.push_back("resolution " + std::to_string((*tree)->getResolution()) +
                             ", the header says " + std::to_string(h->res));
    }
    if ((*tree)->size() != h->size) {
      out.problems.push_back(std::to_string((*tree)->size()) + " nodes, the header says " +
                             std::to_string(h->size));
    }
    if (!is_occupancy_tree_id(h->id) && h->id != "1") out.problems.push_back("loaded a " + h->id);
  }
  check_tree(**tree, &out.problems);
  return out;
}

// Message data: the bytes in data.bin, resolution and id on the lines of params.txt.
Outcome check_octree_data(const fs::path& dir) {
  Outcome out;
  const std::string bytes = read_bytes(dir / "data.bin");
  std::istringstream params(read_bytes(dir / "params.txt"));
  std::string res_text, id;
  std::getline(params, res_text);
  std::getline(params, id);
  const double res = strict_double(res_text).value_or(std::nan(""));
  const std::vector<int8_t> data(bytes.begin(), bytes.end());
  const auto tree = maps::octree_from_binary_data(data, res, id);
  if (!tree) {
    check_error_message(tree.error().message, "OctoMap message data", &out.problems);
    return out;
  }
  out.loaded = true;
  if (!*tree) {
    out.problems.push_back("a null tree without an error");
    return out;
  }
  if ((*tree)->getResolution() != res) out.problems.push_back("resolution not the one given");
  if (bytes.empty()) {
    if ((*tree)->size() != 0) out.problems.push_back("empty data gave a non-empty tree");
  } else if (const auto nodes = binary_node_count(bytes); !nodes) {
    out.problems.push_back("loaded data that is not one whole tree");
  } else if (*nodes != (*tree)->size()) {
    out.problems.push_back(std::to_string((*tree)->size()) + " nodes, the data holds " +
                           std::to_string(*nodes));
  }
  if (!is_occupancy_tree_id(id)) out.problems.push_back("accepted id '" + id + "'");
  check_tree(**tree, &out.problems);
  return out;
}

// A run record read back: documented ranges, and to_json -> from_json -> to_json is stable.
void check_loaded_record(const records::RunRecord& r, std::vector<std::string>* p) {
  if (r.status) {
    const auto& s = *r.status;
    if (s.code < 0 || s.code > 255) p->push_back("status.code out of 0..255");
    if (s.metrics.turns < 0 || s.metrics.expanded < 0) p->push_back("negative turns/expanded");
  }
  if (r.map) {
    if (r.map->width < 0 || r.map->height < 0) p->push_back("negative map size");
    if (r.map->occupied_threshold < 1 || r.map->occupied_threshold > 100) {
      p->push_back("map.occupied_threshold out of 1..100");
    }
    if (!std::isfinite(r.map->robot_radius)) p->push_back("map.robot_radius not finite");
  }
  if (r.debug && (r.debug->width < 0 || r.debug->height < 0)) p->push_back("negative debug size");
  const nlohmann::json once = records::to_json(r);
  const auto again = records::run_record_from_json(once);
  if (!again) {
    p->push_back("to_json of a loaded record does not read back: " + again.error().message);
  } else if (records::to_json(*again) != once) {
    p->push_back("to_json -> run_record_from_json -> to_json changed the record");
  }
}

Outcome check_record_json(const fs::path& file) {
  Outcome out;
  const nlohmann::json j = nlohmann::json::parse(read_bytes(file), nullptr, false);
  if (j.is_discarded()) return out;  // not JSON: nlohmann's job, not the record reader's
  const auto record = records::run_record_from_json(j);
  if (!record) {
    check_error_message(record.error().message, "", &out.problems);
    return out;
  }
  out.loaded = true;
  check_loaded_record(*record, &out.problems);
  return out;
}

// Attribute values of the SVG that are a number spelled as NaN or infinity: a coordinate that
// went wrong on the way into the picture.
bool bad_number_attribute(const tinyxml2::XMLElement* e, std::string* where) {
  for (; e != nullptr; e = e->NextSiblingElement()) {
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
      std::string v = a->Value();
      std::transform(v.begin(), v.end(), v.begin(),
                     [](unsigned char c) { return std::tolower(c); });
      for (const std::string& w : words(std::string(v.begin(), v.end()))) {
        for (const char* bad : {"nan", "-nan", "inf", "-inf"}) {
          std::string token = w;
          token.erase(std::remove(token.begin(), token.end(), ','), token.end());
          if (token == bad) {
            *where = std::string(e->Name()) + " " + a->Name() + "=\"" + a->Value() + "\"";
            return true;
          }
        }
      }
    }
    if (bad_number_attribute(e->FirstChildElement(), where)) return true;
  }
  return false;
}

Outcome check_record_file(const fs::path& file) {
  Outcome out;
  const auto svg = records::render_record_file(file.string());
  if (!svg) {
    check_error_message(svg.error().message, file.string(), &out.problems);
    return out;
  }
  out.loaded = true;
  tinyxml2::XMLDocument doc;
  if (doc.Parse(svg->c_str(), svg->size()) != tinyxml2::XML_SUCCESS) {
    out.problems.push_back(std::string("the SVG is not well-formed XML: ") + doc.ErrorStr());
    return out;
  }
  if (doc.RootElement() == nullptr || std::string(doc.RootElement()->Name()) != "svg") {
    out.problems.push_back("the document's root is not <svg>");
    return out;
  }
  std::string where;
  if (bad_number_attribute(doc.RootElement(), &where)) {
    out.problems.push_back("the SVG has a non-finite number: " + where);
  }
  return out;
}

// The value of `key` in a YAML map, or an undefined node (never the invalid node that indexing
// a scalar or a null gives, which throws on every use).
YAML::Node child(const YAML::Node& map, const std::string& key) {
  if (!map.IsDefined() || !map.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  for (const auto& kv : map) {
    if (kv.first.IsScalar() && kv.first.Scalar() == key) return kv.second;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

// The config: every key the file gives must have reached its field, every field the file leaves
// out must keep its default, and an accepted file has no unknown, repeated or empty keys.
void check_config_against_yaml(const node::NodeConfig& c, const YAML::Node& root,
                               std::vector<std::string>* p) {
  // The defaults: config/default.yaml's, which every key a file leaves out keeps.
  const node::NodeConfig d = node::default_config().config.value();
  std::set<std::string> known;
  auto find = [&](const std::string& section, const std::string& key) -> std::optional<YAML::Node> {
    known.insert(section.empty() ? key : section + "." + key);
    const YAML::Node parent = section.empty() ? root : child(root, section);
    const YAML::Node v = child(parent, key);
    if (!v.IsDefined()) return std::nullopt;
    return v;
  };
  auto scalar = [&](const std::optional<YAML::Node>& v, const std::string& key) {
    if (v && !v->IsScalar()) p->push_back(key + ": accepted a value that is not a scalar");
    return v && v->IsScalar();
  };
  auto same_double = [&](const std::string& section, const std::string& key,
                         std::optional<double> got, std::optional<double> fallback) {
    const auto v = find(section, key);
    const std::string name = section + "." + key;
    if (!scalar(v, name)) {
      if (got != fallback) p->push_back(name + ": absent but not the default");
      return;
    }
    const double want = v->as<double>();
    if (got != want) p->push_back(name + ": field differs from the file's value");
  };
  auto same_int = [&](const std::string& section, const std::string& key, int64_t got,
                      int64_t fallback) {
    const auto v = find(section, key);
    const std::string name = section.empty() ? key : section + "." + key;
    if (!scalar(v, name)) {
      if (got != fallback) p->push_back(name + ": absent but not the default");
      return;
    }
    const auto want = strict_int(v->Scalar(), INT64_MIN / 2, INT64_MAX / 2);
    if (!want || *want != got) p->push_back(name + ": field differs from the file's value");
  };
  auto same_bool = [&](const std::string& section, const std::string& key, std::optional<bool> got,
                       std::optional<bool> fallback) {
    const auto v = find(section, key);
    const std::string name = section.empty() ? key : section + "." + key;
    if (!scalar(v, name)) {
      if (got != fallback) p->push_back(name + ": absent but not the default");
      return;
    }
    if (got != v->as<bool>()) p->push_back(name + ": field differs from the file's value");
  };
  auto same_text = [&](const std::string& section, const std::string& key,
                       std::optional<std::string> got, std::optional<std::string> fallback) {
    const auto v = find(section, key);
    const std::string name = section.empty() ? key : section + "." + key;
    if (!scalar(v, name)) {
      if (got != fallback) p->push_back(name + ": absent but not the default");
      return;
    }
    if (got != v->Scalar()) p->push_back(name + ": field differs from the file's value");
  };
  auto name_of = [](auto value) {
    return std::optional<std::string>(std::string(core::to_string(value)));
  };
  auto opt_name = [&](const auto& value) {
    return value ? name_of(*value) : std::optional<std::string>();
  };

  same_int("", "domain_id", c.domain_id, d.domain_id);
  same_text("", "node_name", c.node_name, d.node_name);
  const char* const lifecycle_modes[] = {"self_activating", "managed"};
  same_text("", "lifecycle", std::string(lifecycle_modes[static_cast<int>(c.lifecycle)]),
            std::string(lifecycle_modes[static_cast<int>(d.lifecycle)]));
  const char* const bond_modes[] = {"managed", "always", "off"};
  same_text("bond", "mode", std::string(bond_modes[static_cast<int>(c.bond.mode)]),
            std::string(bond_modes[static_cast<int>(d.bond.mode)]));
  {
    const auto v = find("bond", "heartbeat_period");
    if (scalar(v, "bond.heartbeat_period")) {
      if (c.bond.heartbeat_period.count() != std::llround(v->as<double>() * 1000.0))
        p->push_back("bond.heartbeat_period: field differs from the file's value");
    } else if (c.bond.heartbeat_period != d.bond.heartbeat_period) {
      p->push_back("bond.heartbeat_period: absent but not the default");
    }
  }
  same_text("ros", "distro", std::string(node::distro_name(c.ros_distro)),
            std::string(node::distro_name(d.ros_distro)));
  same_text("topics", "is_path_valid", c.topics.is_path_valid, d.topics.is_path_valid);
  same_bool("", "ros2_naming", c.ros2_naming, d.ros2_naming);
  same_text("", "frame_id", c.frame_id, d.frame_id);
  {
    // Stored without its leading and trailing '/'.
    const auto v = find("", "namespace");
    if (scalar(v, "namespace")) {
      std::string bare(node::without_leading_slash(v->Scalar()));
      if (!bare.empty() && bare.back() == '/') bare.pop_back();
      if (c.ros_namespace != bare) p->push_back("namespace: field differs from the file's value");
    } else if (c.ros_namespace != d.ros_namespace) {
      p->push_back("namespace: absent but not the default");
    }
  }
  same_text("topics", "projected_map", c.topics.projected_map, d.topics.projected_map);
  same_text("topics", "goal_pose", c.topics.goal_pose, d.topics.goal_pose);
  same_text("topics", "robot_pose", c.topics.robot_pose, d.topics.robot_pose);
  same_text("topics", "plan_request", c.topics.plan_request, d.topics.plan_request);
  same_text("topics", "plan", c.topics.plan, d.topics.plan);
  same_text("topics", "plan_status", c.topics.plan_status, d.topics.plan_status);
  same_text("topics", "planner_debug", c.topics.planner_debug, d.topics.planner_debug);
  same_text("topics", "octomap", c.topics.octomap, d.topics.octomap);
  same_text("topics", "plan_raw", c.topics.plan_raw, d.topics.plan_raw);
  same_text("topics", "plan_pruned", c.topics.plan_pruned, d.topics.plan_pruned);
  same_text("topics", "expansions_forward", c.topics.expansions_forward,
            d.topics.expansions_forward);
  same_text("topics", "expansions_backward", c.topics.expansions_backward,
            d.topics.expansions_backward);
  same_text("topics", "meeting_point", c.topics.meeting_point, d.topics.meeting_point);
  same_text("topics", "compute_path_to_pose", c.topics.compute_path_to_pose,
            d.topics.compute_path_to_pose);
  same_text("topics", "compute_path_through_poses", c.topics.compute_path_through_poses,
            d.topics.compute_path_through_poses);
  same_text("topics", "tf", c.topics.tf, d.topics.tf);
  same_text("topics", "tf_static", c.topics.tf_static, d.topics.tf_static);
  same_text("topics", "clock", c.topics.clock, d.topics.clock);
  const char* const pose_sources[] = {"topic", "tf"};
  same_text("", "robot_pose_source",
            std::string(pose_sources[static_cast<int>(c.robot_pose_source)]),
            std::string(pose_sources[static_cast<int>(d.robot_pose_source)]));
  const char* const pose_types[] = {"PoseStamped", "PoseWithCovarianceStamped"};
  same_text("", "robot_pose_type", std::string(pose_types[static_cast<int>(c.robot_pose_type)]),
            std::string(pose_types[static_cast<int>(d.robot_pose_type)]));
  same_text("", "base_frame", c.base_frame, d.base_frame);
  same_double("", "transform_tolerance", c.transform_tolerance_s, d.transform_tolerance_s);
  same_bool("", "use_sim_time", c.use_sim_time, d.use_sim_time);
  same_int("map", "occupied_threshold", c.map.occupied_threshold, d.map.occupied_threshold);
  same_bool("map", "allow_unknown", c.map.allow_unknown, d.map.allow_unknown);
  same_bool("map", "inflate_unknown", c.map.inflate_unknown, d.map.inflate_unknown);
  same_double("map", "robot_radius", c.map.robot_radius, d.map.robot_radius);
  same_double("map", "inflation_radius", c.map.inflation_radius, d.map.inflation_radius);
  same_double("map", "cost_scaling_factor", c.map.cost_scaling_factor, d.map.cost_scaling_factor);
  same_int("map", "max_cells", c.map.max_cells, d.map.max_cells);
  same_int("map", "memory_budget_mb", c.map_memory_budget_mb, d.map_memory_budget_mb);
  const auto& s = c.planner.settings;
  const auto& ds = d.planner.settings;
  // planner.name: auto is kept as auto (kind is then its choice).
  auto planner_name = [&](const node::PlannerConfig& planner) {
    return planner.auto_kind ? std::optional<std::string>(std::string(core::kAutoPlannerName))
                             : name_of(planner.kind);
  };
  same_text("planner", "name", planner_name(c.planner), planner_name(d.planner));
  same_double("planner", "omega", s.omega, ds.omega);
  same_double("planner", "eta", s.eta, ds.eta);
  same_text("planner", "neighborhood", opt_name(s.neighborhood), opt_name(ds.neighborhood));
  same_text("planner", "corner_policy", opt_name(s.corner_policy), opt_name(ds.corner_policy));
  same_bool("planner", "prune", s.prune, ds.prune);
  same_bool("planner", "smooth", s.smooth, ds.smooth);
  same_double("planner", "smoothing_distance", s.smoothing_distance, ds.smoothing_distance);
  same_double("planner", "sample_step", s.sample_step, ds.sample_step);
  same_text("planner", "smoother", opt_name(s.smoother), opt_name(ds.smoother));
  same_double("planner", "smoother_smoothness", s.smoother_smoothness, ds.smoother_smoothness);
  same_double("planner", "smoother_closeness", s.smoother_closeness, ds.smoother_closeness);
  same_double("planner", "smoother_cost", s.smoother_cost, ds.smoother_cost);
  same_int("planner", "smoother_iterations", s.smoother_iterations.value_or(-1),
           ds.smoother_iterations.value_or(-1));
  same_bool("planner", "compute_length_ratio", s.compute_length_ratio, ds.compute_length_ratio);
  same_double("planner", "cost_weight", s.cost_weight, ds.cost_weight);
  same_double("planner", "goal_tolerance", s.goal_tolerance, ds.goal_tolerance);
  same_double("planner", "start_tolerance", s.start_tolerance, ds.start_tolerance);
  same_double("planner", "path_spacing", c.planner.path_spacing, d.planner.path_spacing);
  {
    const auto v = find("planner", "max_planning_time");
    if (scalar(v, "planner.max_planning_time")) {
      const double seconds = v->as<double>();
      const int64_t us = std::max<int64_t>(std::llround(seconds * 1e6), seconds > 0 ? 1 : 0);
      if (!s.max_planning_time || s.max_planning_time->count() != us) {
        p->push_back("planner.max_planning_time: field differs from the file's value");
      }
    } else if (s.max_planning_time != ds.max_planning_time) {
      p->push_back("planner.max_planning_time: absent but not the default");
    }
  }
  const char* const durabilities[] = {"transient_local", "volatile"};
  same_text("map", "durability", std::string(durabilities[static_cast<int>(c.map_durability)]),
            std::string(durabilities[static_cast<int>(d.map_durability)]));
  const char* const cost_sources[] = {"own", "costmap"};
  same_text("map", "cost_source", std::string(cost_sources[static_cast<int>(c.map_cost_source)]),
            std::string(cost_sources[static_cast<int>(d.map_cost_source)]));
  same_bool("actions", "enabled", c.actions.enabled, d.actions.enabled);
  same_int("actions", "max_results", c.actions.max_results, d.actions.max_results);
  same_int("actions", "kept_results_mb", c.actions.kept_results_mb, d.actions.kept_results_mb);
  same_int("actions", "max_result_poses", c.actions.max_result_poses, d.actions.max_result_poses);
  same_int("actions", "max_goal_poses", c.actions.max_goal_poses, d.actions.max_goal_poses);
  same_int("actions", "replies_in_flight_mb", c.actions.replies_in_flight_mb,
           d.actions.replies_in_flight_mb);
  same_int("actions", "max_pending_replies", c.actions.max_pending_replies,
           d.actions.max_pending_replies);
  same_int("actions", "status_finished_goals", c.actions.status_finished_goals,
           d.actions.status_finished_goals);
  {
    const auto v = find("actions", "reply_ack_timeout");
    if (scalar(v, "actions.reply_ack_timeout")) {
      if (c.actions.reply_ack_timeout.count() != std::llround(v->as<double>() * 1000.0))
        p->push_back("actions.reply_ack_timeout: field differs from the file's value");
    } else if (c.actions.reply_ack_timeout != d.actions.reply_ack_timeout) {
      p->push_back("actions.reply_ack_timeout: absent but not the default");
    }
  }
  {
    // planner.aliases: a map of names to planner names ("default", "auto" or a planner), kept as
    // given; absent, default.yaml's.
    const auto v = find("planner", "aliases");
    if (v && !v->IsNull()) {
      if (!v->IsMap()) {
        p->push_back("planner.aliases: accepted a value that is not a map");
      } else {
        std::vector<std::pair<std::string, std::string>> want;
        for (const auto& kv : *v) want.emplace_back(kv.first.Scalar(), kv.second.Scalar());
        if (c.planner.aliases != want)
          p->push_back("planner.aliases: field differs from the file's value");
        for (const auto& [name, target] : c.planner.aliases)
          if (target != node::kDefaultPlannerAlias && target != core::kAutoPlannerName &&
              !core::planner_kind_from_string(target))
            p->push_back("planner.aliases: accepted an alias of no planner");
      }
    } else if (!v && c.planner.aliases != d.planner.aliases) {
      p->push_back("planner.aliases: absent but not the default");
    } else if (v && !c.planner.aliases.empty()) {
      p->push_back("planner.aliases: given no value, but not empty");
    }
  }
  const char* const mappings[] = {"auto", "fastrtps", "cyclonedds"};
  same_text("actions", "reply_mapping",
            std::string(mappings[static_cast<int>(c.actions.reply_mapping)]),
            std::string(mappings[static_cast<int>(d.actions.reply_mapping)]));
  {
    const auto v = find("actions", "result_timeout");
    if (scalar(v, "actions.result_timeout")) {
      if (c.actions.result_timeout.count() != std::llround(v->as<double>() * 1000.0))
        p->push_back("actions.result_timeout: field differs from the file's value");
    } else if (c.actions.result_timeout != d.actions.result_timeout) {
      p->push_back("actions.result_timeout: absent but not the default");
    }
  }
  for (const auto& [key, got, fallback] : {std::tuple{"reply_wait", c.reply_wait, d.reply_wait},
                                           std::tuple{"map_wait", c.map_wait, d.map_wait}}) {
    const std::string name = std::string("requests.") + key;
    const auto v = find("requests", key);
    if (scalar(v, name)) {
      if (got.count() != std::llround(v->as<double>() * 1000.0))
        p->push_back(name + ": field differs from the file's value");
    } else if (got != fallback) {
      p->push_back(name + ": absent but not the default");
    }
  }
  same_bool("network", "localhost_only", c.localhost_only, d.localhost_only);
  {
    const auto v = find("discovery", "servers");
    std::vector<std::string> listed;
    if (v && v->IsSequence())
      for (const YAML::Node& item : *v) listed.push_back(item.IsScalar() ? item.Scalar() : "");
    if (v && v->IsSequence() ? c.discovery_servers != listed
                             : c.discovery_servers != d.discovery_servers)
      p->push_back("discovery.servers: field differs from the file's value");
    for (const std::string& server : c.discovery_servers)
      if (!node::discovery_server_problem(server).empty())
        p->push_back("discovery.servers: accepted \"" + server + "\"");
  }
  same_text("dds", "participant_profile", c.participant_profile, d.participant_profile);
  same_bool("security", "enable", c.security.enable, d.security.enable);
  same_text("security", "keystore", c.security.keystore, d.security.keystore);
  same_text("security", "enclave", c.security.enclave, d.security.enclave);
  const char* const strategies[] = {"Enforce", "Permissive"};
  same_text("security", "strategy", std::string(strategies[static_cast<int>(c.security.strategy)]),
            std::string(strategies[static_cast<int>(d.security.strategy)]));
  if (!c.security.enclave.empty() && !node::enclave_name_problem(c.security.enclave).empty())
    p->push_back("security.enclave: accepted a value that is not an enclave name");
  same_bool("requests", "preempt", c.preempt, d.preempt);
  same_int("requests", "queue_capacity", c.queue_capacity, d.queue_capacity);
  same_int("requests", "workers", c.workers, d.workers);
  {
    // robots: each entry a namespace as normalized_namespace keeps it, none twice.
    const auto v = find("", "robots");
    std::vector<std::string> listed;
    if (v && v->IsSequence())
      for (const YAML::Node& item : *v)
        if (item.IsScalar()) {
          const auto name = node::normalized_namespace(item.Scalar());
          listed.push_back(name ? *name : "");
        }
    if (v && v->IsSequence() ? c.robots != listed : c.robots != d.robots)
      p->push_back("robots: field differs from the file's value");
    std::set<std::string> distinct(c.robots.begin(), c.robots.end());
    if (distinct.size() != c.robots.size() || distinct.count("") > 0 ||
        c.robots.size() > node::kMaxRobots)
      p->push_back("robots: accepted an empty, repeated or excess robot name");
  }
  const char* const publish[] = {"auto", "always", "never"};
  same_text("debug", "publish", std::string(publish[static_cast<int>(c.debug)]),
            std::string(publish[static_cast<int>(d.debug)]));
  same_text("", "log_level", c.log_level, d.log_level);
  same_double("slicer", "z_min", c.slicer.z_min, d.slicer.z_min);
  same_double("slicer", "z_max", c.slicer.z_max, d.slicer.z_max);
  same_double("slicer", "resolution", c.slicer.resolution, d.slicer.resolution);
  same_bool("slicer", "remove_speckles", c.slicer.remove_speckles, d.slicer.remove_speckles);

  // Documented ranges (config/default.yaml).
  const bool in_range =
      c.domain_id >= 0 && c.domain_id <= 232 && c.map.occupied_threshold >= 1 &&
      c.map.occupied_threshold <= 100 && std::isfinite(c.map.robot_radius) &&
      c.map.robot_radius >= 0 && c.map.max_cells >= 1 && c.map.max_cells <= (int64_t{1} << 28) &&
      c.map_memory_budget_mb >= 1 && c.map_memory_budget_mb <= node::kMaxMapMemoryBudgetMb &&
      c.queue_capacity >= 1 && c.queue_capacity <= 100000 && c.workers >= 0 &&
      c.workers <= node::kMaxWorkers && !c.frame_id.empty() && !c.base_frame.empty() &&
      node::without_leading_slash(c.base_frame) != node::without_leading_slash(c.frame_id) &&
      c.transform_tolerance_s >= 0 && c.transform_tolerance_s <= 60 && c.reply_wait.count() >= 0 &&
      c.bond.heartbeat_period.count() >= 10 && c.bond.heartbeat_period.count() <= 60000 &&
      !c.node_name.empty() && c.reply_wait.count() <= 10000 &&
      c.actions.result_timeout.count() >= 0 && c.actions.result_timeout.count() <= 86400000 &&
      c.actions.max_results >= 1 && c.actions.max_results <= 100000 &&
      c.actions.kept_results_mb >= 1 && c.actions.kept_results_mb <= 65536 &&
      c.actions.max_result_poses >= 1 && c.actions.max_result_poses <= 10000000 &&
      c.actions.max_goal_poses >= 1 && c.actions.max_goal_poses <= 100000 &&
      c.actions.replies_in_flight_mb >= 1 && c.actions.replies_in_flight_mb <= 4096 &&
      c.actions.reply_ack_timeout.count() >= 50 && c.actions.reply_ack_timeout.count() <= 60000 &&
      c.actions.max_pending_replies >= 1 && c.actions.max_pending_replies <= 100000 &&
      c.actions.status_finished_goals >= 0 && c.actions.status_finished_goals <= 100000 &&
      std::isfinite(c.slicer.z_min) && std::isfinite(c.slicer.z_max) &&
      c.slicer.z_min <= c.slicer.z_max && std::isfinite(c.slicer.resolution) &&
      c.slicer.resolution >= 0 && std::isfinite(c.map.inflation_radius) &&
      (c.map.inflation_radius == 0 || c.map.inflation_radius >= c.map.robot_radius) &&
      std::isfinite(c.map.cost_scaling_factor) && c.map.cost_scaling_factor >= 0 &&
      core::kCostWeightRange.contains(s.cost_weight.value_or(0)) &&
      core::kToleranceRange.contains(s.goal_tolerance.value_or(0)) &&
      core::kToleranceRange.contains(s.start_tolerance.value_or(0)) &&
      (!c.planner.path_spacing || node::kPathSpacingRange.contains(*c.planner.path_spacing)) &&
      (!s.max_planning_time ||
       (s.max_planning_time->count() >= 0 && s.max_planning_time->count() <= 3600LL * 1000000));
  if (!in_range) p->push_back("an accepted value is outside its documented range");

  // Every key of the file is known, given once, and has a value.
  const std::set<std::string> sections = {"topics",    "map",    "planner", "requests", "actions",
                                          "debug",     "slicer", "network", "bond",     "security",
                                          "discovery", "dds",    "ros"};
  auto walk = [&](const YAML::Node& map, const std::string& prefix) {
    std::set<std::string> seen;
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) {
        p->push_back(prefix + ": accepted a key that is not a name");
        continue;
      }
      const std::string key = prefix.empty() ? kv.first.Scalar() : prefix + "." + kv.first.Scalar();
      if (!seen.insert(key).second) p->push_back(key + ": accepted a repeated key");
      const bool section = prefix.empty() && sections.count(key) > 0;
      if (!section && known.count(key) == 0) p->push_back(key + ": accepted an unknown key");
      // A list or map key without a value is the empty list or map (the loader reads robots:,
      // discovery.servers: and planner.aliases: so, as yaml-cpp reads `[]` and `{}`); any other
      // key needs a value.
      const bool list_key =
          key == "robots" || key == "discovery.servers" || key == "planner.aliases";
      if (!section && !list_key && kv.second.IsNull())
        p->push_back(key + ": accepted a key without a value");
      if (section && !kv.second.IsMap() && !kv.second.IsNull()) {
        p->push_back(key + ": accepted a section that is not a map");
      }
    }
  };
  if (root.IsMap()) {
    walk(root, "");
    for (const std::string& section : sections) {
      if (child(root, section).IsMap()) walk(child(root, section), section);
    }
  }
}

Outcome check_config(const fs::path& file) {
  Outcome out;
  const node::ConfigResult result = node::load_config(file.string());
  if (!result.config) {
    if (result.errors.empty()) out.problems.push_back("no config and no error");
    for (const std::string& e : result.errors) {
      // Each line names the file (syntax, unreadable) or a key: "key: found X, expected Y",
      // "key: unknown key (did you mean ...)".
      const size_t colon = e.find(": ");
      const bool named = e.rfind(file.string(), 0) == 0 ||
                         (colon != std::string::npos && colon > 0 &&
                          (contains(e, "expected") || contains(e, "unknown key")));
      if (e.empty() || !named) out.problems.push_back("an error naming no key or file: " + e);
      if (leaked_exception(e)) out.problems.push_back("a library exception's text: " + e);
    }
    return out;
  }
  out.loaded = true;
  if (!result.errors.empty()) out.problems.push_back("a config together with errors");
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(read_bytes(file));
  } catch (const std::exception& e) {
    out.problems.push_back(std::string("accepted a file yaml-cpp cannot read: ") + e.what());
    return out;
  }
  if (docs.size() > 1) out.problems.push_back("accepted several YAML documents");
  try {
    check_config_against_yaml(*result.config, docs.empty() ? YAML::Node() : docs.front(),
                              &out.problems);
  } catch (const std::exception& e) {  // YAML::BadConversion of a value the loader accepted
    out.problems.push_back(std::string("accepted a value yaml-cpp cannot convert: ") + e.what());
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Seeds

struct Seed {
  std::string name;
  std::string bytes;
};

std::vector<Seed> seeds_from(const std::vector<fs::path>& files) {
  std::vector<Seed> out;
  for (const fs::path& f : files) out.push_back({f.filename().string(), read_bytes(f)});
  return out;
}

std::vector<fs::path> files_in(const fs::path& dir, const std::string& suffix) {
  std::vector<fs::path> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && name.size() >= suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      out.push_back(e.path());
    }
  }
  std::sort(out.begin(), out.end());  // directory order is not deterministic
  return out;
}

// A window of a Moving AI map in the same format and line ending: the benchmark's large maps
// (512 x 512, 262 KB) cost milliseconds per input under ASan, a 48 x 40 window of them keeps
// their terrain and line endings at a few thousand inputs per second.
std::string movingai_window(const std::string& text, int x0, int y0, int w, int h) {
  const std::string eol = text.find("\r\n") != std::string::npos ? "\r\n" : "\n";
  const auto lines = text_lines(text);
  std::string out = "type octile" + eol + "height " + std::to_string(h) + eol + "width " +
                    std::to_string(w) + eol + "map" + eol;
  for (int y = 0; y < h; ++y) out += lines.at(4 + y0 + y).substr(x0, w) + eol;
  return out;
}

// The first `n` lines of a scenario file (whole lines, its own line ending).
std::string first_lines(const std::string& text, size_t n) {
  size_t pos = 0;
  for (size_t i = 0; i < n && pos != std::string::npos; ++i) {
    pos = text.find('\n', pos);
    if (pos != std::string::npos) ++pos;
  }
  return pos == std::string::npos ? text : text.substr(0, pos);
}

// Calls f(key, leaf) for every voxel (leaf-size cell) in the key box [lo, hi] under a leaf of
// `tree`: a pruned leaf stands for all the voxels it covers.
template <class F>
void for_each_voxel(const octomap::OcTree& tree, const octomap::OcTreeKey& lo,
                    const octomap::OcTreeKey& hi, F f) {
  const unsigned depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs_bbx(lo, hi), end = tree.end_leafs_bbx(); it != end; ++it) {
    const octomap::OcTreeKey base = it.getIndexKey();
    const unsigned span = 1u << (depth - it.getDepth());
    for (unsigned dx = 0; dx < span; ++dx)
      for (unsigned dy = 0; dy < span; ++dy)
        for (unsigned dz = 0; dz < span; ++dz) {
          const octomap::OcTreeKey k(base[0] + dx, base[1] + dy, base[2] + dz);
          if (k[0] < lo[0] || k[0] > hi[0] || k[1] < lo[1] || k[1] > hi[1] || k[2] < lo[2] ||
              k[2] > hi[2]) {
            continue;
          }
          f(k, *it);
        }
  }
}

// A box of a real tree as its own tree: every leaf under [lo, hi] copied voxel by voxel, then
// pruned, so the crop keeps the scene's structure (pruned free space, walls) at a size that
// loads in a fraction of a millisecond.
std::shared_ptr<octomap::OcTree> crop_tree(const octomap::OcTree& tree, const octomap::point3d& lo,
                                           const octomap::point3d& hi) {
  auto crop = std::make_shared<octomap::OcTree>(tree.getResolution());
  octomap::OcTreeKey klo, khi;
  if (!tree.coordToKeyChecked(lo, klo) || !tree.coordToKeyChecked(hi, khi)) return crop;
  for_each_voxel(tree, klo, khi, [&](const octomap::OcTreeKey& k, const octomap::OcTreeNode& leaf) {
    crop->setNodeValue(k, leaf.getLogOdds(), true);
  });
  crop->updateInnerOccupancy();
  crop->prune();
  return crop;
}

// The same voxels in a tree of another occupancy type (ColorOcTree, OcTreeStamped), then pruned;
// a colour tree gets a colour a voxel.
template <class Tree>
std::shared_ptr<Tree> same_voxels_as(const octomap::OcTree& tree) {
  auto out = std::make_shared<Tree>(tree.getResolution());
  const octomap::OcTreeKey all_lo(0, 0, 0), all_hi(0xffff, 0xffff, 0xffff);
  for_each_voxel(
      tree, all_lo, all_hi, [&](const octomap::OcTreeKey& k, const octomap::OcTreeNode& leaf) {
        auto* node = out->setNodeValue(k, leaf.getLogOdds(), true);
        if constexpr (std::is_same_v<Tree, octomap::ColorOcTree>) {
          node->setColor(static_cast<uint8_t>(k[0] * 37), static_cast<uint8_t>(k[1] * 11),
                         static_cast<uint8_t>(k[2] * 5));
        }
      });
  out->updateInnerOccupancy();
  out->prune();
  return out;
}

std::string tree_file(const octomap::AbstractOccupancyOcTree& tree, bool binary) {
  std::ostringstream out;
  binary ? tree.writeBinaryConst(out) : tree.write(out);
  return out.str();
}

// A crop of a real tree around its middle (the busiest part of a scanned floor): 25 x 25 leaves
// and up to 2 m of height; nullptr when empty.
std::shared_ptr<octomap::OcTree> middle_crop(const octomap::OcTree& tree) {
  double x0, y0, z0, x1, y1, z1;
  tree.getMetricMin(x0, y0, z0);
  tree.getMetricMax(x1, y1, z1);
  const double cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
  const double r = 12 * tree.getResolution();
  auto crop = crop_tree(tree, octomap::point3d(cx - r, cy - r, z0),
                        octomap::point3d(cx + r, cy + r, std::min(z1, z0 + 2.0)));
  return crop->size() > 0 ? crop : nullptr;
}

// A tree as both file formats, and the same voxels as a ColorOcTree and an OcTreeStamped (whose
// .ot nodes differ: 8 bytes a colour node, 5 an OcTree or stamped one).
std::vector<Seed> tree_files(const std::string& name, const octomap::OcTree& tree) {
  std::vector<Seed> out;
  const std::pair<std::string, std::shared_ptr<const octomap::AbstractOccupancyOcTree>> types[] = {
      {"", nullptr},
      {" as ColorOcTree", same_voxels_as<octomap::ColorOcTree>(tree)},
      {" as OcTreeStamped", same_voxels_as<octomap::OcTreeStamped>(tree)}};
  for (const auto& [type, copy] : types) {
    const octomap::AbstractOccupancyOcTree& t = copy ? *copy : tree;
    out.push_back({name + type + " (.bt)", tree_file(t, true)});
    out.push_back({name + type + " (.ot)", tree_file(t, false)});
  }
  return out;
}

std::shared_ptr<octomap::OcTree> load_tree_or_null(const fs::path& file) {
  auto tree = maps::load_octree(file.string());
  return tree ? *tree : nullptr;
}

std::vector<Seed> concat(std::vector<Seed> a, const std::vector<Seed>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// A crop of the embedded demo scene (config/scenes/geb079.bt) and a small tree of free and
// occupied leaves.
std::vector<std::pair<std::string, std::shared_ptr<octomap::OcTree>>> project_trees() {
  std::vector<std::pair<std::string, std::shared_ptr<octomap::OcTree>>> out;
  if (auto tree = load_tree_or_null(config_dir() / "scenes" / "geb079.bt")) {
    if (auto crop = middle_crop(*tree)) out.emplace_back("geb079 crop", crop);
  }
  auto small = std::make_shared<octomap::OcTree>(0.1);
  for (int i = 0; i < 20; ++i) {
    small->updateNode(octomap::point3d(0.05f * i, 0.3f, 0.5f), i % 3 != 0);
  }
  out.emplace_back("small", small);
  return out;
}

// Those trees as .bt and .ot files, and the whole scene file.
std::vector<Seed> project_tree_seeds() {
  std::vector<Seed> out;
  for (const auto& [name, tree] : project_trees()) out = concat(out, tree_files(name, *tree));
  const fs::path scene = config_dir() / "scenes" / "geb079.bt";
  if (fs::exists(scene)) out.push_back({"geb079.bt", read_bytes(scene)});
  return out;
}

// ---------------------------------------------------------------------------------------------
// The driver

// The folder of tests/fixtures/fuzz/ whose inputs a loader's check replays: the real-data
// variants share their loader's.
std::string replay_folder(const std::string& loader) {
  const std::string suffix = "_data";
  const bool real_data = loader.size() > suffix.size() && loader != "octomap_data" &&
                         loader.compare(loader.size() - suffix.size(), suffix.size(), suffix) == 0;
  return real_data ? loader.substr(0, loader.size() - suffix.size()) : loader;
}

// One input: the files to write (the first is the one handed to the loader).
struct Input {
  std::vector<std::pair<std::string, std::string>> files;
  std::vector<std::string> log;  // how it was made
};

using MakeInput = std::function<Input(Mutator&)>;
using CheckInput = std::function<Outcome(const fs::path& dir, const Input&)>;

class FuzzLoaders : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(read_settings(&settings_));
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    // A fresh directory of this test's own (temp_dir.hpp): ctest runs the tests of this
    // executable in parallel. Removed after the test, and by the process when it exits; only a
    // process that dies mid-input (a sanitizer report, a crash) leaves it, with that input in it.
    dir_ = vnsba::test::FreshTempDir("fuzz_" + std::string(info->name()));
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // Runs the inputs of `loader`; `syntax` and `dictionary` steer the mutator.
  void run(const std::string& loader, Syntax syntax, const std::vector<std::string>& dictionary,
           const MakeInput& make, const CheckInput& check) {
    const uint64_t n = settings_.iterations;
    std::cout << "[fuzz] " << loader << ": " << n << " inputs, VNSBA_FUZZ_SEED=" << settings_.seed
              << "; the input being read is in " << dir_.string() << " (ITERATION says which)"
              << std::endl;
    uint64_t loaded = 0, rejected = 0, ran = 0;
    int failures = 0;
    std::vector<std::string> previous;
    for (uint64_t i = 0; i < n; ++i) {
      if (settings_.only_iteration && *settings_.only_iteration != i) continue;
      Mutator mutator(input_seed(settings_.seed, loader, i), syntax, dictionary);
      const Input input = make(mutator);
      // Files of the previous input must not be read by this one (a mutated image name could
      // otherwise find the last input's image, and the run would depend on its history).
      for (const std::string& f : previous) fs::remove(dir_ / f);
      previous.clear();
      for (const auto& [name, bytes] : input.files) {
        write_bytes(dir_ / name, bytes);
        previous.push_back(name);
      }
      write_bytes(dir_ / "ITERATION", std::to_string(i) + "\n");
      const Outcome outcome = check(dir_, input);
      ++ran;
      (outcome.loaded ? loaded : rejected) += 1;
      if (outcome.problems.empty()) continue;
      const fs::path saved = save_failure(loader, i, input, outcome);
      std::ostringstream report;
      report << loader << ": input " << i << " (VNSBA_FUZZ_SEED=" << settings_.seed
             << " VNSBA_FUZZ_ITERATION=" << i << ") saved in " << saved.string() << "\n";
      for (const std::string& m : input.log) report << "  made by: " << m << "\n";
      for (const std::string& p : outcome.problems) report << "  problem: " << p << "\n";
      // All inputs run (the stage's time and the failure count stay comparable); the first
      // few are reported in full, every one is saved.
      if (++failures <= kMaxReportedFailures) ADD_FAILURE() << report.str();
    }
    if (failures > kMaxReportedFailures) {
      ADD_FAILURE() << loader << ": " << failures << " failing inputs in all, saved under "
                    << (fs::path(VNSBA_FUZZ_OUT_DIR) / replay_folder(loader)).string();
    }
    std::cout << "[fuzz] " << loader << ": " << ran << " inputs, " << loaded << " loaded, "
              << rejected << " rejected" << std::endl;
    // A mutator that only ever produced garbage (or only valid files) would test nothing of
    // what it claims; with a few thousand inputs both outcomes must be common.
    if (!settings_.only_iteration && ran >= 1000) {
      EXPECT_GE(loaded, ran / 100) << loader << ": almost no input loaded";
      EXPECT_GE(rejected, ran / 100) << loader << ": almost no input was rejected";
    }
  }

  // Saved as a folder that tests/fixtures/fuzz/ takes as it is (FuzzRegression replays it).
  fs::path save_failure(const std::string& loader, uint64_t i, const Input& input,
                        const Outcome& outcome) {
    const fs::path dir =
        fs::path(VNSBA_FUZZ_OUT_DIR) / replay_folder(loader) /
        (loader + "-seed-" + std::to_string(settings_.seed) + "-iteration-" + std::to_string(i));
    fs::remove_all(dir);
    for (const auto& [name, bytes] : input.files) write_bytes(dir / name, bytes);
    std::string notes;
    for (const std::string& m : input.log) notes += "made by: " + m + "\n";
    for (const std::string& p : outcome.problems) notes += "problem: " + p + "\n";
    write_bytes(dir / "FAILURE.txt", notes);
    return dir;
  }

  Settings settings_;
  fs::path dir_;
};

// A single-file loader: a seed picked at random (a valid one 3 times in 4: mutations of an
// invalid file mostly stay invalid in the same way), mutated, written as `file_name`.
MakeInput single_file(const std::vector<Seed>& good, const std::string& file_name,
                      const std::vector<Seed>& bad = {}) {
  auto all = std::make_shared<std::vector<std::string>>();
  for (const Seed& s : good) all->push_back(s.bytes);
  for (const Seed& s : bad) all->push_back(s.bytes);
  return [good, bad, all, file_name](Mutator& m) {
    const bool pick_bad = !bad.empty() && (good.empty() || m.below(4) == 0);
    const Seed& seed = pick_bad ? bad[m.below(bad.size())] : good[m.below(good.size())];
    Input in;
    in.log.push_back("seed " + seed.name);
    in.files.push_back({file_name, m.mutate(seed.bytes, *all, &in.log)});
    return in;
  };
}

CheckInput on_first_file(std::function<Outcome(const fs::path&)> check) {
  return [check](const fs::path& dir, const Input& in) { return check(dir / in.files[0].first); };
}

// The unmutated seeds: good ones must load and pass every check (else the fuzzing would start
// from files the oracles already disagree with), bad ones must be rejected.
void expect_seeds(const std::vector<Seed>& good, const std::vector<Seed>& bad, const fs::path& dir,
                  const std::string& file_name,
                  const std::function<Outcome(const fs::path&)>& check) {
  for (const auto& [seeds, should_load] : {std::pair{&good, true}, std::pair{&bad, false}}) {
    for (const Seed& s : *seeds) {
      write_bytes(dir / file_name, s.bytes);
      const Outcome o = check(dir / file_name);
      EXPECT_EQ(o.loaded, should_load) << "seed " << s.name;
      for (const std::string& p : o.problems) ADD_FAILURE() << "seed " << s.name << ": " << p;
    }
  }
}

const std::vector<std::string> kMovingAiWords = {
    "type", "octile", "height", "width", "map", "version", "1", "1.0", "@", ".", "T", "\t"};

// ---------------------------------------------------------------------------------------------
// Moving AI

TEST_F(FuzzLoaders, MovingAiMap) {
  const auto good = seeds_from(
      {fixture("maps/tiny.map"), fixture("maps/tiny_crlf.map"), fixture("maps/rooms_32.map")});
  const auto bad = seeds_from(files_in(fixture("maps/bad"), ".map"));
  expect_seeds(good, bad, dir_, "input.map", check_movingai_map);
  run("movingai_map", Syntax::kPlain, kMovingAiWords, single_file(good, "input.map", bad),
      on_first_file(check_movingai_map));
}

TEST_F(FuzzLoaders, MovingAiMapRealData) {
  const fs::path dir = data_dir() / "movingai";
  if (!fs::is_directory(dir)) {
    GTEST_SKIP() << "Moving AI data not found at " << dir << ": real-map seeds skipped";
  }
  std::vector<Seed> good = seeds_from({dir / "arena.map", dir / "den312d.map"});
  // Windows of the large maps: street (CRLF), room, maze and random terrain.
  for (const auto& [file, x, y] :
       {std::tuple{"Berlin_0_256.map", 100, 60}, std::tuple{"8room_000.map", 200, 300},
        std::tuple{"maze512-4-0.map", 10, 10}, std::tuple{"random512-20-0.map", 300, 100},
        std::tuple{"brc202d.map", 250, 250}}) {
    good.push_back(
        {std::string(file) + " window", movingai_window(read_bytes(dir / file), x, y, 48, 40)});
  }
  expect_seeds(good, {}, dir_, "input.map", check_movingai_map);
  run("movingai_map_data", Syntax::kPlain, kMovingAiWords, single_file(good, "input.map"),
      on_first_file(check_movingai_map));
}

TEST_F(FuzzLoaders, MovingAiScenarios) {
  const auto good = seeds_from({fixture("maps/tiny.map.scen"), fixture("maps/tiny_spaces.scen")});
  const auto bad = seeds_from(files_in(fixture("maps/bad"), ".scen"));
  expect_seeds(good, bad, dir_, "input.scen", check_movingai_scenarios);
  run("movingai_scen", Syntax::kPlain, kMovingAiWords, single_file(good, "input.scen", bad),
      on_first_file(check_movingai_scenarios));
}

TEST_F(FuzzLoaders, MovingAiScenariosRealData) {
  const fs::path dir = data_dir() / "movingai";
  if (!fs::is_directory(dir)) {
    GTEST_SKIP() << "Moving AI data not found at " << dir << ": real-scenario seeds skipped";
  }
  std::vector<Seed> good = seeds_from({dir / "arena.map.scen"});
  // The first lines of the others: "version 1" with tabs, "version 1.0" with spaces and CRLF.
  for (const char* file : {"Berlin_0_256.map.scen", "8room_000.map.scen", "den312d.map.scen",
                           "maze512-4-0.map.scen", "ost100d.map.scen"}) {
    good.push_back({std::string(file) + " head", first_lines(read_bytes(dir / file), 40)});
  }
  expect_seeds(good, {}, dir_, "input.scen", check_movingai_scenarios);
  run("movingai_scen_data", Syntax::kPlain, kMovingAiWords, single_file(good, "input.scen"),
      on_first_file(check_movingai_scenarios));
}

// ---------------------------------------------------------------------------------------------
// map_server

struct MapServerSeed {
  std::string name;
  std::string yaml;
  std::string image_name;  // as the YAML names it, beside the YAML
  std::string pgm;
  bool valid = true;
};

// The YAML with its image renamed (fixtures in bad/ name "../p5_8bit.pgm"; inputs live in one
// folder).
std::string rename_image(std::string yaml, const std::string& from, const std::string& to) {
  for (size_t p = yaml.find(from); p != std::string::npos; p = yaml.find(from, p + to.size())) {
    yaml.replace(p, from.size(), to);
  }
  return yaml;
}

std::vector<MapServerSeed> map_server_seeds(const fs::path& scratch) {
  std::vector<MapServerSeed> out;
  const fs::path ms = fixture("map_server");
  for (const char* stem : {"p5_8bit", "p2_thresholds", "p5_16bit"}) {
    out.push_back({stem, read_bytes(ms / (std::string(stem) + ".yaml")), std::string(stem) + ".pgm",
                   read_bytes(ms / (std::string(stem) + ".pgm")), true});
  }
  for (const fs::path& yaml : files_in(ms / "bad", ".yaml")) {
    const std::string stem = yaml.stem().string();
    const bool own_image = fs::exists(ms / "bad" / (stem + ".pgm"));
    out.push_back({"bad/" + stem, rename_image(read_bytes(yaml), "../p5_8bit.pgm", "p5_8bit.pgm"),
                   own_image ? stem + ".pgm" : "p5_8bit.pgm",
                   read_bytes(own_image ? ms / "bad" / (stem + ".pgm") : ms / "p5_8bit.pgm"),
                   false});
  }
  // The p5_8bit map in YAML that only a YAML library reads, so that mutations exercise yaml-cpp's
  // side of the reader (and the yaml-cpp oracle): quotes, comments after values, block and flow
  // lists, a flow map document, anchors and aliases, tags, document markers; and YAML that
  // yaml-cpp must refuse or the reader must (two documents, a map value, deep nesting).
  const std::string p5 = read_bytes(ms / "p5_8bit.pgm");
  const std::pair<const char*, const char*> yaml_features[] = {
      {"quoted",
       "image: \"p5_8bit.pgm\"\nmode: 'trinary'\nresolution: \"0.05\"\n"
       "origin: ['-10.0', \"-5.5\", 0.0]\nnegate: '0'\n"},
      {"comments and block list",
       "# map_server map\nimage: p5_8bit.pgm  # beside this file\n"
       "resolution: 0.05 # metres\norigin:\n  - -10.0  # x\n  - -5.5\n"
       "  - 0.0\nfree_thresh: 0.196\n# end\n"},
      {"flow map",
       "{image: p5_8bit.pgm, resolution: 0.05, origin: [-10.0, -5.5, 0.0], "
       "mode: scale, negate: 1}\n"},
      {"anchors",
       "base: &res 0.05\nimage: p5_8bit.pgm\nresolution: *res\n"
       "origin: &o [-10.0, -5.5, 0.0]\nnegate: false\nmode: raw\n"},
      {"tags and markers",
       "%YAML 1.2\n---\nimage: !!str p5_8bit.pgm\nresolution: !!float 0.05\n"
       "origin: !!seq [-10.0, -5.5, 0.0]\noccupied_thresh: 0.7\n...\n"},
  };
  for (const auto& [name, yaml] : yaml_features) {
    out.push_back({std::string("yaml ") + name, yaml, "p5_8bit.pgm", p5, true});
  }
  const std::pair<const char*, const char*> bad_yaml[] = {
      {"two documents", "image: p5_8bit.pgm\nresolution: 0.05\n---\norigin: [0, 0, 0]\n"},
      {"map value", "image: p5_8bit.pgm\nresolution: {m: 0.05}\norigin: [0, 0, 0]\n"},
      {"deep",
       "image: p5_8bit.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nx: [[[[[[[[]]]]]]]]\n"
       "y: [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[\n"},
  };
  for (const auto& [name, yaml] : bad_yaml) {
    out.push_back({std::string("yaml ") + name, yaml, "p5_8bit.pgm", p5, false});
  }
  // map_saver's output (save_map_server) of the rooms fixture and of a slice of the embedded
  // scene, and the latter's image under the other modes.
  std::vector<std::pair<std::string, OccupancyGrid>> grids;
  if (auto rooms = maps::load_movingai_map(fixture("maps/rooms_32.map").string())) {
    rooms->resolution = 0.05;
    rooms->origin_x = -1.6;
    rooms->origin_y = 3.25;
    grids.emplace_back("rooms_32", *rooms);
  }
  for (const auto& [name, tree] : project_trees()) {
    if (name != "geb079 crop") continue;
    if (auto slice = maps::slice_octree(*tree, {})) grids.emplace_back("geb079_slice", *slice);
  }
  for (const auto& [stem, grid] : grids) {
    const auto saved = maps::save_map_server(grid, (scratch / stem).string());
    if (!saved) continue;
    const std::string yaml = read_bytes(*saved);
    const std::string pgm = read_bytes(scratch / (stem + ".pgm"));
    out.push_back({stem + " (save_map_server)", yaml, stem + ".pgm", pgm, true});
    if (stem == "geb079_slice") {
      const std::string base = rename_image(yaml, "mode: trinary", "mode: scale");
      out.push_back({stem + " scale negate", rename_image(base, "negate: 0", "negate: 1"),
                     stem + ".pgm", pgm, true});
      out.push_back({stem + " raw", rename_image(yaml, "mode: trinary", "mode: raw"), stem + ".pgm",
                     pgm, true});
    }
  }
  return out;
}

TEST_F(FuzzLoaders, MapServer) {
  const fs::path scratch = dir_ / "seeds";
  const auto seeds = map_server_seeds(scratch);
  ASSERT_GE(seeds.size(), 20u) << "fixtures or generated seeds missing";
  fs::remove_all(scratch);
  for (const MapServerSeed& s : seeds) {
    write_bytes(dir_ / "input.yaml", s.yaml);
    write_bytes(dir_ / s.image_name, s.pgm);
    const Outcome o = check_map_server(dir_ / "input.yaml");
    EXPECT_EQ(o.loaded, s.valid) << "seed " << s.name;
    for (const std::string& p : o.problems) ADD_FAILURE() << "seed " << s.name << ": " << p;
    fs::remove(dir_ / s.image_name);
  }
  auto yamls = std::make_shared<std::vector<std::string>>();
  auto pgms = std::make_shared<std::vector<std::string>>();
  for (const auto& s : seeds) yamls->push_back(s.yaml), pgms->push_back(s.pgm);
  const std::vector<std::string> words = {
      "image",       "resolution", "origin", "negate", "mode", "occupied_thresh",
      "free_thresh", "trinary",    "scale",  "raw",    "P5",   "P2",
      "#",           "[0, 0, 0]",  "true",   "255",    "\"",   "'",
      "&a ",         "*a",         "!!str ", "---",    "...",  "{",
      "}",           "- ",         "\n  - ", "~",      "? ",   "|"};
  run(
      "map_server", Syntax::kYaml, words,
      [seeds, yamls, pgms](Mutator& m) {
        const MapServerSeed& s = seeds[m.below(seeds.size())];
        Input in;
        in.log.push_back("seed " + s.name);
        // The YAML, the image or both; the image stays where the seed's YAML says.
        const uint64_t which = m.below(5);
        std::string yaml = s.yaml, pgm = s.pgm;
        if (which != 1) {
          in.log.push_back("YAML:");
          yaml = m.mutate(yaml, *yamls, &in.log);
        }
        if (which != 0) {
          in.log.push_back("PGM:");
          pgm = m.mutate(pgm, *pgms, &in.log);
        }
        in.files = {{"input.yaml", yaml}, {s.image_name, pgm}};
        return in;
      },
      on_first_file(check_map_server));
}

// ---------------------------------------------------------------------------------------------
// OctoMap

const std::vector<std::string> kOctreeWords = {"# Octomap OcTree binary file",
                                               "# Octomap OcTree file",
                                               "id",
                                               "OcTree",
                                               "ColorOcTree",
                                               "OcTreeStamped",
                                               "CountingOcTree",
                                               "1",
                                               "size",
                                               "res",
                                               "data",
                                               "\n"};

// The mutator works on one seed at a time; a whole scene (200 KB, most of the time spent in
// OctoMap's reader and the slice) is picked for 1 input in 20 so that the stage stays in budget.
MakeInput tree_inputs(const std::vector<Seed>& seeds, const std::string& file_name) {
  std::vector<Seed> small, large;
  for (const Seed& s : seeds) (s.bytes.size() > 20000 ? large : small).push_back(s);
  auto pick_small = single_file(small.empty() ? seeds : small, file_name);
  auto pick_large = single_file(large.empty() ? seeds : large, file_name);
  return [pick_small, pick_large](Mutator& m) {
    return m.below(20) == 0 ? pick_large(m) : pick_small(m);
  };
}

TEST_F(FuzzLoaders, OctoMapFile) {
  const auto good = project_tree_seeds();
  // Two trees as OcTree, ColorOcTree and OcTreeStamped in both formats, and the scene file.
  ASSERT_EQ(good.size(), 13u) << "the embedded scene config/scenes/geb079.bt did not load";
  expect_seeds(good, {}, dir_, "input.bt", check_octree_file);
  run("octomap_file", Syntax::kPlain, kOctreeWords, tree_inputs(good, "input.bt"),
      on_first_file(check_octree_file));
}

TEST_F(FuzzLoaders, OctoMapFileRealData) {
  const fs::path dir = data_dir() / "octomap";
  if (!fs::is_directory(dir)) {
    GTEST_SKIP() << "OctoMap data not found at " << dir << ": real-tree seeds skipped";
  }
  std::vector<Seed> good =
      seeds_from({dir / "simple.bt", dir / "derived_spherical_scan_res0.05.bt"});
  for (const char* file : {"test.bt", "fr_078_tidyup.bt"}) {
    const auto tree = load_tree_or_null(dir / file);
    if (auto crop = tree ? middle_crop(*tree) : nullptr) {
      good = concat(good, tree_files(std::string(file) + " crop", *crop));
    }
  }
  good.push_back({"test.bt", read_bytes(dir / "test.bt")});
  expect_seeds(good, {}, dir_, "input.bt", check_octree_file);
  run("octomap_file_data", Syntax::kPlain, kOctreeWords, tree_inputs(good, "input.bt"),
      on_first_file(check_octree_file));
}

TEST_F(FuzzLoaders, OctoMapMessageData) {
  // The data of the project's trees as binaryMapToMsg would send it.
  std::vector<Seed> good;
  for (const auto& [name, tree] : project_trees()) {
    const auto data = maps::octree_to_binary_data(*tree);
    // Data and resolution in one seed, split again below.
    good.push_back({name + " data", std::string(data.begin(), data.end()) + "\n" +
                                        std::to_string(tree->getResolution())});
  }
  ASSERT_EQ(good.size(), 2u) << "the embedded scene config/scenes/geb079.bt did not load";
  auto all = std::make_shared<std::vector<std::string>>();
  for (const Seed& s : good) all->push_back(s.bytes.substr(0, s.bytes.rfind('\n')));
  run(
      "octomap_data", Syntax::kPlain, {},
      [good, all](Mutator& m) {
        const Seed& seed = good[m.below(good.size())];
        const size_t cut = seed.bytes.rfind('\n');
        Input in;
        in.log.push_back("seed " + seed.name);
        std::string data = seed.bytes.substr(0, cut);
        // Every occupancy tree sends the same bit stream; the id names the type.
        std::string res = seed.bytes.substr(cut + 1);
        std::string id =
            std::vector<std::string>{"OcTree", "ColorOcTree", "OcTreeStamped"}[m.below(3)];
        const uint64_t which = m.below(10);
        if (which < 8) data = m.mutate(data, *all, &in.log);
        if (which >= 7) {  // resolution and id: boundary values and near misses
          res = Mutator::interesting_numbers()[m.below(Mutator::interesting_numbers().size())];
          in.log.push_back("resolution := " + res);
        }
        if (which == 9) {
          id = std::vector<std::string>{
              "OcTree", "ColorOcTree", "OcTreeStamped", "CountingOcTree", "ocTree", "", "OcTree ",
              "1"}[m.below(8)];
          in.log.push_back("id := '" + id + "'");
        }
        in.files = {{"data.bin", data}, {"params.txt", res + "\n" + id + "\n"}};
        return in;
      },
      [](const fs::path& dir, const Input&) { return check_octree_data(dir); });
}

// ---------------------------------------------------------------------------------------------
// Run records

// Records as the recorder writes them: a real VNS-BA* run on the rooms fixture (debug data and
// all), a run that failed, and one that never got a status.
std::vector<records::RunRecord> record_seeds() {
  std::vector<records::RunRecord> out;
  auto grid = maps::load_movingai_map(fixture("maps/rooms_32.map").string());
  if (!grid) return out;
  grid->resolution = 0.25;
  grid->origin_x = -2.0;
  grid->origin_y = 1.5;
  auto map = core::GridMap::build(*grid);
  if (!map) return out;
  auto shared = std::make_shared<const core::GridMap>(std::move(map).value());
  core::PlannerOptions options = core::default_options(core::PlannerKind::kVnsBaStar);
  options.record_expansions = true;
  std::vector<core::Cell> free;
  for (int32_t y = 0; y < grid->height; ++y)
    for (int32_t x = 0; x < grid->width; ++x)
      if (grid->at(x, y) == 0) free.push_back({x, y});
  if (free.size() < 2) return out;
  // Across the lower left room, around its block: a real run whose record stays a few KB (the
  // JSON reader costs about 1 ms per KB under ASan).
  const core::Cell start = free.front(), goal{13, 5};
  if (grid->at(goal.x, goal.y) != 0) return out;
  const core::PlanResult r = core::plan_once(shared, {start, goal}, options);

  records::MapReference ref;
  ref.file = "maps/rooms.yaml";
  ref.frame_id = "map";
  ref.stamp_sec = 1700000000;
  ref.stamp_nanosec = 250000000;
  ref.width = grid->width;
  ref.height = grid->height;
  ref.resolution = grid->resolution;
  ref.origin_x = grid->origin_x;
  ref.origin_y = grid->origin_y;
  ref.robot_radius = 0.1;
  auto to_world = [&](const core::Cell& c) {
    return core::grid_to_world(core::cell_centre(c), grid->origin_x, grid->origin_y,
                               grid->resolution);
  };

  records::RunRecord run;
  run.request_id = "send_goal-4182-1795331597879";
  run.request = records::RequestRecord{"plan_request", "", to_world(start), to_world(goal)};
  records::StatusRecord st;
  st.code = static_cast<int>(r.status.code);
  st.code_name = std::string(core::to_string(r.status.code));
  st.message = r.status.message;
  st.planner = "vns_bastar";
  st.metrics = r.metrics;
  st.map_stamp_sec = ref.stamp_sec;
  st.map_stamp_nanosec = ref.stamp_nanosec;
  run.status = st;
  run.path = r.world_path;
  records::DebugRecord d;
  d.planner = "vns_bastar";
  d.width = grid->width;
  d.height = grid->height;
  d.resolution = grid->resolution;
  d.origin_x = grid->origin_x;
  d.origin_y = grid->origin_y;
  d.expanded_forward = r.expanded_forward;
  d.expanded_backward = r.expanded_backward;
  d.meeting_cell = r.meeting_cell;
  d.raw_path = r.raw_path;
  for (const auto& p : r.waypoints) {
    d.pruned_waypoints.push_back(
        core::grid_to_world(p, grid->origin_x, grid->origin_y, grid->resolution));
  }
  run.debug = d;
  run.map = ref;
  out.push_back(run);

  records::RunRecord failed = run;
  failed.request_id = "into wall/2";
  failed.status->code = static_cast<int>(core::StatusCode::kGoalOccupied);
  failed.status->code_name = "GOAL_OCCUPIED";
  failed.status->message = "goal (31, 0) is occupied";
  failed.status->metrics = core::Metrics{};
  failed.path.clear();
  failed.debug.reset();
  out.push_back(failed);

  records::RunRecord no_status;
  no_status.request_id = "lost";
  no_status.request =
      records::RequestRecord{"goal_pose", "astar", Eigen::Vector2d(1, 2), std::nullopt};
  out.push_back(no_status);
  return out;
}

const std::vector<std::string> kJsonWords = {
    "null",           "true",       "false",     "[]",      "{}",       "\"\"",  "[1]",
    "\"request_id\"", "\"status\"", "\"debug\"", "\"map\"", "\"path\"", "1e999", "-1"};

std::vector<Seed> record_json_seeds() {
  std::vector<Seed> out;
  int i = 0;
  for (const auto& r : record_seeds()) {
    // Both layouts the recorder might produce: compact and indented.
    out.push_back({"record " + std::to_string(i), records::to_json(r).dump()});
    out.push_back({"record " + std::to_string(i++) + " indented", records::to_json(r).dump(2)});
  }
  return out;
}

TEST_F(FuzzLoaders, RunRecordJson) {
  const auto good = record_json_seeds();
  ASSERT_EQ(good.size(), 6u);
  expect_seeds(good, {}, dir_, "input.json", check_record_json);
  run("run_record_json", Syntax::kJson, kJsonWords, single_file(good, "input.json"),
      on_first_file(check_record_json));
}

TEST_F(FuzzLoaders, RunRecordFile) {
  const auto good = record_json_seeds();
  ASSERT_EQ(good.size(), 6u);
  // The map the records reference, as the recorder saves it (maps/rooms.yaml + .pgm), beside
  // every input unchanged (the map_server test fuzzes such files) so a saved input replays.
  auto grid = maps::load_movingai_map(fixture("maps/rooms_32.map").string());
  ASSERT_TRUE(grid);
  grid->resolution = 0.25;
  grid->origin_x = -2.0;
  grid->origin_y = 1.5;
  fs::create_directories(dir_ / "maps");
  const auto yaml = maps::save_map_server(*grid, (dir_ / "maps" / "rooms").string());
  ASSERT_TRUE(yaml) << yaml.error().message;
  const std::vector<std::pair<std::string, std::string>> map_files = {
      {"maps/rooms.yaml", read_bytes(dir_ / "maps" / "rooms.yaml")},
      {"maps/rooms.pgm", read_bytes(dir_ / "maps" / "rooms.pgm")}};
  expect_seeds(good, {}, dir_, "input.json", check_record_file);
  const MakeInput record = single_file(good, "input.json");
  run(
      "run_record_file", Syntax::kJson, kJsonWords,
      [record, map_files](Mutator& m) {
        Input in = record(m);
        in.files.insert(in.files.end(), map_files.begin(), map_files.end());
        return in;
      },
      on_first_file(check_record_file));
}

// ---------------------------------------------------------------------------------------------
// Config

TEST_F(FuzzLoaders, Config) {
  std::vector<fs::path> good_files = {config_dir() / "default.yaml"};
  for (const char* f : {"custom.yaml", "empty.yaml", "comments_only.yaml"}) {
    good_files.push_back(fixture(std::string("config/") + f));
  }
  std::vector<fs::path> bad_files;
  for (const fs::path& f : files_in(fixture("config"), ".yaml")) {
    if (std::find(good_files.begin(), good_files.end(), f) == good_files.end()) {
      bad_files.push_back(f);
    }
  }
  const auto good = seeds_from(good_files), bad = seeds_from(bad_files);
  ASSERT_GE(bad.size(), 5u);
  expect_seeds(good, bad, dir_, "input.yaml", check_config);
  const std::vector<std::string> words = {"domain_id",
                                          "topics",
                                          "map",
                                          "planner",
                                          "requests",
                                          "debug",
                                          "slicer",
                                          "name",
                                          "omega",
                                          "true",
                                          "no",
                                          "~",
                                          "null",
                                          "!!str",
                                          "&a",
                                          "*a",
                                          "<<",
                                          "---",
                                          "...",
                                          "- ",
                                          "? ",
                                          "|",
                                          ">",
                                          "%YAML 1.2",
                                          "\t",
                                          "vns_bastar",
                                          "8-11-13",
                                          "always",
                                          "jps",
                                          "cost_weight",
                                          "inflation_radius",
                                          "goal_tolerance",
                                          "path_spacing",
                                          "1e309"};
  run("config", Syntax::kYaml, words, single_file(good, "input.yaml", bad),
      on_first_file(check_config));
}

// ---------------------------------------------------------------------------------------------
// The mutator itself

TEST(FuzzMutator, SameSeedSameInputDifferentSeedDifferentInput) {
  const std::string base = "type octile\nheight 4\nwidth 6\nmap\n@.....\n.T..W.\n..O...\nS....G\n";
  const std::vector<std::string> seeds = {base, "version 1\n0\ttiny.map\t6\t4\t0\t3\t5\t3\t5.0\n"};
  std::set<std::string> distinct;
  for (uint64_t i = 0; i < 200; ++i) {
    Mutator a(input_seed(1, "x", i), Syntax::kYaml), b(input_seed(1, "x", i), Syntax::kYaml);
    std::vector<std::string> log_a, log_b;
    const std::string ma = a.mutate(base, seeds, &log_a);
    EXPECT_EQ(ma, b.mutate(base, seeds, &log_b)) << "iteration " << i;
    EXPECT_EQ(log_a, log_b);
    distinct.insert(ma);
  }
  // Most inputs differ from each other (a few mutations, e.g. a truncation at the end, repeat).
  EXPECT_GT(distinct.size(), 150u);
  EXPECT_NE(input_seed(1, "x", 0), input_seed(2, "x", 0));
  EXPECT_NE(input_seed(1, "x", 0), input_seed(1, "y", 0));
}

// Every kind of mutation the header promises is drawn (the log names each).
TEST(FuzzMutator, EveryMutationKindHappens) {
  const std::string base = "a: 1\nb: [2, 3.5]\nc: {d: -4}\n";
  std::set<std::string> kinds;
  size_t longest = 0;
  for (uint64_t i = 0; i < 3000; ++i) {
    Mutator m(input_seed(7, "kinds", i), Syntax::kYaml);
    std::vector<std::string> log;
    longest = std::max(longest, m.mutate(base, {base, "x: y\n"}, &log).size());
    for (const std::string& line : log) kinds.insert(line.substr(0, line.find_first_of(" :")));
  }
  for (const char* kind : {"flip", "byte", "insert", "delete", "copy", "truncate", "splice",
                           "number", "word", "repeat", "swap", "all", "one", "nesting"}) {
    EXPECT_EQ(kinds.count(kind), 1u) << kind;
  }
  EXPECT_GT(longest, 100000u);  // the deepest nesting and the long runs were drawn
  EXPECT_LE(longest, Mutator::kMaxSize + base.size() + 16);
}

// ---------------------------------------------------------------------------------------------
// Regression inputs: every folder under tests/fixtures/fuzz/<loader>/ is an input that once
// failed (as the driver above saves it), replayed with the same checks. A loader without such a
// folder yet is skipped.

struct Replay {
  const char* folder;
  std::function<Outcome(const fs::path&)> check;  // given the input's folder
};

const std::vector<Replay>& replays() {
  static const std::vector<Replay> table = {
      {"movingai_map", [](const fs::path& d) { return check_movingai_map(d / "input.map"); }},
      {"movingai_scen",
       [](const fs::path& d) { return check_movingai_scenarios(d / "input.scen"); }},
      {"map_server", [](const fs::path& d) { return check_map_server(d / "input.yaml"); }},
      {"octomap_file", [](const fs::path& d) { return check_octree_file(d / "input.bt"); }},
      {"octomap_data", [](const fs::path& d) { return check_octree_data(d); }},
      {"run_record_json", [](const fs::path& d) { return check_record_json(d / "input.json"); }},
      {"run_record_file", [](const fs::path& d) { return check_record_file(d / "input.json"); }},
      {"config", [](const fs::path& d) { return check_config(d / "input.yaml"); }},
  };
  return table;
}

class FuzzRegression : public ::testing::TestWithParam<size_t> {};

TEST_P(FuzzRegression, ReplaysSavedInputs) {
  const Replay& r = replays()[GetParam()];
  const fs::path root = fixture("fuzz") / r.folder;
  if (!fs::is_directory(root)) GTEST_SKIP() << "no regression inputs under " << root;
  std::vector<fs::path> cases;
  for (const auto& e : fs::directory_iterator(root)) {
    if (e.is_directory()) cases.push_back(e.path());
  }
  std::sort(cases.begin(), cases.end());
  ASSERT_FALSE(cases.empty()) << root << " holds no input folder";
  for (const fs::path& c : cases) {
    for (const std::string& p : r.check(c).problems) {
      ADD_FAILURE() << r.folder << "/" << c.filename().string() << ": " << p;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Loaders, FuzzRegression, ::testing::Range<size_t>(0, replays().size()),
                         [](const ::testing::TestParamInfo<size_t>& info) {
                           return std::string(replays()[info.param].folder);
                         });

// The map_io.cpp fixes behind the regression inputs above, with the values they must give.

TEST(MapIoFuzzFixes, OptimumInExponentFormIsPrintedToItsExponent) {
  const auto s = maps::load_movingai_scenarios(
      (fixture("fuzz") / "movingai_scen" / "optimum_exponent" / "input.scen").string());
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_EQ(s->size(), 2u);
  EXPECT_EQ((*s)[0].optimal_length, 1500.0);
  EXPECT_DOUBLE_EQ((*s)[0].optimal_resolution, 100.0);  // "1.5e+3": the hundreds
  EXPECT_EQ((*s)[1].optimal_length, 0.25);
  EXPECT_DOUBLE_EQ((*s)[1].optimal_resolution, 0.01);  // "25e-2": the hundredths
}

TEST(MapIoFuzzFixes, OptimumPrintedBeyondADoublesPrecisionIsRefused) {
  const fs::path file = fixture("fuzz") / "movingai_scen" / "optimum_400_decimals" / "input.scen";
  const auto s = maps::load_movingai_scenarios(file.string());
  ASSERT_FALSE(s) << "loaded with optimal_resolution " << (*s)[0].optimal_resolution;
  EXPECT_TRUE(contains(s.error().message, file.string() + ":2: optimal length '5.000"))
      << s.error().message;
  EXPECT_TRUE(contains(s.error().message, "precision")) << s.error().message;
}

TEST(MapIoFuzzFixes, PgmMagicMustBeTheFirstTwoBytes) {
  const fs::path dir = fixture("fuzz") / "map_server" / "p5_comment_before_magic";
  const auto grid = maps::load_map_server((dir / "input.yaml").string());
  ASSERT_FALSE(grid) << "loaded a PGM whose first line is a comment";
  EXPECT_TRUE(contains(grid.error().message,
                       (dir / "p5_8bit.pgm").string() + ": not a PGM image (its first two bytes"))
      << grid.error().message;
}

TEST(MapIoFuzzFixes, P5CommentAfterMaxvalEndsTheHeader) {
  const fs::path dir = fixture("fuzz") / "map_server" / "p5_comment_after_maxval";
  const auto grid = maps::load_map_server((dir / "input.yaml").string());
  ASSERT_TRUE(grid) << grid.error().message;
  ASSERT_EQ(grid->width, 4);
  ASSERT_EQ(grid->height, 3);
  // The raster's first row (0 254 205 0) is the grid's top row: occupied, free, unknown, occupied.
  EXPECT_EQ(grid->at(0, 2), 100);
  EXPECT_EQ(grid->at(1, 2), 0);
  EXPECT_EQ(grid->at(2, 2), -1);
  EXPECT_EQ(grid->at(3, 2), 100);
  // Its last row (205 0 254 80): unknown, occupied, free, occupied (p = 175/255 > 0.65).
  EXPECT_EQ(grid->at(0, 0), -1);
  EXPECT_EQ(grid->at(1, 0), 100);
  EXPECT_EQ(grid->at(2, 0), 0);
  EXPECT_EQ(grid->at(3, 0), 100);
}

}  // namespace
}  // namespace vnsba::fuzz
