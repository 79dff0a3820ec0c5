// NIfTI volumes (io/nifti_volume.h) against nibabel: files nibabel writes
// (tests/tools/nifti_make.py volumes) give nibabel's affine, shape and
// values; malformed files (cut, gzip-corrupt, headers patched here) are one
// Error naming the file, from loadNiftiVolume and from `fibscope filter`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/nifti_volume.h"
#include "test_support.h"

namespace fibscope {
namespace {

using Json = nlohmann::json;
using test::TempDir;

// A JSON value of nifti_make.py: a number, or "nan" / "inf" / "-inf".
float jsonFloat(const Json& v) {
  if (v.is_number()) return v.get<float>();
  const std::string s = v.get<std::string>();
  if (s == "nan") return NAN;
  return s == "inf" ? INFINITY : -INFINITY;
}

class NiftiNibabel : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    python_ = test::pythonWithNibabel();
    if (python_.empty()) return;
    dir_ = new TempDir;
    const auto r = test::runCommand(python_ + " " + test::toolPath("nifti_make.py") + " volumes " + dir_->path());
    made_ = r.exit_code == 0;
    output_ = r.output;
    if (made_) cases_ = Json::parse(test::readBytes(dir_->file("cases.json")));
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (python_.empty()) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel and numpy";
    ASSERT_TRUE(made_) << output_;
  }
  static std::string file(const std::string& name) { return dir_->file(name); }

  static inline std::string python_, output_;
  static inline TempDir* dir_ = nullptr;
  static inline bool made_ = false;
  static inline Json cases_;
};

void expectMatchesNibabel(const NiftiVolume& v, const Json& c) {
  const auto shape = c["shape"].get<std::vector<int>>();
  for (int k = 0; k < 3; ++k) EXPECT_EQ(v.dims[k], k < int(shape.size()) ? shape[k] : 1) << k;
  EXPECT_EQ(v.volumes, c["volumes"].get<uint64_t>());
  EXPECT_EQ(v.nifti_version, c["version"].get<int>());
  const std::string source = c["sform_code"] != 0 ? "sform" : (c["qform_code"] != 0 ? "qform" : "pixdim");
  EXPECT_EQ(v.affine_source, source);
  // img.affine to 1e-6 of its largest entry; world_to_voxel its inverse.
  double scale = 0;
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col) scale = std::max(scale, std::fabs(c["affine"][r][col].get<double>()));
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col)
      EXPECT_NEAR(v.voxel_to_world[col][r], c["affine"][r][col].get<double>(), 1e-6 * scale) << r << "," << col;
  const glm::dmat4 identity = v.world_to_voxel * v.voxel_to_world;
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col) EXPECT_NEAR(identity[col][r], r == col ? 1.0 : 0.0, 1e-9);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(v.voxel_size_mm[k], c["pixdim"][k].get<double>()) << k;
    if (k < int(c["zooms"].size())) {
      EXPECT_EQ(v.voxel_size_mm[k], c["zooms"][k].get<double>()) << k;
    }
  }
  // Every value of the first volume, exactly (float32 of nibabel's float64).
  const Json& values = c["values"];
  ASSERT_EQ(v.values.size(), values.size());
  float lo = NAN, hi = NAN;
  for (size_t i = 0; i < values.size(); ++i) {
    const float want = jsonFloat(values[i]);
    if (std::isnan(want)) {
      EXPECT_TRUE(std::isnan(v.values[i])) << i;
    } else {
      EXPECT_EQ(v.values[i], want) << i;
    }
    if (std::isfinite(want)) {
      lo = std::isnan(lo) ? want : std::min(lo, want);
      hi = std::isnan(hi) ? want : std::max(hi, want);
    }
  }
  EXPECT_EQ(v.min, lo);
  EXPECT_EQ(v.max, hi);
}

TEST_F(NiftiNibabel, volumesMatchNibabelsAffineShapeAndValues) {
  ASSERT_GE(cases_.size(), 25u);
  for (const auto& [name, c] : cases_.items()) {
    SCOPED_TRACE(name);
    NiftiVolume v;
    ASSERT_EQ(test::errorOf([&] { v = loadNiftiVolume(file(c["file"])); }), "");
    EXPECT_EQ(v.path, file(c["file"]));
    expectMatchesNibabel(v, c);
  }
}

TEST_F(NiftiNibabel, maskValuesAreWhatMrtrixReadsAsTrue) {
  for (const auto& [name, c] : cases_.items()) {
    SCOPED_TRACE(name);
    const NiftiVolume v = loadNiftiVolume(file(c["file"]), NiftiValues::MrtrixMask);
    ASSERT_EQ(v.values.size(), c["mask"].size());
    for (size_t i = 0; i < v.values.size(); ++i) EXPECT_EQ(v.values[i], jsonFloat(c["mask"][i])) << i;
  }
  // The half-way values pin the threshold: 0.5 and -0.5 are set, 0.49999997 is not.
  const NiftiVolume v = loadNiftiVolume(file("nonfinite_float32.nii"), NiftiValues::MrtrixMask);
  EXPECT_EQ(v.values[3] + v.values[4] + v.values[5], 0.0f) << "NaN and infinities are no mask";
  EXPECT_EQ(v.values[6], 1.0f);
  EXPECT_EQ(v.values[7], 1.0f);
  EXPECT_EQ(v.values[8], 0.0f);
  EXPECT_EQ(v.values[9], 0.0f);
}

// --- malformed files --------------------------------------------------------

// loadNiftiVolume must throw one line that starts with `names`.
void expectOneLineError(const std::string& path, const std::string& names, const std::string& needle = "") {
  const std::string message = test::errorOf([&] { loadNiftiVolume(path); });
  ASSERT_FALSE(message.empty()) << path << " was read";
  EXPECT_EQ(message.rfind(names + ": ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  if (!needle.empty()) {
    EXPECT_NE(message.find(needle), std::string::npos) << message;
  }
}

template <typename T>
std::string patched(std::string bytes, size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof value);
  return bytes;
}

TEST_F(NiftiNibabel, everyTruncatedPrefixIsAnErrorNamingTheFile) {
  TempDir tmp;
  for (const char* name : {"dt_int16.nii", "gzipped.nii.gz", "nifti2.nii", "four_d_gz.nii.gz"}) {
    const std::string valid = test::readBytes(file(name));
    ASSERT_GT(valid.size(), 200u) << name;
    const std::string cut = tmp.file(std::string("cut_") + name);
    for (size_t n = 0; n < valid.size(); ++n) {
      SCOPED_TRACE(std::string(name) + " cut to " + std::to_string(n) + " bytes");
      test::writeBytes(cut, valid.substr(0, n));
      expectOneLineError(cut, cut);
    }
  }
}

// Where the deflate data of a gzip file start (after its header's name).
size_t gzipDataStart(const std::string& gz) {
  size_t at = 10;
  if (gz[3] & 0x08) at = gz.find('\0', at) + 1;  // FNAME, as Python's gzip writes
  return at;
}

TEST_F(NiftiNibabel, gzipCorruptionIsAnErrorNamingTheFile) {
  TempDir tmp;
  for (const char* name : {"gzipped.nii.gz", "four_d_gz.nii.gz", "nifti2_gz.nii.gz"}) {
    const std::string valid = test::readBytes(file(name));
    const std::string bad = tmp.file(std::string("bad_") + name);
    // Every byte of the compressed data and of the CRC and length trailer.
    for (size_t at = gzipDataStart(valid); at < valid.size(); ++at) {
      SCOPED_TRACE(std::string(name) + " byte " + std::to_string(at) + " of " + std::to_string(valid.size()));
      std::string flipped = valid;
      flipped[at] = char(flipped[at] ^ 0xff);
      test::writeBytes(bad, flipped);
      expectOneLineError(bad, bad);
    }
  }
}

TEST_F(NiftiNibabel, badHeadersAreOneLineErrorsNamingTheFile) {
  TempDir tmp;
  const std::string v1 = test::readBytes(file("dt_int16.nii"));  // NIfTI-1, little-endian, sform
  const std::string v2 = test::readBytes(file("nifti2.nii"));
  const std::string q = test::readBytes(file("qform_only.nii"));
  const std::string none = test::readBytes(file("no_codes.nii"));
  // NIfTI-1 offsets: sizeof_hdr 0, dim 40, datatype 70, pixdim 76, vox_offset
  // 108, scl_slope 112, scl_inter 116, quatern_b 256, srow_x 280, srow_y 296,
  // srow_z 312, magic 344. NIfTI-2: dim 16 (int64).
  struct Bad {
    std::string name, bytes, needle;
  };
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = INFINITY;
  std::vector<Bad> cases = {
      {"empty.nii", "", "not a NIfTI"},
      {"text.nii", "hello, not an image\n", "not a NIfTI"},
      {"sizeof_hdr.nii", patched(v1, 0, int32_t(349)), "sizeof_hdr"},
      {"magic.nii", patched(v1, 344, int32_t(0x00636261)), "magic"},
      {"rgb24.nii", patched(v1, 70, int16_t(128)), "unsupported datatype RGB24"},
      {"complex64.nii", patched(v1, 70, int16_t(32)), "unsupported datatype complex64"},
      {"binary.nii", patched(v1, 70, int16_t(1)), "unsupported datatype"},
      {"dt_unknown.nii", patched(v1, 70, int16_t(12345)), "unsupported datatype code 12345"},
      {"ndim0.nii", patched(v1, 40, int16_t(0)), "dim[0]"},
      {"ndim8.nii", patched(v1, 40, int16_t(8)), "dim[0]"},
      {"dim_zero.nii", patched(v1, 44, int16_t(0)), "dim[2]"},
      {"dim_negative.nii", patched(v1, 44, int16_t(-3)), "dim[2]"},
      {"dims_32767.nii", patched(patched(patched(v1, 42, int16_t(32767)), 44, int16_t(32767)), 46, int16_t(32767)),
       "absurd"},
      {"dims_1000.nii", patched(patched(patched(v1, 42, int16_t(1000)), 44, int16_t(1000)), 46, int16_t(1000)),
       "truncated"},
      {"pixdim_inf.nii", patched(v1, 84, inf), "pixdim[2]"},
      {"pixdim_nan.nii", patched(v1, 80, nan), "pixdim[1]"},
      {"inter_inf.nii", patched(patched(v1, 112, 1.0f), 116, inf), "scl_inter"},
      {"vox_offset_low.nii", patched(v1, 108, 100.0f), "vox_offset"},
      {"vox_offset_frac.nii", patched(v1, 108, 352.5f), "vox_offset"},
      {"vox_offset_far.nii", patched(v1, 108, 1e9f), "truncated"},
      {"sform_zero_column.nii", patched(patched(patched(v1, 284, 0.0f), 300, 0.0f), 316, 0.0f), "singular"},
      {"sform_nan.nii", patched(v1, 280, nan), "not finite"},
      {"qform_zero_pixdim.nii", patched(q, 80, 0.0f), "singular"},
      {"qform_bad_quaternion.nii", patched(q, 256, 2.0f), "quaternion"},
      {"pixdim_zero.nii", patched(none, 88, 0.0f), "singular"},
      {"nifti2_dims_1e6.nii",
       patched(patched(patched(v2, 24, int64_t(1000000)), 32, int64_t(1000000)), 40, int64_t(1000000)), "absurd"},
      {"nifti2_dim_huge.nii", patched(v2, 24, int64_t(1) << 40), "absurd"},
      {"nifti2_truncated.nii", v2.substr(0, v2.size() - 1), "truncated"},
      {"single_with_pair_magic.nii", patched(v1, 344, int32_t(0x0031696e)), ".hdr"},
  };
  for (const Bad& b : cases) {
    SCOPED_TRACE(b.name);
    test::writeBytes(tmp.file(b.name), b.bytes);
    expectOneLineError(tmp.file(b.name), tmp.file(b.name), b.needle);
  }
  // A gzip file far too small for what its header claims: refused before
  // anything is allocated or inflated.
  const std::string huge = tmp.file("dims_1000.nii");
  ASSERT_EQ(test::runCommand("gzip -k -f " + huge).exit_code, 0);
  expectOneLineError(huge + ".gz", huge + ".gz", "more than a gzip file");
  // A .hdr without its .img; a directory; a missing file.
  std::filesystem::copy_file(file("pair.hdr"), tmp.file("lonely.hdr"));
  expectOneLineError(tmp.file("lonely.hdr"), tmp.file("lonely.hdr"), "lonely.img");
  std::filesystem::create_directory(tmp.file("folder.nii"));
  expectOneLineError(tmp.file("folder.nii"), tmp.file("folder.nii"), "not a regular file");
  expectOneLineError(tmp.file("missing.nii"), tmp.file("missing.nii"), "No such file");
  // A .img shorter than its .hdr says: the error names the .img.
  std::filesystem::copy_file(file("pair.hdr"), tmp.file("short.hdr"));
  test::writeBytes(tmp.file("short.img"), test::readBytes(file("pair.img")).substr(0, 50));
  expectOneLineError(tmp.file("short.hdr"), tmp.file("short.img"), "truncated");
}

TEST_F(NiftiNibabel, filterWithABadMaskExitsTwoWithOneLineAndWritesNothing) {
  TempDir tmp;
  const std::string in = tmp.file("in.tck"), out = tmp.file("out.tck");
  ASSERT_EQ(test::runFibscope("phantom " + in + " -n 20").exit_code, 0);
  const std::string v1 = test::readBytes(file("dt_int16.nii"));
  test::writeBytes(tmp.file("cut.nii"), v1.substr(0, v1.size() - 10));
  test::writeBytes(tmp.file("magic.nii"), patched(v1, 344, int32_t(0x00636261)));
  test::writeBytes(tmp.file("rgb.nii"), patched(v1, 70, int16_t(128)));
  std::string gz = test::readBytes(file("gzipped.nii.gz"));
  gz[gz.size() / 2] = char(gz[gz.size() / 2] ^ 0xff);
  test::writeBytes(tmp.file("corrupt.nii.gz"), gz);
  for (const std::string bad : {"cut.nii", "magic.nii", "rgb.nii", "corrupt.nii.gz", "missing.nii"}) {
    for (const std::string option : {"--include", "--exclude", "--include-ordered"}) {
      SCOPED_TRACE(option + " " + bad);
      const auto r = test::runFibscope("filter " + in + " " + out + " " + option + " mask:" + tmp.file(bad));
      EXPECT_EQ(r.exit_code, 2) << r.output;
      EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
      EXPECT_NE(r.output.find(tmp.file(bad) + ": "), std::string::npos) << r.output;
      EXPECT_FALSE(std::filesystem::exists(out));
    }
  }
}

}  // namespace
}  // namespace fibscope
