#include "vnsba/core/grid_map.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>

#include "vnsba/core/distance_transform.hpp"

namespace vnsba::core {

namespace {

bool is_blocked_char(char c) {
  return c == '#' || c == '@' || c == 'O' || c == 'T' || c == 'W';
}

// A radius / resolution quotient this close to an integer n (in cells) means exactly n cells:
// 0.15 m / 0.05 m evaluates to 2.9999999999999996 in doubles, and a radius of 3 cells must
// inflate the cell 3 cells away (ALGORITHM.md section 1).
constexpr double kWholeCellsTolerance = 1e-9;

// Marks every cell whose centre lies within `radius_cells` of a blocked cell's centre: squared
// distance dx*dx + dy*dy <= r*r in cells, r the radius snapped to a whole number of cells when
// within kWholeCellsTolerance of one. Through the exact distance transform, so the cost is
// linear in the cells (4 bytes of scratch per cell) whatever the radius; validate() keeps the
// radius within the map's diagonal. Returns false when `cancel` was raised.
bool inflate(std::vector<uint8_t>& blocked, int32_t width, int32_t height, double radius_cells,
             const std::atomic<bool>* cancel) {
  const double nearest = std::round(radius_cells);
  if (std::abs(radius_cells - nearest) <= kWholeCellsTolerance) radius_cells = nearest;
  if (radius_cells < 1.0) return true;  // no other centre is within less than one cell
  const int32_t reach = static_cast<int32_t>(std::floor(radius_cells));
  // cells^2; for a whole radius both sides of the comparison below are exact integers.
  const double r2 = radius_cells * radius_cells;
  const int32_t stride = width + 2;
  auto padded = [stride](int32_t x, int32_t y) {
    return static_cast<size_t>(y + 1) * stride + x + 1;
  };
  // Phase 1 of the transform reads every source before the first row is written back.
  return squared_distance_rows(
      width, height, reach, [&](int32_t x, int32_t y) { return blocked[padded(x, y)] != 0; },
      [&](int32_t y, const int64_t* squared) {
        uint8_t* row = &blocked[padded(0, y)];
        for (int32_t x = 0; x < width; ++x)
          if (static_cast<double>(squared[x]) <= r2) row[x] = 1;
      },
      cancel);
}

}  // namespace

namespace {

// The map-independent checks of validate(), as "...; " clauses.
void check_options(const GridBuildOptions& options, std::ostringstream& err) {
  if (options.occupied_threshold < 1 || options.occupied_threshold > 100)
    err << "occupied_threshold must be in 1..100 (got " << options.occupied_threshold << "); ";
  if (!std::isfinite(options.robot_radius) || options.robot_radius < 0.0)
    err << "robot_radius must be finite and >= 0 metres (got " << options.robot_radius << "); ";
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
  map.blocked_.assign(static_cast<size_t>(grid.width + 2) * (grid.height + 2), 1);
  for (int32_t y = 0; y < grid.height; ++y) {
    for (int32_t x = 0; x < grid.width; ++x) {
      const int8_t v = grid.at(x, y);
      const bool blocked =
          v == kOccupancyUnknown ? !options.allow_unknown : v >= options.occupied_threshold;
      map.blocked_[map.padded_index(x, y)] = blocked ? 1 : 0;
    }
  }
  if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) return canceled();
  if (!inflate(map.blocked_, map.width_, map.height_, options.robot_radius / grid.resolution,
               cancel)) {
    return canceled();
  }
  if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) return canceled();
  map.build_summed_area_table();
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

void GridMap::build_summed_area_table() {
  const int32_t w1 = width_ + 1;
  summed_area_.assign(static_cast<size_t>(w1) * (height_ + 1), 0);
  for (int32_t y = 0; y < height_; ++y) {
    int32_t row_sum = 0;
    for (int32_t x = 0; x < width_; ++x) {
      row_sum += blocked_[padded_index(x, y)];
      summed_area_[static_cast<size_t>(y + 1) * w1 + (x + 1)] =
          summed_area_[static_cast<size_t>(y) * w1 + (x + 1)] + row_sum;
    }
  }
  blocked_total_ = summed_area_.back();
}

void GridMap::build_bit_grids() {
  row_words_ = (static_cast<size_t>(width_) + 63) / 64;
  column_words_ = (static_cast<size_t>(height_) + 63) / 64;
  // One spare word after the last line of each grid (see BlockedBits).
  row_bits_.assign(static_cast<size_t>(height_) * row_words_ + 1, 0);
  column_bits_.assign(static_cast<size_t>(width_) * column_words_ + 1, 0);
  for (int32_t y = 0; y < height_; ++y) {
    const uint8_t* row = &blocked_[padded_index(0, y)];
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

Eigen::Vector2d GridMap::grid_to_world(const Point2& p) const {
  return core::grid_to_world(p, origin_x_, origin_y_, resolution_);
}

}  // namespace vnsba::core
