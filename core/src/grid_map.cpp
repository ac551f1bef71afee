#include "vnsba/core/grid_map.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>

#include "vnsba/core/distance_transform.hpp"

namespace vnsba::core {

namespace {

// The cost just outside the robot's radius (docs/algorithm.md section 8): below the lethal 1, as
// Nav2's 252 of 253 is below its inscribed cost.
constexpr double kMaxGradientCost = 0.99;

bool is_blocked_char(char c) {
  return c == '#' || c == '@' || c == 'O' || c == 'T' || c == 'W';
}

// The obstacles' distance transform and what follows from it, in one pass over the map
// (docs/algorithm.md sections 1 and 8): every cell's distance to the nearest obstacle centre, the
// inflation (free cells whose centre lies within `radius_cells` of an obstacle's: squared
// distance dx*dx + dy*dy <= r*r in cells, r from metres_to_cells: snapped to a whole number of
// cells when within 1e-9 of one) and the cost gradient beyond it. Linear in the cells whatever
// the radii (the exact transform, distance_transform_bytes_per_cell of scratch a cell: 2 bytes
// below radii of 65534 cells). Returns false when `cancel` was raised.
struct ObstacleDistances {
  std::vector<uint8_t>& cells;              // padded CellLayer; kFree may become kInflated
  std::vector<uint16_t>& squared_distance;  // padded, filled (cells^2, saturated)
  std::vector<float>* costs;                // padded; null when there is no gradient
  int32_t width, height;
  double radius_cells;       // robot_radius in cells
  double gradient_cells;     // inflation_radius in cells (0: no gradient)
  double scaling_per_cell;   // cost_scaling_factor * resolution
  bool unknown_is_obstacle;  // blocked unknown cells count as obstacles (inflate_unknown)

  // The transform's cap (cells): exact within both radii and up to the field's saturation
  // (sqrt(65535) < 256), and never beyond width + height (every distance in the map is below).
  int32_t cap() const {
    const double needed = std::max({std::ceil(radius_cells), std::ceil(gradient_cells), 256.0});
    return static_cast<int32_t>(std::min(needed, static_cast<double>(width) + height));
  }

  bool run(const std::atomic<bool>* cancel) {
    // cells^2; for a whole radius both sides of the comparison below are exact integers.
    const double r2 = radius_cells * radius_cells;
    const int32_t cap = this->cap();
    const int64_t far = far_squared_distance(cap);
    const int32_t stride = width + 2;
    return squared_distance_rows(
        width, height, cap,
        [&](int32_t x, int32_t y) {
          const auto layer = static_cast<CellLayer>(
              cells[static_cast<size_t>(y + 1) * stride + static_cast<size_t>(x + 1)]);
          return GridMap::is_obstacle_layer(layer, unknown_is_obstacle);
        },
        [&](int32_t y, const int64_t* squared) {
          const size_t row_start = static_cast<size_t>(y + 1) * stride + 1;
          uint8_t* layer_row = &cells[row_start];
          uint16_t* distance_row = &squared_distance[row_start];
          float* cost_row = costs ? &(*costs)[row_start] : nullptr;
          for (int32_t x = 0; x < width; ++x) {
            // Squared distances up to cap^2 are exact, and cover the field's range (cap >= 256)
            // unless cap is width + height: then a far one means no obstacle at all.
            distance_row[x] = squared[x] >= far
                                  ? GridMap::kSaturatedSquaredDistance
                                  : static_cast<uint16_t>(std::min<int64_t>(
                                        squared[x], GridMap::kSaturatedSquaredDistance));
            if (layer_row[x] != static_cast<uint8_t>(CellLayer::kFree)) continue;
            const double d = squared[x] >= far ? std::numeric_limits<double>::infinity()
                                               : std::sqrt(static_cast<double>(squared[x]));
            if (static_cast<double>(squared[x]) <= r2) {
              layer_row[x] = static_cast<uint8_t>(CellLayer::kInflated);
            } else if (cost_row != nullptr && d <= gradient_cells) {
              const double gradient =
                  kMaxGradientCost * std::exp(-scaling_per_cell * (d - radius_cells));
              cost_row[x] = std::max(cost_row[x], static_cast<float>(gradient));
            }
          }
        },
        cancel);
  }
};

}  // namespace

namespace {

// The map-independent checks of validate(), as "...; " clauses.
void check_options(const GridBuildOptions& options, std::ostringstream& err) {
  if (options.occupied_threshold < 1 || options.occupied_threshold > 100)
    err << "occupied_threshold must be in 1..100 (got " << options.occupied_threshold << "); ";
  if (!std::isfinite(options.robot_radius) || options.robot_radius < 0.0)
    err << "robot_radius must be finite and >= 0 metres (got " << options.robot_radius << "); ";
  if (!std::isfinite(options.inflation_radius) || options.inflation_radius < 0.0) {
    err << "inflation_radius must be finite and >= 0 metres (got " << options.inflation_radius
        << "); ";
  } else if (options.inflation_radius > 0.0 && std::isfinite(options.robot_radius) &&
             options.inflation_radius < options.robot_radius) {
    err << "inflation_radius " << options.inflation_radius
        << " m must be 0 (no cost gradient) or >= robot_radius " << options.robot_radius << " m; ";
  }
  if (!std::isfinite(options.cost_scaling_factor) || options.cost_scaling_factor < 0.0) {
    err << "cost_scaling_factor must be finite and >= 0 per metre (got "
        << options.cost_scaling_factor << "); ";
  }
  if (options.max_cells < 1 || options.max_cells > kMaxCellsLimit)
    err << "max_cells must be in 1.." << kMaxCellsLimit << " (got " << options.max_cells << "); ";
}

Status invalid_map(std::ostringstream& err) {
  std::string message = err.str();
  if (message.empty()) return Status::ok();
  message.resize(message.size() - 2);  // drop the last "; "
  return Status::error(StatusCode::kInvalidMap, "invalid map: " + message);
}

}  // namespace

Status validate(const GridBuildOptions& options) {
  std::ostringstream err;
  check_options(options, err);
  return invalid_map(err);
}

Status validate(const OccupancyGrid& grid, const GridBuildOptions& options) {
  std::ostringstream err;
  const bool size_ok = grid.width > 0 && grid.height > 0;
  if (grid.width <= 0) err << "width must be > 0 (got " << grid.width << "); ";
  if (grid.height <= 0) err << "height must be > 0 (got " << grid.height << "); ";
  if (size_ok) {
    const int64_t cells = int64_t{grid.width} * grid.height;  // < 2^62: no overflow
    if (cells > options.max_cells) {
      err << "width x height = " << cells << " cells is too large: the limit is "
          << options.max_cells << " cells; ";
    } else if (grid.data.size() != static_cast<size_t>(cells)) {
      err << "data has " << grid.data.size() << " values, expected width x height = " << cells
          << "; ";
    }
  }
  const bool resolution_ok = std::isfinite(grid.resolution) && grid.resolution > 0.0;
  if (!resolution_ok) err << "resolution must be finite and > 0 (got " << grid.resolution << "); ";
  if (!std::isfinite(grid.origin_x)) err << "origin x must be finite; ";
  if (!std::isfinite(grid.origin_y)) err << "origin y must be finite; ";
  check_options(options, err);
  // The radius is bounded by the map it inflates: a robot wider than the whole map cannot be
  // placed on it, and is almost always a unit mistake (millimetres given as metres).
  if (size_ok && resolution_ok && std::isfinite(options.robot_radius) &&
      options.robot_radius > 0.0) {
    const double radius_cells = options.robot_radius / grid.resolution;
    const double diagonal_cells = std::hypot(double(grid.width), double(grid.height));
    if (!(radius_cells <= diagonal_cells)) {
      err << "robot_radius " << options.robot_radius << " m is " << radius_cells
          << " cells at the map's resolution of " << grid.resolution
          << " m, more than the map's diagonal of " << diagonal_cells
          << " cells (is the radius in metres?); ";
    }
  }
  return invalid_map(err);
}

Expected<GridMap> GridMap::build(const OccupancyGrid& grid, const GridBuildOptions& options,
                                 const std::atomic<bool>* cancel) {
  if (Status status = validate(grid, options); !status.is_ok()) return status;
  const auto canceled = [] {
    return Status::error(StatusCode::kCanceled, "map conversion canceled");
  };
  for (size_t i = 0; i < grid.data.size(); ++i) {
    if (grid.data[i] < -1 || grid.data[i] > 100) {
      return Status::error(StatusCode::kInvalidMap, "invalid map: data[" + std::to_string(i) +
                                                        "] = " + std::to_string(int{grid.data[i]}) +
                                                        ", expected -1..100");
    }
  }
  GridMap map;
  map.width_ = grid.width;
  map.height_ = grid.height;
  map.resolution_ = grid.resolution;
  map.origin_x_ = grid.origin_x;
  map.origin_y_ = grid.origin_y;
  map.options_ = options;
  const size_t padded = static_cast<size_t>(grid.width + 2) * (grid.height + 2);
  // Graded values (0 < v < occupied_threshold) are costs v / 100 (docs/algorithm.md section 8).
  const bool gradient = options.inflation_radius > 0.0;
  // The field, and the transform that makes it, only where a radius is configured.
  const bool distance_field = options.robot_radius > 0.0 || gradient;
  bool graded = false;
  // The border is blocked (kOccupied): neighbour lookups at distance 1 need no bounds check.
  map.cells_.assign(padded, static_cast<uint8_t>(CellLayer::kOccupied));
  for (int32_t y = 0; y < grid.height; ++y) {
    uint8_t* row = &map.cells_[map.padded_index(0, y)];
    for (int32_t x = 0; x < grid.width; ++x) {
      const int8_t v = grid.at(x, y);
      const CellLayer layer = classify_value(v, options.occupied_threshold, options.allow_unknown);
      if (layer == CellLayer::kFree && v > 0) graded = true;
      if (layer == CellLayer::kUnknown) map.blocked_unknown_ = true;
      if (is_obstacle_layer(layer, options.inflate_unknown)) map.has_obstacles_ = true;
      row[x] = static_cast<uint8_t>(layer);
    }
  }
  if (graded || gradient) {
    map.costs_.assign(padded, 1.0f);
    for (int32_t y = 0; y < grid.height; ++y) {
      for (int32_t x = 0; x < grid.width; ++x) {
        const int8_t v = grid.at(x, y);
        map.costs_[map.padded_index(x, y)] = v > 0 ? static_cast<float>(v / 100.0) : 0.0f;
      }
    }
  }
  if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) return canceled();
  if (distance_field) {
    map.obstacle_squared_distance_.assign(padded, kSaturatedSquaredDistance);
    ObstacleDistances distances{map.cells_,
                                map.obstacle_squared_distance_,
                                gradient ? &map.costs_ : nullptr,
                                map.width_,
                                map.height_,
                                metres_to_cells(options.robot_radius, grid.resolution),
                                metres_to_cells(options.inflation_radius, grid.resolution),
                                options.cost_scaling_factor * grid.resolution,
                                options.inflate_unknown};
    if (!distances.run(cancel)) return canceled();
  }
  for (int32_t y = 0; y < grid.height; ++y) {
    const uint8_t* row = &map.cells_[map.padded_index(0, y)];
    float* cost_row = map.has_costs() ? &map.costs_[map.padded_index(0, y)] : nullptr;
    for (int32_t x = 0; x < grid.width; ++x) {
      if (row[x] == 0) continue;
      ++map.blocked_total_;
      if (cost_row != nullptr) cost_row[x] = 1.0f;
    }
  }
  if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) return canceled();
  map.build_bit_grids();
  return map;
}

Expected<GridMap> GridMap::from_rows(const std::vector<std::string>& rows_top_first,
                                     double resolution) {
  OccupancyGrid grid;
  grid.height = static_cast<int32_t>(rows_top_first.size());
  grid.width = rows_top_first.empty() ? 0 : static_cast<int32_t>(rows_top_first.front().size());
  grid.resolution = resolution;
  grid.data.assign(static_cast<size_t>(std::max(grid.width, 0)) * grid.height, kOccupancyFree);
  for (int32_t row = 0; row < grid.height; ++row) {
    const std::string& text = rows_top_first[row];
    if (static_cast<int32_t>(text.size()) != grid.width) {
      return Status::error(StatusCode::kInvalidMap, "invalid map: row " + std::to_string(row) +
                                                        " has " + std::to_string(text.size()) +
                                                        " cells, expected " +
                                                        std::to_string(grid.width));
    }
    const int32_t y = grid.height - 1 - row;
    for (int32_t x = 0; x < grid.width; ++x) {
      if (is_blocked_char(text[x]))
        grid.data[static_cast<size_t>(y) * grid.width + x] = kOccupancyOccupied;
    }
  }
  return build(grid);
}

const int32_t* GridMap::build_summed_area() const {
  SummedArea& holder = *summed_area_;
  std::call_once(holder.once, [&] {
    const int32_t w1 = width_ + 1;
    std::vector<int32_t>& counts = holder.counts;
    counts.assign(static_cast<size_t>(w1) * (height_ + 1), 0);
    for (int32_t y = 0; y < height_; ++y) {
      const uint8_t* row = &cells_[padded_index(0, y)];
      int32_t row_sum = 0;
      for (int32_t x = 0; x < width_; ++x) {
        row_sum += row[x] != 0 ? 1 : 0;
        counts[static_cast<size_t>(y + 1) * w1 + (x + 1)] =
            counts[static_cast<size_t>(y) * w1 + (x + 1)] + row_sum;
      }
    }
    holder.table.store(counts.data(), std::memory_order_release);
  });
  return holder.table.load(std::memory_order_acquire);
}

void GridMap::build_bit_grids() {
  row_words_ = (static_cast<size_t>(width_) + 63) / 64;
  column_words_ = (static_cast<size_t>(height_) + 63) / 64;
  // One spare word after the last line of each grid (see BlockedBits).
  row_bits_.assign(static_cast<size_t>(height_) * row_words_ + 1, 0);
  column_bits_.assign(static_cast<size_t>(width_) * column_words_ + 1, 0);
  for (int32_t y = 0; y < height_; ++y) {
    const uint8_t* row = &cells_[padded_index(0, y)];
    uint64_t* row_words = &row_bits_[static_cast<size_t>(y) * row_words_];
    // Row y is bit y % 64 of word y / 64 of every column; column x starts x * column_words_ on.
    const uint64_t bit_of_y = uint64_t{1} << (y & 63);
    uint64_t* column_word = &column_bits_[static_cast<size_t>(y) >> 6];
    for (int32_t x = 0; x < width_; ++x) {
      if (!row[x]) continue;
      row_words[x >> 6] |= uint64_t{1} << (x & 63);
      column_word[static_cast<size_t>(x) * column_words_] |= bit_of_y;
    }
  }
}

std::string_view to_string(CellLayer layer) {
  switch (layer) {
    case CellLayer::kFree:
      return "free";
    case CellLayer::kOccupied:
      return "occupied";
    case CellLayer::kUnknown:
      return "unknown";
    case CellLayer::kInflated:
      return "inflation";
  }
  return "?";
}

MapMemoryEstimate GridMap::estimate_memory(int32_t width, int32_t height,
                                           const GridBuildOptions& options) {
  const size_t w = static_cast<size_t>(std::max(width, 0));
  const size_t h = static_cast<size_t>(std::max(height, 0));
  const size_t cells = w * h;
  const size_t padded = (w + 2) * (h + 2);
  const bool distance_field = options.robot_radius > 0.0 || options.inflation_radius > 0.0;
  MapMemoryEstimate estimate;
  estimate.map_bytes = padded * sizeof(uint8_t)                        // cells_
                       + (h * ((w + 63) / 64) + 1) * sizeof(uint64_t)  // row_bits_
                       + (w * ((h + 63) / 64) + 1) * sizeof(uint64_t)  // column_bits_
                       + padded * sizeof(float)                        // costs_ (when any)
                       + (w + 1) * (h + 1) * sizeof(int32_t);          // summed area (once used)
  if (distance_field) {
    estimate.map_bytes += padded * sizeof(uint16_t);  // obstacle_squared_distance_
    // The transform's vertical distances, and its per-row envelope (s, t and the squared row).
    // Its cap never exceeds width + height (ObstacleDistances::cap), whatever the resolution.
    const int32_t widest_cap = static_cast<int32_t>(std::min<size_t>(w + h, INT32_MAX - 1));
    estimate.scratch_bytes = cells * distance_transform_bytes_per_cell(widest_cap) +
                             w * (2 * sizeof(int32_t) + sizeof(int64_t));
  }
  return estimate;
}

size_t GridMap::bytes() const {
  size_t total = cells_.capacity() * sizeof(uint8_t) +
                 obstacle_squared_distance_.capacity() * sizeof(uint16_t) +
                 costs_.capacity() * sizeof(float) +
                 (row_bits_.capacity() + column_bits_.capacity()) * sizeof(uint64_t);
  if (summed_area_ && summed_area_->table.load(std::memory_order_acquire) != nullptr)
    total += summed_area_->counts.capacity() * sizeof(int32_t);
  return total;
}

double GridMap::density(const Cell& a, const Cell& b) const {
  const int64_t cells = (int64_t{std::abs(a.x - b.x)} + 1) * (int64_t{std::abs(a.y - b.y)} + 1);
  return static_cast<double>(blocked_in_rect(a, b)) / static_cast<double>(cells);
}

Point2 GridMap::world_to_grid(double wx, double wy) const {
  return core::world_to_grid({wx, wy}, origin_x_, origin_y_, resolution_);
}

std::optional<Cell> GridMap::world_to_cell(double wx, double wy) const {
  if (!std::isfinite(wx) || !std::isfinite(wy)) return std::nullopt;
  const Point2 g = world_to_grid(wx, wy);
  const double fx = std::floor(g.x()), fy = std::floor(g.y());
  if (fx < 0.0 || fy < 0.0 || fx >= width_ || fy >= height_) return std::nullopt;
  return Cell{static_cast<int32_t>(fx), static_cast<int32_t>(fy)};
}

}  // namespace vnsba::core
