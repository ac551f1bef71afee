// Map files: Moving AI .map/.scen readers and the ROS map_server .yaml + .pgm reader and writer.
//
// The readers never throw on bad input: every problem comes back as kInvalidMap with
// "<file>:<line>: <problem>" (no line when the problem has none, e.g. a missing key). Memory is
// bounded by the file size: map rows are checked before the grid is allocated, and a PGM header
// cannot claim more pixels than the file holds, so a corrupt header cannot force a huge
// allocation.
#include "vnsba/maps/map_io.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <locale>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>
#include <system_error>

#include "vnsba/yaml/document.hpp"

namespace vnsba::maps {
// The core types this file reads and writes.
using namespace core;  // NOLINT(google-build-using-namespace)
namespace {

constexpr int64_t kMaxSide = 100000;  // cells (or pixels) per side; larger headers are corrupt

// kInvalidMap with "<file>:<line>: <parts...>" (no line when 0). Parts: strings and integers.
template <class... Parts>
Status invalid(const std::string& file, int line, const Parts&... parts) {
  std::ostringstream message;
  message.imbue(std::locale::classic());  // no digit grouping in line numbers
  message << file;
  if (line > 0) message << ':' << line;
  message << ": ";
  (message << ... << parts);
  return Status::error(StatusCode::kInvalidMap, message.str());
}

// A token for an error message: quoted, and cut short so a garbage line cannot flood the log.
std::string quote(std::string_view token) {
  constexpr size_t kMaxShown = 40;
  if (token.size() <= kMaxShown) return "'" + std::string(token) + "'";
  return "'" + std::string(token.substr(0, kMaxShown)) + "...'";
}

// Shortest text that parses back to exactly `value` (locale-independent).
std::string format_double(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::optional<std::string> read_file(const std::string& path) {
  std::error_code ec;  // a folder would "open" on Linux but is not a map file
  if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return std::nullopt;
  return text;
}

Status write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return invalid(path, 0, "cannot open file for writing");
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) return invalid(path, 0, "write failed");
  return Status::ok();
}

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// Lines without their terminator ("\n" or "\r\n"); a final newline does not start another line.
std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  for (size_t begin = 0; begin < text.size();) {
    size_t end = text.find('\n', begin);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(begin, end - begin);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    begin = end + 1;
  }
  return lines;
}

std::vector<std::string_view> split_whitespace(std::string_view s) {
  std::vector<std::string_view> tokens;
  for (size_t i = 0; i < s.size();) {
    while (i < s.size() && is_space(s[i])) ++i;
    const size_t begin = i;
    while (i < s.size() && !is_space(s[i])) ++i;
    if (i > begin) tokens.push_back(s.substr(begin, i - begin));
  }
  return tokens;
}

// Whole-token, locale-independent parses; false on an empty token, trailing junk or overflow.
template <class Number>
bool parse_number(std::string_view s, Number* out) {
  if (s.size() > 1 && s[0] == '+' && s[1] != '-') s.remove_prefix(1);  // YAML allows "+1.5"
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
  return !s.empty() && ec == std::errc() && end == s.data() + s.size();
}

// Header line `index` (0-based) of a .map file: "<keyword> <cells>".
Status read_map_side(const std::string& path, const std::vector<std::string_view>& lines,
                     size_t index, std::string_view keyword, int32_t* cells) {
  const int line = static_cast<int>(index) + 1;
  const auto tokens = split_whitespace(index < lines.size() ? lines[index] : "");
  if (tokens.size() != 2 || tokens[0] != keyword) {
    return invalid(path, line, "expected '", keyword, " <cells>'");
  }
  int64_t value = 0;
  if (!parse_number(tokens[1], &value)) {
    return invalid(path, line, keyword, " ", quote(tokens[1]), " is not an integer");
  }
  if (value <= 0 || value > kMaxSide) {
    return invalid(path, line, keyword, " ", value, " is outside 1..", kMaxSide);
  }
  *cells = static_cast<int32_t>(value);
  return Status::ok();
}

// Moving AI terrain: ground '.', 'G' and swamp 'S' are passable; out of bounds '@' 'O', trees
// 'T' and water 'W' are not.
std::optional<int8_t> movingai_occupancy(char c) {
  if (std::string_view(".GS").find(c) != std::string_view::npos) return kOccupancyFree;
  if (std::string_view("@OTW").find(c) != std::string_view::npos) return kOccupancyOccupied;
  return std::nullopt;
}

enum class PgmMode { kTrinary, kScale, kRaw };

struct MapServerParams {
  std::string image_path;  // resolved against the YAML's folder
  double resolution = 0.0;
  double origin_x = 0.0;
  double origin_y = 0.0;
  bool negate = false;
  double occupied_thresh = 0.65;  // map_saver's values; optional in the YAML
  double free_thresh = 0.196;
  PgmMode mode = PgmMode::kTrinary;
};

// ROS 2 map_server's (Nav2's map_io.cpp) conversion of one grey sample (0..maxval, maxval =
// white) to occupancy: what the node receives when the map is published, so vnsba_plan reads
// the file as the node plans on it. Raw mode ignores `negate`, and reads the shade on 0..255
// (the sample itself in an 8-bit image).
int8_t pgm_occupancy(uint32_t sample, uint32_t maxval, const MapServerParams& params) {
  if (params.mode == PgmMode::kRaw) {
    const double value = std::round(static_cast<double>(sample) / maxval * 255.0);
    return value <= 100 ? static_cast<int8_t>(value) : kOccupancyUnknown;
  }
  const double occupied = params.negate ? static_cast<double>(sample) / maxval
                                        : static_cast<double>(maxval - sample) / maxval;
  if (occupied > params.occupied_thresh) return kOccupancyOccupied;
  if (occupied < params.free_thresh) return kOccupancyFree;
  if (params.mode == PgmMode::kTrinary) return kOccupancyUnknown;
  const double ratio =
      (occupied - params.free_thresh) / (params.occupied_thresh - params.free_thresh);
  return static_cast<int8_t>(std::rint(ratio * 100.0));  // Nav2: 0..100, ties to even
}

// Next whitespace-separated PGM token, skipping '#' comments (to the end of the line); empty at
// the end of the text.
std::string_view next_pgm_token(std::string_view text, size_t* pos) {
  while (*pos < text.size() && (is_space(text[*pos]) || text[*pos] == '#')) {
    *pos = text[*pos] == '#' ? std::min(text.find('\n', *pos), text.size()) : *pos + 1;
  }
  const size_t begin = *pos;
  while (*pos < text.size() && !is_space(text[*pos]) && text[*pos] != '#') ++*pos;
  return text.substr(begin, *pos - begin);
}

// Reads a P2 or P5 PGM (maxval 1..65535; 16-bit P5 samples are big-endian) and converts it,
// flipping rows so that the image's bottom row becomes row 0.
Status read_pgm(const MapServerParams& params, OccupancyGrid* grid) {
  const std::string& path = params.image_path;
  const std::optional<std::string> text = read_file(path);
  if (!text) return invalid(path, 0, "cannot open image file");
  size_t pos = 0;
  // The magic number is the file's first two bytes (Netpbm, and the image readers map_server
  // uses, look there and nowhere else), followed by whitespace or a comment.
  const std::string_view magic = next_pgm_token(*text, &pos);
  if ((magic != "P5" && magic != "P2") || pos != 2) {
    return invalid(path, 0, "not a PGM image (its first two bytes must be P5 or P2)");
  }
  int64_t header[3] = {0, 0, 0};  // width, height, maxval
  const char* const kFields[3] = {"width", "height", "maxval"};
  const int64_t kLimits[3] = {kMaxSide, kMaxSide, 65535};
  for (int i = 0; i < 3; ++i) {
    const std::string_view token = next_pgm_token(*text, &pos);
    if (!parse_number(token, &header[i]) || header[i] < 1 || header[i] > kLimits[i]) {
      return invalid(path, 0, "PGM ", kFields[i], " ", quote(token), " is not in 1..", kLimits[i]);
    }
  }
  const int64_t pixel_count = header[0] * header[1];
  const auto maxval = static_cast<uint32_t>(header[2]);
  std::vector<uint32_t> samples;  // top row first, as stored
  if (magic == "P5") {
    const int64_t bytes_per_sample = maxval > 255 ? 2 : 1;
    // Exactly one whitespace byte separates maxval from the binary samples; a comment right
    // after maxval takes its place up to and including its newline, as libnetpbm reads it
    // (reading its '#' as that byte would shift every sample by the comment's length).
    size_t data_begin = std::min(pos + 1, text->size());
    if (pos < text->size() && (*text)[pos] == '#') {
      const size_t newline = text->find('\n', pos);
      data_begin = newline == std::string::npos ? text->size() : newline + 1;
    }
    const auto available = static_cast<int64_t>(text->size() - data_begin);
    if (available < pixel_count * bytes_per_sample) {
      return invalid(path, 0, "pixel data truncated: expected ", pixel_count * bytes_per_sample,
                     " bytes, found ", available);
    }
    const auto* bytes = reinterpret_cast<const unsigned char*>(text->data() + data_begin);
    samples.resize(static_cast<size_t>(pixel_count));
    for (size_t i = 0; i < samples.size(); ++i) {
      samples[i] = bytes_per_sample == 1 ? bytes[i] : (bytes[2 * i] << 8u) | bytes[2 * i + 1];
    }
  } else {
    // Every ASCII sample takes at least one byte, so the allocation is bounded by the file.
    samples.resize(static_cast<size_t>(std::min<int64_t>(pixel_count, text->size())));
    for (size_t i = 0; i < static_cast<size_t>(pixel_count); ++i) {
      const std::string_view token = next_pgm_token(*text, &pos);
      if (token.empty() || i >= samples.size()) {
        return invalid(path, 0, "pixel data truncated: found ", i, " of ", pixel_count, " samples");
      }
      if (!parse_number(token, &samples[i])) {
        return invalid(path, 0, "sample ", i, " ", quote(token), " is not an unsigned integer");
      }
    }
  }
  for (size_t i = 0; i < samples.size(); ++i) {
    if (samples[i] > maxval) {
      return invalid(path, 0, "sample ", i, " value ", samples[i], " exceeds maxval ", maxval);
    }
  }
  grid->width = static_cast<int32_t>(header[0]);
  grid->height = static_cast<int32_t>(header[1]);
  grid->data.resize(samples.size());
  for (int32_t row = 0; row < grid->height; ++row) {
    const size_t source = static_cast<size_t>(row) * grid->width;
    const size_t target = static_cast<size_t>(grid->height - 1 - row) * grid->width;
    for (int32_t x = 0; x < grid->width; ++x) {
      grid->data[target + x] = pgm_occupancy(samples[source + x], maxval, params);
    }
  }
  return Status::ok();
}

// The map_server YAML: a map of keys, read through yaml-cpp (vnsba/yaml/document.hpp). Each key
// with its value and its 1-based line. Keys map_server does not know are ignored.
struct YamlEntry {
  YAML::Node value;
  int line = 0;
};
using YamlEntries = std::map<std::string, YamlEntry, std::less<>>;

Status read_yaml_entries(const std::string& path, const std::string& text, YamlEntries* entries) {
  const yaml::Document doc = yaml::load_document(text);
  if (doc.problem) {
    const yaml::Problem& p = *doc.problem;
    const std::string column = p.column > 0 ? " at column " + std::to_string(p.column) : "";
    switch (p.kind) {
      case yaml::Problem::Kind::kSyntax:
        return invalid(path, p.line, "YAML syntax error", column, ": ", p.message);
      case yaml::Problem::Kind::kNesting:
        return invalid(path, p.line, column.empty() ? "" : column.substr(1) + ", ", p.message);
      case yaml::Problem::Kind::kDocuments:
        return invalid(path, p.line, p.message);
      default:
        return invalid(path, p.line, "cannot read the YAML: ", p.message);
    }
  }
  if (doc.root.IsNull()) return Status::ok();  // an empty file: the required keys are missing
  if (!doc.root.IsMap()) {
    return invalid(path, yaml::line_of(doc.root), "found ", yaml::kind_of(doc.root),
                   " at the top level, expected a map of keys (image, resolution, origin, ...)");
  }
  for (const auto& item : doc.root) {
    const YAML::Node& key = item.first;
    const int line = yaml::line_of(key);
    if (!key.IsScalar()) {
      return invalid(path, line, "found ", yaml::kind_of(key), " as a key, expected a key name");
    }
    // yaml-cpp reads a line without ':' in a block map as a key without a value, placed at the
    // key itself (after "key:" or in "{key}" the null value is placed after the key).
    if (item.second.IsNull() && item.second.Mark().pos == key.Mark().pos) {
      return invalid(path, line, "expected 'key: value', found ", quote(key.Scalar()));
    }
    if (!entries->emplace(key.Scalar(), YamlEntry{item.second, line}).second) {
      return invalid(path, line, "duplicate key ", quote(key.Scalar()));
    }
  }
  return Status::ok();
}

// The text of a scalar value; an error naming the key when the value is a list, a map or absent
// (`key:` with nothing after it, or YAML's null). `expected` says what the key takes.
Status yaml_text(const std::string& path, std::string_view key, const YamlEntry& entry,
                 std::string_view expected, std::string* out) {
  if (entry.value.IsNull()) {
    return invalid(path, entry.line, key, " has no value, expected ", expected);
  }
  if (!entry.value.IsScalar()) {
    return invalid(path, entry.line, key, " is ", yaml::kind_of(entry.value), ", expected ",
                   expected);
  }
  *out = entry.value.Scalar();
  return Status::ok();
}

// How a value is shown in a message: a text quoted, a list with its first items ("[1, 2]").
std::string shown(const YAML::Node& node) {
  if (node.IsScalar()) return quote(node.Scalar());
  if (!node.IsSequence()) return "(" + std::string(yaml::kind_of(node)) + ")";
  constexpr size_t kMaxShown = 4;
  std::string out = "[";
  size_t i = 0;
  for (const YAML::Node& item : node) {
    if (i > 0) out += ", ";
    if (i++ == kMaxShown) return out + "...]";
    out += item.IsScalar() ? quote(item.Scalar()) : yaml::kind_of(item);
  }
  return out + "]";
}

}  // namespace

Expected<OccupancyGrid> load_movingai_map(const std::string& path) {
  const std::optional<std::string> text = read_file(path);
  if (!text) return invalid(path, 0, "cannot open file");
  const std::vector<std::string_view> lines = split_lines(*text);
  if (split_whitespace(lines.empty() ? "" : lines[0]) !=
      std::vector<std::string_view>{"type", "octile"}) {
    return invalid(path, 1, "expected 'type octile'");
  }
  OccupancyGrid grid;
  if (Status s = read_map_side(path, lines, 1, "height", &grid.height); !s.is_ok()) return s;
  if (Status s = read_map_side(path, lines, 2, "width", &grid.width); !s.is_ok()) return s;
  if (lines.size() < 4 || trim(lines[3]) != "map") return invalid(path, 4, "expected 'map'");

  constexpr size_t kFirstRow = 4;  // index of the file's top map row
  const auto height = static_cast<size_t>(grid.height);
  const auto width = static_cast<size_t>(grid.width);
  if (lines.size() - kFirstRow < height) {
    return invalid(path, static_cast<int>(lines.size()), "file ends after ",
                   lines.size() - kFirstRow, " rows, expected ", height, " (height)");
  }
  // Row lengths first, so that the allocation below is bounded by the file size.
  for (size_t row = 0; row < height; ++row) {
    if (lines[kFirstRow + row].size() != width) {
      return invalid(path, static_cast<int>(kFirstRow + row + 1), "row has ",
                     lines[kFirstRow + row].size(), " cells, expected ", width, " (width)");
    }
  }
  // Blank lines after the last row are tolerated; anything else there is an extra row.
  for (size_t i = kFirstRow + height; i < lines.size(); ++i) {
    if (!trim(lines[i]).empty()) {
      return invalid(path, static_cast<int>(i + 1), "extra row after ", height, " rows (height)");
    }
  }
  grid.data.resize(width * height);
  for (size_t row = 0; row < height; ++row) {
    const std::string_view cells = lines[kFirstRow + row];
    for (size_t x = 0; x < width; ++x) {
      const std::optional<int8_t> value = movingai_occupancy(cells[x]);
      if (!value) {
        const auto byte = static_cast<unsigned char>(cells[x]);
        return invalid(path, static_cast<int>(kFirstRow + row + 1), "unexpected character ",
                       byte >= 0x20 && byte < 0x7f ? quote(cells.substr(x, 1))
                                                   : "byte " + std::to_string(byte),
                       " at x = ", x, " (expected one of . G S @ O T W)");
      }
      grid.data[(height - 1 - row) * width + x] = *value;  // the top line is row height-1
    }
  }
  return grid;
}

Expected<std::vector<MovingAiScenario>> load_movingai_scenarios(const std::string& path) {
  const std::optional<std::string> text = read_file(path);
  if (!text) return invalid(path, 0, "cannot open file");
  const std::vector<std::string_view> lines = split_lines(*text);
  const auto header = split_whitespace(lines.empty() ? "" : lines[0]);
  if (header.size() != 2 || header[0] != "version" || (header[1] != "1" && header[1] != "1.0")) {
    return invalid(path, 1, "expected 'version 1' or 'version 1.0'");
  }
  static const char* const kColumns[9] = {"bucket",     "map",     "map width",
                                          "map height", "start x", "start y",
                                          "goal x",     "goal y",  "optimal length"};
  std::vector<MovingAiScenario> scenarios;
  for (size_t i = 1; i < lines.size(); ++i) {
    const int line = static_cast<int>(i + 1);
    const std::vector<std::string_view> columns = split_whitespace(lines[i]);
    if (columns.empty()) continue;
    if (columns.size() != 9) {
      return invalid(path, line, "expected 9 columns (bucket, map, map width, map height, ",
                     "start x, start y, goal x, goal y, optimal length), found ", columns.size());
    }
    int32_t ints[8] = {};  // the integer columns 0 and 2..7, indexed by column (1 unused)
    for (int c : {0, 2, 3, 4, 5, 6, 7}) {
      if (!parse_number(columns[c], &ints[c])) {
        return invalid(path, line, kColumns[c], " ", quote(columns[c]), " is not an integer");
      }
    }
    for (int c : {2, 3}) {
      if (ints[c] < 1 || ints[c] > kMaxSide) {
        return invalid(path, line, kColumns[c], " ", ints[c], " is outside 1..", kMaxSide);
      }
    }
    for (int c : {4, 5, 6, 7}) {
      const int limit_column = c % 2 == 0 ? 2 : 3;  // x against the width, y the height
      if (ints[c] < 0 || ints[c] >= ints[limit_column]) {
        return invalid(path, line, kColumns[c], " ", ints[c], " is outside the map (",
                       kColumns[limit_column], " ", ints[limit_column], ")");
      }
    }
    MovingAiScenario scenario;
    double& length = scenario.optimal_length;
    if (!parse_number(columns[8], &length) || !std::isfinite(length) || length < 0.0) {
      return invalid(path, line, "optimal length ", quote(columns[8]),
                     " is not a finite non-negative number");
    }
    // One unit of the last printed digit: 10^-(digits after the point), shifted by the exponent
    // of an exponent form ("1.5e+3" is printed to the hundreds, "25e-2" to the hundredths).
    const std::string_view mantissa = columns[8].substr(0, columns[8].find_first_of("eE"));
    const size_t point = mantissa.find('.');
    const size_t digits_after = point == std::string_view::npos ? 0 : mantissa.size() - point - 1;
    double unit = 0.0;  // stays 0 for an exponent beyond int64
    int64_t exponent = 0;
    if (mantissa.size() == columns[8].size() ||
        parse_number(columns[8].substr(mantissa.size() + 1), &exponent)) {
      unit = std::pow(10.0, static_cast<double>(exponent) - static_cast<double>(digits_after));
    }
    // Hundreds of decimals (a corrupt line) would give a unit of 0 or a subnormal: no tolerance
    // a comparison could use, so the line is refused rather than compared exactly.
    if (!std::isfinite(unit) || unit < std::numeric_limits<double>::min()) {
      return invalid(path, line, "optimal length ", quote(columns[8]),
                     " is printed to a precision no double can hold");
    }
    scenario.optimal_resolution = unit;
    scenario.bucket = ints[0];
    scenario.map_name = std::string(columns[1]);
    scenario.map_width = ints[2];
    scenario.map_height = ints[3];
    scenario.start = {ints[4], ints[3] - 1 - ints[5]};  // file y counts from the top line
    scenario.goal = {ints[6], ints[3] - 1 - ints[7]};
    scenario.line = line;
    scenarios.push_back(std::move(scenario));
  }
  return scenarios;
}

namespace {

Expected<OccupancyGrid> read_map_server(const std::string& yaml_path) {
  const std::optional<std::string> text = read_file(yaml_path);
  if (!text) return invalid(yaml_path, 0, "cannot open file");

  YamlEntries entries;
  if (Status s = read_yaml_entries(yaml_path, *text, &entries); !s.is_ok()) return s;
  for (const char* key : {"image", "resolution", "origin"}) {
    if (entries.count(key) == 0) return invalid(yaml_path, 0, "missing required key '", key, "'");
  }
  const auto line_of = [&](const char* key) {
    const auto it = entries.find(key);
    return it == entries.end() ? 0 : it->second.line;
  };
  // The text of an optional key (`out` keeps its default when absent); a list or a map is an
  // error.
  const auto text_of = [&](const char* key, std::string_view expected, std::string* out) {
    const auto it = entries.find(key);
    return it == entries.end() ? Status::ok()
                               : yaml_text(yaml_path, key, it->second, expected, out);
  };

  MapServerParams params;
  std::string image;
  if (Status s = text_of("image", "a file name", &image); !s.is_ok()) return s;
  const std::filesystem::path image_path(image);
  if (image_path.empty()) return invalid(yaml_path, line_of("image"), "image is empty");
  params.image_path = image_path.is_absolute()
                          ? image_path.string()
                          : (std::filesystem::path(yaml_path).parent_path() / image_path).string();

  // Optional numbers keep their defaults; present ones must be finite.
  for (const auto& [key, out] : {std::pair<const char*, double*>{"resolution", &params.resolution},
                                 {"occupied_thresh", &params.occupied_thresh},
                                 {"free_thresh", &params.free_thresh}}) {
    const auto it = entries.find(key);
    if (it == entries.end()) continue;
    std::string value;
    if (Status s = yaml_text(yaml_path, key, it->second, "a finite number", &value); !s.is_ok()) {
      return s;
    }
    if (!parse_number(value, out) || !std::isfinite(*out)) {
      return invalid(yaml_path, it->second.line, key, " ", quote(value), " is not a finite number");
    }
  }
  if (params.resolution <= 0.0) {
    return invalid(yaml_path, line_of("resolution"), "resolution ",
                   format_double(params.resolution), " is not positive (metres per cell)");
  }
  if (params.occupied_thresh <= 0.0 || params.occupied_thresh > 1.0) {
    return invalid(yaml_path, line_of("occupied_thresh"), "occupied_thresh ",
                   format_double(params.occupied_thresh), " is outside (0, 1]");
  }
  if (params.free_thresh < 0.0 || params.free_thresh >= params.occupied_thresh) {
    return invalid(yaml_path, line_of("free_thresh"), "free_thresh ",
                   format_double(params.free_thresh), " is outside [0, occupied_thresh)");
  }

  std::string negate = "0";
  if (Status s = text_of("negate", "0, 1, true or false", &negate); !s.is_ok()) return s;
  params.negate = negate == "1" || negate == "true" || negate == "True";
  if (!params.negate && negate != "0" && negate != "false" && negate != "False") {
    return invalid(yaml_path, line_of("negate"), "negate ", quote(negate),
                   " is not 0, 1, true or false");
  }
  std::string mode = "trinary";
  if (Status s = text_of("mode", "trinary, scale or raw", &mode); !s.is_ok()) return s;
  params.mode = mode == "scale" ? PgmMode::kScale
                : mode == "raw" ? PgmMode::kRaw
                                : PgmMode::kTrinary;
  if (params.mode == PgmMode::kTrinary && mode != "trinary") {
    return invalid(yaml_path, line_of("mode"), "mode ", quote(mode),
                   " is not trinary, scale or raw");
  }

  // origin: [x, y, yaw] in metres and radians, a flow ([x, y, yaw]) or block ("- x" lines) list.
  const YAML::Node& origin = entries.at("origin").value;
  double xyz[3] = {};
  bool numbers = origin.IsSequence() && origin.size() == 3;
  for (size_t i = 0; numbers && i < 3; ++i) {
    const YAML::Node item = origin[i];
    numbers = item.IsScalar() && parse_number(item.Scalar(), &xyz[i]) && std::isfinite(xyz[i]);
  }
  if (!numbers) {
    return invalid(yaml_path, line_of("origin"), "origin ", shown(origin),
                   " is not [x, y, yaw] with finite numbers");
  }
  if (xyz[2] != 0.0) {
    return invalid(yaml_path, line_of("origin"), "origin yaw ", format_double(xyz[2]),
                   " rad is not 0: only axis-aligned grids are supported");
  }
  params.origin_x = xyz[0];
  params.origin_y = xyz[1];

  OccupancyGrid grid;
  if (Status s = read_pgm(params, &grid); !s.is_ok()) {
    s.message += " (image of " + yaml_path + ")";
    return s;
  }
  grid.resolution = params.resolution;
  grid.origin_x = params.origin_x;
  grid.origin_y = params.origin_y;
  return grid;
}

}  // namespace

Expected<OccupancyGrid> load_map_server(const std::string& yaml_path) {
  try {
    return read_map_server(yaml_path);
  } catch (const YAML::Exception& e) {  // not expected past load_document: a safety net
    return invalid(yaml_path, yaml::line_of(e.mark), "cannot read the YAML: ", e.msg);
  }
}

Expected<std::string> save_map_server(const OccupancyGrid& grid, const std::string& stem,
                                      int occupied_threshold) {
  const int64_t cells = int64_t{grid.width} * grid.height;
  if (grid.width <= 0 || grid.height <= 0) {
    return invalid(stem, 0, "cannot save: width ", grid.width, " or height ", grid.height,
                   " is not positive");
  }
  if (static_cast<int64_t>(grid.data.size()) != cells) {
    return invalid(stem, 0, "cannot save: data has ", grid.data.size(),
                   " values, expected width * height = ", cells);
  }
  if (!std::isfinite(grid.resolution) || grid.resolution <= 0.0) {
    return invalid(stem, 0, "cannot save: resolution ", format_double(grid.resolution),
                   " is not finite and positive");
  }
  if (!std::isfinite(grid.origin_x) || !std::isfinite(grid.origin_y)) {
    return invalid(stem, 0, "cannot save: origin_x/origin_y is not finite");
  }
  if (occupied_threshold < 1 || occupied_threshold > 100) {
    return Status::error(
        StatusCode::kInvalidRequest,
        "occupied_threshold " + std::to_string(occupied_threshold) + " is outside 1..100");
  }
  const std::string pgm_path = stem + ".pgm";
  const std::string yaml_path = stem + ".yaml";

  // map_saver's trinary colours: occupied black 0, free (0..25 %) white 254, the rest grey 205.
  constexpr int kFreeMax = 25;
  std::string pgm =
      "P5\n" + std::to_string(grid.width) + " " + std::to_string(grid.height) + "\n255\n";
  for (int32_t row = 0; row < grid.height; ++row) {  // PGM rows run top to bottom
    for (int32_t x = 0; x < grid.width; ++x) {
      const int value = grid.at(x, grid.height - 1 - row);
      const bool occupied = classify_value(value, occupied_threshold, true) == CellLayer::kOccupied;
      pgm.push_back(static_cast<char>(occupied                            ? 0
                                      : (value >= 0 && value <= kFreeMax) ? 254
                                                                          : 205));
    }
  }
  // free_thresh 0.196 sits just below grey 205's p = 50/255 = 0.19608, so unknown reads back as
  // unknown and white 254 (p = 0.0039) as free; black (p = 1) is above occupied_thresh.
  const std::string yaml = "image: " + std::filesystem::path(pgm_path).filename().string() +
                           "\nmode: trinary\nresolution: " + format_double(grid.resolution) +
                           "\norigin: [" + format_double(grid.origin_x) + ", " +
                           format_double(grid.origin_y) +
                           ", 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  if (Status s = write_file(pgm_path, pgm); !s.is_ok()) return s;
  if (Status s = write_file(yaml_path, yaml); !s.is_ok()) return s;
  return yaml_path;
}

}  // namespace vnsba::maps
