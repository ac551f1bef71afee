// 2D slices of OctoMap 3D maps, like octomap_server's projected map (docs/architecture.md, "The
// way of a map"). Depends on liboctomap only; the result is the occupancy form the node receives,
// so the rest of the pipeline is one.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/status.hpp"

namespace octomap {
class OcTree;
}

namespace vnsba::maps {

struct SliceBounds {
  double x_min = 0.0, y_min = 0.0;  // metres
  double x_max = 0.0, y_max = 0.0;  // metres, > the minimum
};

// What the caller calls each option, for its error messages: a tool names its flag or config key
// ("--resolution", "slicer.resolution in config/default.yaml"). The defaults are the fields'
// names.
struct SliceOptionNames {
  std::string z_min = "z_min";
  std::string z_max = "z_max";
  std::string resolution = "resolution";
  std::string bounds = "bounds";
  std::string max_cells = "max_cells";
};

struct SliceOptions {
  double z_min = 0.1;  // metres: the height band [z_min, z_max]; z_min <= z_max
  double z_max = 1.5;  // metres
  // Metres per output cell: 0 means the tree's leaf size; otherwise it must be a whole multiple
  // (1, 2, 3, ...) of the leaf size (within 1e-6 relative), so cells align with voxels.
  double resolution = 0.0;
  // The area to slice; by default the tree's metric bounds (x, y) snapped outward to cells.
  std::optional<SliceBounds> bounds;
  // Turn occupied cells with no occupied 8-neighbour into free ones (sensor speckles).
  bool remove_speckles = false;
  int64_t max_cells = int64_t{1} << 24;  // refuse larger slices (memory guard)
  SliceOptionNames names;                // for error messages only
};

// Slices `tree`: a cell is occupied (100) if any occupied leaf overlapping the band projects onto
// it, free (0) if only free leaves do, unknown (-1) otherwise. Pruned (large) leaves cover every
// cell under their footprint. Cost grows with the number of leaves overlapping the band, not
// with the tree's volume. Errors (kInvalidRequest) name the option as `names` calls it: an empty
// band (z_min > z_max), a band outside the tree's height range, a resolution that is not a
// multiple of the leaf size, bounds that are empty, a slice over max_cells (the message says
// which bounds or resolution would fit, and the tree's extent); kInvalidMap for an empty tree
// or a leaf size so large that the tree's extent in metres overflows a double.
//
// Geometry, in OctoMap's integer keys (checked against liboctomap 1.9.7): voxel boundaries are
// the whole multiples of the leaf size counted from 0 (a leaf covers [k * leaf, (k + 1) * leaf)),
// and the output grid is anchored at 0 too, so cell edges lie on voxel edges: origin =
// floor(min / resolution) * resolution and the far edge rounds up (bounds snap outward; a value
// within 1e-6 cells of an edge counts as on it, so 0.3 / 0.1 = 2.9999999999999996 means 3). The
// grid's resolution is exactly k * leaf size. Default bounds are the tree's exact key box.
// Band: a leaf counts if its z extent overlaps [z_min, z_max] by a positive length; a leaf that
// only touches the band (its top at z_min or its bottom at z_max) does not; a zero-thickness
// band (z_min == z_max) takes the leaves containing that height, voxels being half-open as in
// OctoMap's coordToKey. Band edges within 1e-6 leaf of a voxel boundary snap to it. A leaf's
// footprint marks every cell it overlaps with positive area. Speckles are judged on the
// unmodified slice, so a one-voxel pillar standing alone is a speckle too.
// Cost: the leaves in the band (OctoMap's leaf_bbx iterator over the output area and band) plus
// a branch-and-bound walk along the tree's outer faces for its key box (z always, x and y only
// for default bounds); no pass over all leaves. Never throws (out of memory: kInternalError).
core::Expected<core::OccupancyGrid> slice_octree(const octomap::OcTree& tree,
                                                 const SliceOptions& options);

// Reads a .bt (binary) or .ot (full) file of any occupancy tree liboctomap 1.9 reads: OcTree (or
// its deprecated id "1"), ColorOcTree, OcTreeStamped, through liboctomap's factory
// (AbstractOcTree::createTree). A ColorOcTree or OcTreeStamped comes back as the OcTree of its
// occupancy (the same nodes and log-odds; colours and timestamps are dropped), so every caller
// slices and publishes one type. Errors (kInvalidMap) name the file and the problem: missing,
// unreadable, truncated, corrupt, not an OctoMap file, another tree type (CountingOcTree...).
// The first line picks the format, not the extension; pre-2011 legacy .bt files without a text
// header are refused. The data layout (per tree type in .ot files) is walked and its node count
// compared with the header before OctoMap reads it (OctoMap's readers use unread bytes on
// truncated input and recurse without a depth limit on corrupt input), so truncated or corrupt
// files are errors, never crashes.
core::Expected<std::shared_ptr<octomap::OcTree>> load_octree(const std::string& path);

// A tree from the data of an octomap_msgs/Octomap message with binary = true (the bytes of
// writeBinaryData), as octomap_msgs' binaryMsgToMap reads it. The id may be "OcTree",
// "ColorOcTree" or "OcTreeStamped" (their binary data is the same occupancy bit stream); the
// tree comes back as an OcTree. Resolution must be finite and > 0; empty data is an empty tree
// (as binaryMapToMsg writes one). Truncated, trailing or corrupt bytes are kInvalidMap (checked
// before OctoMap).
core::Expected<std::shared_ptr<octomap::OcTree>> octree_from_binary_data(
    const std::vector<int8_t>& data, double resolution, const std::string& id);

// The inverse, for tools and tests: the bytes octomap_msgs' binaryMapToMsg would put in data.
// Empty for an empty tree (or, never thrown, when out of memory). Debian's liboctomap prints a
// "Writing N nodes to output stream..." debug line to stderr on each call.
std::vector<int8_t> octree_to_binary_data(const octomap::OcTree& tree);

}  // namespace vnsba::maps
