// `fibscope render --pipeline svo-straight | svo-curved` as a user meets it: a small
// phantom rendered as octree-traced straight tubes (the summary reports the
// build), and one-line errors with exit code 2 for a bad radius or voxel
// size. Validation layers on. Skipped without a Vulkan device.
#include <gtest/gtest.h>

#include <string>

#include "test_support.h"

namespace fibscope {
namespace {

test::CommandResult runFibscope(const std::string& args) {
  return test::runCommand(std::string(FIBSCOPE_EXE) + " " + args);
}

class GpuCliSvo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = runFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  test::TempDir dir_;
};

TEST_F(GpuCliSvo, renderDrawsThePhantomAsOctreeTracedTubes) {
  const std::string common = "render --validate --phantom-streamlines 20 --size 96x72 --view axial --no-ssao -o ";
  const std::string lines = dir_.file("lines.png"), tubes = dir_.file("svo.png");
  const auto a = runFibscope(common + lines);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const auto b = runFibscope(common + tubes + " --pipeline svo-straight --tube-radius 2.0 --tube-tolerance 0.05");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_NE(b.output.find("svo: "), std::string::npos) << b.output;
  EXPECT_NE(b.output.find("leaves"), std::string::npos) << b.output;
  const test::Png pa = test::readOurPng(lines), pb = test::readOurPng(tubes);
  ASSERT_EQ(pa.rgba.size(), pb.rgba.size());
  size_t changed = 0;
  for (size_t i = 0; i < pa.rgba.size(); i += 4)
    changed += pa.rgba[i] != pb.rgba[i] || pa.rgba[i + 1] != pb.rgba[i + 1] || pa.rgba[i + 2] != pb.rgba[i + 2];
  EXPECT_GT(changed, 200u) << changed;
}

// svo-curved: the same small phantom as sphere-traced curved tubes,
// resampled to 0.1 mm tolerance (few nodes a fiber, so the curves bow away
// from the straight capsules between the same nodes): it draws tubes, reports the build, and its picture
// differs from svo-straight's.
TEST_F(GpuCliSvo, renderDrawsThePhantomAsCurvedOctreeTubes) {
  const std::string common = "render --validate --phantom-streamlines 12 --size 96x72 --view axial --no-ssao -o ";
  const std::string lines = dir_.file("lines.png"), straight = dir_.file("straight.png"), curved = dir_.file("curved.png");
  const auto a = runFibscope(common + lines);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const std::string tube = " --tube-radius 1.5 --voxel 1.5 --tube-tolerance 0.1";
  const auto b = runFibscope(common + straight + " --pipeline svo-straight" + tube);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const auto c = runFibscope(common + curved + " --pipeline svo-curved" + tube);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  EXPECT_NE(c.output.find("svo: "), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("trace"), std::string::npos) << c.output;
  const test::Png pa = test::readOurPng(lines), pb = test::readOurPng(straight), pc = test::readOurPng(curved);
  ASSERT_EQ(pa.rgba.size(), pc.rgba.size());
  ASSERT_EQ(pb.rgba.size(), pc.rgba.size());
  const auto differ = [](const test::Png& x, const test::Png& y) {
    size_t n = 0;
    for (size_t i = 0; i < x.rgba.size(); i += 4)
      n += x.rgba[i] != y.rgba[i] || x.rgba[i + 1] != y.rgba[i + 1] || x.rgba[i + 2] != y.rgba[i + 2];
    return n;
  };
  EXPECT_GT(differ(pa, pc), 200u);
  EXPECT_GT(differ(pb, pc), 0u);
  // --voxel is for the SVO pipelines only.
  const auto d = runFibscope(common + dir_.file("x.png") + " --voxel 0.5");
  EXPECT_EQ(d.exit_code, 2) << d.output;
}

// --ao-method df --df-shadows (issue 16 item 4): the tubes' distance field
// is built and reported with its passes' times, and the picture differs
// from SSAO's.
TEST_F(GpuCliSvo, renderShadesTheTubesWithDistanceFieldAoAndShadows) {
  const std::string common = "render --validate --phantom-streamlines 20 --size 96x72 --view axial --pipeline "
                             "svo-straight --tube-radius 2.0 --tube-tolerance 0.05 -o ";
  const std::string ssao = dir_.file("ssao.png"), df = dir_.file("df.png");
  const auto a = runFibscope(common + ssao);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  EXPECT_EQ(a.output.find("distance field:"), std::string::npos) << a.output;
  const auto b = runFibscope(common + df + " --ao-method df --df-shadows");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_NE(b.output.find("distance field: voxel"), std::string::npos) << b.output;
  EXPECT_NE(b.output.find("df shadow"), std::string::npos) << b.output;
  const test::Png pa = test::readOurPng(ssao), pb = test::readOurPng(df);
  ASSERT_EQ(pa.rgba.size(), pb.rgba.size());
  size_t changed = 0;
  for (size_t i = 0; i < pa.rgba.size(); i += 4)
    changed += pa.rgba[i] != pb.rgba[i] || pa.rgba[i + 1] != pb.rgba[i + 1] || pa.rgba[i + 2] != pb.rgba[i + 2];
  EXPECT_GT(changed, 100u) << changed;
  const auto c = runFibscope(common + dir_.file("x.png") + " --ao-method fancy");
  EXPECT_EQ(c.exit_code, 2) << c.output;
}

TEST_F(GpuCliSvo, badRadiusOrVoxelIsOneLineAndExitCode2) {
  const std::string common = "render --phantom-streamlines 10 --size 32x32 --pipeline svo-straight -o " + dir_.file("x.png");
  for (const std::string& bad : {std::string(" --tube-radius 0"), std::string(" --tube-radius -1"),
                                 std::string(" --tube-radius 0.5 --voxel 0"), std::string(" --tube-radius 0.5 --voxel -2"),
                                 std::string(" --tube-radius 0.5 --voxel 0.001")}) {
    const auto r = runFibscope(common + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    // The option named, or (a voxel too fine for the octree) the side it would need.
    EXPECT_TRUE(r.output.find("fibscope: error: --") != std::string::npos ||
                r.output.find("voxels a side") != std::string::npos)
        << bad << ": " << r.output;
    EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << bad << ": " << r.output;
  }
}

// --svo-lod-px: one value in [0, 64], only with an svo pipeline; anything
// else is one line naming the option and exit code 2. A valid one renders
// and the summary says the LoD.
TEST_F(GpuCliSvo, svoLodPxRendersAndBadValuesAreOneLineAndExitCode2) {
  const std::string common = "render --phantom-streamlines 10 --size 32x32 --tube-radius 1 -o " + dir_.file("x.png");
  const auto ok = runFibscope(common + " --pipeline svo-straight --svo-lod-px 2");
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_NE(ok.output.find("(lod 2 px)"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find(", lod "), std::string::npos) << ok.output;  // its bytes in the summary
  for (const std::string& bad : {std::string(" --pipeline svo-straight --svo-lod-px -1"),
                                 std::string(" --pipeline svo-curved --svo-lod-px 65"),
                                 std::string(" --pipeline svo-straight --svo-lod-px abc"),
                                 std::string(" --pipeline svo-straight --svo-lod-px 1,2"),
                                 std::string(" --pipeline svo-straight --svo-lod-px nan"),
                                 std::string(" --svo-lod-px 2")}) {
    const auto r = runFibscope(common + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    EXPECT_NE(r.output.find("fibscope: error: --svo-lod-px"), std::string::npos) << bad << ": " << r.output;
    EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << bad << ": " << r.output;
  }
}

}  // namespace
}  // namespace fibscope
