// `fibscope filter --fiber-scalar`: on a TRX with dps and a TRK with
// properties (written by the project's writers), the kept streamlines are
// those a selection computed here from the arrays keeps, with a report line
// per range; on a TrackVis file nibabel wrote, the kept ones are those
// nibabel's data_per_streamline puts in the ranges (nibabel reading both
// files); a missing array, a bad spec and a .tck input are one line, exit
// status 2 and no output (render's: gpu_viewer_dissection_test.cpp).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "io/reader.h"
#include "io/writer.h"
#include "test_support.h"

namespace fibscope {
namespace {

// 300 streamlines with an "id" (its index), "fa" (some NaN) and a
// two-component "pair" per streamline.
Tractogram withScalars() {
  Tractogram t = test::smallTractogram(300, 9);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0, 1);
  t.per_streamline = {{"id", 1, "float32", {}}, {"fa", 1, "float32", {}}, {"pair", 2, "float32", {}}};
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    t.per_streamline[0].values.push_back(float(s));
    t.per_streamline[1].values.push_back(s % 41 == 7 ? NAN : u(rng));
    t.per_streamline[2].values.push_back(u(rng) * 4 - 2);
    t.per_streamline[2].values.push_back(u(rng) * 4 - 2);
  }
  return t;
}

std::vector<size_t> ids(const Tractogram& t) {
  const auto it = std::find_if(t.per_streamline.begin(), t.per_streamline.end(),
                               [](const DataArray& a) { return a.name == "id"; });
  EXPECT_NE(it, t.per_streamline.end());
  std::vector<size_t> out;
  if (it != t.per_streamline.end())
    for (float v : it->values) out.push_back(size_t(v));
  return out;
}

TEST(ScalarRangeCommand, keepsWhatASelectionFromTheArraysKeepsInTrxAndTrk) {
  test::TempDir dir;
  const Tractogram t = withScalars();
  // fa in [0.2, 0.7] and pair[1] <= 0.5, computed from the arrays here.
  std::vector<size_t> want;
  uint64_t by_fa = 0, by_pair = 0;
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    const double fa = t.per_streamline[1].values[s], p1 = t.per_streamline[2].values[2 * s + 1];
    if (!(fa >= 0.2 && fa <= 0.7)) ++by_fa;
    else if (!(p1 <= 0.5)) ++by_pair;
    else want.push_back(s);
  }
  ASSERT_GT(want.size(), 20u);
  ASSERT_GT(by_pair, 0u);
  for (const char* ext : {".trx", ".trk"}) {
    SCOPED_TRACE(ext);
    const std::string in = dir.file(std::string("in") + ext), out = dir.file(std::string("out") + ext);
    writeTractogram(in, t, TractogramHeader{});
    const auto r = test::runFibscope("filter " + in + " " + out + " --fiber-scalar fa:0.2:0.7 --fiber-scalar 'pair[1]::0.5'");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(ids(readTractogram(out)), want);
    const std::string total = " of " + std::to_string(t.streamlineCount()) + " streamlines kept";
    EXPECT_NE(r.output.find(std::to_string(want.size()) + total), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("dropped " + std::to_string(by_fa) + " ("), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("): fa outside [0.2, 0.7]"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("dropped " + std::to_string(by_pair) + " ("), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("): pair[1] outside [-inf, 0.5]"), std::string::npos) << r.output;
  }
  // The same ranges from a ROI set write the same file.
  test::writeBytes(dir.file("set.json"), R"({"fibscope_roi_set": 1, "scalar_ranges": [
      {"name": "fa", "min": 0.2, "max": 0.7}, {"name": "pair", "component": 1, "max": 0.5},
      {"name": "fa", "min": 5, "enabled": false}]})");
  const auto set = test::runFibscope("filter " + dir.file("in.trx") + " " + dir.file("set.trx") + " --roi-set " +
                                     dir.file("set.json"));
  ASSERT_EQ(set.exit_code, 0) << set.output;
  EXPECT_EQ(ids(readTractogram(dir.file("set.trx"))), want);
}

TEST(ScalarRangeCommand, aMissingArrayABadSpecOrATckInputIsOneLineAndWritesNothing) {
  test::TempDir dir;
  const Tractogram t = withScalars();
  const std::string trx = dir.file("in.trx"), tck = dir.file("in.tck"), out = dir.file("out.trk");
  writeTractogram(trx, t, TractogramHeader{});
  Tractogram plain = t;
  plain.per_streamline.clear();
  writeTractogram(tck, plain, TractogramHeader{});
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {trx + " " + out + " --fiber-scalar fa_mean:0.3:",
       trx + ": no per-streamline array \"fa_mean\" for the scalar range fa_mean:0.3: (its per-streamline arrays: "
             "fa, id, pair[2])"},
      {trx + " " + out + " --fiber-scalar 'pair[2]:0:1'", trx + ": per-streamline array \"pair\" has 2 components"},
      {tck + " " + out + " --fiber-scalar fa:0.3:", tck + ": no per-streamline array \"fa\""},
      {trx + " " + out + " --fiber-scalar fa:x:1", "--fiber-scalar \"fa:x:1\": MIN \"x\" is not a finite number"},
      {trx + " " + out + " --fiber-scalar fa:2:1", "--fiber-scalar \"fa:2:1\": MIN 2 is above MAX 1"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const auto r = test::runFibscope("filter " + c.args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

// --- nibabel as the outside reference ---------------------------------------

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(ScalarRangeCommand, keptStreamlinesAreThoseNibabelsDataPerStreamlinePutsInTheRanges) {
  const std::string python = test::pythonWithNibabel();
  if (python.empty()) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel";
  test::TempDir dir;
  const std::string tool = python + " " + test::toolPath("trk_reference.py");
  const auto made = test::runCommand(tool + " make " + dir.path());
  ASSERT_EQ(made.exit_code, 0) << made.output;
  // nibabel's file: per streamline "weight" (1 component) and "pair" (2).
  const std::string in = dir.file("oblique_lps.trk"), out = dir.file("kept.trk");
  const nlohmann::json ref = readJson(dir.file("oblique_lps.json"));
  const auto weight = ref["data_per_streamline"]["weight"], pair = ref["data_per_streamline"]["pair"];
  const auto& streamlines = ref["streamlines"];
  std::vector<size_t> want;
  for (size_t s = 0; s < streamlines.size(); ++s) {
    const double w = weight[s][0].get<double>(), p = pair[s][1].get<double>();
    if (w >= 0.4 && w <= 1.6 && p >= -3) want.push_back(s);
  }
  ASSERT_GT(want.size(), 3u);
  ASSERT_LT(want.size(), streamlines.size());
  const auto r = test::runFibscope("filter " + in + " " + out + " --fiber-scalar weight:0.4:1.6 --fiber-scalar 'pair[1]:-3:'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto dumped = test::runCommand(tool + " dump " + out + " " + dir.file("kept.json"));
  ASSERT_EQ(dumped.exit_code, 0) << dumped.output;
  const nlohmann::json got = readJson(dir.file("kept.json"));
  ASSERT_EQ(got["streamlines"].size(), want.size());
  for (size_t k = 0; k < want.size(); ++k) {
    SCOPED_TRACE(k);
    EXPECT_EQ(got["data_per_streamline"]["weight"][k], weight[want[k]]);
    EXPECT_EQ(got["data_per_streamline"]["pair"][k], pair[want[k]]);
    const auto& a = got["streamlines"][k];
    const auto& b = streamlines[want[k]];
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i].get<double>(), b[i].get<double>(), 1e-3);
  }
}

}  // namespace
}  // namespace fibscope
