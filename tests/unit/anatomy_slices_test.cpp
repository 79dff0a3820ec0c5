// The CPU side of anatomical slices (render/anatomy_slices.h): the slice
// planes through the voxels of an oblique affine, the slab that follows the
// active slice, the robust display range against a sort, the settings a
// volume starts with, the depth range that keeps a volume in view, and the
// refusal of a volume too large to show. No GPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "render/anatomy_slices.h"
#include "test_support.h"

namespace fibscope {
namespace {

// An oblique, anisotropic, flipped grid (voxel -> world), as sforms are.
AnatomyGrid obliqueGrid() {
  glm::dmat4 m = glm::rotate(glm::dmat4(1.0), glm::radians(25.0), glm::normalize(glm::dvec3(1, -2, 0.5)));
  m = m * glm::scale(glm::dmat4(1.0), glm::dvec3(1.5, -0.9, 2.2));
  m[3] = glm::dvec4(-40, 12.5, -7, 1);
  AnatomyGrid g;
  g.dims = {40, 50, 30};
  g.voxel_to_world = m;
  g.world_to_voxel = glm::inverse(m);
  return g;
}

glm::dvec3 world(const AnatomyGrid& g, glm::dvec3 voxel) { return glm::dvec3(g.voxel_to_world * glm::dvec4(voxel, 1.0)); }

double side(const PlaneEq& p, glm::dvec3 x) { return p[0] * x.x + p[1] * x.y + p[2] * x.z + p[3]; }

TEST(AnatomySlices, aSlicePlaneHoldsItsVoxelsAndFacesIncreasingVoxelCoordinate) {
  const AnatomyGrid g = obliqueGrid();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5, 60);
  for (int axis = 0; axis < 3; ++axis) {
    const double position = 12.25;
    const PlaneEq p = slicePlane(g, axis, position);
    EXPECT_NEAR(std::hypot(p[0], p[1], p[2]), 1.0, 1e-12);
    for (int n = 0; n < 20; ++n) {
      glm::dvec3 v(u(rng), u(rng), u(rng));
      v[axis] = position;
      EXPECT_NEAR(side(p, world(g, v)), 0.0, 1e-9);
      glm::dvec3 w = v;
      w[axis] += 1;  // one voxel further along the axis: in front, by the spacing along the normal
      EXPECT_GT(side(p, world(g, w)), 0.5);
    }
  }
}

TEST(AnatomySlices, theSlabFollowsTheActiveSliceOnlyWhenAsked) {
  const AnatomyGrid g = obliqueGrid();
  RenderSettings s;
  s.slice_j = 17;
  s.active_slice = SliceAxis::J;
  EXPECT_FALSE(withSlabFollowingSlice(s, g).slab_plane.has_value());
  s.slab_follows_slice = true;
  const RenderSettings followed = withSlabFollowingSlice(s, g);
  ASSERT_TRUE(followed.slab_plane.has_value());
  EXPECT_EQ(*followed.slab_plane, slicePlane(g, 1, 17));
}

TEST(AnatomySlices, theRobustRangeIsTheSecondAndNinetyEighthPercentileOfTheFiniteValues) {
  std::vector<float> values(1001);
  std::iota(values.begin(), values.end(), -500.0f);
  std::shuffle(values.begin(), values.end(), std::mt19937(5));
  values.push_back(NAN);
  values.push_back(INFINITY);
  values.push_back(-INFINITY);
  // The sorted finite values' entries round(0.02 * 1000) and round(0.98 * 1000).
  std::vector<float> sorted;
  for (float v : values)
    if (std::isfinite(v)) sorted.push_back(v);
  std::sort(sorted.begin(), sorted.end());
  const ValueRange r = robustValueRange(values);
  EXPECT_EQ(r.min, sorted[20]);
  EXPECT_EQ(r.max, sorted[980]);

  // A mask of 1 % ones: the percentiles agree, the min and max do not.
  std::vector<float> mask(1000, 0.0f);
  for (int i = 0; i < 10; ++i) mask[size_t(i) * 97] = 1.0f;
  EXPECT_EQ(robustValueRange(mask).min, 0.0f);
  EXPECT_EQ(robustValueRange(mask).max, 1.0f);
  const std::vector<float> constant(50, 7.0f);
  EXPECT_EQ(robustValueRange(constant).min, 6.0f);
  EXPECT_EQ(robustValueRange(constant).max, 7.0f);
  const std::vector<float> none = {NAN, INFINITY};
  EXPECT_EQ(robustValueRange(none).min, 0.0f);
  EXPECT_EQ(robustValueRange(none).max, 1.0f);
}

TEST(AnatomySlices, aVolumeStartsCentredAtItsRobustRangeUnlessTheUserGaveThem) {
  const AnatomyGrid g = obliqueGrid();
  RenderSettings s;
  s.slice_i = 3;
  s.anatomy_min = -2;
  s.anatomy_max = 2;
  fitAnatomySettings(s, g, ValueRange{10, 90}, [](std::string_view name) { return name == "slice-i"; });
  EXPECT_EQ(s.slice_i, 3.0f);
  EXPECT_EQ(s.slice_j, 24.5f);
  EXPECT_EQ(s.slice_k, 14.5f);
  EXPECT_EQ(s.anatomy_min, 10.0f);
  EXPECT_EQ(s.anatomy_max, 90.0f);
  fitAnatomySettings(s, g, ValueRange{0, 1}, [](std::string_view name) { return name == "anatomy-range"; });
  EXPECT_EQ(s.slice_i, 19.5f);
  EXPECT_EQ(s.anatomy_max, 90.0f);
}

TEST(AnatomySlices, theDepthRangeWidensToTheWholeVolumeAndNeverNarrows) {
  const AnatomyGrid g = obliqueGrid();
  Bounds small;
  small.min = {-5, -5, -5};
  small.max = {5, 5, 5};
  const Camera framed = fitCamera(small, {1, 0.3, 0.2}, {0, 0, 1}, 64, 48);
  const std::array<Vec3d, 8> corners = volumeCorners(g);
  const Camera wide = enclosingDepthRange(framed, corners);
  const glm::dvec3 eye(wide.eye[0], wide.eye[1], wide.eye[2]);
  const glm::dvec3 forward = glm::normalize(glm::dvec3(wide.target[0], wide.target[1], wide.target[2]) - eye);
  for (const Vec3d& c : corners) {
    const double d = glm::dot(glm::dvec3(c[0], c[1], c[2]) - eye, forward);
    if (d <= 0) continue;
    EXPECT_GT(d, wide.near_mm);
    EXPECT_LT(d, wide.far_mm);
  }
  EXPECT_LE(wide.near_mm, framed.near_mm);
  EXPECT_GE(wide.far_mm, framed.far_mm);
  // The corners are the voxel grid's outer faces.
  EXPECT_NEAR(glm::length(glm::dvec3(corners[7][0], corners[7][1], corners[7][2]) - world(g, glm::dvec3(39.5, 49.5, 29.5))),
              0.0, 1e-9);
}

// A NIfTI-1 header (and 4 bytes of extension flags) of a float32 volume of
// the given size, with no voxels after it.
std::string niftiHeaderOnly(int nx, int ny, int nz) {
  std::string h(352, '\0');
  auto put32 = [&](size_t at, int32_t v) { std::memcpy(&h[at], &v, 4); };
  auto put16 = [&](size_t at, int16_t v) { std::memcpy(&h[at], &v, 2); };
  auto putf = [&](size_t at, float v) { std::memcpy(&h[at], &v, 4); };
  put32(0, 348);
  const int16_t dims[8] = {3, int16_t(nx), int16_t(ny), int16_t(nz), 1, 1, 1, 1};
  for (int i = 0; i < 8; ++i) put16(40 + 2 * size_t(i), dims[i]);
  put16(70, 16);  // DT_FLOAT32
  put16(72, 32);
  for (int i = 0; i < 4; ++i) putf(76 + 4 * size_t(i), 1.0f);
  putf(108, 352.0f);  // vox_offset
  std::memcpy(&h[344], "n+1\0", 4);
  return h;
}

TEST(AnatomySlices, aVolumeTooLargeToShowIsRefusedByItsHeaderInOneLineNamingTheFile) {
  test::TempDir dir;
  const std::string path = dir.file("huge.nii");
  test::writeBytes(path, niftiHeaderOnly(1024, 1024, 1024));
  const std::string message = test::errorOf([&] { loadAnatomyVolume(path); });
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("1024 x 1024 x 1024"), std::string::npos) << message;
  EXPECT_NE(message.find(std::to_string(kMaxAnatomyVoxels)), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  // The same header read as a mask (no limit) is refused for its missing voxels instead.
  const std::string truncated = test::errorOf([&] { loadNiftiVolume(path); });
  EXPECT_NE(truncated.find("truncated"), std::string::npos) << truncated;
}

}  // namespace
}  // namespace fibscope
