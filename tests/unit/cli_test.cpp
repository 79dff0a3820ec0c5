// The fibscope command line as a user meets it: exit codes, one-line
// errors, never overwriting silently, info output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "io/reader.h"
#include "io/writer.h"
#include "phantom/phantom.h"
#include "test_support.h"

namespace fibscope {
namespace {

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

TEST(Cli, missingFileGivesOneLineErrorAndExitCode2) {
  const auto r = test::runFibscope("info /nonexistent/brain.tck");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/brain.tck"), std::string::npos) << r.output;
}

TEST(Cli, unknownExtensionIsNamed) {
  test::TempDir dir;
  test::writeBytes(dir.file("fibers.xyz"), "hello");
  const auto r = test::runFibscope("info " + dir.file("fibers.xyz"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("unknown tractogram format"), std::string::npos) << r.output;
}

TEST(Cli, badUsageExitsWith2) {
  EXPECT_EQ(test::runFibscope("info").exit_code, 2);
  EXPECT_EQ(test::runFibscope("nosuchcommand").exit_code, 2);
  EXPECT_EQ(test::runFibscope("--help").exit_code, 0);
}

TEST(Cli, convertNeverOverwritesWithoutForce) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(20);
  writeTractogram(dir.file("in.tck"), t, TractogramHeader{});
  test::writeBytes(dir.file("out.trk"), "precious");
  auto r = test::runFibscope("convert " + dir.file("in.tck") + " " + dir.file("out.trk"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  EXPECT_EQ(test::readBytes(dir.file("out.trk")), "precious");
  r = test::runFibscope("convert --force " + dir.file("in.tck") + " " + dir.file("out.trk"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(test::readBytes(dir.file("out.trk")), "precious");
}

TEST(Cli, failedConvertLeavesNoOutputBehind) {
  test::TempDir dir;
  // A tck whose second streamline holds a partial NaN triplet: a hard error
  // after the writer has already started.
  const Tractogram t = test::smallTractogram(3);
  writeTractogram(dir.file("in.tck"), t, TractogramHeader{});
  std::string bytes = test::readBytes(dir.file("in.tck"));
  const size_t file_key = bytes.find("file: . ");
  ASSERT_NE(file_key, std::string::npos);
  const size_t data = std::stoul(bytes.substr(file_key + 8));
  const size_t second = data + 12 * (t.pointsIn(0) + 1) + 4;  // y of the first point of streamline 1
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&bytes[second], &nan, 4);
  test::writeBytes(dir.file("bad.tck"), bytes);
  const auto r = test::runFibscope("convert " + dir.file("bad.tck") + " " + dir.file("out.trx"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_TRUE(e.path().filename() == "in.tck" || e.path().filename() == "bad.tck") << e.path();
}

TEST(Cli, infoJsonReportsCountsAndGeometry) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(40, 7, true);
  writeTractogram(dir.file("in.trx"), t, TractogramHeader{});
  const auto r = test::runFibscope("info --json " + dir.file("in.trx") + " 2>/dev/null");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  ASSERT_EQ(j.size(), 1u);
  EXPECT_EQ(j[0]["format"], "trx");
  EXPECT_EQ(j[0]["streamlines"], t.streamlineCount());
  EXPECT_EQ(j[0]["points"], t.pointCount());
  EXPECT_EQ(j[0]["segments"], t.pointCount() - t.streamlineCount());
  EXPECT_NEAR(j[0]["step_mm"]["median"].get<double>(), 0.5, 0.5 * 2e-4);
  EXPECT_EQ(j[0]["per_streamline"][0]["name"], "weight");
  EXPECT_EQ(j[0]["per_point"][0]["name"], "fa");
  float lo = 1e9f;
  for (size_t i = 0; i < t.pointCount(); ++i) lo = std::min(lo, t.point(i)[0]);
  EXPECT_FLOAT_EQ(j[0]["bounding_box_mm"]["min"][0].get<float>(), lo);
}

TEST(Cli, phantomIsDeterministicAndReadable) {
  test::TempDir dir;
  auto r = test::runFibscope("phantom " + dir.file("a.tck") + " -n 200 --seed 4");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::runFibscope("phantom " + dir.file("b.tck") + " -n 200 --seed 4 --threads 1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Same seed: same points (the headers may differ only by nothing at all).
  EXPECT_EQ(test::readBytes(dir.file("a.tck")), test::readBytes(dir.file("b.tck")));
  r = test::runFibscope("info --json " + dir.file("a.tck") + " 2>/dev/null");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j[0]["streamlines"], 200);
  EXPECT_NEAR(j[0]["step_mm"]["median"].get<double>(), 0.1, 1e-4);
  EXPECT_GT(j[0]["step_mm"]["fraction_within_1pct_of_median"].get<double>(), 0.999);
  EXPECT_GE(j[0]["length_mm"]["min"].get<double>(), 20.0 - 0.1);
  EXPECT_LE(j[0]["length_mm"]["max"].get<double>(), 250.0 + 0.1);
}

// --mix bundles is the named bundles alone: a file with the mix written in
// its header differs from the default's, and reads back as the library
// makes it; an unknown mix is one line, exit 2, and no file.
TEST(Cli, phantomMixSelectsTheNamedBundlesOrTheWholeBrain) {
  test::TempDir dir;
  auto r = test::runFibscope("phantom " + dir.file("named.tck") + " -n 100 --seed 4 --mix bundles");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::runFibscope("phantom " + dir.file("whole.tck") + " -n 100 --seed 4 --mix whole-brain");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  PhantomOptions named;
  applyNamedBundlesPhantomMix(named);
  named.streamlines = 100;
  named.seed = 4;
  const Tractogram a = readAllStreamlines(*openTractogram(dir.file("named.tck")));
  const Tractogram b = readAllStreamlines(*openPhantom(named));
  ASSERT_EQ(a.pointCount(), b.pointCount());
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_NE(test::readBytes(dir.file("named.tck")), test::readBytes(dir.file("whole.tck")));
  r = test::runFibscope("phantom " + dir.file("bad.tck") + " -n 10 --mix fat");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad.tck")));
}

}  // namespace fibscope
