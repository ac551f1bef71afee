// The planning grid: occupancy values in, one byte a cell (its CellLayer, nonzero = blocked) and
// two bit grids out; the obstacle distance field only where a radius is configured, the costs
// only where a value or the gradient gives some, the summed-area table only once a planner asks.
//
// docs/algorithm.md section 1. A GridMap is built once per incoming map and is immutable
// afterwards, so any number of planners may share it (std::shared_ptr<const GridMap>) while a newer
// map is being built elsewhere.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vnsba/core/geometry.hpp"
#include "vnsba/core/status.hpp"

namespace vnsba::core {

// Occupancy values as ROS nav_msgs/OccupancyGrid carries them: 0..100 = probability of being
// occupied in percent, -1 = unknown. Row-major, row 0 at the origin (bottom-left in the world).
struct OccupancyGrid {
  int32_t width = 0;         // cells
  int32_t height = 0;        // cells
  double resolution = 1.0;   // metres per cell
  double origin_x = 0.0;     // metres, world position of the corner of cell (0, 0)
  double origin_y = 0.0;     // metres
  std::vector<int8_t> data;  // width * height values

  int8_t at(int32_t x, int32_t y) const { return data[static_cast<size_t>(y) * width + x]; }
};

constexpr int8_t kOccupancyUnknown = -1;
constexpr int8_t kOccupancyFree = 0;
constexpr int8_t kOccupancyOccupied = 100;

// The largest max_cells any build accepts (cells): the summed-area table counts in int32 and
// the padded index is uint32, and a search needs tens of bytes per cell (8 GB at this size).
constexpr int64_t kMaxCellsLimit = int64_t{1} << 28;

struct GridBuildOptions {
  int occupied_threshold = 65;  // values >= this are blocked (1..100)
  bool allow_unknown = false;   // unknown (-1) cells are free when true, blocked otherwise
  // Whether blocked unknown cells are inflated (robot_radius) and give costs (inflation_radius)
  // like occupied ones. false, Nav2's convention (its inflation layer inflates lethal cells
  // only): an OctoMap slice has unknown cells along every scan frontier, and inflating them
  // closed corridors no occupied cell narrows. true: a margin around unknown space.
  bool inflate_unknown = false;
  double robot_radius = 0.0;  // metres; cells whose centre is within this of a blocked centre
                              // are blocked too (0 = no inflation). At most the diagonal of
                              // the map it inflates (checked per map by validate()).
  // The cost gradient beyond the robot's radius (docs/algorithm.md section 8, Nav2's inflation
  // layer): a free cell whose centre is d metres from the nearest obstacle centre, with
  // robot_radius < d <= inflation_radius, costs 0.99 * exp(-cost_scaling_factor * (d -
  // robot_radius)). 0 = no gradient (the paper's binary grid); otherwise >= robot_radius.
  double inflation_radius = 0.0;         // metres
  double cost_scaling_factor = 3.0;      // per metre, >= 0 (Nav2's example configuration uses 3)
  int64_t max_cells = int64_t{1} << 28;  // refuse larger maps (memory guard), cells, at most
                                         // kMaxCellsLimit
};

// A radius or tolerance in metres as a number of cells at `resolution` metres a cell, snapped to a
// whole number of cells when within 1e-9 of one: 0.15 m / 0.05 m is 2.9999999999999996 in doubles
// and means 3 cells (docs/algorithm.md section 1). The one conversion of robot_radius,
// inflation_radius and the tolerances to cells.
inline double metres_to_cells(double metres, double resolution) {
  const double cells = metres / resolution;
  const double whole = std::round(cells);
  return std::abs(cells - whole) <= 1e-9 ? whole : cells;
}

// Checks the options alone (what a config can check before any map arrives).
Status validate(const GridBuildOptions& options);
// Checks an OccupancyGrid and the build options for it (including robot_radius against the
// map's size); the message names the field at fault.
Status validate(const OccupancyGrid& grid, const GridBuildOptions& options = {});

// Blocked flags packed one bit per cell (1 = blocked) along lines of cells: the rows of a map
// (bit x of row y) or its columns (bit y of column x). Cell i of a line is bit i % 64 of word
// i / 64, and every line starts on a word boundary (its last word's unused bits are 0). After
// the last line comes one spare word (0), so that the word after any cell's word can be read.
// Line of sight reads a whole span of a line with a few word masks instead of one cell per step.
struct BlockedBits {
  const uint64_t* words = nullptr;
  size_t words_per_line = 0;

  const uint64_t* line(int32_t index) const {
    return words + static_cast<size_t>(index) * words_per_line;
  }
  bool blocked(int32_t line_index, int32_t cell) const {
    return (line(line_index)[cell >> 6] >> (cell & 63)) & 1;
  }
  // Whether any of cells lo..hi (inclusive, 0 <= lo <= hi < line length) of a bit line is
  // blocked: a word or two of masks for the spans a walk or a scan reads.
  static bool span_blocked(const uint64_t* line, int32_t lo, int32_t hi) {
    constexpr uint64_t kAllBits = ~uint64_t{0};
    const int32_t first = lo >> 6, last = hi >> 6;           // word indices
    const uint64_t from_lo = kAllBits << (lo & 63);          // bits lo % 64 .. 63
    const uint64_t up_to_hi = kAllBits >> (63 - (hi & 63));  // bits 0 .. hi % 64
    if (first == last) return (line[first] & from_lo & up_to_hi) != 0;
    if ((line[first] & from_lo) != 0) return true;
    for (int32_t w = first + 1; w < last; ++w)
      if (line[w] != 0) return true;
    return (line[last] & up_to_hi) != 0;
  }
};

// Why a cell is blocked or not: the one classification of cells (docs/algorithm.md, sections 1
// and 8). Obstacles are the occupied and (unless allow_unknown) the unknown cells; inflation
// blocks the free cells within robot_radius of an obstacle.
enum class CellLayer : uint8_t {
  kFree = 0,
  kOccupied,  // map value >= occupied_threshold
  kUnknown,   // map value -1 with allow_unknown false
  kInflated,  // free in the map, within robot_radius of an obstacle
};
std::string_view to_string(CellLayer layer);  // "free", "occupied", "unknown", "inflation"

// The one rule for a map value on its own (no inflation, which needs the neighbours): occupied at
// or above `occupied_threshold`, unknown when negative (-1) unless `allow_unknown` makes it free,
// free otherwise (graded values 1..threshold-1 are free cells with a cost). GridMap, the pictures
// and the map files all classify through it.
constexpr CellLayer classify_value(int value, int occupied_threshold, bool allow_unknown) {
  if (value < 0) return allow_unknown ? CellLayer::kFree : CellLayer::kUnknown;
  return value >= occupied_threshold ? CellLayer::kOccupied : CellLayer::kFree;
}

// What a map of a given size costs in memory, before it is built (bytes): what a memory budget
// checks a slice against before converting it. Upper bounds: costs are counted whenever the
// options or a graded value could give them.
struct MapMemoryEstimate {
  size_t map_bytes = 0;      // the built GridMap (GridMap::bytes() is at most this)
  size_t scratch_bytes = 0;  // held only while GridMap::build runs, on top of map_bytes
  size_t peak_bytes() const { return map_bytes + scratch_bytes; }
};

class GridMap {
 public:
  // The memory a width x height map built with `options` needs (see MapMemoryEstimate). The one
  // place that knows the layout of a map's arrays; the node's memory budget reads it.
  static MapMemoryEstimate estimate_memory(int32_t width, int32_t height,
                                           const GridBuildOptions& options);
  // Bytes held by this map's arrays (their capacities), the summed-area table once built.
  size_t bytes() const;

  // Validates, thresholds, inflates and builds the bit grids (the summed-area table waits for
  // its first use). O(cells) whatever the robot radius (inflation goes through the exact distance
  // transform, 2 bytes of scratch per cell, 4 for radii beyond 65534 cells; none without a
  // robot_radius or inflation_radius). Polls `cancel` (may be null) once per row and stops
  // with kCanceled when it is raised (a newer map supersedes this one).
  static Expected<GridMap> build(const OccupancyGrid& grid, const GridBuildOptions& options = {},
                                 const std::atomic<bool>* cancel = nullptr);

  // Test and tool convenience: '#' '@' 'O' 'T' 'W' are blocked, anything else free. The first
  // string is the *top* row (as the text reads), so it becomes row height-1.
  static Expected<GridMap> from_rows(const std::vector<std::string>& rows_top_first,
                                     double resolution = 1.0);

  int32_t width() const { return width_; }
  int32_t height() const { return height_; }
  int64_t cell_count() const { return int64_t{width_} * height_; }
  double resolution() const { return resolution_; }
  double origin_x() const { return origin_x_; }
  double origin_y() const { return origin_y_; }

  bool in_bounds(int32_t x, int32_t y) const {
    return x >= 0 && y >= 0 && x < width_ && y < height_;
  }
  bool in_bounds(const Cell& c) const { return in_bounds(c.x, c.y); }
  // Out-of-map cells count as blocked.
  bool blocked(int32_t x, int32_t y) const {
    return !in_bounds(x, y) || cells_[padded_index(x, y)] != 0;
  }
  bool blocked(const Cell& c) const { return blocked(c.x, c.y); }
  bool free(const Cell& c) const { return !blocked(c); }

  // The layer that blocks a cell (kFree when it is free). The cell must be in the map.
  CellLayer layer(const Cell& c) const { return static_cast<CellLayer>(cells_[padded_index(c)]); }
  // Whether cells of `layer` are obstacles: what inflation and the cost gradient grow from and
  // what clearance measures to. Occupied cells, and blocked unknown ones with inflate_unknown.
  bool is_obstacle(CellLayer layer) const {
    return is_obstacle_layer(layer, options_.inflate_unknown);
  }
  static constexpr bool is_obstacle_layer(CellLayer layer, bool inflate_unknown) {
    return layer == CellLayer::kOccupied || (inflate_unknown && layer == CellLayer::kUnknown);
  }
  // Whether some blocked cell is neither an obstacle nor inflation (a blocked unknown cell that
  // is not inflated): then obstacle_distance alone cannot tell that a cell is free.
  bool has_blocked_non_obstacles() const { return blocked_unknown_ && !options_.inflate_unknown; }
  // Whether some unknown cell is blocked (allow_unknown false and the slice has unknown cells).
  bool has_blocked_unknown() const { return blocked_unknown_; }
  // Whether some cell is an obstacle (is_obstacle): without, clearance is +infinity everywhere.
  bool has_obstacles() const { return has_obstacles_; }

  // --- The obstacle distance field (only with robot_radius > 0 or inflation_radius > 0). ---
  // Per cell the squared distance d^2 (cells^2, an integer) from its centre to the nearest
  // obstacle centre (is_obstacle, inflation not counted), exact up to kSaturatedSquaredDistance
  // and stored as that value beyond: 2 bytes a cell, exact within 255 cells of an obstacle. Its
  // readers take it as bounds (obstacle_distance_at_least / _at_most); metrics.hpp's
  // nearest_obstacle_distance is exact anywhere, with or without the field.
  static constexpr uint16_t kSaturatedSquaredDistance = 65535;  // cells^2: "at least this"
  bool has_obstacle_distances() const { return !obstacle_squared_distance_.empty(); }
  // A lower bound of the distance (cells) from the centre of `c` to the nearest obstacle centre:
  // exact where the field holds it (sqrt's rounding aside, half an ulp), about 255.998 beyond,
  // 0 without the field. The cell must be in the map.
  double obstacle_distance_at_least(const Cell& c) const {
    if (!has_obstacle_distances()) return 0.0;
    return std::sqrt(static_cast<double>(obstacle_squared_distance_[padded_index(c)]));
  }
  // An upper bound of the same distance: exact where the field holds it, +infinity beyond it
  // (or without the field, or on a map without obstacles).
  double obstacle_distance_at_most(const Cell& c) const {
    if (!has_obstacle_distances()) return std::numeric_limits<double>::infinity();
    const uint16_t squared = obstacle_squared_distance_[padded_index(c)];
    return squared == kSaturatedSquaredDistance ? std::numeric_limits<double>::infinity()
                                                : std::sqrt(static_cast<double>(squared));
  }
  // The build options this map was made with (robot_radius etc., for messages in metres).
  const GridBuildOptions& build_options() const { return options_; }

  // --- Cell costs (docs/algorithm.md section 8). ---
  // Whether any free cell costs more than 0: a graded map value (0 < v < occupied_threshold) or
  // the inflation gradient. Without costs every planner is the binary one whatever cost_weight.
  bool has_costs() const { return !costs_.empty(); }
  // The cost c in [0, 1) of a free cell (0 without costs). The cell must be in the map.
  double cost(const Cell& c) const { return has_costs() ? costs_[padded_index(c)] : 0.0; }
  // Costs on the padded layout (blocked cells and the border hold 1), for the searches; null
  // without costs.
  const float* cost_data() const { return has_costs() ? costs_.data() : nullptr; }

  // Number of blocked cells in the inclusive rectangle spanned by a and b (any corner order),
  // O(1) from the summed-area table, which the first call builds (4 bytes a cell, O(cells) once;
  // thread-safe: any number of planners may make that first call at once). Both cells must be in
  // the map.
  int64_t blocked_in_rect(const Cell& a, const Cell& b) const {
    const int32_t* table = summed_area_->table.load(std::memory_order_acquire);
    return count_in_rect(table != nullptr ? table : build_summed_area(), a, b);
  }
  // The same count when the table is built already, nullopt otherwise (never builds it): for
  // line of sight, which walks the bit grids when no planner asked for the table.
  std::optional<int64_t> blocked_in_rect_if_counted(const Cell& a, const Cell& b) const {
    const int32_t* table = summed_area_->table.load(std::memory_order_acquire);
    if (table == nullptr) return std::nullopt;
    return count_in_rect(table, a, b);
  }
  // Builds the summed-area table now, if no call has yet (Planner::prepare: before a query).
  void build_density_table() const { build_summed_area(); }
  // blocked_in_rect / cells in the rectangle, in [0, 1].
  double density(const Cell& a, const Cell& b) const;
  int64_t blocked_count() const { return blocked_total_; }

  // --- Grid conversion: the one implementation (metres <-> cells). ---
  // World point (metres) -> cell containing it; nullopt when outside the map or not finite.
  std::optional<Cell> world_to_cell(double wx, double wy) const;
  // World point (metres) -> continuous cell coordinates (no bounds check).
  Point2 world_to_grid(double wx, double wy) const;
  // Continuous cell coordinates -> world point (metres). Inline: every point of every plan's
  // world path passes here.
  Eigen::Vector2d grid_to_world(const Point2& p) const {
    return core::grid_to_world(p, origin_x_, origin_y_, resolution_);
  }
  Eigen::Vector2d cell_centre_world(const Cell& c) const { return grid_to_world(cell_centre(c)); }

  // --- Padded layout for the search hot loops. ---
  // The blocked array has a one-cell border of blocked cells around the map, so neighbour
  // lookups at distance 1 never need a bounds check (and distance 2 from any cell whose 8
  // neighbours are inside the map stays inside the padding).
  int32_t stride() const { return width_ + 2; }
  size_t padded_size() const { return cells_.size(); }
  uint32_t padded_index(int32_t x, int32_t y) const {
    return static_cast<uint32_t>((y + 1) * (width_ + 2) + (x + 1));
  }
  uint32_t padded_index(const Cell& c) const { return padded_index(c.x, c.y); }
  Cell cell_of(uint32_t padded) const {
    return {static_cast<int32_t>(padded % stride()) - 1,
            static_cast<int32_t>(padded / stride()) - 1};
  }
  // The cells' CellLayer values on the padded layout (the border holds kOccupied): nonzero =
  // blocked.
  const uint8_t* blocked_data() const { return cells_.data(); }

  // --- Bit grids for line of sight (line_of_sight.cpp's one walk, for every segment). ---
  // The same blocked flags as blocked(), without the padding: rows for segments that are
  // shallower than 45 degrees, columns (the transpose) for steeper ones, so that a segment
  // always walks its lines along their words. 1 bit per cell in each: 2 bits = 0.25 bytes per
  // cell together, plus up to 63 bits of padding at the end of every row and column.
  BlockedBits blocked_rows() const { return {row_bits_.data(), row_words_}; }
  BlockedBits blocked_columns() const { return {column_bits_.data(), column_words_}; }

 private:
  // The summed-area table, built on first use: (width+1) x (height+1) blocked counts. On the
  // heap so that a GridMap stays movable (std::once_flag is not); a copy starts without it.
  struct SummedArea {
    std::once_flag once;
    std::vector<int32_t> counts;
    std::atomic<const int32_t*> table{nullptr};  // counts.data() once built
  };
  struct LazySummedArea {
    std::unique_ptr<SummedArea> holder = std::make_unique<SummedArea>();
    LazySummedArea() = default;
    LazySummedArea(const LazySummedArea&) {}
    LazySummedArea& operator=(const LazySummedArea&) {
      holder = std::make_unique<SummedArea>();
      return *this;
    }
    LazySummedArea(LazySummedArea&&) noexcept = default;
    LazySummedArea& operator=(LazySummedArea&&) noexcept = default;
    SummedArea* operator->() const { return holder.get(); }
    SummedArea& operator*() const { return *holder; }
    explicit operator bool() const { return holder != nullptr; }
  };

  GridMap() = default;
  const int32_t* build_summed_area() const;  // builds it once, returns the table
  int64_t count_in_rect(const int32_t* sat, const Cell& a, const Cell& b) const {
    const size_t x0 = static_cast<size_t>(a.x < b.x ? a.x : b.x);
    const size_t x1 = static_cast<size_t>(a.x < b.x ? b.x : a.x) + 1;
    const size_t y0 = static_cast<size_t>(a.y < b.y ? a.y : b.y);
    const size_t y1 = static_cast<size_t>(a.y < b.y ? b.y : a.y) + 1;
    const size_t w1 = static_cast<size_t>(width_) + 1;
    return int64_t{sat[y1 * w1 + x1]} - sat[y0 * w1 + x1] - sat[y1 * w1 + x0] + sat[y0 * w1 + x0];
  }
  void build_bit_grids();

  int32_t width_ = 0;
  int32_t height_ = 0;
  double resolution_ = 1.0;
  double origin_x_ = 0.0;
  double origin_y_ = 0.0;
  GridBuildOptions options_;
  std::vector<uint8_t> cells_;  // padded CellLayer values, the border kOccupied (nonzero = blocked)
  // Padded, cells^2, empty without robot_radius and inflation_radius (see
  // kSaturatedSquaredDistance).
  std::vector<uint16_t> obstacle_squared_distance_;
  std::vector<float> costs_;  // padded, empty without costs (see cost_data())
  LazySummedArea summed_area_;
  int64_t blocked_total_ = 0;
  bool blocked_unknown_ = false;       // see has_blocked_unknown()
  bool has_obstacles_ = false;         // see has_obstacles()
  std::vector<uint64_t> row_bits_;     // height rows of row_words_ words each, a spare word
  std::vector<uint64_t> column_bits_;  // width columns of column_words_ words each, a spare word
  size_t row_words_ = 0;               // ceil(width / 64)
  size_t column_words_ = 0;            // ceil(height / 64)
};

}  // namespace vnsba::core
