// Fiber density of a tractogram on a grid of cubic voxels (`fibscope info`):
// how many voxels the fibers occupy and how many distinct fibers pass
// through each occupied voxel. It tells a tractogram that fills the white
// matter thinly (tracker output: a few fibers per 1 mm voxel over most of
// the brain) from one packed into a few thick bundles, which occlude, and so
// cull, very differently (issue 18).
//
// A fiber occupies every voxel its polyline passes through: each segment is
// walked voxel by voxel (Amanatides and Woo's traversal), so no voxel a
// segment crosses is missed however short the voxel or long the step, and a
// fiber is counted once per voxel however many of its points lie there. The
// grid is aligned with the world origin (voxel i covers [i v, (i+1) v) on
// each axis), independent of the file's bounding box, so accumulators of
// different chunks of one file, or of two files, share their voxels.
//
// Memory grows with the occupied voxels only (a hash table; about 1.5 M
// voxels of 1 mm for a whole brain), never with the number of points.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/tractogram.h"

namespace fibscope {

struct FiberDensity {
  double voxel_mm = 1;
  uint64_t fibers = 0;           // streamlines with at least one point
  uint64_t occupied_voxels = 0;  // voxels crossed by at least one fiber
  double occupied_cm3 = 0;       // occupied_voxels * voxel^3, in cm^3
  // Distinct fibers per occupied voxel.
  double mean = 0;
  uint64_t median = 0, p90 = 0, p99 = 0, max = 0;
  double single_fiber_fraction = 0;  // occupied voxels crossed by exactly one fiber
  // histogram[k]: occupied voxels with between 2^k and 2^(k+1) - 1 fibers.
  std::vector<uint64_t> histogram;
};

class FiberDensityAccumulator {
 public:
  // Throws Error unless voxel_mm is finite and in [0.01, 100].
  explicit FiberDensityAccumulator(double voxel_mm = 1.0);

  // Adds the streamlines of a chunk. A streamline is never split between
  // chunks (readers hand out whole streamlines).
  void add(const Tractogram& chunk);
  // Adds the fibers counted by another accumulator of the same voxel size
  // (a different set of fibers: for parallel accumulation).
  void merge(const FiberDensityAccumulator& other);
  FiberDensity result() const;

  double voxelMm() const { return voxel_mm_; }

 private:
  struct Voxel {
    uint64_t fibers = 0;
    uint64_t last_fiber = UINT64_MAX;  // the last fiber counted here, so each counts once
  };
  void addFiber(const float* xyz, size_t n);
  void visit(uint64_t key);

  double voxel_mm_;
  uint64_t fiber_ = 0;  // index of the fiber being added
  uint64_t last_key_ = UINT64_MAX;
  std::unordered_map<uint64_t, Voxel> voxels_;
};

// The key of voxel (i, j, k): each index offset by 2^20 into 21 bits, so
// indices of -2^20 .. 2^20 - 1 voxels (a kilometre at 1 mm) are exact;
// farther coordinates are clamped to the edge voxel.
uint64_t fiberDensityVoxelKey(int64_t i, int64_t j, int64_t k);

}  // namespace fibscope
