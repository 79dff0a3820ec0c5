// Mask regions (select/voxel_mask.h, shared/voxel_mask.h): the nearest-voxel
// rule on hand-made points (voxel centres, half-way points, the image's
// edges), for every storage order of the same world-space mask; the crop;
// `mask:PATH` specs; and against MRtrix3's tckedit on points a few float
// ulps from the faces between set and unset voxels (tests/tools/nifti_make.py
// masks), where any other arithmetic than tckedit's goes the other way on
// some of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "core/error.h"
#include "io/reader.h"
#include "select/region.h"
#include "select/voxel_mask.h"
#include "shared/voxel_mask.h"
#include "test_support.h"

namespace fibscope {
namespace {

TEST(VoxelMask, roundingIsHalfAwayFromZeroForEveryFloat) {
  for (const float c : {0.49999997f, 0.5f, -0.5f, -0.49999997f, 1.5f, 2.5f, -2.5f, 0.0f, -0.0f, 8388607.5f, 8388608.0f,
                        1e30f, -1e30f, 16777215.0f})
    EXPECT_EQ(shader::roundHalfAwayFromZero(c), std::round(c)) << c;
  EXPECT_TRUE(std::isnan(shader::roundHalfAwayFromZero(NAN)));
  // Against the C library on quarter and half steps and their neighbours.
  for (int k = -4000; k <= 4000; ++k) {
    const float q = float(k) / 4.0f;
    for (const float c : {std::nextafter(q, -INFINITY), q, std::nextafter(q, INFINITY)})
      ASSERT_EQ(shader::roundHalfAwayFromZero(c), std::round(c)) << c;
  }
}

// A volume as loadNiftiVolume(…, MrtrixMask) gives it: 0/1 values, an sform
// whose column lengths are the voxel sizes.
NiftiVolume maskVolume(glm::ivec3 dims, const glm::dmat4& voxel_to_world, const std::vector<int>& set) {
  NiftiVolume v;
  v.path = "hand-made.nii";
  v.dims = dims;
  v.voxel_to_world = voxel_to_world;
  v.world_to_voxel = glm::inverse(voxel_to_world);
  v.affine_source = "sform";
  for (int j = 0; j < 3; ++j) v.voxel_size_mm[j] = glm::length(glm::dvec3(voxel_to_world[j]));
  v.values.assign(size_t(dims.x) * dims.y * dims.z, 0.0f);
  for (size_t i = 0; i + 2 < set.size(); i += 3) v.values[v.index(set[i], set[i + 1], set[i + 2])] = 1.0f;
  return v;
}

bool inside(const VoxelMask& m, float x, float y, float z) {
  const float p[3] = {x, y, z};
  return m.contains(p);
}

// Voxel -> world with voxel axes along world axes `axis`, `sign` (+1 / -1),
// 1 mm, so that world voxel centres are the integers 0..n-1 in any order.
glm::dmat4 storage(const int axis[3], const int sign[3], glm::ivec3 world_dims) {
  glm::dmat4 a(0.0);
  a[3][3] = 1;
  for (int j = 0; j < 3; ++j) {
    a[j][axis[j]] = sign[j];
    if (sign[j] < 0) a[3][axis[j]] = world_dims[axis[j]] - 1;
  }
  return a;
}

// The same world-space mask (voxel centres at integer mm, set voxels given
// in world coordinates) stored in each of the 48 orders and directions.
std::vector<VoxelMask> everyStorageOf(glm::ivec3 world_dims, const std::vector<int>& world_set) {
  std::vector<VoxelMask> out;
  int axis[3] = {0, 1, 2};
  do {
    for (int flips = 0; flips < 8; ++flips) {
      const int sign[3] = {flips & 1 ? -1 : 1, flips & 2 ? -1 : 1, flips & 4 ? -1 : 1};
      const glm::dmat4 a = storage(axis, sign, world_dims);
      const glm::dmat4 inv = glm::inverse(a);
      glm::ivec3 dims;
      for (int j = 0; j < 3; ++j) dims[j] = world_dims[axis[j]];
      std::vector<int> set;
      for (size_t i = 0; i + 2 < world_set.size(); i += 3) {
        const glm::dvec4 v = inv * glm::dvec4(world_set[i], world_set[i + 1], world_set[i + 2], 1.0);
        for (int k = 0; k < 3; ++k) set.push_back(int(std::lround(v[k])));
      }
      out.push_back(makeVoxelMask(maskVolume(dims, a, set)));
    }
  } while (std::next_permutation(axis, axis + 3));
  return out;
}

TEST(VoxelMask, nearestVoxelAtCentresHalfWaysAndEdgesWhateverTheStorageOrder) {
  // World voxels 0..3 x 0..3 x 0..3 (1 mm, centres at integers); set: (2,1,1)
  // and the corner (0,3,3).
  const std::vector<VoxelMask> masks = everyStorageOf({4, 4, 4}, {2, 1, 1, 0, 3, 3});
  ASSERT_EQ(masks.size(), 48u);
  for (size_t s = 0; s < masks.size(); ++s) {
    SCOPED_TRACE("storage " + std::to_string(s));
    const VoxelMask& m = masks[s];
    EXPECT_TRUE(inside(m, 2, 1, 1));
    EXPECT_FALSE(inside(m, 1, 1, 1));
    EXPECT_TRUE(inside(m, 0, 3, 3));
    // Half-way points go to the voxel on the R, A, S side (tckedit rounds
    // half away from zero in the realigned, near-RAS grid).
    EXPECT_TRUE(inside(m, 1.5f, 1, 1));
    EXPECT_FALSE(inside(m, 2.5f, 1, 1));
    EXPECT_TRUE(inside(m, 2, 0.5f, 1));
    EXPECT_FALSE(inside(m, 2, 1.5f, 1));
    EXPECT_TRUE(inside(m, 2, 1, 0.5f));
    EXPECT_FALSE(inside(m, 2, 1, 1.5f));
    EXPECT_FALSE(inside(m, std::nextafter(1.5f, 0.0f), 1, 1)) << "an ulp below the half-way point";
    EXPECT_TRUE(inside(m, std::nextafter(2.5f, 0.0f), 1, 1));
    // Outside the image is outside: -0.5 rounds to -1, 3.5 to 4.
    EXPECT_TRUE(inside(m, -0.49f, 3, 3));
    EXPECT_FALSE(inside(m, -0.5f, 3, 3));
    EXPECT_TRUE(inside(m, 0, 3.49f, 3));
    EXPECT_FALSE(inside(m, 0, 3.5f, 3));
    EXPECT_TRUE(inside(m, 0, 3, 3.49f));
    EXPECT_FALSE(inside(m, 0, 3, 3.5f));
    EXPECT_FALSE(inside(m, 0, 3, 300));
    EXPECT_FALSE(inside(m, NAN, 3, 3));
    EXPECT_FALSE(inside(m, 0, INFINITY, 3));
  }
}

TEST(VoxelMask, everyVoxelCentreOfAnObliqueImageIsItsOwnVoxel) {
  // Rotated, anisotropic, with permuted and flipped axes: every voxel centre
  // must be decided by that voxel's value (whatever realignment and crop do).
  std::mt19937 rng(7);
  for (const glm::dvec3& angles : {glm::dvec3(0, 0, 0), glm::dvec3(20, -10, 35), glm::dvec3(5, 80, -100),
                                  glm::dvec3(170, 30, 60)}) {
    SCOPED_TRACE(angles.x);
    glm::dmat4 a(1.0);
    const glm::dmat3 rx(1, 0, 0, 0, std::cos(glm::radians(angles.x)), std::sin(glm::radians(angles.x)), 0,
                        -std::sin(glm::radians(angles.x)), std::cos(glm::radians(angles.x)));
    const glm::dmat3 ry(std::cos(glm::radians(angles.y)), 0, -std::sin(glm::radians(angles.y)), 0, 1, 0,
                        std::sin(glm::radians(angles.y)), 0, std::cos(glm::radians(angles.y)));
    const glm::dmat3 rz(std::cos(glm::radians(angles.z)), std::sin(glm::radians(angles.z)), 0,
                        -std::sin(glm::radians(angles.z)), std::cos(glm::radians(angles.z)), 0, 0, 0, 1);
    const glm::dmat3 r = rz * ry * rx * glm::dmat3(glm::dvec3(1.3, 0, 0), glm::dvec3(0, -0.9, 0), glm::dvec3(0, 0, 2.1));
    for (int j = 0; j < 3; ++j) a[j] = glm::dvec4(r[j], 0.0);
    a[3] = glm::dvec4(-7.5, 3.25, 11.0, 1.0);
    const glm::ivec3 dims(9, 7, 6);
    std::vector<int> set;
    for (int k = 1; k < dims.z - 1; ++k)
      for (int j = 1; j < dims.y - 1; ++j)
        for (int i = 2; i < dims.x - 1; ++i)
          if (rng() % 3 == 0) set.insert(set.end(), {i, j, k});
    const NiftiVolume v = maskVolume(dims, a, set);
    const VoxelMask m = makeVoxelMask(v);
    EXPECT_EQ(m.set_voxels, set.size() / 3);
    for (int k = 0; k < dims.z; ++k)
      for (int j = 0; j < dims.y; ++j)
        for (int i = 0; i < dims.x; ++i) {
          const glm::dvec4 w = a * glm::dvec4(i, j, k, 1.0);
          ASSERT_EQ(inside(m, float(w.x), float(w.y), float(w.z)), v.value(i, j, k) != 0) << i << " " << j << " " << k;
        }
  }
}

TEST(VoxelMask, isCroppedToItsSetVoxelsAndOneMoreAsTckeditDoes) {
  const glm::dmat4 ras(1.0);
  auto sizeOf = [&](const std::vector<int>& set) {
    const VoxelMask m = makeVoxelMask(maskVolume({10, 10, 10}, ras, set));
    return glm::ivec3(m.size[0], m.size[1], m.size[2]);
  };
  EXPECT_EQ(sizeOf({5, 5, 5}), glm::ivec3(3, 3, 3));
  EXPECT_EQ(sizeOf({0, 0, 0}), glm::ivec3(2, 2, 2));
  EXPECT_EQ(sizeOf({9, 9, 9}), glm::ivec3(2, 2, 2));
  EXPECT_EQ(sizeOf({2, 3, 4, 6, 3, 4}), glm::ivec3(7, 3, 3));
  const std::string empty = test::errorOf([&] { makeVoxelMask(maskVolume({4, 4, 4}, ras, {})); });
  EXPECT_EQ(empty.rfind("hand-made.nii: ", 0), 0u) << empty;
  EXPECT_NE(empty.find("empty"), std::string::npos) << empty;
}

// --- mask:PATH regions and tckedit ------------------------------------------

class MaskAgainstTckedit : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (test::runCommand("command -v tckedit").exit_code != 0) {
      skip_ = "MRtrix3 (tckedit) not installed";
      return;
    }
    if (test::pythonWithNibabel().empty()) {
      skip_ = "needs /usr/bin/python3 with nibabel and numpy";
      return;
    }
    dir_ = new test::TempDir;
    const auto r = test::runCommand(test::pythonWithNibabel() + " " + test::toolPath("nifti_make.py") + " masks " +
                                    dir_->path());
    made_ = r.exit_code == 0;
    output_ = r.output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    ASSERT_TRUE(made_) << output_;
  }
  static inline test::TempDir* dir_ = nullptr;
  static inline bool made_ = false;
  static inline std::string skip_, output_;
};

TEST_F(MaskAgainstTckedit, pointsAFewUlpsFromVoxelFacesGoWhereTckeditPutsThem) {
  // Permuted and flipped oblique, RAS, float non-binary, gzipped LAS scaled.
  for (const std::string name : {"blob", "oblique", "float", "blob_gz"}) {
    const std::string mask = dir_->file(name + (name == "blob_gz" ? ".nii.gz" : ".nii"));
    const std::string in = dir_->file("faces_" + name + ".tck");
    for (const std::string option : {"include", "exclude"}) {
      SCOPED_TRACE(name + " -" + option);
      const std::string want = dir_->file("want.tck"), got = dir_->file("got.tck");
      const auto t = test::runCommand("tckedit -quiet -force -nthreads 0 " + in + " " + want + " -" + option + " " + mask);
      ASSERT_EQ(t.exit_code, 0) << t.output;
      const auto f = test::runFibscope("filter --force " + in + " " + got + " --" + option + " mask:" + mask);
      ASSERT_EQ(f.exit_code, 0) << f.output;
      const Tractogram all = readTractogram(in), a = readTractogram(want), b = readTractogram(got);
      // About half of the points on each side of the faces.
      ASSERT_GT(a.streamlineCount(), all.streamlineCount() / 5);
      ASSERT_LT(a.streamlineCount(), all.streamlineCount() * 4 / 5);
      ASSERT_EQ(b.streamlineCount(), a.streamlineCount());
      EXPECT_EQ(b.positions, a.positions);
    }
  }
}

TEST_F(MaskAgainstTckedit, maskSpecsKeepTheirPathWithColonsAndCommas) {
  const std::string odd = dir_->file("a:b,c.nii");
  std::filesystem::copy_file(dir_->file("blob.nii"), odd, std::filesystem::copy_options::overwrite_existing);
  const Region r = parseRegion("mask:" + odd);
  EXPECT_EQ(regionSpec(r), "mask:" + odd);
  const float centre[3] = {25, 0, 0}, far[3] = {-25, 0, 0};
  EXPECT_TRUE(regionContains(r, centre));
  EXPECT_FALSE(regionContains(r, far));
  const Region copy = r;  // shares the loaded mask
  EXPECT_EQ(std::get<MaskRegion>(copy).mask.get(), std::get<MaskRegion>(r).mask.get());
  const std::string empty = test::errorOf([] { parseRegion("mask:"); });
  EXPECT_EQ(empty.rfind("mask:: ", 0), 0u) << empty;
  const std::string missing = test::errorOf([&] { parseRegion("mask:" + dir_->file("none.nii")); });
  EXPECT_EQ(missing.rfind(dir_->file("none.nii") + ": ", 0), 0u) << missing;
}

}  // namespace
}  // namespace fibscope
