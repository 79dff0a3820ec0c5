// `fibscope bundle` as a user meets it: a tiny phantom bundled on the GPU
// (lavapipe) keeps its fibers and point counts while its points move a
// bounded amount; bad options and bad input give one line and exit code 2
// and leave no output behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "io/reader.h"
#include "io/writer.h"
#include "test_support.h"

namespace fibscope {
namespace {

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

// Small grid and few iterations: seconds on lavapipe.
const char* const kSmall = " --voxel 4 --step 3 --radius 3";

bool onlyFile(const test::TempDir& dir, const std::string& name) {
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    if (e.path().filename() != name) return false;
  return true;
}

}  // namespace

TEST(GpuCliBundle, bundledPhantomKeepsItsFibersAndMovesItsPoints) {
  test::TempDir dir;
  auto r = test::runFibscope("phantom " + dir.file("in.tck") + " --streamlines 200 --seed 2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::runFibscope("bundle " + dir.file("in.tck") + " " + dir.file("out.trk") + kSmall +
                        " --iterations 3 --report");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  if (r.output.find("no usable Vulkan device") != std::string::npos) GTEST_SKIP() << r.output;
  EXPECT_NE(r.output.find("displacement mean"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ink"), std::string::npos) << r.output;
  const Tractogram in = readTractogram(dir.file("in.tck"));
  const Tractogram out = readTractogram(dir.file("out.trk"));
  ASSERT_EQ(out.streamlineCount(), in.streamlineCount());
  ASSERT_EQ(out.offsets, in.offsets);
  double mean = 0, max = 0;
  size_t moved = 0;
  for (size_t i = 0; i < in.pointCount(); ++i) {
    const double d = std::hypot(out.point(i)[0] - in.point(i)[0], out.point(i)[1] - in.point(i)[1],
                                out.point(i)[2] - in.point(i)[2]);
    mean += d / double(in.pointCount());
    max = std::max(max, d);
    moved += d > 1e-3;
  }
  EXPECT_GT(moved, in.pointCount() / 2);
  EXPECT_GT(mean, 0.1);
  // Each iteration moves a sample by at most R h (advection) and smoothing
  // keeps it within the hull of its neighbours: 3 iterations of 12 mm at
  // most, plus what smoothing straightens.
  EXPECT_LT(max, 3 * 12.0 + 10.0);
  EXPECT_LT(mean, 12.0);

  // The anisotropic mode, written as fiblets through the compressor.
  r = test::runFibscope("bundle " + dir.file("in.tck") + " " + dir.file("out.fbl") + kSmall +
                        " --iterations 1 --mode anisotropic");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("200 fibers"), std::string::npos) << r.output;
  r = test::runFibscope("info " + dir.file("out.fbl"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("streamlines           200"), std::string::npos) << r.output;

  // Structure-aware advection: said in the report, and it moves the points
  // otherwise than the plain run with the same parameters.
  r = test::runFibscope("bundle " + dir.file("in.tck") + " " + dir.file("aware.trk") + kSmall +
                        " --iterations 3 --structure-aware --structure-power 3 --report");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("structure   aware: power 3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("bundle structure tensor"), std::string::npos) << r.output;
  const Tractogram aware = readTractogram(dir.file("aware.trk"));
  ASSERT_EQ(aware.offsets, in.offsets);
  double differ = 0;
  for (size_t i = 0; i < in.pointCount(); ++i)
    differ += std::hypot(aware.point(i)[0] - out.point(i)[0], aware.point(i)[1] - out.point(i)[1],
                         aware.point(i)[2] - out.point(i)[2]) /
              double(in.pointCount());
  EXPECT_GT(differ, 0.05 * mean);
}

TEST(CliBundle, malformedOptionsExitWith2BeforeWritingAnything) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(20);
  writeTractogram(dir.file("in.tck"), t, TractogramHeader{});
  auto r = test::runFibscope("bundle " + dir.file("in.tck") + " " + dir.file("out.tck") + " --radius abc");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = test::runFibscope("bundle " + dir.file("in.tck") + " " + dir.file("out.tck") + " --smoothing 1.5");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("smoothing is 1.5"), std::string::npos) << r.output;
  r = test::runFibscope("bundle " + dir.file("in.tck") + " " + dir.file("out.tck") + " --mode radial");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = test::runFibscope("bundle " + dir.file("in.tck") + " " + dir.file("out.tck") +
                        " --structure-aware --structure-power 0");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("structure power is 0"), std::string::npos) << r.output;
  r = test::runFibscope("bundle " + dir.file("in.tck") + " " + dir.file("out.xyz"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("out.xyz"), std::string::npos) << r.output;
  EXPECT_TRUE(onlyFile(dir, "in.tck"));
}

TEST(CliBundle, badInputNamesTheFileAndLeavesNoOutput) {
  test::TempDir dir;
  test::writeBytes(dir.file("bad.tck"), "mrtrix tracks\nfile: . 99999\ndatatype: Float32LE\nEND\n");
  auto r = test::runFibscope("bundle " + dir.file("bad.tck") + " " + dir.file("out.tck"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("bad.tck"), std::string::npos) << r.output;
  // A model whose points all coincide cannot be bundled.
  Tractogram same;
  const float p[6] = {1, 2, 3, 1, 2, 3};
  same.addStreamline(p, 2);
  writeTractogram(dir.file("point.tck"), same, TractogramHeader{});
  r = test::runFibscope("bundle " + dir.file("point.tck") + " " + dir.file("out.tck"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("point.tck: bundling: the model has no extent"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.tck")));
}

}  // namespace fibscope
