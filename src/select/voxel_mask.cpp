#include "select/voxel_mask.h"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>

#include "core/error.h"
#include "shared/voxel_mask.h"

namespace fibscope {
namespace {

// Voxel axes as MRtrix3's Header holds them: unit directions (the columns
// of `direction`), voxel sizes and the world position of voxel (0, 0, 0).
struct Grid {
  glm::dmat3 direction{1.0};  // column j: voxel axis j
  glm::dvec3 spacing{1.0};
  glm::dvec3 origin{0.0};
  int size[3] = {1, 1, 1};
};

Grid mrtrixGrid(const NiftiVolume& v) {
  Grid g;
  const glm::dmat3 linear(v.voxel_to_world);
  g.origin = glm::dvec3(v.voxel_to_world[3]);
  for (int j = 0; j < 3; ++j) g.size[j] = v.dims[j];
  if (v.affine_source == "sform") {
    // File::NIfTI::fetch: unit columns; pixdim as the voxel sizes unless one
    // is off its column's length by more than 1e-5, then all the lengths.
    bool rescale = false;
    for (int j = 0; j < 3; ++j)
      if (std::fabs(v.voxel_size_mm[j] / glm::length(linear[j]) - 1.0) > 1e-5) rescale = true;
    for (int j = 0; j < 3; ++j) {
      const double length = glm::length(linear[j]);
      g.direction[j] = linear[j] / length;
      g.spacing[j] = rescale ? length : v.voxel_size_mm[j];
    }
  } else {
    // qform: R * diag(pixdim) (with qfac), so the sizes are pixdim; the
    // nibabel fallback: the columns' lengths (1 on missing axes).
    for (int j = 0; j < 3; ++j) {
      g.spacing[j] = v.affine_source == "qform" ? v.voxel_size_mm[j] : glm::length(linear[j]);
      g.direction[j] = linear[j] / g.spacing[j];
    }
  }
  return g;
}

// Header::realign_transform with Axes::get_permutation_to_make_axial: the
// voxel axis nearest world axis i becomes axis i, flipped to point along it.
// file_axis[i] and flipped[i] say where new axis i comes from.
Grid realign(const Grid& g, int file_axis[3], bool flipped[3]) {
  int perm[3];
  for (int i = 0; i < 3; ++i) {
    // The first largest |direction(i, j)| of row i.
    perm[i] = 0;
    for (int j = 1; j < 3; ++j)
      if (std::fabs(g.direction[j][i]) > std::fabs(g.direction[perm[i]][i])) perm[i] = j;
  }
  auto other = [](int a, int b) {
    for (int i = 0; i < 3; ++i)
      if (i != a && i != b) return i;
    return 0;
  };
  if (perm[0] == perm[1]) perm[1] = other(perm[0], perm[2]);
  if (perm[0] == perm[2]) perm[2] = other(perm[0], perm[1]);
  if (perm[1] == perm[2]) perm[2] = other(perm[0], perm[1]);
  bool flip[3];
  for (int i = 0; i < 3; ++i) flip[perm[i]] = g.direction[perm[i]][i] < 0.0;

  Grid flippedGrid = g;
  for (int j = 0; j < 3; ++j) {
    if (!flip[j]) continue;
    // The far end of the axis becomes voxel 0 (same operations as MRtrix3).
    const double length = double(g.size[j] - 1) * g.spacing[j];
    for (int n = 0; n < 3; ++n) {
      flippedGrid.direction[j][n] = -flippedGrid.direction[j][n];
      flippedGrid.origin[n] -= length * flippedGrid.direction[j][n];
    }
  }
  Grid out = flippedGrid;
  for (int i = 0; i < 3; ++i) {
    out.direction[i] = flippedGrid.direction[perm[i]];
    out.spacing[i] = flippedGrid.spacing[perm[i]];
    out.size[i] = flippedGrid.size[perm[i]];
    file_axis[i] = perm[i];
    flipped[i] = flip[perm[i]];
  }
  return out;
}

}  // namespace

bool VoxelMask::voxelOf(const float* p, int voxel[3]) const {
  const shader::vec3 q(p[0], p[1], p[2]);
  for (int i = 0; i < 3; ++i) {
    const float r = shader::roundHalfAwayFromZero(shader::voxelMaskCoordinate(world_to_voxel[i], q));
    if (!(r >= 0.0f && r < float(size[i]))) return false;
    voxel[i] = int(r);
  }
  return true;
}

bool VoxelMask::contains(const float* p) const {
  int v[3];
  if (!voxelOf(p, v)) return false;
  const size_t bit = (size_t(v[2]) * size_t(size[1]) + size_t(v[1])) * size_t(size[0]) + size_t(v[0]);
  return bits[bit >> 5] >> (bit & 31) & 1u;
}

VoxelMask makeVoxelMask(const NiftiVolume& volume) {
  int file_axis[3];
  bool flipped[3];
  const Grid grid = realign(mrtrixGrid(volume), file_axis, flipped);

  // The set voxels' bounding box in the realigned grid.
  auto fileIndex = [&](const int a[3]) {
    int f[3];
    for (int i = 0; i < 3; ++i) f[file_axis[i]] = flipped[i] ? grid.size[i] - 1 - a[i] : a[i];
    return volume.index(f[0], f[1], f[2]);
  };
  int lo[3] = {grid.size[0], grid.size[1], grid.size[2]}, hi[3] = {-1, -1, -1};
  uint64_t set = 0;
  int a[3];
  for (a[2] = 0; a[2] < grid.size[2]; ++a[2])
    for (a[1] = 0; a[1] < grid.size[1]; ++a[1])
      for (a[0] = 0; a[0] < grid.size[0]; ++a[0]) {
        if (volume.values[fileIndex(a)] == 0.0f) continue;
        ++set;
        for (int i = 0; i < 3; ++i) {
          lo[i] = std::min(lo[i], a[i]);
          hi[i] = std::max(hi[i], a[i]);
        }
      }
  if (set == 0) fail(volume.path, "the mask is empty (no voxel is >= 0.5 in magnitude)");

  // Tractography::Mask's crop: one voxel of margin where the image has it.
  VoxelMask m;
  m.path = volume.path;
  m.set_voxels = set;
  int from[3];
  for (int i = 0; i < 3; ++i) {
    from[i] = lo[i] > 0 ? lo[i] - 1 : 0;
    m.size[i] = std::min(grid.size[i] - from[i], hi[i] + 2 - from[i]);
  }
  glm::dvec3 origin = grid.origin;  // Adapter::Subset's translation, same order
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) origin[i] += double(from[j]) * grid.spacing[j] * grid.direction[j][i];

  // Transform(header): voxel2scanner = direction * diag(spacing), and its
  // inverse in double, then cast to float as Mask::scanner2voxel is.
  glm::dmat3 linear;
  for (int j = 0; j < 3; ++j) linear[j] = grid.direction[j] * grid.spacing[j];
  const glm::dmat3 inverse = glm::inverse(linear);
  const glm::dvec3 translation = -inverse * origin;
  for (int i = 0; i < 3; ++i)
    m.world_to_voxel[i] = shader::vec4(float(inverse[0][i]), float(inverse[1][i]), float(inverse[2][i]),
                                       float(translation[i]));

  const size_t count = size_t(m.size[0]) * size_t(m.size[1]) * size_t(m.size[2]);
  m.bits.assign((count + 31) / 32, 0u);
  int b[3];
  for (b[2] = 0; b[2] < m.size[2]; ++b[2])
    for (b[1] = 0; b[1] < m.size[1]; ++b[1])
      for (b[0] = 0; b[0] < m.size[0]; ++b[0]) {
        const int g[3] = {b[0] + from[0], b[1] + from[1], b[2] + from[2]};
        if (volume.values[fileIndex(g)] == 0.0f) continue;
        const size_t bit = (size_t(b[2]) * size_t(m.size[1]) + size_t(b[1])) * size_t(m.size[0]) + size_t(b[0]);
        m.bits[bit >> 5] |= 1u << (bit & 31);
      }
  return m;
}

std::shared_ptr<const VoxelMask> loadVoxelMask(const std::string& path) {
  return std::make_shared<const VoxelMask>(makeVoxelMask(loadNiftiVolume(path, NiftiValues::MrtrixMask)));
}

}  // namespace fibscope
