#include "io/fiber_density.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "core/error.h"

namespace fibscope {
namespace {

constexpr int64_t kIndexBias = int64_t(1) << 20;  // 21 bits per index

// A segment crossing more voxels than this (a jump of 64 m at 1 mm: never a
// tracker's step, only a broken or hostile file) is counted at its two end
// voxels only, so one absurd segment cannot cost millions of hash inserts.
constexpr int64_t kMaxSegmentVoxels = int64_t(1) << 16;

int64_t clampIndex(double x) {
  return int64_t(std::clamp(std::floor(x), double(-kIndexBias), double(kIndexBias - 1)));
}

}  // namespace

uint64_t fiberDensityVoxelKey(int64_t i, int64_t j, int64_t k) {
  auto bits = [](int64_t x) { return uint64_t(std::clamp(x, -kIndexBias, kIndexBias - 1) + kIndexBias); };
  return bits(i) | bits(j) << 21 | bits(k) << 42;
}

FiberDensityAccumulator::FiberDensityAccumulator(double voxel_mm) : voxel_mm_(voxel_mm) {
  if (!std::isfinite(voxel_mm) || voxel_mm < 0.01 || voxel_mm > 100)
    throw Error("fiber density voxel size must be between 0.01 and 100 mm, not " + std::to_string(voxel_mm));
}

void FiberDensityAccumulator::visit(uint64_t key) {
  if (key == last_key_) return;  // consecutive points in one voxel: most of them
  last_key_ = key;
  Voxel& v = voxels_[key];
  if (v.last_fiber == fiber_) return;  // the fiber came back to a voxel it crossed before
  v.last_fiber = fiber_;
  ++v.fibers;
}

void FiberDensityAccumulator::addFiber(const float* xyz, size_t n) {
  const double inv = 1.0 / voxel_mm_;
  last_key_ = UINT64_MAX;
  bool any = false;
  double a[3] = {0, 0, 0};
  bool have_a = false;
  for (size_t p = 0; p < n; ++p) {
    const double b[3] = {xyz[3 * p] * inv, xyz[3 * p + 1] * inv, xyz[3 * p + 2] * inv};
    if (!std::isfinite(b[0]) || !std::isfinite(b[1]) || !std::isfinite(b[2])) {
      have_a = false;  // a non-finite point breaks the polyline; readers reject them anyway
      continue;
    }
    const int64_t end[3] = {clampIndex(b[0]), clampIndex(b[1]), clampIndex(b[2])};
    if (!have_a) {
      visit(fiberDensityVoxelKey(end[0], end[1], end[2]));
    } else {
      // Amanatides-Woo: from a's voxel to b's, one face crossing at a time,
      // always crossing the nearest face along the segment. Exactly
      // |di| + |dj| + |dk| steps, so rounding can never make it overrun.
      int64_t cell[3] = {clampIndex(a[0]), clampIndex(a[1]), clampIndex(a[2])};
      int64_t remaining[3], step[3];
      double t_max[3], t_delta[3];
      int64_t total = 0;
      for (int axis = 0; axis < 3; ++axis) {
        const double d = b[axis] - a[axis];
        remaining[axis] = std::abs(end[axis] - cell[axis]);
        step[axis] = end[axis] > cell[axis] ? 1 : -1;
        total += remaining[axis];
        if (remaining[axis] == 0 || d == 0) {
          t_max[axis] = t_delta[axis] = INFINITY;
        } else {
          const double face = double(cell[axis] + (step[axis] > 0 ? 1 : 0));
          t_max[axis] = (face - a[axis]) / d;
          t_delta[axis] = 1.0 / std::abs(d);
        }
      }
      if (total > kMaxSegmentVoxels) {
        visit(fiberDensityVoxelKey(end[0], end[1], end[2]));
      } else {
        for (int64_t s = 0; s < total; ++s) {
          int axis = -1;
          for (int c = 0; c < 3; ++c)
            if (remaining[c] > 0 && (axis < 0 || t_max[c] < t_max[axis])) axis = c;
          cell[axis] += step[axis];
          --remaining[axis];
          t_max[axis] += t_delta[axis];
          visit(fiberDensityVoxelKey(cell[0], cell[1], cell[2]));
        }
      }
    }
    std::copy(b, b + 3, a);
    have_a = true;
    any = true;
  }
  if (any) ++fiber_;
}

void FiberDensityAccumulator::add(const Tractogram& chunk) {
  for (size_t f = 0; f < chunk.streamlineCount(); ++f)
    if (chunk.pointsIn(f) > 0) addFiber(chunk.point(chunk.offsets[f]), chunk.pointsIn(f));
}

void FiberDensityAccumulator::merge(const FiberDensityAccumulator& other) {
  if (other.voxel_mm_ != voxel_mm_) throw Error("fiber density accumulators of different voxel sizes cannot merge");
  for (const auto& [key, v] : other.voxels_) voxels_[key].fibers += v.fibers;
  // Fibers added later get indices above every stamp of either side.
  fiber_ += other.fiber_;
  last_key_ = UINT64_MAX;
}

FiberDensity FiberDensityAccumulator::result() const {
  FiberDensity r;
  r.voxel_mm = voxel_mm_;
  r.fibers = fiber_;
  r.occupied_voxels = voxels_.size();
  r.occupied_cm3 = double(voxels_.size()) * voxel_mm_ * voxel_mm_ * voxel_mm_ / 1000.0;
  if (voxels_.empty()) return r;
  std::vector<uint64_t> counts;
  counts.reserve(voxels_.size());
  double sum = 0;
  uint64_t single = 0;
  for (const auto& [key, v] : voxels_) {
    counts.push_back(v.fibers);
    sum += double(v.fibers);
    single += v.fibers == 1;
    const int bin = std::bit_width(v.fibers) - 1;
    if (r.histogram.size() <= size_t(bin)) r.histogram.resize(bin + 1, 0);
    ++r.histogram[bin];
  }
  std::sort(counts.begin(), counts.end());
  // Nearest-rank percentiles: the smallest count with at least q of the voxels at or below it.
  auto rank = [&](double q) {
    const size_t k = size_t(std::ceil(q * double(counts.size())));
    return counts[std::clamp<size_t>(k, 1, counts.size()) - 1];
  };
  r.mean = sum / double(counts.size());
  r.median = rank(0.5);
  r.p90 = rank(0.9);
  r.p99 = rank(0.99);
  r.max = counts.back();
  r.single_fiber_fraction = double(single) / double(counts.size());
  return r;
}

}  // namespace fibscope
