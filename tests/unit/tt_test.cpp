// DSI Studio TinyTrack (.tt.gz) reader: files written by scipy's MAT-4
// writer with the expected RAS+ points computed by numpy
// (tests/tools/tt_make.py), hand-built matrices for both byte orders, and
// malformed files as one-line errors naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/reader.h"
#include "read_whole.h"
#include "test_support.h"

namespace fibscope {
namespace {

constexpr const char* kPython = "/usr/bin/python3";

bool hasScipy() {
  static const bool ok = test::runCommand(std::string(kPython) + " -c 'import numpy, scipy.io'").exit_code == 0;
  return ok;
}

using test::readWhole;
using Read = test::WholeRead;
std::string errorOf(const std::string& path) { return test::readError(path); }

TEST(TinyTrack, readsScipyWrittenFilesAsNumpyPlacesTheirPoints) {
  if (!hasScipy()) GTEST_SKIP() << kPython << " with numpy and scipy is missing (tests/tools/tt_make.py needs them)";
  test::TempDir dir;
  const auto made = test::runCommand(std::string(kPython) + " " + test::toolPath("tt_make.py") + " " + dir.path());
  ASSERT_EQ(made.exit_code, 0) << made.output;
  for (const char* name : {"mni_1x16", "oblique_4x4"}) {
    SCOPED_TRACE(name);
    const nlohmann::json want = nlohmann::json::parse(test::readBytes(dir.file(std::string(name) + ".json")));
    const std::string path = dir.file(std::string(name) + ".tt.gz");
    for (size_t max_points : {size_t(50), size_t(1) << 18}) {
      const Read got = readWhole(path, max_points);
      ASSERT_EQ(got.all.streamlineCount(), want["streamlines"].size());
      for (size_t i = 0; i < got.all.streamlineCount(); ++i) {
        const auto& w = want["streamlines"][i];
        ASSERT_EQ(3 * (got.all.offsets[i + 1] - got.all.offsets[i]), w.size()) << "streamline " << i;
        const float* p = got.all.point(got.all.offsets[i]);
        for (size_t k = 0; k < w.size(); ++k) ASSERT_NEAR(p[k], w[k].get<double>(), 1e-4) << i << " " << k;
      }
      EXPECT_EQ(got.header.format, "tt");
      EXPECT_TRUE(got.header.space.known);
      for (size_t k = 0; k < 16; ++k)
        EXPECT_FLOAT_EQ(got.header.space.voxel_to_rasmm[k], float(want["affine"][k].get<double>()));
      EXPECT_EQ(got.header.space.dimensions, (std::array<int32_t, 3>{90, 108, 90}));
      EXPECT_EQ(got.header.space.voxel_sizes, (std::array<float, 3>{2, 2, 2}));
      const uint64_t size = std::filesystem::file_size(path);
      for (size_t i = 1; i < got.progress.size(); ++i) EXPECT_LE(got.progress[i - 1], got.progress[i]);
      EXPECT_EQ(got.progress.back(), size);
    }
  }
  EXPECT_EQ(readWhole(dir.file("mni_1x16.tt.gz"), 1 << 16).header.space.voxel_order, "LAS");
}

// MAT-4 matrices by hand, in either byte order (the record bytes inside a
// track block are little-endian either way: DSI Studio's memory).
class Mat4 {
 public:
  explicit Mat4(bool big_endian) : big_(big_endian) {}
  void matrix(const std::string& name, int precision, int32_t rows, int32_t cols, const std::string& data) {
    int32_t head[5] = {(big_ ? 1000 : 0) + 10 * precision, rows, cols, 0, int32_t(name.size() + 1)};
    for (int32_t v : head) put(&v, 4);
    bytes_ += name;
    bytes_ += '\0';
    bytes_ += data;
  }
  void floats(const std::string& name, const std::vector<float>& v, int32_t rows, int32_t cols) {
    std::string data;
    for (float f : v) {
      char b[4];
      std::memcpy(b, &f, 4);
      if (big_) std::reverse(b, b + 4);
      data.append(b, 4);
    }
    matrix(name, 1, rows, cols, data);
  }
  std::string save(const test::TempDir& dir, const std::string& name) const {
    const std::string path = dir.file(name);
    test::writeBytes(path, test::gzipBytes(bytes_));
    return path;
  }

 private:
  void put(const void* p, size_t n) {
    char b[8];
    std::memcpy(b, p, n);
    if (big_) std::reverse(b, b + n);
    bytes_.append(b, n);
  }
  bool big_;
  std::string bytes_;
};

// A record: count, first point, steps (little-endian).
std::string tract(const std::vector<std::array<int32_t, 3>>& points, uint32_t count_override = 0) {
  std::string out;
  const uint32_t count = count_override ? count_override : uint32_t(3 * points.size());
  out.append(reinterpret_cast<const char*>(&count), 4);
  out.append(reinterpret_cast<const char*>(points[0].data()), 12);
  for (size_t j = 1; j < points.size(); ++j)
    for (int k = 0; k < 3; ++k) out += char(int8_t(points[j][size_t(k)] - points[j - 1][size_t(k)]));
  return out;
}

const std::vector<float> kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

TEST(TinyTrack, bothByteOrdersReadTheSame) {
  test::TempDir dir;
  const std::string data = tract({{32, 64, 96}, {40, 60, 100}, {-88, 187, 0}});
  std::vector<float> positions[2];
  for (bool big : {false, true}) {
    Mat4 m(big);
    m.floats("trans_to_mni", {2, 0, 0, -10, 0, 2, 0, 20, 0, 0, 2, 30, 0, 0, 0, 1}, 1, 16);
    m.matrix("track", 5, int32_t(data.size()), 1, data);
    positions[big] = readWhole(m.save(dir, big ? "be.tt.gz" : "le.tt.gz"), 100).all.positions;
  }
  // (32/32 - 0.5) * 2 - 10 = -9, (64/32 - 0.5) * 2 + 20 = 23, (96/32 - 0.5) * 2 + 30 = 35; ...
  const std::vector<float> want = {-9, 23, 35, -8.5f, 22.75f, 35.25f, -16.5f, 30.6875f, 29};
  EXPECT_EQ(positions[0], want);
  EXPECT_EQ(positions[1], want);
}

TEST(TinyTrack, malformedFilesAreOneLineErrorsNamingTheFile) {
  test::TempDir dir;
  const std::string good = tract({{0, 0, 0}, {1, 1, 1}});
  std::vector<std::pair<std::string, std::string>> cases;  // path, expected words
  auto add = [&](const std::string& name, const std::function<void(Mat4&)>& build, const std::string& words) {
    Mat4 m(false);
    build(m);
    cases.emplace_back(m.save(dir, name + ".tt.gz"), words);
  };
  add("no_affine", [&](Mat4& m) { m.matrix("track", 5, int32_t(good.size()), 1, good); }, "before any trans_to_mni");
  add("singular", [&](Mat4& m) {
    m.floats("trans_to_mni", {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, 1, 16);
    m.matrix("track", 5, int32_t(good.size()), 1, good);
  }, "singular");
  add("not_affine", [&](Mat4& m) { m.floats("trans_to_mni", std::vector<float>(16, 1.0f), 4, 4); }, "not an affine");
  add("count_4", [&](Mat4& m) {
    const std::string bad = tract({{0, 0, 0}, {1, 1, 1}}, 4);
    m.floats("trans_to_mni", kIdentity, 4, 4);
    m.matrix("track", 5, int32_t(bad.size()), 1, bad);
  }, "expected a positive multiple of 3");
  add("count_past_block", [&](Mat4& m) {
    const std::string bad = tract({{0, 0, 0}, {1, 1, 1}}, 3000);
    m.floats("trans_to_mni", kIdentity, 4, 4);
    m.matrix("track", 5, int32_t(bad.size()), 1, bad);
  }, "its track block has");
  add("block_cut", [&](Mat4& m) {
    m.floats("trans_to_mni", kIdentity, 4, 4);
    m.matrix("track", 5, int32_t(good.size() + 7), 1, good + std::string(7, '\0'));
  }, "ends inside its 16-byte header");
  add("float_track", [&](Mat4& m) {
    m.floats("trans_to_mni", kIdentity, 4, 4);
    m.floats("track", {1, 2, 3}, 3, 1);
  }, "not real uint8 data");
  add("huge_matrix", [&](Mat4& m) { m.matrix("trans_to_mni", 0, 2147483647, 2147483647, ""); }, "can hold");
  add("no_tracts", [&](Mat4& m) { m.floats("voxel_size", {1, 1, 1}, 1, 3); }, "not a DSI Studio tract file");
  const std::string garbage = dir.file("garbage.tt.gz"), empty = dir.file("empty.tt.gz"), cut = dir.file("cut.tt.gz");
  test::writeBytes(garbage, test::gzipBytes("this is not a MATLAB file at all, just text"));
  test::writeBytes(empty, "");
  {
    Mat4 m(false);
    m.floats("trans_to_mni", kIdentity, 4, 4);
    m.matrix("track", 5, int32_t(good.size()), 1, good);
    const std::string whole = test::readBytes(m.save(dir, "whole.tt.gz"));
    test::writeBytes(cut, whole.substr(0, whole.size() - 12));
  }
  cases.emplace_back(garbage, "");
  cases.emplace_back(empty, "");
  cases.emplace_back(cut, "");
  for (const auto& [path, words] : cases) {
    SCOPED_TRACE(path);
    const std::string e = errorOf(path);
    ASSERT_FALSE(e.empty());
    EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_NE(e.find(words), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace fibscope
