// The viewer's spline tubes (viewer_tubes.h, the `tubes` script command,
// the tubes panel) as a user meets them: the dissection's kept fibers drawn
// as tubes over the lines, the method switched from the settings (compute
// and fragment ray casting write the same texels, gpu_tube_raster_test.cpp,
// so the frames are the same), "off" giving back the lines' frame exactly,
// and the tubes following the criteria (none kept: no tubes). Offscreen,
// validation layers on, 300 phantom fibers at 320 x 200.
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "app/viewer/viewer_script.h"
#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"
#include "phantom/phantom.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::differingPixels;
using test::drawnPixels;

TEST(ViewerScriptTubes, parsesWhichFibersAndTheRadius) {
  const auto steps = parseScript("tubes selection 2.5\ntubes both\ntubes filtered\ntubes off\n", "s.txt");
  ASSERT_EQ(steps.size(), 4u);
  const auto tubes = [&](size_t i) { return std::get<TubesAction>(std::get<ViewerAction>(steps[i].command)); };
  EXPECT_TRUE(tubes(0).selection && !tubes(0).filtered);
  EXPECT_EQ(tubes(0).radius_mm, 2.5f);
  EXPECT_TRUE(tubes(1).selection && tubes(1).filtered);
  EXPECT_EQ(tubes(1).radius_mm, 0.0f);  // keeps the radius
  EXPECT_TRUE(!tubes(2).selection && tubes(2).filtered);
  EXPECT_TRUE(!tubes(3).selection && !tubes(3).filtered);
  const auto data = parseScript("tubes filtered from=w range=0.3,2\ntubes both from=\n", "s.txt");
  EXPECT_EQ(std::get<TubesAction>(std::get<ViewerAction>(data[0].command)).radius_from, "w");
  EXPECT_EQ(std::get<TubesAction>(std::get<ViewerAction>(data[0].command)).radius_min, 0.3f);
  EXPECT_EQ(std::get<TubesAction>(std::get<ViewerAction>(data[0].command)).radius_max, 2.0f);
  EXPECT_EQ(std::get<TubesAction>(std::get<ViewerAction>(data[1].command)).radius_from, "");
  for (const char* bad : {"tubes\n", "tubes some\n", "tubes selection 0\n", "tubes selection -1\n",
                          "tubes selection x\n", "tubes off 1 2\n", "tubes filtered range=2\n",
                          "tubes filtered range=2,1\n", "tubes filtered range=0,1\n"})
    EXPECT_THROW(parseScript(bad, "s.txt"), Error) << bad;
}

class GpuViewerTubes : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::runFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  test::TempDir dir_;
};

TEST_F(GpuViewerTubes, keptFibersShowAsTubesByEitherMethodAndOffGivesTheLinesBack) {
  const auto png = [&](const char* name) { return dir_.file(name); };
  const std::string script = dir_.file("tubes.txt");
  test::writeBytes(script,
                   "wait 2\n"
                   "screenshot " + png("all.png") + " 320x200\n"
                   "roi-add a include sphere:0,0,20,15\n"
                   "wait 2\n"
                   "screenshot " + png("kept.png") + " 320x200\n"
                   "tubes filtered 1.5\n"  // the script goes on once they are built
                   "screenshot " + png("tubes.png") + " 320x200\n"
                   "set tube-method raycast\n"
                   "wait 1\n"
                   "screenshot " + png("raycast.png") + " 320x200\n"
                   "tubes off\n"
                   "wait 1\n"
                   "screenshot " + png("off.png") + " 320x200\n"
                   "tubes filtered\n"
                   "roi-remove a\n"  // no criteria: no kept fibers to take
                   "wait 3\n"
                   "screenshot " + png("none.png") + " 320x200\n"
                   "quit\n");
  const auto r = test::runCommand("FIBSCOPE_CACHE_DIR='" + dir_.path() + "' " + std::string(FIBSCOPE_EXE) +
                                  " view --validate --phantom-streamlines 300 --offscreen --size 320x200 "
                                  "--no-orientation-labels --script " + script);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const test::Png all = test::readOurPng(png("all.png")), kept = test::readOurPng(png("kept.png")),
                  tubes = test::readOurPng(png("tubes.png")), raycast = test::readOurPng(png("raycast.png")),
                  off = test::readOurPng(png("off.png")), none = test::readOurPng(png("none.png"));
  ASSERT_EQ(tubes.width, 320u);
  // The filter keeps some fibers; as 3 mm tubes they cover more pixels
  // than as 1 px lines.
  EXPECT_LT(drawnPixels(kept), drawnPixels(all));
  EXPECT_GT(drawnPixels(tubes), drawnPixels(kept) + 500) << drawnPixels(tubes) << " vs " << drawnPixels(kept);
  EXPECT_EQ(differingPixels(tubes, raycast), 0u);
  EXPECT_EQ(differingPixels(off, kept), 0u);
  EXPECT_EQ(differingPixels(none, all), 0u);
}

// The radius from a per-fiber array (a TRX dps, kept in the .fbl as
// "dps/w") or a per-point one (a TRX dpv, "dpv/p"): wider tubes than the
// constant smallest radius; an array the model lacks is a message and no
// tubes (the lines' frame exactly).
TEST_F(GpuViewerTubes, theRadiusComesFromAPerFiberOrAPerPointArray) {
  PhantomOptions p;
  p.streamlines = 300;
  Tractogram t = readAllStreamlines(*openPhantom(p));
  DataArray w{"w", 1, "float32", {}};
  for (size_t f = 0; f < t.streamlineCount(); ++f) w.values.push_back(float(f % 5));
  t.per_streamline.push_back(w);
  // A per-point array: 0 on the first half of every fiber, 1 on the rest
  // (kept through the .fbl as a dpv section).
  DataArray pp{"p", 1, "float32", {}};
  for (size_t f = 0; f < t.streamlineCount(); ++f)
    for (size_t i = 0; i < t.pointsIn(f); ++i) pp.values.push_back(2 * i < t.pointsIn(f) ? 0.0f : 1.0f);
  t.per_point.push_back(pp);
  const std::string trx = dir_.file("w.trx");
  writeTractogram(trx, t, TractogramHeader{});
  const auto png = [&](const char* name) { return dir_.file(name); };
  const std::string script = dir_.file("radius.txt");
  test::writeBytes(script,
                   "wait 2\n"
                   "roi-add a include sphere:0,0,20,15\n"
                   "wait 2\n"
                   "screenshot " + png("kept.png") + " 320x200\n"
                   "tubes filtered 0.2\n"
                   "screenshot " + png("thin.png") + " 320x200\n"
                   "tubes filtered from=w range=0.2,2\n"
                   "screenshot " + png("data.png") + " 320x200\n"
                   "tubes filtered from=p range=0.2,2\n"
                   "screenshot " + png("points.png") + " 320x200\n"
                   "tubes filtered from=missing\n"
                   "wait 2\n"
                   "screenshot " + png("missing.png") + " 320x200\n"
                   "quit\n");
  const auto r = test::runCommand("FIBSCOPE_CACHE_DIR='" + dir_.path() + "' " + std::string(FIBSCOPE_EXE) +
                                  " view --validate --offscreen --size 320x200 --no-orientation-labels --script " +
                                  script + " " + trx);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const test::Png kept = test::readOurPng(png("kept.png")), thin = test::readOurPng(png("thin.png")),
                  data = test::readOurPng(png("data.png")), missing = test::readOurPng(png("missing.png")),
                  points = test::readOurPng(png("points.png"));
  ASSERT_EQ(data.width, 320u);
  // Four in five fibers get 0.65 to 2 mm instead of 0.2 mm.
  EXPECT_GT(drawnPixels(data), drawnPixels(thin) + 500) << drawnPixels(data) << " vs " << drawnPixels(thin);
  // The second half of every fiber 2 mm thick instead of 0.2 mm: wider
  // than the thin tubes, and another picture than the per-fiber radii.
  EXPECT_GT(drawnPixels(points), drawnPixels(thin) + 500) << drawnPixels(points) << " vs " << drawnPixels(thin);
  EXPECT_GT(differingPixels(points, data), 500u);
  EXPECT_EQ(differingPixels(missing, kept), 0u);
}

}  // namespace
}  // namespace fibscope
