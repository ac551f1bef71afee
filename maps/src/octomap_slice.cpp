// 2D slices of OctoMap trees and the OctoMap file / message readers (docs/architecture.md, "The
// way of a map").
//
// Everything is done in OctoMap's integer keys, so no voxel is ever rounded into the wrong cell.
// OctoMap's convention (OcTreeBaseImpl::coordToKey / keyToCoord, checked against 1.9.7): a leaf
// with key k covers [(k - 2^15) * res, (k - 2^15 + 1) * res) on each axis, i.e. voxel boundaries
// are the whole multiples of the leaf size counted from 0 (voxels are half-open, [lo, hi)); a
// pruned node at depth d spans 2^(16 - d) leaves starting at a multiple of that span. Below,
// "relative keys" are k - 2^15: the voxel's index from 0. An output cell of m leaves covers the
// relative keys [c * m, c * m + m), so the output grid anchored at 0 stays aligned with voxels.
#include "vnsba/maps/octomap_slice.hpp"

#include <octomap/AbstractOcTree.h>
#include <octomap/AbstractOccupancyOcTree.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <octomap/OcTreeStamped.h>

#include <algorithm>
#include <bitset>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string_view>
#include <utility>

namespace vnsba::maps {
// The core types this file reads and writes.
using namespace core;  // NOLINT(google-build-using-namespace)
namespace {

std::string fmt(double value) {
  char buffer[32];
  return std::string(buffer, std::to_chars(buffer, buffer + sizeof(buffer), value).ptr);
}

Status bad_request(const std::string& message) {
  return Status::error(StatusCode::kInvalidRequest, message);
}
Status invalid_map(const std::string& message) {
  return Status::error(StatusCode::kInvalidMap, message);
}

int64_t floor_div(int64_t a, int64_t b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

// A value within 1e-6 of a whole number is that number: band edges and bounds given as decimal
// metres (0.1 / 0.05 = 1.9999999999999998) land on the voxel boundary they mean.
double snap(double v) {
  const double r = std::round(v);
  return std::abs(v - r) <= 1e-6 ? r : v;
}

// OctoMap trees are 2^16 leaves across (OcTree's tree depth).
constexpr unsigned kTreeDepth = 16;

// What is wrong with a tree's leaf size (its resolution: a .bt/.ot header's `res`, a message's
// `resolution`), or "". A finite, positive leaf size can still be too large: the tree's extent,
// 2^depth leaves, must be a finite number of metres, or every coordinate computed from it is
// infinite.
std::string leaf_size_problem(double leaf, unsigned depth) {
  if (!std::isfinite(leaf) || leaf <= 0.0) return "is " + fmt(leaf) + ", not finite and > 0";
  const double leaves = std::ldexp(1.0, static_cast<int>(depth));
  if (!std::isfinite(leaf * leaves)) {
    return "is " + fmt(leaf) + " m: too large, the tree's extent (" + fmt(leaves) +
           " leaves across) would overflow a double; the largest leaf size is " +
           fmt(std::numeric_limits<double>::max() / leaves) + " m";
  }
  return "";
}

// Smallest (or, when `upper`, largest) relative key along `axis` of any leaf under `node`, whose
// range starts at relative key `lo` and spans `span` keys. Branch and bound: a subtree that cannot
// beat `best` is skipped, so the cost follows the nodes on the tree's outer faces, not all leaves.
void extreme_key(const octomap::OcTree& tree, const octomap::OcTreeNode* node, int64_t lo,
                 int64_t span, unsigned axis, bool upper, int64_t& best) {
  if (upper ? lo + span - 1 <= best : lo >= best) return;
  if (!tree.nodeHasChildren(node)) {
    best = upper ? lo + span - 1 : lo;
    return;
  }
  const int64_t half = span / 2;
  for (const unsigned side : {upper ? 1u : 0u, upper ? 0u : 1u}) {
    for (unsigned i = 0; i < 8; ++i) {  // child i is on the upper side of axis a when bit a is set
      if (((i >> axis) & 1u) == side && tree.nodeChildExists(node, i)) {
        extreme_key(tree, tree.getNodeChild(node, i), lo + side * half, half, axis, upper, best);
      }
    }
  }
}

// The occupancy trees liboctomap 1.9 reads, by the id their files and messages carry, and the
// bytes of one node's data in a .ot file (the node type's writeData, checked against liboctomap
// 1.9.7's headers and the files it writes): OcTree a float log-odds; ColorOcTree the float and
// three colour bytes (r, g, b); OcTreeStamped only the float, as OcTreeNodeStamped does not write
// its timestamp. In .bt files and message data every type writes the same occupancy bit stream
// (writeBinaryData). Any other id (CountingOcTree, a user's tree type) is refused: its layout is
// not known here, so its bytes could not be checked before liboctomap reads them.
struct TreeType {
  const char* id;
  size_t full_value_bytes;
};
constexpr TreeType kTreeTypes[] = {{"OcTree", 4}, {"ColorOcTree", 4 + 3}, {"OcTreeStamped", 4}};

const TreeType* find_tree_type(const std::string& id) {
  for (const TreeType& t : kTreeTypes) {
    if (id == t.id) return &t;
  }
  return nullptr;
}

std::string known_tree_types() {
  std::string out;
  for (const TreeType& t : kTreeTypes) out += (out.empty() ? "" : ", ") + std::string(t.id);
  return out;
}

// An id from a file or a message for an error message: quoted, cut short, control and non-ASCII
// bytes as '?'.
std::string shown_id(const std::string& id) {
  std::string out = id.substr(0, 40);
  for (char& c : out) {
    if (c < 0x20 || c > 0x7e) c = '?';
  }
  return "'" + out + (id.size() > 40 ? "...'" : "'");
}

// Checks the layout of a serialised tree before OctoMap reads it: OctoMap's readers trust their
// input (a truncated stream makes them use bytes they never read, a corrupt one makes them
// recurse below the tree depth). `full_value_bytes` > 0 is the .ot layout (per node: the node's
// data, starting with its float log-odds, `full_value_bytes` in all, then one byte with a bit per
// existing child, followed by each child); 0 the layout of writeBinaryData (per inner node: two
// bytes holding a 2-bit code per child, (byte >> 2i) & 3 for child i of that byte: 0 none, 1 free
// leaf, 2 occupied leaf, 3 inner node whose bytes follow). Returns the problem, or "" with
// `nodes` (all nodes, as OcTree::size counts them) set.
std::string check_layout(std::string_view data, size_t full_value_bytes, unsigned depth_limit,
                         uint64_t& nodes) {
  const bool full = full_value_bytes > 0;
  const size_t node_bytes = full ? full_value_bytes + 1 : 2;
  std::vector<std::pair<unsigned, unsigned>> pending{{0, 1}};  // (depth, nodes left to read)
  size_t pos = 0;
  nodes = 1;
  while (!pending.empty()) {
    if (pending.back().second == 0) {
      pending.pop_back();
      continue;
    }
    --pending.back().second;
    const unsigned depth = pending.back().first;
    if (pos + node_bytes > data.size()) {
      return "truncated: the data ends inside node " + std::to_string(nodes) + " (" +
             std::to_string(data.size()) + " bytes)";
    }
    const auto* p = reinterpret_cast<const unsigned char*>(data.data() + pos);
    pos += node_bytes;
    unsigned created = 0, followed = 0;
    if (full) {
      float value;
      std::memcpy(&value, p, sizeof value);
      if (!std::isfinite(value)) return "corrupt: a node's log-odds is not finite";
      created = followed = static_cast<unsigned>(std::bitset<8>(p[full_value_bytes]).count());
    } else {
      for (unsigned i = 0; i < 8; ++i) {
        const unsigned code = (p[i / 4] >> (2 * (i % 4))) & 3u;
        created += code != 0;
        followed += code == 3;
      }
    }
    if (created > 0 && depth >= depth_limit) {
      return "corrupt: nodes below the tree depth " + std::to_string(depth_limit);
    }
    nodes += created;
    if (followed > 0) pending.emplace_back(depth + 1, followed);
  }
  if (pos != data.size()) {
    return "corrupt: " + std::to_string(data.size() - pos) + " bytes after the end of the tree";
  }
  return "";
}

// OcTree's .ot node stream (OcTreeBaseImpl::writeData's layout: per node its float log-odds, a
// byte with a bit per existing child, then the children in order) of any occupancy tree.
template <class Tree>
void append_occupancy_nodes(const Tree& tree, const typename Tree::NodeType* node,
                            std::string& out) {
  const float value = node->getLogOdds();
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
  unsigned children = 0;
  for (unsigned i = 0; i < 8; ++i) children |= (tree.nodeChildExists(node, i) ? 1u : 0u) << i;
  out.push_back(static_cast<char>(children));
  for (unsigned i = 0; i < 8; ++i) {  // at most 16 levels deep: check_layout saw to that
    if (tree.nodeChildExists(node, i))
      append_occupancy_nodes(tree, tree.getNodeChild(node, i), out);
  }
}

// A ColorOcTree or OcTreeStamped as the OcTree of its occupancy: the same nodes with the same
// log-odds; colours and timestamps are dropped. Why a conversion and not a slice templated on the
// tree type: the slice reads only occupancy, and every caller (the node, vnsba_slicer's
// publishing, vnsba_plan, the benchmarks) holds, re-publishes and slices an OcTree, so one type
// serves them all and the slice stays one compiled function. It costs one pass and, for a
// moment, a second tree. It goes through OcTree's own .ot reader rather than
// writeBinaryData/readBinaryData, which would keep only max-likelihood occupancy and print a
// debug line to stderr on each call (Debian's liboctomap).
template <class Tree>
std::shared_ptr<octomap::OcTree> occupancy_octree(const Tree& tree) {
  auto out = std::make_shared<octomap::OcTree>(tree.getResolution());
  if (tree.getRoot() == nullptr) return out;
  std::string nodes;
  nodes.reserve(tree.size() * 5);
  append_occupancy_nodes(tree, tree.getRoot(), nodes);
  std::istringstream stream(std::move(nodes));
  out->readData(stream);
  return out;
}

// Builds a tree of `type` from checked bytes through liboctomap's factory
// (AbstractOcTree::createTree, then readData for .ot or readBinaryData for .bt and messages),
// as an OcTree. `what` starts every error message.
Expected<std::shared_ptr<octomap::OcTree>> read_tree(std::string_view data, double resolution,
                                                     const TreeType& type, bool full,
                                                     const std::string& what,
                                                     std::optional<uint64_t> expected_nodes) {
  if (data.empty() && !full && !expected_nodes) {  // an empty tree writes no bytes
    return std::make_shared<octomap::OcTree>(resolution);
  }
  uint64_t nodes = 0;
  if (std::string problem = check_layout(data, full ? type.full_value_bytes : 0, kTreeDepth, nodes);
      !problem.empty()) {
    return invalid_map(what + problem);
  }
  if (expected_nodes && *expected_nodes != nodes) {
    return invalid_map(what + "corrupt: the header says " + std::to_string(*expected_nodes) +
                       " nodes, the data holds " + std::to_string(nodes));
  }
  std::unique_ptr<octomap::AbstractOcTree> created(
      octomap::AbstractOcTree::createTree(type.id, resolution));
  auto* tree = dynamic_cast<octomap::AbstractOccupancyOcTree*>(created.get());
  if (tree == nullptr) {
    return invalid_map(what + "liboctomap cannot create a " + type.id + " (not registered)");
  }
  std::istringstream stream{std::string(data)};
  full ? tree->readData(stream) : tree->readBinaryData(stream);
  if (!stream || tree->size() != nodes) {
    return invalid_map(what + "OctoMap could not read the tree data");
  }
  std::shared_ptr<octomap::OcTree> octree;
  if (auto* t = dynamic_cast<octomap::OcTree*>(tree)) {
    octree = std::shared_ptr<octomap::OcTree>(std::shared_ptr(std::move(created)), t);
  } else if (const auto* color = dynamic_cast<const octomap::ColorOcTree*>(tree)) {
    octree = occupancy_octree(*color);
  } else if (const auto* stamped = dynamic_cast<const octomap::OcTreeStamped*>(tree)) {
    octree = occupancy_octree(*stamped);
  }
  if (!octree || octree->size() != nodes) {
    return invalid_map(what + "OctoMap could not read the tree data as an OcTree");
  }
  return octree;
}

// Occupied cells with no occupied 8-neighbour become free (decided on the unmodified grid).
void remove_speckles(OccupancyGrid& grid) {
  const std::vector<int8_t> raw = grid.data;
  const int64_t w = grid.width, h = grid.height;
  auto occupied = [&](int64_t x, int64_t y) {
    return x >= 0 && y >= 0 && x < w && y < h && raw[y * w + x] == kOccupancyOccupied;
  };
  for (int64_t y = 0; y < h; ++y) {
    for (int64_t x = 0; x < w; ++x) {
      int neighbours = 0;
      for (int d = 0; d < 9; ++d) neighbours += d != 4 && occupied(x + d % 3 - 1, y + d / 3 - 1);
      if (occupied(x, y) && neighbours == 0) grid.data[y * w + x] = kOccupancyFree;
    }
  }
}

Expected<OccupancyGrid> slice(const octomap::OcTree& tree, const SliceOptions& o) {
  const SliceOptionNames& names = o.names;
  const std::string band =
      "[" + names.z_min + ", " + names.z_max + "] = [" + fmt(o.z_min) + ", " + fmt(o.z_max) + "] m";
  if (!std::isfinite(o.z_min) || !std::isfinite(o.z_max) || o.z_min > o.z_max) {
    return bad_request("band " + band + " must be finite with " + names.z_min +
                       " <= " + names.z_max);
  }
  if (!std::isfinite(o.resolution) || o.resolution < 0.0) {
    return bad_request(names.resolution + " is " + fmt(o.resolution) +
                       ", must be 0 (the tree's leaf size) or a positive number of metres");
  }
  if (tree.size() == 0 || tree.getRoot() == nullptr) {
    return invalid_map("the OctoMap tree is empty");
  }
  const double leaf = tree.getResolution();
  const unsigned depth = tree.getTreeDepth();
  const int64_t half_keys = int64_t{1} << (depth - 1);  // OctoMap's tree_max_val
  if (const std::string problem = leaf_size_problem(leaf, depth); !problem.empty()) {
    return invalid_map("the tree's resolution (leaf size) " + problem);
  }
  // Output cells of m leaves.
  int64_t m = 1;
  if (o.resolution > 0.0) {
    const double ratio = o.resolution / leaf;
    m = std::llround(std::min(ratio, 1e9));
    if (m < 1 || std::abs(ratio - m) > 1e-6 * m || m > 2 * half_keys) {
      return bad_request(names.resolution + " is " + fmt(o.resolution) +
                         " m, not a whole multiple (1 to " + std::to_string(2 * half_keys) +
                         ") of the tree's leaf size " + fmt(leaf) + " m");
    }
  }
  const double cell = leaf * m;

  // The tree's key box (exact, unlike getMetricMin/Max's float centres); x and y only when the
  // bounds default to it.
  int64_t tree_lo[3] = {}, tree_hi[3] = {};
  for (unsigned a = o.bounds ? 2 : 0; a < 3; ++a) {
    tree_lo[a] = INT64_MAX;
    tree_hi[a] = INT64_MIN;
    extreme_key(tree, tree.getRoot(), -half_keys, 2 * half_keys, a, false, tree_lo[a]);
    extreme_key(tree, tree.getRoot(), -half_keys, 2 * half_keys, a, true, tree_hi[a]);
  }

  // The band as relative z keys [z_lo, z_hi]: leaves overlapping [z_min, z_max] by a positive
  // length (touching does not count); a band of zero thickness takes the leaves containing it.
  const double key_limit = 4.0 * half_keys;  // beyond the key space: clamping changes nothing
  const double band_lo = snap(std::clamp(o.z_min / leaf, -key_limit, key_limit));
  const double band_hi = snap(std::clamp(o.z_max / leaf, -key_limit, key_limit));
  const auto z_lo = static_cast<int64_t>(std::floor(band_lo));
  const int64_t z_hi = band_hi > band_lo ? static_cast<int64_t>(std::ceil(band_hi)) - 1 : z_lo;
  if (z_lo > tree_hi[2] || z_hi < tree_lo[2]) {
    return bad_request("band " + band + " is outside the tree's height range [" +
                       fmt(tree_lo[2] * leaf) + ", " + fmt((tree_hi[2] + 1) * leaf) + "] m");
  }

  // Output cells [cx0, cx1) x [cy0, cy1), in cells of m leaves from 0.
  int64_t cx0, cx1, cy0, cy1;
  if (o.bounds) {
    const SliceBounds& b = *o.bounds;
    const std::string given = names.bounds + " = " + fmt(b.x_min) + "," + fmt(b.y_min) + "," +
                              fmt(b.x_max) + "," + fmt(b.y_max) + " m";
    for (const double v : {b.x_min, b.y_min, b.x_max, b.y_max}) {
      if (!std::isfinite(v) || std::abs(v / cell) > 1e12) {
        return bad_request(given + ": must be finite and within 1e12 cells of 0 (x_min,y_min," +
                           "x_max,y_max in metres)");
      }
    }
    if (!(b.x_max > b.x_min) || !(b.y_max > b.y_min)) {
      return bad_request(given + " is empty: need x_min,y_min,x_max,y_max with x_max > x_min " +
                         "and y_max > y_min");
    }
    cx0 = static_cast<int64_t>(std::floor(snap(b.x_min / cell)));
    cy0 = static_cast<int64_t>(std::floor(snap(b.y_min / cell)));
    cx1 = std::max(cx0 + 1, static_cast<int64_t>(std::ceil(snap(b.x_max / cell))));
    cy1 = std::max(cy0 + 1, static_cast<int64_t>(std::ceil(snap(b.y_max / cell))));
  } else {
    cx0 = floor_div(tree_lo[0], m);
    cy0 = floor_div(tree_lo[1], m);
    cx1 = floor_div(tree_hi[0], m) + 1;
    cy1 = floor_div(tree_hi[1], m) + 1;
  }
  const int64_t width = cx1 - cx0, height = cy1 - cy0;
  if (static_cast<double>(width) * static_cast<double>(height) > static_cast<double>(o.max_cells) ||
      width > INT32_MAX || height > INT32_MAX) {
    std::string area;
    if (o.bounds) {
      area = "the " + names.bounds + " given";
    } else {
      area = "the tree's extent [" + fmt(cx0 * cell) + ", " + fmt(cx1 * cell) + "] x [" +
             fmt(cy0 * cell) + ", " + fmt(cy1 * cell) + "] m";
    }
    return bad_request(
        "the slice would have " + std::to_string(width) + " x " + std::to_string(height) +
        " cells of " + fmt(cell) + " m (" + area + "), over " + names.max_cells + " (" +
        std::to_string(o.max_cells) + " cells): slice a smaller area with " + names.bounds +
        " x_min,y_min,x_max,y_max (metres), or coarser cells with " + names.resolution +
        " (a whole multiple of the leaf size " + fmt(leaf) + " m)");
  }

  OccupancyGrid grid;
  grid.width = static_cast<int32_t>(width);
  grid.height = static_cast<int32_t>(height);
  grid.resolution = cell;
  grid.origin_x = static_cast<double>(cx0) * cell;
  grid.origin_y = static_cast<double>(cy0) * cell;
  grid.data.assign(static_cast<size_t>(width * height), kOccupancyUnknown);

  // The key box to visit: the output area in x, y and the band in z, inside the key space.
  const int64_t key_max = half_keys - 1;
  const int64_t lo[3] = {std::max(cx0 * m, -half_keys), std::max(cy0 * m, -half_keys),
                         std::max(z_lo, -half_keys)};
  const int64_t hi[3] = {std::min(cx1 * m - 1, key_max), std::min(cy1 * m - 1, key_max),
                         std::min(z_hi, key_max)};
  if (lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]) {
    auto to_key = [&](const int64_t* k) {
      return octomap::OcTreeKey(static_cast<octomap::key_type>(k[0] + half_keys),
                                static_cast<octomap::key_type>(k[1] + half_keys),
                                static_cast<octomap::key_type>(k[2] + half_keys));
    };
    for (auto it = tree.begin_leafs_bbx(to_key(lo), to_key(hi)), end = tree.end_leafs_bbx();
         it != end; ++it) {
      // getIndexKey is the node's smallest key; it spans `span` keys on each axis.
      const octomap::OcTreeKey key = it.getIndexKey();
      const int64_t span = int64_t{1} << (depth - it.getDepth());
      const int64_t kx = key[0] - half_keys, ky = key[1] - half_keys, kz = key[2] - half_keys;
      if (kz > z_hi || kz + span - 1 < z_lo) continue;  // the iterator's box test is inclusive
      const int64_t x0 = std::max(floor_div(kx, m), cx0);
      const int64_t x1 = std::min(floor_div(kx + span - 1, m), cx1 - 1);
      const int64_t y0 = std::max(floor_div(ky, m), cy0);
      const int64_t y1 = std::min(floor_div(ky + span - 1, m), cy1 - 1);
      const bool occupied = tree.isNodeOccupied(*it);
      for (int64_t y = y0; y <= y1; ++y) {
        int8_t* row = grid.data.data() + (y - cy0) * width;
        for (int64_t x = x0; x <= x1; ++x) {
          int8_t& v = row[x - cx0];
          if (occupied) {
            v = kOccupancyOccupied;
          } else if (v != kOccupancyOccupied) {
            v = kOccupancyFree;
          }
        }
      }
    }
  }

  if (o.remove_speckles) remove_speckles(grid);
  return grid;
}

Expected<std::shared_ptr<octomap::OcTree>> load(const std::string& path) {
  const std::string what = "OctoMap file '" + path + "': ";
  auto bad = [&](const std::string& problem) { return invalid_map(what + problem); };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return bad("does not exist");
  if (!std::filesystem::is_regular_file(path, ec)) return bad("is not a regular file");
  std::ifstream file(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  if (!file.is_open() || file.bad()) return bad("cannot be read");

  // The first line decides the format (the extension is only a convention): .bt files start with
  // "# Octomap OcTree binary file", .ot files with "# Octomap OcTree file". Header keywords follow
  // as OctoMap's AbstractOcTree::readHeader reads them, up to the "data" line.
  std::istringstream in(bytes);
  std::string line, token, id;
  std::getline(in, line);
  const bool binary = line.rfind("# Octomap OcTree binary file", 0) == 0;
  if (!binary && line.rfind("# Octomap OcTree file", 0) != 0) {
    return bad("not an OctoMap file (bad first line; legacy pre-2011 .bt files are not read)");
  }
  std::optional<uint64_t> size;
  double res = 0.0;
  while (in >> token && token != "data") {
    if (token == "id") {
      in >> id;
    } else if (token == "size") {
      in >> size.emplace();
    } else if (token == "res") {
      in >> res;
    } else {
      std::getline(in, line);  // a comment or an unknown keyword: skip the line
    }
  }
  if (token != "data") return bad("truncated or corrupt header (no \"data\" line)");
  std::getline(in, line);        // the rest of the "data" line
  if (id == "1") id = "OcTree";  // OctoMap's deprecated id
  if (!in || !size || !std::isfinite(res) || res <= 0.0) {
    return bad("corrupt header: needs id, size (node count) and res (resolution > 0)");
  }
  if (const std::string problem = leaf_size_problem(res, kTreeDepth); !problem.empty()) {
    return bad("header res (the leaf size) " + problem);
  }
  const TreeType* type = find_tree_type(id);
  if (type == nullptr) {
    return bad("holds a tree of type " + shown_id(id) + ", not one of the occupancy trees read (" +
               known_tree_types() + ")");
  }
  // A "data" line with no newline after it leaves the stream at its end: no position to read
  // the tree from (tellg() would be -1).
  const std::streamoff data_start = in.eof() ? -1 : static_cast<std::streamoff>(in.tellg());
  if (data_start < 0) return bad("truncated header: nothing follows the \"data\" line");
  const auto data = std::string_view(bytes).substr(static_cast<size_t>(data_start));
  if (*size == 0 && data.empty()) return std::make_shared<octomap::OcTree>(res);
  return read_tree(data, res, *type, !binary, what, size);
}

}  // namespace

Expected<OccupancyGrid> slice_octree(const octomap::OcTree& tree, const SliceOptions& options) {
  try {
    return slice(tree, options);
  } catch (const std::exception& e) {  // out of memory; OctoMap's iterators do not throw
    return Status::error(StatusCode::kInternalError, std::string("slice_octree: ") + e.what());
  }
}

Expected<std::shared_ptr<octomap::OcTree>> load_octree(const std::string& path) {
  try {
    return load(path);
  } catch (const std::exception& e) {
    return invalid_map("OctoMap file '" + path + "': " + e.what());
  }
}

Expected<std::shared_ptr<octomap::OcTree>> octree_from_binary_data(const std::vector<int8_t>& data,
                                                                   double resolution,
                                                                   const std::string& id) {
  const std::string what = "OctoMap message data: ";
  const TreeType* type = find_tree_type(id);
  if (type == nullptr) {
    return invalid_map(what + "id " + shown_id(id) + " is not supported (only " +
                       known_tree_types() + ")");
  }
  if (const std::string problem = leaf_size_problem(resolution, kTreeDepth); !problem.empty()) {
    return invalid_map(what + "resolution (the leaf size) " + problem);
  }
  try {
    const std::string_view bytes(reinterpret_cast<const char*>(data.data()), data.size());
    return read_tree(bytes, resolution, *type, false, what, std::nullopt);
  } catch (const std::exception& e) {
    return invalid_map(what + e.what());
  }
}

std::vector<int8_t> octree_to_binary_data(const octomap::OcTree& tree) {
  try {
    std::ostringstream stream;
    tree.writeBinaryData(stream);
    const std::string bytes = stream.str();
    return std::vector<int8_t>(bytes.begin(), bytes.end());
  } catch (const std::exception&) {
    return {};  // out of memory
  }
}

}  // namespace vnsba::maps
