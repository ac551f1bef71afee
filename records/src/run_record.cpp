#include "vnsba/records/run_record.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>

#include "vnsba/maps/map_io.hpp"

namespace vnsba::records {

using nlohmann::json;

namespace {

json number(double value) {
  return std::isfinite(value) ? json(value) : json(nullptr);
}

json point(const Eigen::Vector2d& p) {
  return json::array({number(p.x()), number(p.y())});
}

json cell(const core::Cell& c) {
  return json::array({c.x, c.y});
}

// The lists of a record that grow with the run (the path, the debug data's cells and waypoints):
// to_json puts them in the tree, write_json writes them element by element. `pointer` is where
// they go, `key` the last part of it.
struct BulkList {
  const char* pointer;
  const char* key;
  const std::vector<core::Cell>* cells = nullptr;
  const std::vector<Eigen::Vector2d>* points = nullptr;
  size_t size() const { return cells ? cells->size() : points->size(); }
  json element(size_t i) const { return cells ? cell((*cells)[i]) : point((*points)[i]); }
};

std::vector<BulkList> bulk_lists(const RunRecord& r) {
  std::vector<BulkList> lists = {{"/path", "path", nullptr, &r.path}};
  if (r.debug) {
    const DebugRecord& d = *r.debug;
    lists.push_back({"/debug/expanded_forward", "expanded_forward", &d.expanded_forward});
    lists.push_back({"/debug/expanded_backward", "expanded_backward", &d.expanded_backward});
    lists.push_back({"/debug/raw_path", "raw_path", &d.raw_path});
    lists.push_back({"/debug/pruned_waypoints", "pruned_waypoints", nullptr, &d.pruned_waypoints});
  }
  return lists;
}

// The clearance of a path: +inf (a map without obstacles) is the string "inf", NaN (no path) null.
json clearance(double value) {
  if (std::isinf(value) && value > 0) return json("inf");
  return number(value);
}

json optional_point(const std::optional<Eigen::Vector2d>& p) {
  return p ? point(*p) : json(nullptr);
}

// Reads typed values out of a JSON document; the first problem is kept with the key's path.
class Reader {
 public:
  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  // The geometry fields (a resolution, an origin coordinate, a radius) that were null, in the
  // order read: each reads as NaN, which no picture can be drawn with.
  const std::vector<std::string>& null_geometry() const { return null_geometry_; }

  // The member `key` of object `j` at `path`, or nullptr when absent or null.
  const json* member(const json& j, const std::string& key, const std::string& path) {
    if (!j.is_object()) {
      fail(path, "must be an object");
      return nullptr;
    }
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) return nullptr;
    return &*it;
  }
  const json* required(const json& j, const std::string& key, const std::string& path) {
    const json* m = member(j, key, path);
    if (m == nullptr && ok()) fail(join(path, key), "is missing");
    return m;
  }
  std::string string(const json& j, const std::string& key, const std::string& path) {
    const json* m = member(j, key, path);
    if (m == nullptr) return {};
    if (!m->is_string()) {
      fail(join(path, key), "must be a string");
      return {};
    }
    return m->get<std::string>();
  }
  // A number; null (a non-finite value when written) reads as NaN.
  double real(const json& j, const std::string& key, const std::string& path) {
    const json* m = member(j, key, path);
    if (m == nullptr) return std::numeric_limits<double>::quiet_NaN();
    if (!m->is_number()) {
      fail(join(path, key), "must be a number");
      return 0.0;
    }
    return m->get<double>();
  }
  // A number of the geometry a picture is drawn in: as real(), and a null is remembered by its
  // path (null_geometry()).
  double geometry(const json& j, const std::string& key, const std::string& path) {
    if (j.is_object() && j.contains(key) && j.at(key).is_null())
      null_geometry_.push_back(join(path, key));
    return real(j, key, path);
  }
  int64_t integer(const json& j, const std::string& key, const std::string& path, int64_t lo,
                  int64_t hi) {
    const json* m = member(j, key, path);
    if (m == nullptr) return 0;
    if (!m->is_number_integer()) {
      fail(join(path, key), "must be an integer");
      return 0;
    }
    const int64_t v = m->is_number_unsigned()
                          ? static_cast<int64_t>(std::min<uint64_t>(m->get<uint64_t>(), INT64_MAX))
                          : m->get<int64_t>();
    if (v < lo || v > hi) {
      fail(join(path, key), "is " + std::to_string(v) + ", must be in [" + std::to_string(lo) +
                                ", " + std::to_string(hi) + "]");
      return 0;
    }
    return v;
  }
  bool boolean(const json& j, const std::string& key, const std::string& path) {
    const json* m = member(j, key, path);
    if (m == nullptr) return false;
    if (!m->is_boolean()) {
      fail(join(path, key), "must be true or false");
      return false;
    }
    return m->get<bool>();
  }
  std::optional<Eigen::Vector2d> point(const json& j, const std::string& key,
                                       const std::string& path) {
    const json* m = member(j, key, path);
    if (m == nullptr) return std::nullopt;
    return point_value(*m, join(path, key));
  }
  std::optional<Eigen::Vector2d> point_value(const json& m, const std::string& path) {
    if (!m.is_array() || m.size() != 2 || !m[0].is_number() || !m[1].is_number()) {
      if (!(m.is_array() && m.size() == 2 && (m[0].is_null() || m[1].is_null())))
        fail(path, "must be [x, y] with two numbers");
      return std::nullopt;
    }
    return Eigen::Vector2d(m[0].get<double>(), m[1].get<double>());
  }
  // The origin of a grid, [x, y]; a null coordinate (written for a non-finite one) reads as NaN,
  // so that the geometry check refuses it rather than reading 0.
  std::optional<Eigen::Vector2d> origin(const json& j, const std::string& path) {
    const json* m = member(j, "origin", path);
    if (m == nullptr) return std::nullopt;
    auto number_or_null = [](const json& v) { return v.is_number() || v.is_null(); };
    if (!m->is_array() || m->size() != 2 || !number_or_null((*m)[0]) || !number_or_null((*m)[1])) {
      fail(join(path, "origin"), "must be [x, y] with two numbers");
      return std::nullopt;
    }
    auto coordinate = [&](size_t i) {
      const json& v = (*m)[i];
      if (!v.is_null()) return v.get<double>();
      null_geometry_.push_back(join(path, "origin") + "[" + std::to_string(i) + "]");
      return std::numeric_limits<double>::quiet_NaN();
    };
    return Eigen::Vector2d(coordinate(0), coordinate(1));
  }
  std::vector<Eigen::Vector2d> points(const json& j, const std::string& key,
                                      const std::string& path) {
    return array_of<Eigen::Vector2d>(
        j, key, path, "an array of [x, y]",
        [this](const json& e, const std::string& at) { return point_value(e, at); });
  }
  std::vector<core::Cell> cells(const json& j, const std::string& key, const std::string& path) {
    return array_of<core::Cell>(
        j, key, path, "an array of [x, y] cells",
        [this](const json& e, const std::string& at) { return cell_value(e, at); });
  }
  // The elements of an array member read by `element` (which reports its own errors); elements
  // it cannot read are left out.
  template <class T, class ReadElement>
  std::vector<T> array_of(const json& j, const std::string& key, const std::string& path,
                          const char* what, ReadElement element) {
    std::vector<T> out;
    const json* m = member(j, key, path);
    if (m == nullptr) return out;
    if (!m->is_array()) {
      fail(join(path, key), std::string("must be ") + what);
      return out;
    }
    out.reserve(m->size());
    for (size_t i = 0; i < m->size() && ok(); ++i) {
      std::optional<T> value = element((*m)[i], join(path, key) + "[" + std::to_string(i) + "]");
      if (value) out.push_back(*value);
    }
    return out;
  }
  std::optional<core::Cell> cell_value(const json& m, const std::string& path) {
    if (!m.is_array() || m.size() != 2 || !m[0].is_number_integer() || !m[1].is_number_integer()) {
      fail(path, "must be [x, y] with two integers");
      return std::nullopt;
    }
    const int64_t x = m[0].get<int64_t>(), y = m[1].get<int64_t>();
    if (x < INT32_MIN || x > INT32_MAX || y < INT32_MIN || y > INT32_MAX) {
      fail(path, "is out of the 32-bit cell range");
      return std::nullopt;
    }
    return core::Cell{static_cast<int32_t>(x), static_cast<int32_t>(y)};
  }
  void fail(const std::string& path, const std::string& what) {
    if (error_.empty()) error_ = path + " " + what;
  }
  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

 private:
  std::string error_;
  std::vector<std::string> null_geometry_;
};

}  // namespace

namespace {

// The record as JSON with every bulk list (bulk_lists) empty.
json skeleton(const RunRecord& r) {
  json j;
  j["request_id"] = r.request_id;
  if (r.request) {
    j["request"] = {{"source", r.request->source},
                    {"planner", r.request->planner},
                    {"start", optional_point(r.request->start)},
                    {"goal", optional_point(r.request->goal)}};
  } else {
    j["request"] = nullptr;
  }
  if (r.status) {
    const StatusRecord& s = *r.status;
    const core::Metrics& m = s.metrics;
    j["status"] = {{"code", s.code},
                   {"code_name", s.code_name},
                   {"message", s.message},
                   {"planner", s.planner},
                   {"length_m", number(m.length_m)},
                   {"length_cells", number(m.length_cells)},
                   {"raw_cost_cells", number(m.raw_cost_cells)},
                   {"turns", m.turns},
                   {"turn_angle_deg", number(m.turn_angle_deg)},
                   {"expanded", m.expanded},
                   {"planning_time_us", m.planning_time_us},
                   {"length_ratio", number(m.length_ratio)},
                   {"clearance_m", clearance(m.clearance_m)},
                   {"map_stamp", {{"sec", s.map_stamp_sec}, {"nanosec", s.map_stamp_nanosec}}}};
  } else {
    j["status"] = nullptr;
  }
  j["path"] = json::array();
  if (r.debug) {
    const DebugRecord& d = *r.debug;
    j["debug"] = {{"planner", d.planner},
                  {"width", d.width},
                  {"height", d.height},
                  {"resolution", number(d.resolution)},
                  {"origin", point({d.origin_x, d.origin_y})},
                  {"expanded_forward", json::array()},
                  {"expanded_backward", json::array()},
                  {"meeting_cell", d.meeting_cell ? cell(*d.meeting_cell) : json(nullptr)},
                  {"raw_path", json::array()},
                  {"pruned_waypoints", json::array()}};
  } else {
    j["debug"] = nullptr;
  }
  if (r.map) {
    const MapReference& m = *r.map;
    j["map"] = {{"file", m.file},
                {"frame_id", m.frame_id},
                {"stamp", {{"sec", m.stamp_sec}, {"nanosec", m.stamp_nanosec}}},
                {"width", m.width},
                {"height", m.height},
                {"resolution", number(m.resolution)},
                {"origin", point({m.origin_x, m.origin_y})},
                {"occupied_threshold", m.occupied_threshold},
                {"allow_unknown", m.allow_unknown},
                {"inflate_unknown", m.inflate_unknown},
                {"robot_radius", number(m.robot_radius)},
                {"inflation_radius", number(m.inflation_radius)},
                {"cost_scaling_factor", number(m.cost_scaling_factor)}};
  } else {
    j["map"] = nullptr;
  }
  if (r.options) {
    json o = json::object();
    if (r.options->neighborhood) o["neighborhood"] = core::to_string(*r.options->neighborhood);
    if (r.options->prune) o["prune"] = *r.options->prune;
    if (r.options->smooth) o["smooth"] = *r.options->smooth;
    // Written only for relax: smoother none is the pipeline records had before the key existed,
    // and its records stay byte for byte what they were (bench/compare_outputs.sh).
    if (r.options->smoother == core::PathSmoother::kRelax) o["smoother"] = "relax";
    if (r.options->cost_weight) o["cost_weight"] = number(*r.options->cost_weight);
    j["options"] = o;
  } else {
    j["options"] = nullptr;
  }
  return j;
}

}  // namespace

json to_json(const RunRecord& r) {
  json j = skeleton(r);
  for (const BulkList& list : bulk_lists(r)) {
    json& array = j[json::json_pointer(list.pointer)];
    for (size_t i = 0; i < list.size(); ++i) array.push_back(list.element(i));
  }
  return j;
}

void write_json(std::ostream& out, const RunRecord& r) {
  // The skeleton as to_json(r).dump(1) writes it; each bulk list's `"key": []` in it (a key
  // written once in the document, and never inside a string, where its quotes are escaped) is
  // replaced by its elements, 16 to a line, indented one deeper than its key.
  const std::string text = skeleton(r).dump(1);
  struct Place {
    size_t at;  // of the `[]`
    BulkList list;
  };
  std::vector<Place> places;
  for (const BulkList& list : bulk_lists(r)) {
    if (list.size() == 0) continue;
    const std::string empty = "\"" + std::string(list.key) + "\": []";
    const size_t at = text.find(empty);
    if (at != std::string::npos) places.push_back({at + empty.size() - 2, list});
  }
  std::sort(places.begin(), places.end(),
            [](const Place& a, const Place& b) { return a.at < b.at; });
  constexpr size_t kPerLine = 16;
  size_t from = 0;
  for (const Place& place : places) {
    const size_t line = text.rfind('\n', place.at) + 1;  // npos + 1 = 0: the first line
    const std::string indent(text.find_first_not_of(' ', line) - line, ' ');
    out.write(text.data() + from, static_cast<std::streamsize>(place.at - from));
    out << '[';
    for (size_t i = 0; i < place.list.size(); ++i) {
      out << (i == 0 ? "" : ",");
      if (i % kPerLine == 0) out << '\n' << indent << ' ';
      out << place.list.element(i).dump();
    }
    out << '\n' << indent << ']';
    from = place.at + 2;
  }
  out.write(text.data() + from, static_cast<std::streamsize>(text.size() - from));
}

core::Status write_json_file(const std::string& path, const RunRecord& record) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return core::Status::error(core::StatusCode::kInvalidRequest, "cannot write " + path);
  write_json(out, record);
  out.flush();
  if (!out) return core::Status::error(core::StatusCode::kInvalidRequest, "write failed: " + path);
  return core::Status::ok();
}

OptionsRecord options_record(const core::PlannerOptions& options) {
  OptionsRecord o;
  o.neighborhood = options.neighborhood;
  o.prune = options.prune;
  o.smooth = options.smooth;
  o.smoother = options.smoother;
  o.cost_weight = options.cost_weight;
  return o;
}

core::Expected<RunRecord> run_record_from_json(const json& j,
                                               std::vector<std::string>* null_geometry) {
  Reader in;
  RunRecord r;
  if (!j.is_object())
    return core::Status::error(core::StatusCode::kInvalidRequest, "the record must be an object");
  if (in.required(j, "request_id", "")) r.request_id = in.string(j, "request_id", "");
  if (const json* q = in.member(j, "request", "")) {
    RequestRecord req;
    req.source = in.string(*q, "source", "request");
    req.planner = in.string(*q, "planner", "request");
    req.start = in.point(*q, "start", "request");
    req.goal = in.point(*q, "goal", "request");
    r.request = req;
  }
  if (const json* s = in.member(j, "status", "")) {
    StatusRecord st;
    st.code = static_cast<int>(in.integer(*s, "code", "status", 0, 255));
    st.code_name = in.string(*s, "code_name", "status");
    st.message = in.string(*s, "message", "status");
    st.planner = in.string(*s, "planner", "status");
    core::Metrics& m = st.metrics;
    m.length_m = in.real(*s, "length_m", "status");
    m.length_cells = in.real(*s, "length_cells", "status");
    m.raw_cost_cells = in.real(*s, "raw_cost_cells", "status");
    m.turns = static_cast<int32_t>(in.integer(*s, "turns", "status", 0, INT32_MAX));
    m.turn_angle_deg = in.real(*s, "turn_angle_deg", "status");
    m.expanded = in.integer(*s, "expanded", "status", 0, INT64_MAX);
    m.planning_time_us = in.integer(*s, "planning_time_us", "status", INT64_MIN, INT64_MAX);
    m.length_ratio = in.real(*s, "length_ratio", "status");
    // Absent (older records) or null: NaN; "inf": a map without obstacles.
    const json* c = in.member(*s, "clearance_m", "status");
    if (c != nullptr && c->is_string() && c->get<std::string>() == "inf")
      m.clearance_m = std::numeric_limits<double>::infinity();
    else if (c != nullptr && !c->is_number())
      in.fail("status.clearance_m", "must be a number of metres, \"inf\" or null");
    else
      m.clearance_m = in.real(*s, "clearance_m", "status");
    if (const json* stamp = in.member(*s, "map_stamp", "status")) {
      st.map_stamp_sec = in.integer(*stamp, "sec", "status.map_stamp", INT32_MIN, INT32_MAX);
      st.map_stamp_nanosec =
          static_cast<uint32_t>(in.integer(*stamp, "nanosec", "status.map_stamp", 0, UINT32_MAX));
    }
    r.status = st;
  }
  r.path = in.points(j, "path", "");
  if (const json* d = in.member(j, "debug", "")) {
    DebugRecord dbg;
    dbg.planner = in.string(*d, "planner", "debug");
    dbg.width = static_cast<int32_t>(in.integer(*d, "width", "debug", 0, INT32_MAX));
    dbg.height = static_cast<int32_t>(in.integer(*d, "height", "debug", 0, INT32_MAX));
    dbg.resolution = in.geometry(*d, "resolution", "debug");
    if (auto o = in.origin(*d, "debug")) {
      dbg.origin_x = o->x();
      dbg.origin_y = o->y();
    }
    dbg.expanded_forward = in.cells(*d, "expanded_forward", "debug");
    dbg.expanded_backward = in.cells(*d, "expanded_backward", "debug");
    if (const json* mc = in.member(*d, "meeting_cell", "debug"))
      dbg.meeting_cell = in.cell_value(*mc, "debug.meeting_cell");
    dbg.raw_path = in.cells(*d, "raw_path", "debug");
    dbg.pruned_waypoints = in.points(*d, "pruned_waypoints", "debug");
    r.debug = dbg;
  }
  if (const json* m = in.member(j, "map", "")) {
    MapReference map;
    map.file = in.string(*m, "file", "map");
    map.frame_id = in.string(*m, "frame_id", "map");
    if (const json* stamp = in.member(*m, "stamp", "map")) {
      map.stamp_sec = in.integer(*stamp, "sec", "map.stamp", INT32_MIN, INT32_MAX);
      map.stamp_nanosec =
          static_cast<uint32_t>(in.integer(*stamp, "nanosec", "map.stamp", 0, UINT32_MAX));
    }
    map.width = static_cast<int32_t>(in.integer(*m, "width", "map", 0, INT32_MAX));
    map.height = static_cast<int32_t>(in.integer(*m, "height", "map", 0, INT32_MAX));
    map.resolution = in.geometry(*m, "resolution", "map");
    if (auto o = in.origin(*m, "map")) {
      map.origin_x = o->x();
      map.origin_y = o->y();
    }
    // Required: an absent key read as 0, outside 1..100, and thresholded everything as blocked.
    if (in.required(*m, "occupied_threshold", "map") != nullptr)
      map.occupied_threshold =
          static_cast<int>(in.integer(*m, "occupied_threshold", "map", 1, 100));
    map.allow_unknown = in.boolean(*m, "allow_unknown", "map");
    // Absent (records from before map.inflate_unknown): unknown cells were inflated then.
    map.inflate_unknown =
        m->contains("inflate_unknown") ? in.boolean(*m, "inflate_unknown", "map") : true;
    // Absent (older records): no inflation. Null, written for a non-finite value, stays NaN, which
    // check_record refuses.
    const double radius = in.geometry(*m, "robot_radius", "map");
    map.robot_radius = m->contains("robot_radius") ? radius : 0.0;
    // Absent (records from before the cost gradient): no gradient.
    const double inflation = in.geometry(*m, "inflation_radius", "map");
    map.inflation_radius = m->contains("inflation_radius") ? inflation : 0.0;
    const double scaling = in.geometry(*m, "cost_scaling_factor", "map");
    map.cost_scaling_factor =
        m->contains("cost_scaling_factor") ? scaling : MapReference{}.cost_scaling_factor;
    r.map = map;
  }
  // Absent in records from before the options were recorded, and field by field: not recorded.
  if (const json* o = in.member(j, "options", "")) {
    OptionsRecord options;
    if (in.member(*o, "neighborhood", "options") != nullptr) {
      const std::string name = in.string(*o, "neighborhood", "options");
      options.neighborhood = core::neighborhood_from_string(name);
      if (in.ok() && !options.neighborhood)
        in.fail("options.neighborhood", "is \"" + name + "\", must be \"8\" or \"8-11-13\"");
    }
    if (in.member(*o, "prune", "options") != nullptr)
      options.prune = in.boolean(*o, "prune", "options");
    if (in.member(*o, "smooth", "options") != nullptr)
      options.smooth = in.boolean(*o, "smooth", "options");
    if (in.member(*o, "smoother", "options") != nullptr) {
      const std::string name = in.string(*o, "smoother", "options");
      options.smoother = core::path_smoother_from_string(name);
      if (in.ok() && !options.smoother)
        in.fail("options.smoother", "is \"" + name + "\", must be \"none\" or \"relax\"");
    }
    if (in.member(*o, "cost_weight", "options") != nullptr) {
      options.cost_weight = in.real(*o, "cost_weight", "options");
      if (in.ok() && !core::kCostWeightRange.contains(*options.cost_weight))
        in.fail("options.cost_weight", "must be " + core::kCostWeightRange.describe());
    }
    r.options = options;
  }
  if (!in.ok()) return core::Status::error(core::StatusCode::kInvalidRequest, in.error());
  if (null_geometry != nullptr) *null_geometry = in.null_geometry();
  return r;
}

std::string safe_file_stem(const std::string& request_id) {
  std::string stem;
  for (const char c : request_id) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '-' || c == '_' || c == '.';
    stem += keep ? c : '_';
  }
  if (stem.empty()) stem = "unnamed";
  if (stem.front() == '.') stem.front() = '_';  // no hidden files, no "." or ".."
  constexpr size_t kMaxLength = 120;
  if (stem.size() > kMaxLength || stem != request_id) {
    // Different ids must not share a file: ids that were changed or cut get a hash of the
    // original appended.
    char hash[20];
    std::snprintf(hash, sizeof hash, "-%08zx", std::hash<std::string>{}(request_id)&0xffffffffu);
    if (stem.size() > kMaxLength) stem.resize(kMaxLength);
    stem += hash;
  }
  return stem;
}

namespace {

struct Frame {
  int32_t width = 0, height = 0;
  double resolution = 1.0, origin_x = 0.0, origin_y = 0.0;
  bool valid() const {
    return width > 0 && height > 0 && std::isfinite(resolution) && resolution > 0 &&
           std::isfinite(origin_x) && std::isfinite(origin_y);
  }
  core::Point2 to_grid(const Eigen::Vector2d& world) const {
    return core::world_to_grid(world, origin_x, origin_y, resolution);
  }
};

// Limits the picture of a run without any map to a sane size (cells per side).
constexpr int32_t kMaxFrameCells = 4096;

// A frame around the run's points when no map geometry is known: 5 % margin, about 200 cells
// across the longer side.
Frame frame_around(const RunRecord& r) {
  std::vector<Eigen::Vector2d> pts = r.path;
  if (r.request) {
    if (r.request->start) pts.push_back(*r.request->start);
    if (r.request->goal) pts.push_back(*r.request->goal);
  }
  pts.erase(std::remove_if(pts.begin(), pts.end(),
                           [](const Eigen::Vector2d& p) { return !p.allFinite(); }),
            pts.end());
  Frame f;
  if (pts.empty()) {
    f.width = f.height = 10;
    return f;
  }
  Eigen::Vector2d lo = pts.front(), hi = pts.front();
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1.0});
  f.resolution = extent / 200.0;
  const double margin = 0.05 * extent;
  f.origin_x = lo.x() - margin;
  f.origin_y = lo.y() - margin;
  auto cells = [&](double span) {
    return static_cast<int32_t>(std::clamp(std::ceil((span + 2 * margin) / f.resolution), 1.0,
                                           static_cast<double>(kMaxFrameCells)));
  };
  f.width = cells(hi.x() - lo.x());
  f.height = cells(hi.y() - lo.y());
  return f;
}

// core::validate of one grid of the record; `data` (its cells) is taken when given, otherwise
// free cells stand in for them (a geometry without occupancy, as the picture draws it).
core::Status check_grid(const std::string& field, int32_t width, int32_t height, double resolution,
                        double origin_x, double origin_y, const std::vector<int8_t>* data,
                        const core::GridBuildOptions& options) {
  core::OccupancyGrid g;
  g.width = width;
  g.height = height;
  g.resolution = resolution;
  g.origin_x = origin_x;
  g.origin_y = origin_y;
  const int64_t cells = int64_t{std::max(width, 0)} * std::max(height, 0);
  if (data != nullptr)
    g.data = *data;
  else if (cells <= options.max_cells)
    g.data.assign(static_cast<size_t>(cells), core::kOccupancyFree);
  core::Status s = core::validate(g, options);
  if (!s.is_ok()) {
    // "invalid map: resolution must be ..." names the key; the record's section goes before it.
    const std::string generic = "invalid map: ";
    if (s.message.rfind(generic, 0) == 0) s.message.erase(0, generic.size());
    s.message = field + ": " + s.message;
  }
  return s;
}

}  // namespace

core::Status check_record(const RunRecord& r, const core::OccupancyGrid* grid, int64_t max_cells) {
  core::GridBuildOptions options;
  options.max_cells = max_cells;
  const core::GridBuildOptions debug_options = options;
  if (r.map) {
    options = r.map->build_options();
    options.max_cells = max_cells;
    const core::Status s =
        check_grid("map", r.map->width, r.map->height, r.map->resolution, r.map->origin_x,
                   r.map->origin_y, grid != nullptr ? &grid->data : nullptr, options);
    if (!s.is_ok()) return s;
  }
  if (!r.debug) return core::Status::ok();
  const DebugRecord& d = *r.debug;
  if (const core::Status s = check_grid("debug", d.width, d.height, d.resolution, d.origin_x,
                                        d.origin_y, nullptr, debug_options);
      !s.is_ok())
    return s;
  auto outside = [&](const core::Cell& c, const std::string& field) {
    return core::Status::error(
        core::StatusCode::kInvalidMap,
        field + " = [" + std::to_string(c.x) + ", " + std::to_string(c.y) +
            "] is outside the debug grid (debug.width x debug.height = " + std::to_string(d.width) +
            " x " + std::to_string(d.height) + " cells)");
  };
  auto inside = [&](const core::Cell& c) {
    return c.x >= 0 && c.y >= 0 && c.x < d.width && c.y < d.height;
  };
  for (const auto& [field, list] : {std::pair<const char*, const std::vector<core::Cell>*>{
                                        "expanded_forward", &d.expanded_forward},
                                    {"expanded_backward", &d.expanded_backward},
                                    {"raw_path", &d.raw_path}})
    for (size_t i = 0; i < list->size(); ++i)
      if (!inside((*list)[i]))
        return outside((*list)[i], "debug." + std::string(field) + "[" + std::to_string(i) + "]");
  if (d.meeting_cell && !inside(*d.meeting_cell))
    return outside(*d.meeting_cell, "debug.meeting_cell");
  return core::Status::ok();
}

render::RunPicture picture_of(const RunRecord& r, const core::OccupancyGrid* grid) {
  render::RunPicture picture;
  Frame frame;
  std::shared_ptr<render::MapPicture> map;
  if (grid != nullptr && grid->width > 0 && grid->height > 0 &&
      grid->data.size() == static_cast<size_t>(grid->width) * grid->height) {
    const core::GridBuildOptions build =
        r.map ? r.map->build_options() : MapReference{}.build_options();
    const int threshold = build.occupied_threshold;
    auto planning = core::GridMap::build(*grid, build);
    map = std::make_shared<render::MapPicture>(
        render::map_picture(*grid, threshold, planning ? &planning.value() : nullptr));
    frame = {grid->width, grid->height, grid->resolution, grid->origin_x, grid->origin_y};
  }
  if (!map && r.debug) {
    frame = {r.debug->width, r.debug->height, r.debug->resolution, r.debug->origin_x,
             r.debug->origin_y};
    if (!frame.valid() || int64_t{frame.width} * frame.height > int64_t{1} << 28) frame = {};
  }
  if (!map && !frame.valid() && r.map) {
    frame = {r.map->width, r.map->height, r.map->resolution, r.map->origin_x, r.map->origin_y};
    if (int64_t{frame.width} * frame.height > int64_t{1} << 28) frame = {};
  }
  if (!map && !frame.valid()) frame = frame_around(r);
  if (!map) {
    // Geometry without occupancy: every cell is drawn free (unknown would hide the layers).
    auto empty = std::make_shared<render::MapPicture>();
    empty->width = frame.width;
    empty->height = frame.height;
    empty->resolution = frame.resolution;
    empty->origin_x = frame.origin_x;
    empty->origin_y = frame.origin_y;
    empty->cells.assign(static_cast<size_t>(frame.width) * frame.height, render::CellState::kFree);
    map = empty;
  }
  picture.map = map;
  picture.title = r.request_id;
  if (r.request) {
    if (r.request->start && r.request->start->allFinite())
      picture.start = frame.to_grid(*r.request->start);
    if (r.request->goal && r.request->goal->allFinite())
      picture.goal = frame.to_grid(*r.request->goal);
  }
  for (const auto& p : r.path) picture.path.push_back(frame.to_grid(p));
  if (!picture.start && !picture.path.empty()) picture.start = picture.path.front();
  if (!picture.goal && !picture.path.empty()) picture.goal = picture.path.back();
  // Debug cells index the debug message's grid; they are drawn only when that grid is the one
  // in the picture (a slice replaced between the plan and the recording would misplace them).
  if (r.debug) {
    const bool same_grid =
        r.debug->width == frame.width && r.debug->height == frame.height &&
        std::abs(r.debug->resolution - frame.resolution) <= 1e-6 * frame.resolution &&
        std::abs(r.debug->origin_x - frame.origin_x) <= 1e-6 * frame.resolution &&
        std::abs(r.debug->origin_y - frame.origin_y) <= 1e-6 * frame.resolution;
    if (same_grid) {
      picture.expanded_forward = r.debug->expanded_forward;
      picture.expanded_backward = r.debug->expanded_backward;
      picture.meeting_cell = r.debug->meeting_cell;
      picture.raw_path = r.debug->raw_path;
    }
    for (const auto& p : r.debug->pruned_waypoints) picture.waypoints.push_back(frame.to_grid(p));
  }
  if (r.status) {
    picture.status = r.status->code_name.empty() ? "code " + std::to_string(r.status->code)
                                                 : r.status->code_name;
    picture.message = r.status->message;
    picture.planner = r.status->planner;
    if (r.status->code == 0) picture.metrics = r.status->metrics;
  } else {
    picture.status = "NO_STATUS";
    picture.message = "no status was received for this request";
  }
  if (r.options) {
    picture.options.neighborhood = r.options->neighborhood;
    picture.options.prune = r.options->prune;
    picture.options.smooth = r.options->smooth;
    picture.options.smoother = r.options->smoother;
    picture.options.cost_weight = r.options->cost_weight;
  }
  if (r.map) {
    // Older records read 0 for radii they lack; the caption names only positive ones.
    picture.options.robot_radius = r.map->robot_radius;
    picture.options.inflation_radius = r.map->inflation_radius;
  }
  if (picture.planner.empty() && r.debug) picture.planner = r.debug->planner;
  if (picture.planner.empty() && r.request) picture.planner = r.request->planner;
  return picture;
}

core::Expected<std::string> render_record_file(const std::string& json_path) {
  std::ifstream file(json_path, std::ios::binary);
  if (!file)
    return core::Status::error(core::StatusCode::kInvalidRequest, json_path + ": cannot read");
  json j = json::parse(file, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded())
    return core::Status::error(core::StatusCode::kInvalidRequest, json_path + ": not valid JSON");
  std::vector<std::string> null_geometry;
  auto record = run_record_from_json(j, &null_geometry);
  if (!record)
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               json_path + ": " + record.error().message);
  // The geometry check would see NaN there ("got nan"); the file says null.
  if (!null_geometry.empty())
    return core::Status::error(core::StatusCode::kInvalidMap,
                               json_path + ": " + null_geometry.front() +
                                   " is null (written for a value that was not a finite number): "
                                   "the run cannot be drawn without it");
  std::optional<core::OccupancyGrid> grid;
  if (record->map && !record->map->file.empty()) {
    const std::filesystem::path map_path =
        std::filesystem::path(json_path).parent_path() / record->map->file;
    auto loaded = maps::load_map_server(map_path.string());
    if (!loaded)
      return core::Status::error(core::StatusCode::kInvalidMap,
                                 json_path + ": map.file: " + loaded.error().message);
    // map_server files store the image, not the exact origin digits: keep the record's
    // geometry where the file's agrees with it.
    grid = std::move(loaded).value();
    if (grid->width != record->map->width || grid->height != record->map->height) {
      // A record that is wrong on its own says so first (map.width 0 rather than a mismatch).
      if (const core::Status own = check_record(*record, nullptr); !own.is_ok())
        return core::Status::error(own.code, json_path + ": " + own.message);
      return core::Status::error(
          core::StatusCode::kInvalidMap,
          json_path + ": map.file is " + std::to_string(grid->width) + " x " +
              std::to_string(grid->height) + " cells, the record says " +
              std::to_string(record->map->width) + " x " + std::to_string(record->map->height));
    }
    grid->resolution = record->map->resolution;
    grid->origin_x = record->map->origin_x;
    grid->origin_y = record->map->origin_y;
  }
  if (const core::Status checked = check_record(*record, grid ? &*grid : nullptr); !checked.is_ok())
    return core::Status::error(checked.code, json_path + ": " + checked.message);
  return render::render_svg(picture_of(*record, grid ? &*grid : nullptr));
}

}  // namespace vnsba::records
