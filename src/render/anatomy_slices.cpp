#include "render/anatomy_slices.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"

namespace fibscope {

NiftiVolume loadAnatomyVolume(const std::string& path) {
  return loadNiftiVolume(path, NiftiValues::Scaled,
                         NiftiVoxelLimit{kMaxAnatomyVoxels, "an anatomical image (512^3, 512 MiB as float)"});
}

AnatomyGrid anatomyGrid(const NiftiVolume& volume) {
  return AnatomyGrid{volume.dims, volume.voxel_to_world, volume.world_to_voxel};
}

PlaneEq slicePlane(const AnatomyGrid& grid, int axis, double position) {
  // Voxel coordinate `axis` of world p is row `axis` of world_to_voxel
  // (glm is column-major: m[column][row]) times (p, 1).
  const glm::dmat4& m = grid.world_to_voxel;
  const glm::dvec3 row(m[0][axis], m[1][axis], m[2][axis]);
  const double length = glm::length(row);
  return {row.x / length, row.y / length, row.z / length, (m[3][axis] - position) / length};
}

namespace {
constexpr std::string_view kViews[3] = {"sagittal", "coronal", "axial"};  // normals along x, y, z
}  // namespace

std::string_view sliceAxisView(const AnatomyGrid& grid, int axis) {
  const PlaneEq p = slicePlane(grid, axis, 0);
  const double c[3] = {std::abs(p[0]), std::abs(p[1]), std::abs(p[2])};
  return kViews[c[0] >= c[1] && c[0] >= c[2] ? 0 : c[1] >= c[2] ? 1 : 2];
}

int anatomicalSliceAxis(const AnatomyGrid& grid, std::string_view view) {
  const auto it = std::find(std::begin(kViews), std::end(kViews), view);
  if (it == std::end(kViews)) return -1;
  const int world = int(it - std::begin(kViews));
  // The axis whose normal has the largest share of that world axis.
  int best = 0;
  double most = -1;
  for (int axis = 0; axis < 3; ++axis) {
    const PlaneEq p = slicePlane(grid, axis, 0);
    const double c = std::abs(p[size_t(world)]);
    if (c > most) most = c, best = axis;
  }
  return best;
}

RenderSettings withSlabFollowingSlice(const RenderSettings& settings, const AnatomyGrid& grid) {
  if (!settings.slab_follows_slice) return settings;
  RenderSettings s = settings;
  const int axis = int(settings.active_slice);
  s.slab_plane = slicePlane(grid, axis, slicePosition(settings, axis));
  return s;
}

ValueRange robustValueRange(std::span<const float> values) {
  constexpr size_t kMaxSamples = size_t(1) << 22;
  const size_t stride = std::max<size_t>(1, (values.size() + kMaxSamples - 1) / kMaxSamples);
  std::vector<float> finite;
  finite.reserve(std::min(values.size(), kMaxSamples));
  for (size_t i = 0; i < values.size(); i += stride)
    if (std::isfinite(values[i])) finite.push_back(values[i]);
  if (finite.empty()) return {};
  auto percentile = [&](double p) {
    const size_t rank = size_t(std::floor(p * double(finite.size() - 1) + 0.5));
    std::nth_element(finite.begin(), finite.begin() + std::ptrdiff_t(rank), finite.end());
    return finite[rank];
  };
  ValueRange r{percentile(0.02), percentile(0.98)};
  if (r.min < r.max) return r;
  const auto [lo, hi] = std::minmax_element(finite.begin(), finite.end());
  if (*lo < *hi) return {*lo, *hi};
  return {*lo - 1.0f, *lo};
}

float sliceCentre(const AnatomyGrid& grid, int axis) { return 0.5f * float(grid.dims[axis] - 1); }

void fitAnatomySettings(RenderSettings& settings, const AnatomyGrid& grid, ValueRange robust,
                        const std::function<bool(std::string_view)>& given) {
  constexpr std::string_view kNames[3] = {"slice-i", "slice-j", "slice-k"};
  for (int a = 0; a < 3; ++a)
    if (!given(kNames[a])) setSlicePosition(settings, a, sliceCentre(grid, a));
  if (!given("anatomy-range")) {
    settings.anatomy_min = robust.min;
    settings.anatomy_max = robust.max;
  }
}

std::array<Vec3d, 8> volumeCorners(const AnatomyGrid& grid) {
  std::array<Vec3d, 8> corners{};
  for (int c = 0; c < 8; ++c) {
    const glm::dvec4 v((c & 1) ? grid.dims.x - 0.5 : -0.5, (c & 2) ? grid.dims.y - 0.5 : -0.5,
                       (c & 4) ? grid.dims.z - 0.5 : -0.5, 1.0);
    const glm::dvec4 w = grid.voxel_to_world * v;
    corners[size_t(c)] = {w.x, w.y, w.z};
  }
  return corners;
}

}  // namespace fibscope
