#include "test_support.h"

#include <sys/wait.h>
#include <unistd.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"
#include "phantom/phantom.h"

namespace fibscope::test {

TempDir::TempDir() {
  const char* base = std::getenv("TMPDIR");
  std::string templ = std::string(base && *base ? base : "/tmp") + "/fibscope-test-XXXXXX";
  if (!::mkdtemp(templ.data())) throw std::runtime_error("mkdtemp failed");
  path_ = templ;
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

CommandResult runCommand(const std::string& command_line) {
  CommandResult r;
  // Grouped so that redirections inside `command_line` still apply.
  FILE* pipe = ::popen(("{ " + command_line + "\n} 2>&1").c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.output.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return r;
}

CommandResult runFibscope(const std::string& args) { return runCommand(std::string(FIBSCOPE_EXE) + " " + args); }

std::string pythonWithNibabel() {
  for (const char* py : {"/usr/bin/python3", "python3"}) {
    if (runCommand(std::string(py) + " -c 'import nibabel, numpy'").exit_code == 0) return py;
  }
  return {};
}

std::string toolPath(const std::string& name) { return std::string(FIBSCOPE_TEST_TOOLS_DIR) + "/" + name; }

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

Tractogram smallTractogram(size_t streamlines, unsigned seed, bool with_data) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::uniform_int_distribution<int> len(2, 60);
  Tractogram t;
  if (with_data) {
    t.per_streamline.push_back({"weight", 1, "float32", {}});
    t.per_point.push_back({"fa", 1, "float32", {}});
  }
  for (size_t s = 0; s < streamlines; ++s) {
    const int n = len(rng);
    float p[3] = {50 * u(rng), 50 * u(rng), 50 * u(rng)};
    float d[3] = {u(rng), u(rng), u(rng)};
    std::vector<float> xyz;
    for (int i = 0; i < n; ++i) {
      const float norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + 1e-6f;
      for (int k = 0; k < 3; ++k) {
        xyz.push_back(p[k]);
        p[k] += 0.5f * d[k] / norm;
        d[k] += 0.2f * u(rng);
      }
      if (with_data) t.per_point[0].values.push_back(0.5f + 0.5f * u(rng));
    }
    t.addStreamline(xyz.data(), n);
    if (with_data) t.per_streamline[0].values.push_back(float(s) * 0.25f);
  }
  return t;
}

std::string writePhantomTck(const TempDir& dir, const std::string& name, uint64_t streamlines, uint64_t seed) {
  PhantomOptions options;
  options.streamlines = streamlines;
  options.seed = seed;
  options.threads = 1;
  auto reader = openPhantom(options);
  Tractogram all = readAllStreamlines(*reader);
  all.per_streamline.clear();
  const std::string path = dir.file(name);
  writeTractogram(path, all, TractogramHeader{});
  return path;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

Png readOurPng(const std::string& path) {
  const std::string bytes = test::readBytes(path);
  Png png;
  if (bytes.size() < 8 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return png;
  auto be32 = [&](size_t at) {
    return uint32_t(uint8_t(bytes[at])) << 24 | uint32_t(uint8_t(bytes[at + 1])) << 16 |
           uint32_t(uint8_t(bytes[at + 2])) << 8 | uint32_t(uint8_t(bytes[at + 3]));
  };
  std::string idat;
  uint32_t w = 0, h = 0;
  for (size_t at = 8; at + 12 <= bytes.size();) {
    const uint32_t length = be32(at);
    const std::string type = bytes.substr(at + 4, 4);
    if (at + 12 + length > bytes.size()) return png;
    if (type == "IHDR") {
      w = be32(at + 8);
      h = be32(at + 12);
      if (bytes[at + 16] != 8 || bytes[at + 17] != 6) return png;
    }
    if (type == "IDAT") idat += bytes.substr(at + 8, length);
    at += 12 + length;
  }
  std::vector<uint8_t> raw(size_t(h) * (1 + size_t(w) * 4));
  uLongf raw_size = uLongf(raw.size());
  if (w == 0 || uncompress(raw.data(), &raw_size, reinterpret_cast<const Bytef*>(idat.data()), uLong(idat.size())) !=
                    Z_OK ||
      raw_size != raw.size())
    return png;
  png.rgba.reserve(size_t(w) * h * 4);
  for (uint32_t y = 0; y < h; ++y) {
    const uint8_t* row = &raw[size_t(y) * (1 + size_t(w) * 4)];
    if (row[0] != 0) return Png{};
    png.rgba.insert(png.rgba.end(), row + 1, row + 1 + size_t(w) * 4);
  }
  png.width = w;
  png.height = h;
  return png;
}


size_t differingPixels(const Png& a, const Png& b) {
  if (a.width != b.width || a.height != b.height) return size_t(std::max(a.width, b.width)) * std::max(a.height, b.height);
  size_t n = 0;
  for (size_t i = 0; i + 3 < a.rgba.size(); i += 4)
    n += a.rgba[i] != b.rgba[i] || a.rgba[i + 1] != b.rgba[i + 1] || a.rgba[i + 2] != b.rgba[i + 2];
  return n;
}

size_t drawnPixels(const Png& p) {
  size_t n = 0;
  for (size_t i = 0; i + 3 < p.rgba.size(); i += 4) n += p.rgba[i] + p.rgba[i + 1] + p.rgba[i + 2] > 30;
  return n;
}

std::string gzipBytes(const std::string& bytes, int level) {
  z_stream z{};
  // windowBits 15 + 16: the gzip header and trailer (CRC-32, size).
  if (deflateInit2(&z, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) throw std::runtime_error("deflateInit2");
  std::string out(deflateBound(&z, uLong(bytes.size())) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = uInt(bytes.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  const int status = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (status != Z_STREAM_END) throw std::runtime_error("deflate did not finish");
  return out;
}

std::string readChunked(const std::function<std::unique_ptr<TractogramReader>()>& open, Tractogram* out,
                        std::vector<std::string>* warnings, TractogramHeader* header, size_t max_points) {
  try {
    auto reader = open();
    Tractogram all, chunk;
    for (const auto& a : reader->header().per_point) all.per_point.push_back({a.name, a.components, a.dtype, {}});
    for (const auto& a : reader->header().per_streamline)
      all.per_streamline.push_back({a.name, a.components, a.dtype, {}});
    while (reader->read(chunk, max_points)) {
      EXPECT_EQ(chunk.validate(), "");
      all.append(chunk);
    }
    if (out) *out = all;
    if (warnings) *warnings = reader->warnings();
    if (header) *header = reader->header();
    return {};
  } catch (const Error& e) {
    return e.what();
  }
}

}  // namespace fibscope::test
