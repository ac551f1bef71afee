// OctoMap slices and readers.
//
// Synthetic trees are checked cell by cell against a brute-force projection that shares nothing
// with the code under test: it samples the tree with OcTree::search on a lattice of points
// strictly inside each output cell's column and inside the band. Real trees come from
// VNSBA_DATA_DIR/octomap (skipped when absent).
#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <octomap/OcTreeStamped.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <queue>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "temp_files.hpp"
#include "vnsba/core/grid_map.hpp"
#include "vnsba/core/planner.hpp"
#include "vnsba/maps/map_io.hpp"
#include "vnsba/maps/octomap_slice.hpp"

namespace {

namespace fs = std::filesystem;
using octomap::OcTree;
using vnsba::core::Cell;
using vnsba::core::GridMap;
using vnsba::core::OccupancyGrid;
using vnsba::core::StatusCode;
using vnsba::maps::slice_octree;
using vnsba::maps::SliceBounds;
using vnsba::maps::SliceOptions;
using vnsba::test::FreshTempDir;
using vnsba::test::ReadBytes;
using vnsba::test::WriteBytes;

constexpr float kOccupied = 2.0f;  // log-odds written into synthetic voxels
constexpr float kFree = -2.0f;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

std::string OctomapDir() {
  return std::string(VNSBA_DATA_DIR) + "/octomap";
}

// Sets the voxels [x0, x1) x [y0, y1) x [z0, z1), in leaf units counted from 0, without pruning.
// Any occupancy tree type (OcTree, ColorOcTree, OcTreeStamped).
template <class Tree>
void Fill(Tree& tree, int x0, int x1, int y0, int y1, int z0, int z1, bool occupied) {
  const double r = tree.getResolution();
  for (int x = x0; x < x1; ++x) {
    for (int y = y0; y < y1; ++y) {
      for (int z = z0; z < z1; ++z) {
        tree.setNodeValue(
            octomap::point3d(static_cast<float>((x + 0.5) * r), static_cast<float>((y + 0.5) * r),
                             static_cast<float>((z + 0.5) * r)),
            occupied ? kOccupied : kFree, /*lazy_eval=*/true);
      }
    }
  }
}

// The scene's extent in leaf units: x [-13, 27), y [-7, 23), z [0, 18).
constexpr int kSceneX0 = -13, kSceneX1 = 27, kSceneY0 = -7, kSceneY1 = 23;
constexpr int kSceneZ1 = 18;

// A room: occupied floor with a hole, free space, a box, two pillars, a hanging box, an aligned
// 8x8x8 occupied cube (prunes to one leaf), a partial ceiling, one isolated speckle, a pair of
// voxels touching diagonally and an unknown corner.
template <class Tree = OcTree>
std::unique_ptr<Tree> Scene(double resolution, bool prune) {
  auto tree = std::make_unique<Tree>(resolution);
  Tree& t = *tree;
  Fill(t, kSceneX0, 22, kSceneY0, kSceneY1, 1, 16, false);      // free space ...
  Fill(t, 22, kSceneX1, kSceneY0, 15, 1, 16, false);            // ... minus an unknown corner
  Fill(t, kSceneX0, kSceneX1, kSceneY0, kSceneY1, 0, 1, true);  // floor
  for (int x = 2; x < 5; ++x) {                                 // a hole in it
    for (int y = -5; y < -3; ++y)
      t.deleteNode((x + 0.5) * resolution, (y + 0.5) * resolution, 0.5 * resolution);
  }
  Fill(t, -8, -3, -2, 6, 1, 7, true);                             // box
  Fill(t, 4, 5, 10, 11, 1, 16, true);                             // thin pillar
  Fill(t, 18, 20, 2, 4, 1, 16, true);                             // thick pillar
  Fill(t, 0, 5, 14, 19, 10, 15, true);                            // hanging box
  Fill(t, 8, 16, 8, 16, 0, 8, true);                              // aligned cube
  Fill(t, kSceneX0, 10, kSceneY0, kSceneY1, 17, kSceneZ1, true);  // partial ceiling
  Fill(t, -10, -9, 18, 19, 3, 4, true);                           // speckle
  Fill(t, -12, -11, 14, 15, 3, 4, true);  // two voxels touching at a corner only
  Fill(t, -11, -10, 15, 16, 3, 4, true);
  t.updateInnerOccupancy();
  if (prune) t.prune();
  return tree;
}

struct Geometry {
  int64_t cx0 = 0, cy0 = 0, width = 0, height = 0;  // cells of m leaves, counted from 0
  int m = 1;
};

// The grid a slice should have, from the extent in leaf units snapped outward to cells of m.
Geometry ExpectedGeometry(double x0, double x1, double y0, double y1, int m) {
  Geometry g;
  g.m = m;
  g.cx0 = static_cast<int64_t>(std::floor(x0 / m));
  g.cy0 = static_cast<int64_t>(std::floor(y0 / m));
  g.width = static_cast<int64_t>(std::ceil(x1 / m)) - g.cx0;
  g.height = static_cast<int64_t>(std::ceil(y1 / m)) - g.cy0;
  return g;
}

// Brute force: samples at a quarter and three quarters of every leaf across the cell, and in z at
// the midpoints of pieces of at most leaf/4 along the band (its height when it is a plane).
template <class Tree>
std::vector<int8_t> BruteForce(const Tree& tree, const Geometry& g, double z_min, double z_max) {
  const double leaf = tree.getResolution();
  std::vector<double> zs;
  if (z_max > z_min) {
    const int n = static_cast<int>(std::ceil((z_max - z_min) / (leaf / 4)));
    for (int j = 0; j < n; ++j) zs.push_back(z_min + (j + 0.5) * (z_max - z_min) / n);
  } else {
    zs.push_back(z_min);
  }
  std::vector<int8_t> out(static_cast<size_t>(g.width * g.height), -1);
  for (int64_t cy = 0; cy < g.height; ++cy) {
    for (int64_t cx = 0; cx < g.width; ++cx) {
      bool found = false, occupied = false;
      for (int i = 0; i < 2 * g.m && !occupied; ++i) {
        for (int j = 0; j < 2 * g.m && !occupied; ++j) {
          const double x = ((g.cx0 + cx) * g.m + 0.25 + 0.5 * i) * leaf;
          const double y = ((g.cy0 + cy) * g.m + 0.25 + 0.5 * j) * leaf;
          for (const double z : zs) {
            const auto* node = tree.search(x, y, z);
            if (node == nullptr) continue;
            found = true;
            if (tree.isNodeOccupied(node)) {
              occupied = true;
              break;
            }
          }
        }
      }
      out[static_cast<size_t>(cy * g.width + cx)] = occupied ? 100 : found ? 0 : -1;
    }
  }
  return out;
}

// Compares geometry and data; reports the first few differing cells.
void ExpectSliceEquals(const OccupancyGrid& grid, const Geometry& g, double leaf,
                       const std::vector<int8_t>& expected, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(grid.width, g.width);
  ASSERT_EQ(grid.height, g.height);
  EXPECT_NEAR(grid.resolution, g.m * leaf, 1e-12);
  EXPECT_NEAR(grid.origin_x, static_cast<double>(g.cx0 * g.m) * leaf, 1e-9);
  EXPECT_NEAR(grid.origin_y, static_cast<double>(g.cy0 * g.m) * leaf, 1e-9);
  ASSERT_EQ(grid.data.size(), expected.size());
  int mismatches = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    if (grid.data[i] == expected[i]) continue;
    if (++mismatches <= 5) {
      ADD_FAILURE() << "cell (" << i % g.width << ", " << i / g.width << "): slice "
                    << int{grid.data[i]} << ", brute force " << int{expected[i]};
    }
  }
  EXPECT_EQ(mismatches, 0);
}

int Count(const OccupancyGrid& grid, int8_t value) {
  return static_cast<int>(std::count(grid.data.begin(), grid.data.end(), value));
}

SliceOptions Band(double z_min, double z_max, double resolution = 0.0) {
  SliceOptions o;
  o.z_min = z_min;
  o.z_max = z_max;
  o.resolution = resolution;
  return o;
}

// ---------------------------------------------------------------------------------------------

TEST(OctomapSlice, OctomapVoxelBoundariesAreMultiplesOfTheLeafSizeFromZero) {
  // The convention the slice relies on: key k covers [(k - 2^15) res, (k - 2^15 + 1) res).
  OcTree tree(0.1);
  EXPECT_EQ(tree.coordToKey(0.0), 32768);
  EXPECT_EQ(tree.coordToKey(-1e-9), 32767);
  EXPECT_EQ(tree.coordToKey(0.0999), 32768);
  EXPECT_EQ(tree.coordToKey(0.1001), 32769);
  EXPECT_NEAR(tree.keyToCoord(32768), 0.05, 1e-12);
  // One voxel [0.3, 0.4) x [-0.2, -0.1) x [0.5, 0.6) lands on exactly one cell with those edges.
  Fill(tree, 3, 4, -2, -1, 5, 6, true);
  const auto grid = slice_octree(tree, Band(0.0, 1.0));
  ASSERT_TRUE(grid) << grid.error().message;
  ASSERT_EQ(grid->width, 1);
  ASSERT_EQ(grid->height, 1);
  EXPECT_NEAR(grid->origin_x, 0.3, 1e-12);
  EXPECT_NEAR(grid->origin_y, -0.2, 1e-12);
  EXPECT_EQ(grid->data[0], 100);
}

TEST(OctomapSlice, DecimalEdgesLandOnTheVoxelBoundaryTheyNameAndTouchingDoesNotCount) {
  OcTree tree(0.1);
  Fill(tree, 0, 10, 0, 10, 2, 3, true);   // occupied layer [0.2, 0.3)
  Fill(tree, 0, 10, 0, 10, 3, 8, false);  // free space [0.3, 0.8)
  ASSERT_LT(0.3 / 0.1, 3.0);  // 2.9999999999999996: a naive floor would take the layer below
  ASSERT_LT(0.7 / 0.1, 7.0);
  SliceOptions o = Band(0.3, 0.7);
  o.bounds = SliceBounds{0.3, 0.3, 0.7, 0.7};
  const auto grid = slice_octree(tree, o);
  ASSERT_TRUE(grid) << grid.error().message;
  EXPECT_EQ(grid->width, 4);
  EXPECT_EQ(grid->height, 4);
  EXPECT_NEAR(grid->origin_x, 0.3, 1e-12);
  EXPECT_EQ(Count(*grid, 0), 16);  // the occupied layer only touches the band
  // A band touching the tree's bottom face from below overlaps nothing.
  const auto below = slice_octree(tree, Band(0.1, 0.2));
  ASSERT_FALSE(below);
  EXPECT_NE(below.error().message.find("outside the tree's height range [0.2, 0.8"),
            std::string::npos)
      << below.error().message;
  // A band reaching 1e-9 into the layer is still "on" its boundary (1e-6 leaf tolerance) ...
  EXPECT_EQ(Count(*slice_octree(tree, Band(0.3 - 1e-9, 0.7)), 100), 0);
  // ... one reaching a hundredth of a leaf into it is not.
  EXPECT_EQ(Count(*slice_octree(tree, Band(0.299, 0.7)), 100), 100);
}

class SyntheticSlice : public ::testing::TestWithParam<double> {};

TEST_P(SyntheticSlice, MatchesBruteForceAtEveryBandAndCellSize) {
  const double leaf = GetParam();
  for (const bool prune : {false, true}) {
    const auto tree = Scene(leaf, prune);
    // Bands in leaf units: aligned, cutting through leaves and through the pruned cube's middle,
    // one thin slab inside a leaf layer, planes inside and on a voxel boundary, the whole tree.
    const std::vector<std::pair<double, double>> bands = {
        {1, 6}, {0.5, 3.5}, {2.5, 5.5}, {9.25, 9.75}, {4.5, 4.5}, {7, 7}, {-1, 30}, {10.5, 16.5}};
    for (const int m : {1, 2, 3}) {
      const Geometry g = ExpectedGeometry(kSceneX0, kSceneX1, kSceneY0, kSceneY1, m);
      for (const auto& [lo, hi] : bands) {
        const auto grid = slice_octree(*tree, Band(lo * leaf, hi * leaf, m * leaf));
        const std::string what = "leaf " + std::to_string(leaf) + (prune ? " pruned" : "") +
                                 ", m " + std::to_string(m) + ", band [" + std::to_string(lo) +
                                 ", " + std::to_string(hi) + "] leaves";
        ASSERT_TRUE(grid) << what << ": " << grid.error().message;
        ExpectSliceEquals(*grid, g, leaf, BruteForce(*tree, g, lo * leaf, hi * leaf), what);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Resolutions, SyntheticSlice, ::testing::Values(0.05, 0.1, 0.25));

TEST(OctomapSlice, PruningShrinksTheTreeButNotTheSlice) {
  const auto raw = Scene(0.1, false);
  const auto pruned = Scene(0.1, true);
  EXPECT_LT(pruned->getNumLeafNodes(), raw->getNumLeafNodes());
  size_t large_leaves = 0;  // the aligned cube became one leaf of 8 x 8 x 8 voxels
  for (auto it = pruned->begin_leafs(), end = pruned->end_leafs(); it != end; ++it) {
    if (it.getSize() > 7.9 * pruned->getResolution()) ++large_leaves;
  }
  EXPECT_GE(large_leaves, 1u);
  for (const auto& [lo, hi] : {std::pair{0.1, 0.6}, std::pair{0.25, 0.55}, std::pair{0.0, 2.0}}) {
    const auto a = slice_octree(*raw, Band(lo, hi));
    const auto b = slice_octree(*pruned, Band(lo, hi));
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->data, b->data) << "band [" << lo << ", " << hi << "]";
  }
}

TEST(OctomapSlice, ExplicitBoundsPartlyOutsideTheTreeAreSnappedOutwardAndUnknownOutside) {
  const double leaf = 0.1;
  const auto tree = Scene(leaf, true);
  for (const int m : {1, 2, 3}) {
    SliceOptions o = Band(0.1, 0.6, m * leaf);
    // In leaf units: x [-20.3, 5.2], y [15.5, 31]: beyond the tree on three sides.
    o.bounds = SliceBounds{-20.3 * leaf, 15.5 * leaf, 5.2 * leaf, 31 * leaf};
    const auto grid = slice_octree(*tree, o);
    ASSERT_TRUE(grid) << grid.error().message;
    const Geometry g = ExpectedGeometry(-20.3, 5.2, 15.5, 31, m);
    ExpectSliceEquals(*grid, g, leaf, BruteForce(*tree, g, 0.1, 0.6), "m " + std::to_string(m));
    for (int32_t y = 0; y < grid->height; ++y) {
      for (int32_t x = 0; x < grid->width; ++x) {  // cells wholly left of the tree
        if ((g.cx0 + x + 1) * m <= kSceneX0) {
          EXPECT_EQ(grid->at(x, y), -1);
        }
      }
    }
  }
  // Bounds entirely away from the tree: all unknown, no error.
  SliceOptions far = Band(0.1, 0.6);
  far.bounds = SliceBounds{100.0, 100.0, 101.0, 102.0};
  const auto grid = slice_octree(*tree, far);
  ASSERT_TRUE(grid) << grid.error().message;
  EXPECT_EQ(grid->width * grid->height, 10 * 20);
  EXPECT_EQ(Count(*grid, -1), 200);
}

TEST(OctomapSlice, SpeckleRemovalClearsOnlyOccupiedCellsWithoutOccupiedNeighbours) {
  const auto tree = Scene(0.1, true);
  SliceOptions o = Band(0.1, 0.6);
  const auto raw = slice_octree(*tree, o);
  o.remove_speckles = true;
  const auto clean = slice_octree(*tree, o);
  ASSERT_TRUE(raw && clean);
  ASSERT_EQ(raw->data.size(), clean->data.size());
  int removed = 0;
  for (int32_t y = 0; y < raw->height; ++y) {
    for (int32_t x = 0; x < raw->width; ++x) {
      bool neighbour = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int32_t nx = x + dx, ny = y + dy;
          if ((dx || dy) && nx >= 0 && ny >= 0 && nx < raw->width && ny < raw->height &&
              raw->at(nx, ny) == 100) {
            neighbour = true;
          }
        }
      }
      const bool speckle = raw->at(x, y) == 100 && !neighbour;
      EXPECT_EQ(clean->at(x, y), speckle ? 0 : raw->at(x, y)) << x << ", " << y;
      removed += speckle;
    }
  }
  // The scene's speckle at (-10, 18) and the one-voxel pillar at (4, 10) are isolated.
  EXPECT_EQ(removed, 2);
  EXPECT_EQ(raw->at(-10 - kSceneX0, 18 - kSceneY0), 100);
  EXPECT_EQ(clean->at(-10 - kSceneX0, 18 - kSceneY0), 0);
  EXPECT_EQ(clean->at(-12 - kSceneX0, 14 - kSceneY0), 100);  // diagonal neighbours count
  EXPECT_EQ(clean->at(-11 - kSceneX0, 15 - kSceneY0), 100);
}

TEST(OctomapSlice, ErrorsNameTheOptionAtFault) {
  const auto tree = Scene(0.1, true);
  auto expect_error = [&](const SliceOptions& o, StatusCode code, const std::string& name) {
    const auto r = slice_octree(*tree, o);
    ASSERT_FALSE(r) << name;
    EXPECT_EQ(r.error().code, code) << r.error().message;
    EXPECT_NE(r.error().message.find(name), std::string::npos) << r.error().message;
  };
  const StatusCode bad = StatusCode::kInvalidRequest;
  expect_error(Band(kNaN, 1.0), bad, "z_min");
  expect_error(Band(0.0, kInf), bad, "z_max");
  expect_error(Band(1.0, 0.5), bad, "z_min");
  expect_error(Band(1.0, 0.5), bad, "z_max");
  expect_error(Band(1.9, 5.0), bad, "outside the tree's height range [0, 1.8]");
  expect_error(Band(-3.0, -0.01), bad, "outside the tree's height range");
  expect_error(Band(1.8, 1.8), bad, "outside the tree's height range");  // touches the top only
  expect_error(Band(0.1, 0.6, 0.15), bad, "resolution");
  expect_error(Band(0.1, 0.6, 0.05), bad, "resolution");
  expect_error(Band(0.1, 0.6, -0.1), bad, "resolution");
  expect_error(Band(0.1, 0.6, kNaN), bad, "resolution");
  expect_error(Band(0.1, 0.6, 1e300), bad, "resolution");
  SliceOptions o = Band(0.1, 0.6);
  o.bounds = SliceBounds{1.0, 0.0, 1.0, 2.0};
  expect_error(o, bad, "bounds");
  o.bounds = SliceBounds{0.0, 0.0, kNaN, 2.0};
  expect_error(o, bad, "bounds");
  o.bounds = SliceBounds{-1e300, 0.0, 1e300, 2.0};
  expect_error(o, bad, "bounds");
  o.bounds = SliceBounds{0.0, 0.0, 1e6, 1e6};
  expect_error(o, bad, "max_cells");
  o.bounds.reset();
  o.max_cells = 100;
  expect_error(o, bad, "max_cells");
  o.max_cells = 0;
  expect_error(o, bad, "max_cells");
  OcTree empty(0.1);
  const auto r = slice_octree(empty, Band(0.1, 0.6));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, StatusCode::kInvalidMap);
  OcTree huge(1e305);  // leaves so large that the key space overflows a double
  huge.setNodeValue(octomap::OcTreeKey(32768, 32768, 32768), kOccupied);
  const auto h = slice_octree(huge, Band(0.0, 1e305));
  ASSERT_FALSE(h);
  EXPECT_EQ(h.error().code, StatusCode::kInvalidMap);
  EXPECT_NE(h.error().message.find("leaf size"), std::string::npos) << h.error().message;
}

// A finite, positive leaf size can still be too large: the tree's 2^16 leaves across would span
// more metres than a double holds. The error says that (not "not finite"), wherever the leaf size
// comes from: a tree, a .bt header's res, a message's resolution.
TEST(OctomapSlice, ALeafSizeWhoseExtentOverflowsIsSaidToBeTooLarge) {
  auto expect_too_large = [](const auto& r, const std::string& field) {
    ASSERT_FALSE(r) << field;
    EXPECT_EQ(r.error().code, StatusCode::kInvalidMap);
    const std::string& m = r.error().message;
    EXPECT_NE(m.find(field + " is 1e+305 m: too large"), std::string::npos) << m;
    EXPECT_NE(m.find("overflow"), std::string::npos) << m;
    EXPECT_EQ(m.find("not finite"), std::string::npos) << m;
  };
  OcTree huge(1e305);
  huge.setNodeValue(octomap::OcTreeKey(32768, 32768, 32768), kOccupied);
  expect_too_large(slice_octree(huge, Band(0.0, 1e305)), "the tree's resolution (leaf size)");
  expect_too_large(vnsba::maps::octree_from_binary_data(vnsba::maps::octree_to_binary_data(huge),
                                                        1e305, "OcTree"),
                   "resolution (the leaf size)");
  const fs::path dir = FreshTempDir("huge_res");
  WriteBytes(dir / "huge_res.bt",
             "# Octomap OcTree binary file\nid OcTree\nsize 1\nres 1e305\ndata\n");
  expect_too_large(vnsba::maps::load_octree((dir / "huge_res.bt").string()),
                   "header res (the leaf size)");
  // Large leaves whose extent still fits are trees like any other.
  OcTree large(1e300);
  large.setNodeValue(octomap::OcTreeKey(32768, 32768, 32768), kOccupied);
  const auto r = slice_octree(large, Band(0.0, 1e300));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->resolution, 1e300);
}

// Errors call each option what the caller says it is (a tool's flag, a config key in a file),
// and a slice over the cell limit says which options make it fit and how far the tree reaches.
TEST(OctomapSlice, ErrorsUseTheCallersNamesAndSayWhatFixesThem) {
  const auto tree = Scene(0.1, true);
  const vnsba::maps::SliceOptionNames names = {"--z-min", "--z-max",
                                               "slicer.resolution in cfg.yaml", "--bounds",
                                               "map.max_cells in cfg.yaml"};
  auto message = [&](SliceOptions o) {
    o.names = names;
    const auto r = slice_octree(*tree, o);
    EXPECT_FALSE(r);
    return r ? std::string() : r.error().message;
  };
  EXPECT_NE(message(Band(0.1, 0.6, 0.15)).find("slicer.resolution in cfg.yaml is 0.15 m, not"),
            std::string::npos)
      << message(Band(0.1, 0.6, 0.15));
  EXPECT_NE(message(Band(0.1, 0.6, -1)).find("slicer.resolution in cfg.yaml is -1"),
            std::string::npos);
  const std::string band = message(Band(1.0, 0.5));
  EXPECT_NE(band.find("--z-min <= --z-max"), std::string::npos) << band;
  SliceOptions o = Band(0.1, 0.6);
  o.bounds = SliceBounds{1.0, 0.0, 1.0, 2.0};
  const std::string empty = message(o);
  EXPECT_NE(empty.find("--bounds = 1,0,1,2 m is empty"), std::string::npos) << empty;
  o.bounds.reset();
  o.max_cells = 100;
  const std::string large = message(o);
  for (const std::string& part :
       {std::string("over map.max_cells in cfg.yaml (100 cells)"),
        std::string("a smaller area with --bounds x_min,y_min,x_max,y_max (metres)"),
        std::string("coarser cells with slicer.resolution in cfg.yaml"),
        std::string("the tree's extent [")})
    EXPECT_NE(large.find(part), std::string::npos) << part << " not in: " << large;
}

TEST(OctomapSlice, ArbitraryOptionsNeverCrash) {
  const auto tree = Scene(0.25, true);
  std::mt19937 rng(7);
  const std::vector<double> values = {kNaN, kInf, -kInf, 0.0,  -0.0, 1e-300, -1e300, 1e300,   0.25,
                                      0.5,  0.75, 1.0,   -1.0, 3.0,  1e12,   8192.0, -8192.0, 5e-7};
  auto pick = [&] {
    return rng() % 3 == 0 ? values[rng() % values.size()]
                          : std::uniform_real_distribution<double>(-20.0, 20.0)(rng);
  };
  for (int i = 0; i < 3000; ++i) {
    SliceOptions o;
    o.z_min = pick();
    o.z_max = rng() % 2 ? pick() : o.z_min + std::abs(pick());
    o.resolution = rng() % 2 ? 0.0 : pick();
    if (rng() % 2) o.bounds = SliceBounds{pick(), pick(), pick(), pick()};
    o.remove_speckles = rng() % 2;
    o.max_cells = rng() % 4 == 0 ? static_cast<int64_t>(rng() % 1000) - 10 : int64_t{1} << 20;
    const auto r = slice_octree(*tree, o);
    if (!r) {
      EXPECT_TRUE(r.error().code == StatusCode::kInvalidRequest) << r.error().message;
      continue;
    }
    ASSERT_EQ(r->data.size(), static_cast<size_t>(r->width) * r->height);
    ASSERT_GT(r->width, 0);
    for (const int8_t v : r->data) ASSERT_TRUE(v == -1 || v == 0 || v == 100);
  }
}

// --- Messages (octomap_msgs/Octomap with binary = true) ---------------------------------------

TEST(OctomapBinaryData, RoundTripKeepsTheLeaves) {
  const auto tree = Scene(0.05, true);
  const std::vector<int8_t> data = vnsba::maps::octree_to_binary_data(*tree);
  ASSERT_FALSE(data.empty());
  const auto back = vnsba::maps::octree_from_binary_data(data, 0.05, "OcTree");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ((*back)->size(), tree->size());
  EXPECT_EQ((*back)->getNumLeafNodes(), tree->getNumLeafNodes());
  for (const auto& [lo, hi] : {std::pair{0.05, 0.3}, std::pair{0.0, 1.0}, std::pair{0.5, 0.8}}) {
    const auto a = slice_octree(*tree, Band(lo, hi));
    const auto b = slice_octree(**back, Band(lo, hi));
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->data, b->data);
    EXPECT_EQ(a->width, b->width);
    EXPECT_EQ(a->origin_x, b->origin_x);
  }
  // An empty tree writes no bytes and reads back empty.
  OcTree empty(0.1);
  EXPECT_TRUE(vnsba::maps::octree_to_binary_data(empty).empty());
  const auto none = vnsba::maps::octree_from_binary_data({}, 0.1, "OcTree");
  ASSERT_TRUE(none);
  EXPECT_EQ((*none)->size(), 0u);
}

TEST(OctomapBinaryData, BadIdResolutionOrBytesAreErrorsNotCrashes) {
  const auto tree = Scene(0.1, true);
  const std::vector<int8_t> data = vnsba::maps::octree_to_binary_data(*tree);
  auto expect_invalid = [](const auto& r, const std::string& text) {
    ASSERT_FALSE(r) << text;
    EXPECT_EQ(r.error().code, StatusCode::kInvalidMap);
    EXPECT_NE(r.error().message.find(text), std::string::npos) << r.error().message;
  };
  // Ids of trees that are not occupancy trees, or not spelled as liboctomap spells them.
  for (const std::string id : {"CountingOcTree", "ocTree", "", "OcTree ", "1"}) {
    expect_invalid(vnsba::maps::octree_from_binary_data(data, 0.1, id), "is not supported");
  }
  expect_invalid(vnsba::maps::octree_from_binary_data(data, 0.0, "OcTree"), "resolution");
  expect_invalid(vnsba::maps::octree_from_binary_data(data, kNaN, "OcTree"), "resolution");
  expect_invalid(vnsba::maps::octree_from_binary_data(data, -0.1, "OcTree"), "resolution");
  for (size_t cut = 1; cut < data.size(); cut += 1 + cut / 16) {
    const std::vector<int8_t> head(data.begin(), data.begin() + static_cast<ptrdiff_t>(cut));
    expect_invalid(vnsba::maps::octree_from_binary_data(head, 0.1, "OcTree"), "truncated");
  }
  std::vector<int8_t> longer = data;
  longer.push_back(0);
  expect_invalid(vnsba::maps::octree_from_binary_data(longer, 0.1, "OcTree"), "after the end");
  // Inner nodes nested below the tree depth (16): 17 levels of "child 0 has children".
  const std::vector<int8_t> deep(2 * 18, 0x03);
  expect_invalid(vnsba::maps::octree_from_binary_data(deep, 0.1, "OcTree"), "depth");
  // Random corruption: any outcome but a crash; what loads must slice.
  std::mt19937 rng(11);
  for (int i = 0; i < 300; ++i) {
    std::vector<int8_t> bad = data;
    for (int k = 0; k < 1 + i % 4; ++k) bad[rng() % bad.size()] = static_cast<int8_t>(rng());
    const auto r = vnsba::maps::octree_from_binary_data(bad, 0.1, "OcTree");
    if (r) {
      const auto s = slice_octree(**r, Band(0.1, 0.6));
      if (!s) {
        EXPECT_NE(s.error().code, StatusCode::kInternalError) << s.error().message;
      }
    } else {
      EXPECT_EQ(r.error().code, StatusCode::kInvalidMap);
    }
  }
}

// --- Files --------------------------------------------------------------------------------------

TEST(OctomapLoad, MissingOrForeignFilesAreInvalidMaps) {
  const fs::path dir = FreshTempDir("load_errors");
  auto expect_invalid = [](const std::string& path, const std::string& text) {
    const auto r = vnsba::maps::load_octree(path);
    ASSERT_FALSE(r) << path;
    EXPECT_EQ(r.error().code, StatusCode::kInvalidMap);
    EXPECT_NE(r.error().message.find(path), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(text), std::string::npos) << r.error().message;
  };
  expect_invalid((dir / "missing.bt").string(), "does not exist");
  expect_invalid(dir.string(), "not a regular file");
  WriteBytes(dir / "notes.bt", "just some text\nnot a tree\n");
  expect_invalid((dir / "notes.bt").string(), "not an OctoMap file");
  WriteBytes(dir / "empty.bt", "");
  expect_invalid((dir / "empty.bt").string(), "not an OctoMap file");
  WriteBytes(dir / "header_only.bt", "# Octomap OcTree binary file\nid OcTree\nsize 9\nres 0.1\n");
  expect_invalid((dir / "header_only.bt").string(), "no \"data\" line");
  WriteBytes(dir / "bad_res.bt", "# Octomap OcTree binary file\nid OcTree\nsize 9\nres -1\ndata\n");
  expect_invalid((dir / "bad_res.bt").string(), "resolution");
  WriteBytes(dir / "no_data.bt",
             "# Octomap OcTree binary file\nid OcTree\nsize 9\nres 0.1\ndata\n");
  expect_invalid((dir / "no_data.bt").string(), "truncated");

  // A tree type that is not an occupancy tree liboctomap reads (a CountingOcTree's data, or a
  // type the reader does not know), in both formats.
  for (const std::string name : {"counting.ot", "counting.bt"}) {
    WriteBytes(dir / name, std::string(name == "counting.ot" ? "# Octomap OcTree file\n"
                                                             : "# Octomap OcTree binary file\n") +
                               "id CountingOcTree\nsize 1\nres 0.1\ndata\n" +
                               std::string(name == "counting.ot" ? 5 : 2, '\0'));
    expect_invalid((dir / name).string(), "'CountingOcTree', not one of the occupancy trees");
  }
  WriteBytes(dir / "odd_id.bt",
             "# Octomap OcTree binary file\nid \x1b[2JMyTree\nsize 1\nres 0.1\ndata\n");
  expect_invalid((dir / "odd_id.bt").string(), "'?[2JMyTree'");  // control bytes not echoed
}

TEST(OctomapLoad, FullAndBinaryFilesOfTheSameTreeSliceAlike) {
  const fs::path dir = FreshTempDir("formats");
  auto tree = Scene(0.1, true);
  ASSERT_TRUE(tree->write((dir / "scene.ot").string()));
  ASSERT_TRUE(tree->writeBinary((dir / "scene.bt").string()));  // max-likelihood + prune first
  const auto full = vnsba::maps::load_octree((dir / "scene.ot").string());
  const auto binary = vnsba::maps::load_octree((dir / "scene.bt").string());
  ASSERT_TRUE(full) << full.error().message;
  ASSERT_TRUE(binary) << binary.error().message;
  const auto a = slice_octree(**full, Band(0.1, 0.6));
  const auto b = slice_octree(**binary, Band(0.1, 0.6));
  const auto c = slice_octree(*tree, Band(0.1, 0.6));
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(a->data, c->data);
  EXPECT_EQ(b->data, c->data);
  // Truncated copies of both.
  for (const std::string name : {"scene.ot", "scene.bt"}) {
    const std::string bytes = ReadBytes((dir / name).string());
    for (const size_t keep : {bytes.size() - 1, bytes.size() / 2, bytes.size() - 100}) {
      WriteBytes(dir / ("cut_" + name), bytes.substr(0, keep));
      const auto r = vnsba::maps::load_octree((dir / ("cut_" + name)).string());
      ASSERT_FALSE(r) << name << " cut to " << keep;
      EXPECT_NE(r.error().message.find("truncated"), std::string::npos) << r.error().message;
    }
  }
}

// --- Colour and stamped trees -------------------------------------------------------------------

// The scene as a tree of type Tree with the same voxels as Scene<OcTree>; a ColorOcTree also gets
// colours (they must not matter).
template <class Tree>
std::unique_ptr<Tree> SceneAs(double resolution, bool prune) {
  auto tree = Scene<Tree>(resolution, false);
  if constexpr (std::is_same_v<Tree, octomap::ColorOcTree>) {
    uint8_t shade = 0;
    for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it, shade += 37) {
      it->setColor(shade, static_cast<uint8_t>(255 - shade), 7);
    }
    tree->updateInnerOccupancy();
  }
  if (prune) tree->prune();
  return tree;
}

template <class Tree>
std::string FileBytes(const Tree& tree, bool binary) {
  std::ostringstream out;
  binary ? tree.writeBinaryConst(out) : tree.write(out);
  return out.str();
}

// The log-odds of every node of a tree, depth first: two trees with the same nodes and values have
// the same list.
template <class Tree>
std::vector<float> NodeValues(const Tree& tree) {
  std::vector<float> out;
  for (auto it = tree.begin_tree(), end = tree.end_tree(); it != end; ++it) {
    out.push_back(it->getLogOdds());
  }
  return out;
}

// A ColorOcTree and an OcTreeStamped holding the OcTree's voxels, written as .bt and .ot, load
// and slice exactly as the OcTree does (the OcTree is the oracle), at every band and cell size.
TEST(OctomapLoad, ColourAndStampedTreesSliceAsTheOcTreeWithTheSameVoxels) {
  const fs::path dir = FreshTempDir("types");
  for (const bool prune : {false, true}) {
    const auto oracle = Scene(0.1, prune);
    const auto color = SceneAs<octomap::ColorOcTree>(0.1, prune);
    const auto stamped = SceneAs<octomap::OcTreeStamped>(0.1, prune);
    ASSERT_GT(oracle->size(), 1000u);
    struct File {
      std::string name;
      std::string bytes;
      std::vector<float> values;  // the nodes' log-odds, for the full (.ot) files
    };
    const File files[] = {
        {"color.ot", FileBytes(*color, false), NodeValues(*color)},
        {"color.bt", FileBytes(*color, true), {}},
        {"stamped.ot", FileBytes(*stamped, false), NodeValues(*stamped)},
        {"stamped.bt", FileBytes(*stamped, true), {}},
    };
    for (const File& f : files) {
      SCOPED_TRACE(f.name + (prune ? " pruned" : ""));
      // The file says what it holds: the reader must not be reading OcTree files here.
      EXPECT_NE(f.bytes.find(f.name[0] == 'c' ? "id ColorOcTree\n" : "id OcTreeStamped\n"),
                std::string::npos);
      WriteBytes(dir / f.name, f.bytes);
      const auto loaded = vnsba::maps::load_octree((dir / f.name).string());
      ASSERT_TRUE(loaded) << loaded.error().message;
      EXPECT_EQ((*loaded)->getResolution(), 0.1);
      // .ot keeps every node and its log-odds; .bt keeps the nodes (at max likelihood).
      EXPECT_EQ((*loaded)->size(), f.name[0] == 'c' ? color->size() : stamped->size());
      if (!f.values.empty()) {
        EXPECT_EQ(NodeValues(**loaded), f.values);
      }
      for (const auto& [lo, hi] : {std::pair{0.05, 0.3}, std::pair{0.1, 0.6}, std::pair{0.0, 2.0},
                                   std::pair{0.35, 0.35}, std::pair{1.0, 1.6}}) {
        for (const double cell : {0.0, 0.3}) {
          const auto got = slice_octree(**loaded, Band(lo, hi, cell));
          const auto want = slice_octree(*oracle, Band(lo, hi, cell));
          ASSERT_TRUE(got && want) << lo << " " << hi << " " << cell;
          EXPECT_EQ(got->width, want->width);
          EXPECT_EQ(got->height, want->height);
          EXPECT_EQ(got->origin_x, want->origin_x);
          EXPECT_EQ(got->origin_y, want->origin_y);
          EXPECT_EQ(got->resolution, want->resolution);
          EXPECT_EQ(got->data, want->data) << "band [" << lo << ", " << hi << "], cell " << cell;
        }
      }
    }
  }
}

// Message data of every occupancy tree type is the same bit stream: the ids name the type, and
// each slices as the OcTree.
TEST(OctomapBinaryData, ColourAndStampedIdsAreRead) {
  const auto oracle = Scene(0.1, true);
  const auto color = SceneAs<octomap::ColorOcTree>(0.1, true);
  std::ostringstream stream;
  color->writeBinaryData(stream);
  const std::string bytes = stream.str();
  const std::vector<int8_t> data(bytes.begin(), bytes.end());
  for (const std::string id : {"OcTree", "ColorOcTree", "OcTreeStamped"}) {
    SCOPED_TRACE(id);
    const auto tree = vnsba::maps::octree_from_binary_data(data, 0.1, id);
    ASSERT_TRUE(tree) << tree.error().message;
    EXPECT_EQ((*tree)->size(), color->size());
    const auto got = slice_octree(**tree, Band(0.1, 0.6));
    const auto want = slice_octree(*oracle, Band(0.1, 0.6));
    ASSERT_TRUE(got && want);
    EXPECT_EQ(got->data, want->data);
    // Truncated and trailing bytes are refused for every id, before liboctomap reads them.
    const std::vector<int8_t> head(data.begin(),
                                   data.begin() + static_cast<ptrdiff_t>(data.size() / 2));
    const auto cut = vnsba::maps::octree_from_binary_data(head, 0.1, id);
    ASSERT_FALSE(cut);
    EXPECT_NE(cut.error().message.find("truncated"), std::string::npos) << cut.error().message;
    std::vector<int8_t> longer = data;
    longer.push_back(0);
    EXPECT_FALSE(vnsba::maps::octree_from_binary_data(longer, 0.1, id));
  }
}

// Truncated and corrupt colour and stamped files are refused with a message naming the file;
// nothing crashes, and whatever loads slices.
TEST(OctomapLoad, TruncatedOrCorruptColourAndStampedFilesAreRefused) {
  const fs::path dir = FreshTempDir("types_bad");
  // A small tree, so that every truncation can be tried.
  auto small = [](auto tree) {
    for (int i = 0; i < 12; ++i) {
      tree->updateNode(octomap::point3d(0.05f + 0.1f * i, 0.35f, 0.25f), i % 3 != 0);
    }
    return tree;
  };
  const auto color = small(std::make_unique<octomap::ColorOcTree>(0.1));
  const auto stamped = small(std::make_unique<octomap::OcTreeStamped>(0.1));
  const std::pair<std::string, std::string> files[] = {
      {"color.ot", FileBytes(*color, false)},
      {"color.bt", FileBytes(*color, true)},
      {"stamped.ot", FileBytes(*stamped, false)},
      {"stamped.bt", FileBytes(*stamped, true)},
  };
  auto expect_refused = [](const fs::path& path, const std::vector<std::string>& any_of) {
    const auto r = vnsba::maps::load_octree(path.string());
    ASSERT_FALSE(r) << path;
    EXPECT_EQ(r.error().code, StatusCode::kInvalidMap);
    EXPECT_NE(r.error().message.find(path.string()), std::string::npos) << r.error().message;
    bool named = any_of.empty();
    for (const std::string& text : any_of)
      named |= r.error().message.find(text) != std::string::npos;
    EXPECT_TRUE(named) << r.error().message;
  };
  for (const auto& [name, bytes] : files) {
    SCOPED_TRACE(name);
    const size_t data_start = bytes.find("\ndata\n") + 6;
    ASSERT_LT(data_start, bytes.size());
    const fs::path cut = dir / ("cut_" + name);
    for (size_t keep = 0; keep < bytes.size(); ++keep) {
      WriteBytes(cut, bytes.substr(0, keep));
      SCOPED_TRACE(keep);
      expect_refused(cut, {});
      if (keep > data_start) expect_refused(cut, {"truncated"});
    }
    // One byte more, a node count that disagrees, a log-odds that is not a number.
    const fs::path bad = dir / ("bad_" + name);
    WriteBytes(bad, bytes + std::string(1, '\0'));
    expect_refused(bad, {"after the end of the tree"});
    std::string size_off = bytes;
    const size_t size_at = size_off.find("\nsize ") + 6;
    size_off.insert(size_at, "1");  // "size 1<n>"
    WriteBytes(bad, size_off);
    expect_refused(bad, {"the header says"});
    if (name.find(".ot") != std::string::npos) {
      std::string nan_value = bytes;
      const float nan = std::numeric_limits<float>::quiet_NaN();
      nan_value.replace(data_start, sizeof nan, reinterpret_cast<const char*>(&nan), sizeof nan);
      WriteBytes(bad, nan_value);
      expect_refused(bad, {"not finite"});
    }
  }
  // The .ot data of one type labelled as another: the per-node layouts differ (8 bytes a colour
  // node, 5 an OcTree or stamped one), so the walk does not end where the data does.
  const std::string color_ot = FileBytes(*color, false);
  std::string as_octree = color_ot;
  as_octree.replace(as_octree.find("id ColorOcTree"), 14, "id OcTree");
  WriteBytes(dir / "relabelled.ot", as_octree);
  expect_refused(dir / "relabelled.ot", {"corrupt", "truncated"});
  std::string as_color = FileBytes(*stamped, false);
  as_color.replace(as_color.find("id OcTreeStamped"), 16, "id ColorOcTree");
  WriteBytes(dir / "relabelled2.ot", as_color);
  expect_refused(dir / "relabelled2.ot", {"corrupt", "truncated"});

  // Random corruption of every byte position's neighbourhood: any outcome but a crash.
  std::mt19937 rng(16);
  for (const auto& [name, bytes] : files) {
    for (int i = 0; i < 400; ++i) {
      std::string corrupt = bytes;
      for (int k = 0; k < 1 + i % 3; ++k)
        corrupt[rng() % corrupt.size()] = static_cast<char>(rng());
      const fs::path path = dir / ("random_" + name);
      WriteBytes(path, corrupt);
      const auto r = vnsba::maps::load_octree(path.string());
      if (!r) {
        EXPECT_EQ(r.error().code, StatusCode::kInvalidMap);
        EXPECT_NE(r.error().message.find(path.string()), std::string::npos);
        continue;
      }
      const auto s = slice_octree(**r, Band(0.0, 1.0));
      if (!s) {
        EXPECT_NE(s.error().code, StatusCode::kInternalError) << s.error().message;
      }
    }
  }
}

// --- Real maps ----------------------------------------------------------------------------------

class RealOctomap : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::is_directory(OctomapDir()))
      GTEST_SKIP() << "OctoMap data not found at " << OctomapDir();
  }
};

// The largest 4-connected free component (an 8-connected planner without corner cutting can
// always cross it): its first cell and the cell farthest from it in breadth-first order.
std::pair<Cell, Cell> FarApartFreeCells(const GridMap& map, size_t& component_size) {
  std::vector<int> label(static_cast<size_t>(map.cell_count()), -1);
  size_t best_size = 0;
  std::pair<Cell, Cell> best;
  int next_label = 0;
  for (int32_t y = 0; y < map.height(); ++y) {
    for (int32_t x = 0; x < map.width(); ++x) {
      if (map.blocked(x, y) || label[static_cast<size_t>(y) * map.width() + x] >= 0) continue;
      std::queue<Cell> queue;
      queue.push({x, y});
      label[static_cast<size_t>(y) * map.width() + x] = next_label;
      size_t size = 0;
      Cell last{x, y};
      while (!queue.empty()) {
        const Cell c = queue.front();
        queue.pop();
        ++size;
        last = c;
        for (const auto& [dx, dy] :
             {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
          const Cell n{c.x + dx, c.y + dy};
          if (map.blocked(n) || label[static_cast<size_t>(n.y) * map.width() + n.x] >= 0) continue;
          label[static_cast<size_t>(n.y) * map.width() + n.x] = next_label;
          queue.push(n);
        }
      }
      if (size > best_size) {
        best_size = size;
        best = {Cell{x, y}, last};
      }
      ++next_label;
    }
  }
  component_size = best_size;
  return best;
}

TEST_F(RealOctomap, SlicesHaveTheTreeBoundsAndCarryAPlannableMap) {
  const fs::path tmp = FreshTempDir("real");
  for (const std::string name : {"geb079.bt", "fr_078_tidyup.bt"}) {
    SCOPED_TRACE(name);
    const auto loaded = vnsba::maps::load_octree(OctomapDir() + "/" + name);
    ASSERT_TRUE(loaded) << loaded.error().message;
    const OcTree& tree = **loaded;
    const double res = tree.getResolution();
    double x0, y0, z0, x1, y1, z1;
    tree.getMetricMin(x0, y0, z0);
    tree.getMetricMax(x1, y1, z1);
    for (const auto& [lo, hi] : {std::pair{0.1, 0.5}, std::pair{0.5, 1.5}}) {
      SCOPED_TRACE("band [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      const auto grid = slice_octree(tree, Band(lo, hi));
      ASSERT_TRUE(grid) << grid.error().message;
      // The bounds are on voxel boundaries already, so snapping keeps them.
      EXPECT_EQ(grid->width, std::llround((x1 - x0) / res));
      EXPECT_EQ(grid->height, std::llround((y1 - y0) / res));
      EXPECT_NEAR(grid->origin_x, x0, 1e-5);
      EXPECT_NEAR(grid->origin_y, y0, 1e-5);
      EXPECT_DOUBLE_EQ(grid->resolution, res);
      EXPECT_GT(Count(*grid, 100), 0);
      EXPECT_GT(Count(*grid, 0), 0);
      EXPECT_GT(Count(*grid, -1), 0);

      const auto map = GridMap::build(*grid);
      ASSERT_TRUE(map) << map.error().message;
      size_t component = 0;
      const auto [start, goal] = FarApartFreeCells(*map, component);
      ASSERT_GT(component, 100u);
      const auto shared = std::make_shared<const GridMap>(*map);
      const auto plan = vnsba::core::plan_once(
          shared, {start, goal}, vnsba::core::default_options(vnsba::core::PlannerKind::kAStar));
      ASSERT_TRUE(plan.status.is_ok()) << plan.status.message;
      ASSERT_FALSE(plan.raw_path.empty());
      EXPECT_EQ(plan.raw_path.front(), start);
      EXPECT_EQ(plan.raw_path.back(), goal);
      for (const Cell& c : plan.raw_path) EXPECT_TRUE(map->free(c));

      // map_server round trip is exact for 0 / 100 / -1 slices.
      const auto yaml = vnsba::maps::save_map_server(*grid, (tmp / (name + "_slice")).string());
      ASSERT_TRUE(yaml) << yaml.error().message;
      const auto back = vnsba::maps::load_map_server(*yaml);
      ASSERT_TRUE(back) << back.error().message;
      EXPECT_EQ(back->width, grid->width);
      EXPECT_EQ(back->height, grid->height);
      EXPECT_NEAR(back->origin_x, grid->origin_x, 1e-9);
      EXPECT_NEAR(back->origin_y, grid->origin_y, 1e-9);
      EXPECT_EQ(back->data, grid->data);
    }
    const auto above = slice_octree(tree, Band(z1 + 0.2, z1 + 1.0));
    ASSERT_FALSE(above);
    EXPECT_EQ(above.error().code, StatusCode::kInvalidRequest);
    EXPECT_NE(above.error().message.find("outside the tree's height range"), std::string::npos);
  }
}

TEST_F(RealOctomap, WindowOfARealTreeMatchesBruteForce) {
  const auto loaded = vnsba::maps::load_octree(OctomapDir() + "/geb079.bt");
  ASSERT_TRUE(loaded) << loaded.error().message;
  const OcTree& tree = **loaded;
  const double leaf = tree.getResolution();  // 0.08
  for (const int m : {1, 3}) {
    SliceOptions o = Band(0.5, 1.5, m * leaf);
    o.bounds = SliceBounds{-2.0, -3.0, 1.0, 0.0};  // 3 m x 3 m, on no particular boundary
    const auto grid = slice_octree(tree, o);
    ASSERT_TRUE(grid) << grid.error().message;
    const Geometry g = ExpectedGeometry(-25, 12.5, -37.5, 0, m);  // the bounds in leaves
    ExpectSliceEquals(*grid, g, leaf, BruteForce(tree, g, 0.5, 1.5),
                      "geb079 m " + std::to_string(m));
    EXPECT_GT(Count(*grid, 100), 0);
  }
}

TEST_F(RealOctomap, TruncatedCopyIsAnError) {
  const std::string bytes = ReadBytes(OctomapDir() + "/geb079.bt");
  ASSERT_GT(bytes.size(), 1000u);
  const fs::path dir = FreshTempDir("truncated");
  for (const size_t keep : {size_t{200}, bytes.size() / 3, bytes.size() - 1}) {
    const fs::path path = dir / "geb079_cut.bt";
    WriteBytes(path, bytes.substr(0, keep));
    const auto r = vnsba::maps::load_octree(path.string());
    ASSERT_FALSE(r) << keep;
    EXPECT_EQ(r.error().code, StatusCode::kInvalidMap);
    EXPECT_NE(r.error().message.find("truncated"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(path.string()), std::string::npos);
  }
}

TEST_F(RealOctomap, HugePrunedLeavesAreBoundedByMaxCells) {
  // simple.bt (1 m) has leaves spanning the whole key space (+-32768 m).
  const auto loaded = vnsba::maps::load_octree(OctomapDir() + "/simple.bt");
  ASSERT_TRUE(loaded) << loaded.error().message;
  const auto r = slice_octree(**loaded, Band(-1.0, 1.0));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("max_cells"), std::string::npos) << r.error().message;
  SliceOptions o = Band(-1.0, 1.0);
  o.bounds = SliceBounds{-10.0, -10.0, 10.0, 10.0};
  const auto window = slice_octree(**loaded, o);
  ASSERT_TRUE(window) << window.error().message;
  const Geometry g = ExpectedGeometry(-10, 10, -10, 10, 1);
  ExpectSliceEquals(*window, g, 1.0, BruteForce(**loaded, g, -1.0, 1.0), "simple.bt");
}

// A real colour OctoMap (e.g. freiburg1_360.bt from the OctoMap RGB-D datasets), when
// VNSBA_DATA_DIR/octomap holds one: loaded, sliced, and a window checked against the brute force
// over the ColorOcTree as liboctomap itself reads it.
TEST_F(RealOctomap, ColourTreeLoadsAndSlices) {
  std::vector<fs::path> color_files;
  for (const auto& entry : fs::directory_iterator(OctomapDir())) {
    std::ifstream in(entry.path(), std::ios::binary);
    std::string head(400, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<size_t>(in.gcount()));
    if (head.rfind("# Octomap OcTree", 0) == 0 &&
        head.find("\nid ColorOcTree") != std::string::npos) {
      color_files.push_back(entry.path());
    }
  }
  if (color_files.empty()) {
    GTEST_SKIP() << "no ColorOcTree file (such as freiburg1_360.bt) in " << OctomapDir()
                 << ": the real colour tree is not tested";
  }
  std::sort(color_files.begin(), color_files.end());
  for (const fs::path& file : color_files) {
    SCOPED_TRACE(file.string());
    const auto loaded = vnsba::maps::load_octree(file.string());
    ASSERT_TRUE(loaded) << loaded.error().message;
    const OcTree& tree = **loaded;
    double x0, y0, z0, x1, y1, z1;
    tree.getMetricMin(x0, y0, z0);
    tree.getMetricMax(x1, y1, z1);
    const auto grid = slice_octree(tree, Band(z0, z1));
    ASSERT_TRUE(grid) << grid.error().message;
    EXPECT_GT(Count(*grid, 100), 0);
    EXPECT_GT(Count(*grid, 0), 0);

    // liboctomap's own reading of the file, as the colour tree it is.
    std::unique_ptr<octomap::ColorOcTree> direct;
    if (ReadBytes(file.string()).rfind("# Octomap OcTree binary file", 0) == 0) {
      direct = std::make_unique<octomap::ColorOcTree>(0.1);
      ASSERT_TRUE(direct->readBinary(file.string()));
    } else {
      direct.reset(
          dynamic_cast<octomap::ColorOcTree*>(octomap::AbstractOcTree::read(file.string())));
      ASSERT_NE(direct, nullptr);
    }
    EXPECT_EQ(direct->size(), tree.size());
    const double leaf = tree.getResolution();
    const double cx = std::floor((x0 + x1) / 2 / leaf), cy = std::floor((y0 + y1) / 2 / leaf);
    SliceOptions o = Band(z0, z1);
    o.bounds = SliceBounds{(cx - 20) * leaf, (cy - 20) * leaf, (cx + 20) * leaf, (cy + 20) * leaf};
    const auto window = slice_octree(tree, o);
    ASSERT_TRUE(window) << window.error().message;
    const Geometry g = ExpectedGeometry(cx - 20, cx + 20, cy - 20, cy + 20, 1);
    ExpectSliceEquals(*window, g, leaf, BruteForce(*direct, g, z0, z1), file.filename().string());
  }
}

}  // namespace
