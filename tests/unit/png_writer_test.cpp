// The PNG writer (src/io/png_writer.h): the file's structure, and
// zlib (an independent decoder) reading back what the banded, multi-threaded
// compression wrote.
#include "io/png_writer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "core/error.h"
#include "test_support.h"

namespace fibscope {
namespace {

TEST(PngWriter, hasTheSignatureAndChunks) {
  test::TempDir dir;
  std::vector<uint8_t> rgba(3 * 2 * 4, 255);
  writePngRgba(dir.file("a.png"), 3, 2, rgba);
  const std::string bytes = test::readBytes(dir.file("a.png"));
  ASSERT_GE(bytes.size(), 8u + 25u + 12u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(bytes.substr(12, 4), "IHDR");
  EXPECT_EQ(bytes.substr(16, 8), std::string("\0\0\0\3\0\0\0\2", 8));  // big-endian width, height
  EXPECT_EQ(bytes.substr(bytes.size() - 8, 4), "IEND");
  EXPECT_THROW(writePngRgba(dir.file("b.png"), 3, 3, rgba), Error);
  // An independent decoder reads it back when one is installed.
  const std::string python = test::pythonWithNibabel();
  if (python.empty()) return;
  const test::CommandResult r = test::runCommand(
      python + " -c \"import zlib,struct,sys;d=open(sys.argv[1],'rb').read();"
               "n=struct.unpack('>I',d[33:37])[0];raw=zlib.decompress(d[41:41+n]);print(len(raw), raw[0], raw[1])\" " +
      dir.file("a.png"));
  EXPECT_EQ(r.output, "26 0 255\n");  // two rows of 1 filter byte + 12 RGBA bytes
}

// Tall images are deflated in bands of rows on several threads and joined
// into one zlib stream: zlib itself must read back every scanline.
TEST(PngWriter, manyRowsDecodeToTheScanlines) {
  test::TempDir dir;
  constexpr uint32_t kWidth = 37, kHeight = 300;
  std::vector<uint8_t> rgba(size_t(kWidth) * kHeight * 4);
  uint32_t state = 12345;
  for (size_t i = 0; i < rgba.size(); ++i) {
    state = state * 1664525u + 1013904223u;
    // Runs and noise, so that both matches and literals occur at the seams.
    rgba[i] = (i / 512) % 2 ? uint8_t(state >> 24) : uint8_t(i / 97);
  }
  writePngRgba(dir.file("tall.png"), kWidth, kHeight, rgba);
  std::string scanlines;
  for (uint32_t y = 0; y < kHeight; ++y) {
    scanlines.push_back('\0');
    scanlines.append(reinterpret_cast<const char*>(rgba.data()) + size_t(y) * kWidth * 4, kWidth * 4);
  }
  {
    std::FILE* f = std::fopen(dir.file("expected.raw").c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(scanlines.data(), 1, scanlines.size(), f), scanlines.size());
    std::fclose(f);
  }
  const std::string python = test::pythonWithNibabel();
  if (python.empty()) GTEST_SKIP() << "no /usr/bin/python3 to decode with zlib";
  const test::CommandResult r = test::runCommand(
      python + " -c \"import zlib,struct,sys;d=open(sys.argv[1],'rb').read();i=8;z=b''\n"
               "while i<len(d):\n n=struct.unpack('>I',d[i:i+4])[0];t=d[i+4:i+8]\n"
               " assert zlib.crc32(d[i+4:i+8+n])==struct.unpack('>I',d[i+8+n:i+12+n])[0]\n"
               " z+=d[i+8:i+8+n] if t==b'IDAT' else b'';i+=12+n\n"
               "print(zlib.decompress(z)==open(sys.argv[2],'rb').read())\" " +
      dir.file("tall.png") + " " + dir.file("expected.raw"));
  EXPECT_EQ(r.output, "True\n");
}

}  // namespace
}  // namespace fibscope
