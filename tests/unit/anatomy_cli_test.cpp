// `--anatomy FILE` of render and bench given a file that cannot be shown:
// exit code 2, one line naming the file, and no PNG. The volume is read
// before the device is made, so no GPU is needed to see it refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>

#include "test_support.h"

namespace fibscope {
namespace {

// A NIfTI-1 header of a float32 volume of 1024^3 voxels, without them.
std::string hugeHeader() {
  std::string h(352, '\0');
  const int32_t size = 348;
  std::memcpy(&h[0], &size, 4);
  const int16_t dims[8] = {3, 1024, 1024, 1024, 1, 1, 1, 1};
  std::memcpy(&h[40], dims, sizeof dims);
  const int16_t datatype = 16, bitpix = 32;
  std::memcpy(&h[70], &datatype, 2);
  std::memcpy(&h[72], &bitpix, 2);
  const float pixdim[4] = {1, 1, 1, 1}, offset = 352;
  std::memcpy(&h[76], pixdim, sizeof pixdim);
  std::memcpy(&h[108], &offset, 4);
  std::memcpy(&h[344], "n+1\0", 4);
  return h;
}

TEST(AnatomyCli, anImageThatCannotBeShownIsOneLineNamingItExitTwoAndNoPng) {
  test::TempDir dir;
  const std::string garbage = dir.file("garbage.nii"), gz = dir.file("cut.nii.gz"), huge = dir.file("huge.nii");
  test::writeBytes(garbage, std::string(400, 'x'));
  test::writeBytes(gz, std::string("\x1f\x8b\x08\x00\x00\x00\x00\x00", 8));  // a gzip header, then nothing
  test::writeBytes(huge, hugeHeader());
  std::filesystem::create_directory(dir.file("folder.nii"));
  for (const std::string& bad : {dir.file("missing.nii.gz"), garbage, gz, huge, dir.file("folder.nii")}) {
    for (const std::string command : {"render", "bench"}) {
      SCOPED_TRACE(command + " " + bad);
      const std::string png = dir.file("out.png");
      const std::string args = command == "render" ? "render --size 32x24 --anatomy " + bad + " -o " + png
                                                   : "bench --frames 1 --size 32x24 --anatomy " + bad;
      const auto r = test::runFibscope(args);
      EXPECT_EQ(r.exit_code, 2) << r.output;
      EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
      EXPECT_NE(r.output.find("error: " + bad + ": "), std::string::npos) << r.output;
      EXPECT_FALSE(std::filesystem::exists(png));
    }
  }
}

}  // namespace
}  // namespace fibscope
