// End to end: every malformed file, in every format, meets `fibscope info`
// as a user would: either it reads (a recoverable oddity, with warnings) or
// it fails with exit code 2 and exactly one line that names the file. Never
// a crash, a hang or a multi-line dump.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "io/writer.h"
#include "test_support.h"

namespace fibscope {
namespace {

struct Corruption {
  std::string name;
  std::string bytes;
};

// Truncations at many points of the file, header bytes overwritten, and the
// magic replaced.
std::vector<Corruption> corruptionsOf(const std::string& valid) {
  std::vector<Corruption> out;
  for (double f : {0.0, 0.01, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 0.9, 0.99})
    out.push_back({"truncated at " + std::to_string(int(f * 100)) + "%", valid.substr(0, size_t(f * valid.size()))});
  for (size_t at : {size_t(0), size_t(7), size_t(30), size_t(100), size_t(250), size_t(600), valid.size() / 2}) {
    if (at + 8 > valid.size()) continue;
    std::string bad = valid;
    std::fill(bad.begin() + at, bad.begin() + at + 8, '\xff');
    out.push_back({"0xff at byte " + std::to_string(at), bad});
    std::fill(bad.begin() + at, bad.begin() + at + 8, '\x00');
    out.push_back({"0x00 at byte " + std::to_string(at), bad});
  }
  return out;
}

// Returns whether the file was rejected.
bool expectOneLineErrorOrSuccess(const std::string& path, const std::string& what) {
  const auto r = test::runFibscope("info " + path + " >/dev/null");
  EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 2) << what << ": exit " << r.exit_code << "\n" << r.output;
  if (r.exit_code == 2) {
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << what << ":\n" << r.output;
    EXPECT_EQ(r.output.rfind("fibscope: error: " + path, 0), 0u) << what << ":\n" << r.output;
  } else {
    // Whatever was read is reported with warnings, one line each.
    for (size_t start = 0; start < r.output.size();) {
      const size_t end = r.output.find('\n', start);
      EXPECT_EQ(r.output.rfind("fibscope: warning: ", start), start) << what << ":\n" << r.output;
      start = end == std::string::npos ? r.output.size() : end + 1;
    }
  }
  return r.exit_code == 2;
}

class CliMalformed : public ::testing::TestWithParam<std::string> {};

}  // namespace

TEST_P(CliMalformed, everyCorruptionGivesOneLineErrorOrReadsWithWarnings) {
  test::TempDir dir;
  const std::string ext = GetParam();
  const std::string valid_path = dir.file("valid." + ext);
  if (ext == "vtk") {
    test::writeBytes(valid_path,
                     "# vtk DataFile Version 3.0\ntest\nASCII\nDATASET POLYDATA\nPOINTS 6 float\n"
                     "0 0 0 1 0 0 2 0.5 0\n3 1 1 4 1 2 5 2 2\nLINES 2 8\n3 0 1 2\n3 3 4 5\n"
                     "POINT_DATA 6\nSCALARS fa float 1\nLOOKUP_TABLE default\n0.1 0.2 0.3 0.4 0.5 0.6\n");
  } else {
    writeTractogram(valid_path, test::smallTractogram(12, 3, true), TractogramHeader{});
  }
  const std::string valid = test::readBytes(valid_path);
  ASSERT_GT(valid.size(), 64u);
  int index = 0, rejected = 0;
  for (const auto& c : corruptionsOf(valid)) {
    const std::string path = dir.file("bad" + std::to_string(index++) + "." + ext);
    test::writeBytes(path, c.bytes);
    rejected += expectOneLineErrorOrSuccess(path, ext + ", " + c.name);
  }
  // The sweep must reach the error paths (an empty or headless file is never valid).
  EXPECT_GE(rejected, 3) << "of " << index << " corruptions";
}

INSTANTIATE_TEST_SUITE_P(AllFormats, CliMalformed, ::testing::Values("tck", "trk", "trx", "vtk"));

}  // namespace fibscope
