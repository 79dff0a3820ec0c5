// Interoperability with MRtrix3, the reference tractography tool: a real
// tckgen tractogram must read exactly as MRtrix prints it, and fibscope's
// outputs must read back in MRtrix.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/reader.h"
#include "test_support.h"

namespace fibscope {
namespace {

// Builds the MRtrix tractogram once for the whole suite.
class MrtrixInterop : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    const auto r = test::runCommand(test::toolPath("mrtrix_tractogram.sh") + " " + dir_->path());
    status_ = r.exit_code;
    output_ = r.output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (status_ == 77) GTEST_SKIP() << "MRtrix3 or nibabel missing: " << output_;
    ASSERT_EQ(status_, 0) << output_;
  }
  static std::string file(const std::string& name) { return dir_->file(name); }

  static test::TempDir* dir_;
  static int status_;
  static std::string output_;
};

test::TempDir* MrtrixInterop::dir_ = nullptr;
int MrtrixInterop::status_ = -1;
std::string MrtrixInterop::output_;

std::vector<float> readTxtPoints(const std::string& path) {
  std::ifstream f(path);
  std::vector<float> v;
  float x;
  while (f >> x) v.push_back(x);
  return v;
}

// tckstats prints "mean median std min max count" under a header line.
std::vector<double> tckstatsRow(const std::string& path) {
  std::ifstream f(path);
  std::string header, row;
  std::getline(f, header);
  std::getline(f, row);
  std::istringstream ss(row);
  std::vector<double> v;
  double x;
  while (ss >> x) v.push_back(x);
  return v;
}

}  // namespace

TEST_F(MrtrixInterop, tckgenOutputReadsAsMrtrixPrintsIt) {
  TractogramHeader header;
  const Tractogram t = readTractogram(file("fact.tck"), &header);
  EXPECT_EQ(header.declared_streamlines, 300);
  ASSERT_EQ(t.streamlineCount(), 300u);
  EXPECT_EQ(header.property("method"), "FACT");
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    char name[64];
    std::snprintf(name, sizeof name, "txt/s-%07zu.txt", s);
    const std::vector<float> ref = readTxtPoints(file(name));
    ASSERT_EQ(ref.size(), 3 * t.pointsIn(s)) << "streamline " << s;
    const float* p = t.point(t.offsets[s]);
    for (size_t i = 0; i < ref.size(); ++i)  // MRtrix prints 6 significant digits
      ASSERT_NEAR(p[i], ref[i], 1e-5 * std::fabs(ref[i]) + 1e-6) << "streamline " << s << " value " << i;
  }
}

TEST_F(MrtrixInterop, infoAgreesWithTckinfoAndTckstats) {
  const auto r = test::runFibscope("info --json " + file("fact.tck") + " 2>/dev/null");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output)[0];
  std::ifstream info(file("tckinfo.txt"));
  std::string all((std::istreambuf_iterator<char>(info)), {});
  const auto at = all.find("actual count in file:");
  ASSERT_NE(at, std::string::npos) << all;
  EXPECT_EQ(j["streamlines"].get<uint64_t>(), std::stoull(all.substr(at + 21)));
  // tckstats measures length as (points - 1) * step_size; FACT's last step
  // can be shorter, so fibscope's true polyline length is at most one step
  // below it.
  const auto row = tckstatsRow(file("tckstats.txt"));
  ASSERT_EQ(row.size(), 6u);
  EXPECT_NEAR(j["length_mm"]["mean"].get<double>(), row[0], 0.5);
  EXPECT_NEAR(j["length_mm"]["min"].get<double>(), row[3], 0.5);
  EXPECT_NEAR(j["length_mm"]["max"].get<double>(), row[4], 0.5);
  EXPECT_NEAR(j["step_mm"]["median"].get<double>(), 0.5, 1e-3);
}

TEST_F(MrtrixInterop, mrtrixVtkMatchesTck) {
  const Tractogram tck = readTractogram(file("fact.tck"));
  const Tractogram vtk = readTractogram(file("fact.vtk"));
  ASSERT_EQ(vtk.offsets, tck.offsets);
  for (size_t i = 0; i < tck.positions.size(); ++i)  // MRtrix writes ASCII VTK with 6 digits
    ASSERT_NEAR(vtk.positions[i], tck.positions[i], 1e-5 * std::fabs(tck.positions[i]) + 1e-6) << i;
}

TEST_F(MrtrixInterop, roundTripThroughEveryFormatKeepsPointsAndOrder) {
  const std::string a = file("fact.tck"), trk = file("rt.trk"), trx = file("rt.trx"), back = file("rt.tck");
  for (const auto& [in, out] : {std::pair{a, trk}, {trk, trx}, {trx, back}}) {
    const auto r = test::runFibscope("convert --force " + in + " " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const Tractogram original = readTractogram(a);
  const Tractogram final = readTractogram(back);
  ASSERT_EQ(final.offsets, original.offsets);
  for (size_t i = 0; i < original.positions.size(); ++i)
    ASSERT_NEAR(final.positions[i], original.positions[i], 4 * std::numeric_limits<float>::epsilon() *
                                                               (std::fabs(original.positions[i]) + 1.0f))
        << i;
  // MRtrix reads fibscope's tck and counts the same streamlines.
  const auto r = test::runCommand("tckinfo -count " + back + " | grep 'actual count'");
  EXPECT_NE(r.output.find("300"), std::string::npos) << r.output;
}

}  // namespace fibscope
