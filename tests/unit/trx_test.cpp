// TRX reader and writer: files written by an independent reference
// (tests/tools/trx_reference.py, numpy + zipfile, from the spec) read back
// value for value; our files read by the reference; round trips; malformed
// archives and directories; every truncated prefix of a zip; float16
// conversion against numpy.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/half.h"
#include "io/reader.h"
#include "io/trx_format.h"
#include "io/writer.h"
#include "test_support.h"

namespace fibscope {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kPython = "/usr/bin/python3";

bool hasNumpy() {
  static const bool ok = test::runCommand(std::string(kPython) + " -c 'import numpy'").exit_code == 0;
  return ok;
}

#define REQUIRE_NUMPY() \
  if (!hasNumpy()) GTEST_SKIP() << kPython << " with numpy is missing; the TRX reference script needs it"

// Runs the reference script; throws (failing the test) with its output when it fails.
std::string runReference(const std::string& args) {
  const auto r = test::runCommand(std::string(kPython) + " " + test::toolPath("trx_reference.py") + " " + args);
  if (r.exit_code != 0) throw std::runtime_error("trx_reference.py " + args + " failed: " + r.output);
  return r.output;
}

json referenceJson(const std::string& args) { return json::parse(runReference(args)); }

// Reads everything through the streaming interface, `max_points` per chunk.
Tractogram readChunked(const std::string& path, size_t max_points, TractogramHeader* header = nullptr,
                       std::vector<std::string>* warnings = nullptr) {
  auto reader = openTractogram(path);
  Tractogram all;
  for (const auto& a : reader->header().per_streamline) all.per_streamline.push_back({a.name, a.components, a.dtype, {}});
  for (const auto& a : reader->header().per_point) all.per_point.push_back({a.name, a.components, a.dtype, {}});
  Tractogram chunk;
  while (reader->read(chunk, max_points)) {
    EXPECT_EQ(chunk.validate(), "");
    EXPECT_TRUE(chunk.streamlineCount() == 1 || chunk.pointCount() <= max_points);
    all.append(chunk);
  }
  EXPECT_LE(reader->bytesRead(), reader->header().file_bytes);
  if (header) *header = reader->header();
  if (warnings) *warnings = reader->warnings();
  return all;
}

std::string readError(const std::string& path) {
  return test::errorOf([&] { readChunked(path, 5); });
}

void expectOneLineError(const std::string& message, const std::string& path, const std::string& needle) {
  EXPECT_NE(message, "") << "no error for " << path;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind(path, 0), 0u) << message;
  EXPECT_NE(message.find(needle), std::string::npos) << "'" << needle << "' not in: " << message;
}

void expectArraysMatch(const std::vector<DataArray>& ours, const json& reference, float tolerance = 0) {
  ASSERT_EQ(ours.size(), reference.size());
  for (const DataArray& a : ours) {
    ASSERT_TRUE(reference.contains(a.name)) << a.name;
    const json& r = reference[a.name];
    EXPECT_EQ(a.dtype, r["dtype"].get<std::string>()) << a.name;
    EXPECT_EQ(a.components, r["components"].get<uint32_t>()) << a.name;
    ASSERT_EQ(a.values.size(), r["values"].size()) << a.name;
    for (size_t i = 0; i < a.values.size(); ++i) {
      const float expected = static_cast<float>(r["values"][i].get<double>());
      ASSERT_NEAR(a.values[i], expected, tolerance * std::max(1.0f, std::abs(expected))) << a.name << " value " << i;
    }
  }
}

// Compares what our reader produced with the reference's description of the file.
void expectMatchesReference(const Tractogram& t, const TractogramHeader& h, const json& ref) {
  ASSERT_EQ(t.validate(), "");
  ASSERT_EQ(t.streamlineCount(), ref["nb_streamlines"].get<size_t>());
  ASSERT_EQ(t.pointCount(), ref["nb_vertices"].get<size_t>());
  EXPECT_EQ(h.declared_streamlines, ref["nb_streamlines"].get<int64_t>());
  for (size_t i = 0; i < t.streamlineCount(); ++i) ASSERT_EQ(t.pointsIn(i), ref["lengths"][i].get<size_t>()) << i;
  const json& positions = ref["positions"];
  ASSERT_EQ(t.positions.size(), positions.size());
  for (size_t i = 0; i < t.positions.size(); ++i)
    ASSERT_EQ(t.positions[i], static_cast<float>(positions[i].get<double>())) << "coordinate " << i;
  expectArraysMatch(t.per_streamline, ref["dps"]);
  expectArraysMatch(t.per_point, ref["dpv"]);
  ASSERT_EQ(h.groups.size(), ref["groups"].size());
  for (const Group& g : h.groups) {
    ASSERT_TRUE(ref["groups"].contains(g.name));
    EXPECT_EQ(g.streamlines, ref["groups"][g.name]["indices"].get<std::vector<uint32_t>>()) << g.name;
  }
  const json& header = ref["header"];
  EXPECT_TRUE(h.space.known);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      EXPECT_EQ(h.space.voxel_to_rasmm[r * 4 + c], header["VOXEL_TO_RASMM"][r][c].get<float>());
  for (int a = 0; a < 3; ++a) EXPECT_EQ(h.space.dimensions[a], header["DIMENSIONS"][a].get<int32_t>());
}

// Same names, dtypes and components; values equal up to float precision
// (arrays are held as float, so float64 and 64-bit integers round).
void expectSameArrays(const json& ours, const json& reference) {
  ASSERT_EQ(ours.size(), reference.size());
  for (const auto& [name, r] : reference.items()) {
    ASSERT_TRUE(ours.contains(name)) << name;
    EXPECT_EQ(ours[name]["dtype"], r["dtype"]) << name;
    EXPECT_EQ(ours[name]["components"], r["components"]) << name;
    ASSERT_EQ(ours[name]["values"].size(), r["values"].size()) << name;
    for (size_t i = 0; i < r["values"].size(); ++i) {
      const double expected = r["values"][i].get<double>();
      ASSERT_NEAR(ours[name]["values"][i].get<double>(), expected, 1e-7 * std::max(1.0, std::abs(expected))) << name;
    }
  }
}

// Writes `t` through the TRX writer in chunks of `per_chunk` streamlines.
void writeChunked(const std::string& path, const Tractogram& t, const TractogramHeader& like,
                  const WriterOptions& options, size_t per_chunk, std::vector<std::string>* warnings = nullptr) {
  auto writer = createTrxWriter(path, like, options);
  for (size_t first = 0; first < t.streamlineCount(); first += per_chunk) {
    const size_t last = std::min(t.streamlineCount(), first + per_chunk);
    Tractogram chunk;
    for (const auto& a : t.per_streamline) chunk.per_streamline.push_back({a.name, a.components, a.dtype, {}});
    for (const auto& a : t.per_point) chunk.per_point.push_back({a.name, a.components, a.dtype, {}});
    for (size_t s = first; s < last; ++s) {
      chunk.addStreamline(t.point(t.offsets[s]), t.pointsIn(s));
      for (size_t a = 0; a < t.per_streamline.size(); ++a) {
        const auto& src = t.per_streamline[a];
        chunk.per_streamline[a].values.insert(chunk.per_streamline[a].values.end(),
                                              src.values.begin() + s * src.components,
                                              src.values.begin() + (s + 1) * src.components);
      }
      for (size_t a = 0; a < t.per_point.size(); ++a) {
        const auto& src = t.per_point[a];
        chunk.per_point[a].values.insert(chunk.per_point[a].values.end(),
                                         src.values.begin() + t.offsets[s] * src.components,
                                         src.values.begin() + t.offsets[s + 1] * src.components);
      }
    }
    writer->write(chunk);
  }
  writer->finish();
  if (warnings) *warnings = writer->warnings();
}

TractogramHeader likeFor(const Tractogram& t) {
  TractogramHeader like;
  like.format = "tck";
  like.per_streamline = t.per_streamline;
  like.per_point = t.per_point;
  for (auto& a : like.per_streamline) a.values.clear();
  for (auto& a : like.per_point) a.values.clear();
  like.space.known = true;
  like.space.voxel_to_rasmm = {2, 0, 0, -100, 0, 2, 0, -120, 0, 0, 2, -80, 0, 0, 0, 1};
  like.space.dimensions = {100, 120, 90};
  return like;
}

std::vector<std::string> listDirectory(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

// A valid reference TRX directory to break in the malformed tests.
std::string makeReferenceDirectory(const test::TempDir& dir, const std::string& extra = "") {
  const std::string path = dir.file("ref.trx");
  runReference("make " + path + " --layout dir --streamlines 6 --data --groups " + extra);
  return path;
}

// A fresh copy of directory `from` at `to` (replacing it).
std::string copyOf(const std::string& from, const std::string& to) {
  fs::remove_all(to);
  fs::copy(from, to, fs::copy_options::recursive);
  return to;
}

void rewriteHeader(const std::string& trx, const std::function<void(json&)>& edit) {
  json header = json::parse(test::readBytes(trx + "/header.json"));
  edit(header);
  test::writeBytes(trx + "/header.json", header.dump());
}

template <typename T>
std::vector<T> readArray(const std::string& file) {
  const std::string bytes = test::readBytes(file);
  std::vector<T> v(bytes.size() / sizeof(T));
  std::memcpy(v.data(), bytes.data(), v.size() * sizeof(T));
  return v;
}

template <typename T>
void writeArray(const std::string& file, const std::vector<T>& v) {
  test::writeBytes(file, std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T)));
}

// ---------------------------------------------------------------------------

TEST(TrxFormat, parsesMemberNames) {
  std::string why;
  auto p = trx::parseMemberName("positions.3.float16", &why);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->name, "positions");
  EXPECT_EQ(p->components, 3u);
  EXPECT_EQ(p->dtype, trx::DType::kFloat16);
  p = trx::parseMemberName("fa.float32", &why);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->name, "fa");
  EXPECT_EQ(p->components, 1u);
  p = trx::parseMemberName("fa.mean.uint8", &why);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->name, "fa.mean");
  p = trx::parseMemberName("x.3.1.int16", &why);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->name, "x.3");
  EXPECT_EQ(p->components, 1u);
  EXPECT_EQ(p->dtype, trx::DType::kInt16);
  p = trx::parseMemberName("flags.bit", &why);
  ASSERT_TRUE(p);
  EXPECT_EQ(trx::dtypeSize(p->dtype), 1u);

  EXPECT_FALSE(trx::parseMemberName("fa.float128", &why));
  EXPECT_NE(why.find("unknown dtype 'float128'"), std::string::npos) << why;
  EXPECT_FALSE(trx::parseMemberName("fa.0.float32", &why));
  EXPECT_FALSE(trx::parseMemberName("fa.99999999999.float32", &why));
  EXPECT_FALSE(trx::parseMemberName(".float32", &why));
  p = trx::parseMemberName("3.float32", &why);  // "3" is a name, not a count
  ASSERT_TRUE(p);
  EXPECT_EQ(p->name, "3");
  EXPECT_FALSE(trx::parseMemberName("README", &why));
  EXPECT_FALSE(trx::parseMemberName("fa.Float32", &why));
}

TEST(TrxFormat, memberFileNamesParseBack) {
  for (const auto& [name, components] : std::vector<std::pair<std::string, uint32_t>>{
           {"fa", 1}, {"colour", 3}, {"x.3", 1}, {"x.3", 4}, {"a.b", 1}, {"v2", 2}}) {
    const std::string file = trx::memberFileName(name, components, trx::DType::kUint16);
    const auto parsed = trx::parseMemberName(file, nullptr);
    ASSERT_TRUE(parsed) << file;
    EXPECT_EQ(parsed->name, name) << file;
    EXPECT_EQ(parsed->components, components) << file;
  }
  EXPECT_EQ(trx::memberFileName("fa", 1, trx::DType::kFloat32), "fa.float32");
  EXPECT_EQ(trx::memberFileName("c", 3, trx::DType::kUint8), "c.3.uint8");
  EXPECT_FALSE(trx::isValidArrayName("a/b"));
  EXPECT_FALSE(trx::isValidArrayName(".."));
  EXPECT_FALSE(trx::isValidArrayName(""));
  EXPECT_TRUE(trx::isValidArrayName("mean fa"));
}

TEST(TrxFormat, integerEncodingRoundsToNearestAndSaturates) {
  const std::vector<float> v = {-1.0f, 0.4f, 0.5f, 1.5f, 254.5f, 255.6f, NAN};
  std::vector<uint8_t> out(v.size());
  EXPECT_EQ(trx::encodeFromFloat(trx::DType::kUint8, v.data(), v.size(), out.data()), 3u);  // -1, 256, NaN
  EXPECT_EQ(out, (std::vector<uint8_t>{0, 0, 0, 2, 254, 255, 0}));
  const std::vector<float> big = {1e19f, -1e19f, 3.0f};
  std::vector<uint8_t> bytes(big.size() * 8);
  EXPECT_EQ(trx::encodeFromFloat(trx::DType::kInt64, big.data(), big.size(), bytes.data()), 2u);
  int64_t first = 0, second = 0, third = 0;
  std::memcpy(&first, bytes.data(), 8);
  std::memcpy(&second, bytes.data() + 8, 8);
  std::memcpy(&third, bytes.data() + 16, 8);
  EXPECT_EQ(first, std::numeric_limits<int64_t>::max());
  EXPECT_EQ(second, std::numeric_limits<int64_t>::min());
  EXPECT_EQ(third, 3);
  std::vector<float> back(3);
  trx::decodeToFloat(trx::DType::kInt64, bytes.data(), 3, back.data());
  EXPECT_EQ(back[2], 3.0f);
  const std::vector<uint8_t> signed_bytes = {0xff, 0x01};
  std::vector<uint64_t> indices(2);
  EXPECT_EQ(trx::decodeIndices(trx::DType::kInt8, signed_bytes.data(), 2, indices.data()), 0u);  // -1 is negative
}

TEST(TrxHalf, halfToFloatMatchesNumpyForEveryBitPattern) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  runReference("half-to-float " + dir.file("table.f32"));
  const auto table = readArray<float>(dir.file("table.f32"));
  ASSERT_EQ(table.size(), 65536u);
  for (uint32_t h = 0; h < 65536; ++h) {
    const float ours = halfToFloat(static_cast<uint16_t>(h));
    if (std::isnan(table[h])) {
      EXPECT_TRUE(std::isnan(ours)) << std::hex << h;
    } else {
      ASSERT_EQ(std::bit_cast<uint32_t>(ours), std::bit_cast<uint32_t>(table[h])) << std::hex << "half 0x" << h;
    }
  }
}

TEST(TrxHalf, floatToHalfRoundsLikeNumpy) {
  REQUIRE_NUMPY();
  std::vector<float> values = {
      0.0f, -0.0f, 1.0f, -2.5f, 65504.0f, 65519.0f, 65520.0f, -65520.0f, 1e9f, INFINITY, -INFINITY,
      std::ldexp(1.0f, -24),                 // smallest subnormal
      std::ldexp(1.0f, -25),                 // half of it: ties to even (0)
      std::ldexp(1.0f, -25) * 1.0001f,       // just above the tie
      std::ldexp(3.0f, -25),                 // tie between subnormals 1 and 2: even (2)
      std::ldexp(1023.0f, -24),              // largest subnormal
      std::ldexp(1023.5f, -24),              // tie up into the smallest normal
      std::ldexp(1.0f, -14),                 // smallest normal
      1.0f + std::ldexp(1.0f, -11),          // tie: stays 1
      1.0f + std::ldexp(3.0f, -11),          // tie: up to even
      1.0f + std::ldexp(1.0f, -11) * 1.01f,  // above the tie
      std::ldexp(1.0f, -26), 1e-30f, -1e-30f, 0.1f, 80.123f, -79.987f, 2048.5f, 4097.0f,
  };
  std::mt19937 rng(7);
  std::uniform_int_distribution<uint32_t> bits;
  std::uniform_real_distribution<float> near(-70000.0f, 70000.0f);
  for (int i = 0; i < 50000; ++i) values.push_back(std::bit_cast<float>(bits(rng)));  // every exponent
  for (int i = 0; i < 50000; ++i) values.push_back(near(rng) * (i % 2 ? 1.0f : 1e-4f));
  values.push_back(std::bit_cast<float>(0x7fc00001u));  // a NaN

  test::TempDir dir;
  writeArray(dir.file("in.f32"), values);
  runReference("float-to-half " + dir.file("in.f32") + " " + dir.file("out.f16"));
  const auto expected = readArray<uint16_t>(dir.file("out.f16"));
  ASSERT_EQ(expected.size(), values.size());
  size_t mismatches = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    const uint16_t ours = floatToHalf(values[i]);
    const bool expected_nan = (expected[i] & 0x7c00u) == 0x7c00u && (expected[i] & 0x3ffu) != 0;
    if (expected_nan) {
      EXPECT_TRUE((ours & 0x7c00u) == 0x7c00u && (ours & 0x3ffu) != 0) << values[i];
    } else if (ours != expected[i] && mismatches++ < 10) {
      ADD_FAILURE() << "float " << values[i] << " (0x" << std::hex << std::bit_cast<uint32_t>(values[i])
                    << "): ours 0x" << ours << ", numpy 0x" << expected[i];
    }
  }
  EXPECT_EQ(mismatches, 0u);
}

// ---------------------------------------------------------------------------
// Reading files written by the reference

TEST(TrxReader, readsReferenceFilesOfEveryLayoutAndDtype) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const std::vector<std::string> variants = {
      "--layout dir --positions float32 --offsets uint64 --data --groups",
      "--layout stored --positions float16 --offsets uint32 --data --groups --empty",
      "--layout deflated --positions float64 --offsets uint64 --data",
      "--layout mixed --positions float32 --offsets int32 --no-sentinel --data --groups",
      "--layout stored --positions float32 --offsets uint32 --top-folder bundle",
      "--layout deflated --positions float16 --offsets int64 --no-sentinel --top-folder t --groups --streamlines 40",
      "--layout stored --streamlines 0",
  };
  // One interpreter makes them all: "make PATH VARIANT" per line, one JSON per line out.
  std::string commands;
  for (size_t n = 0; n < variants.size(); ++n)
    commands += "make " + dir.file("v" + std::to_string(n) + ".trx") + " " + variants[n] + "\n";
  test::writeBytes(dir.file("commands.txt"), commands);
  std::istringstream lines(runReference("batch < " + dir.file("commands.txt")));
  for (size_t n = 0; n < variants.size(); ++n) {
    SCOPED_TRACE(variants[n]);
    const std::string path = dir.file("v" + std::to_string(n) + ".trx");
    std::string line;
    ASSERT_TRUE(std::getline(lines, line));
    const json ref = json::parse(line);
    TractogramHeader header;
    std::vector<std::string> warnings;
    const Tractogram t = readChunked(path, 7, &header, &warnings);
    expectMatchesReference(t, header, ref);
    EXPECT_EQ(header.property("SOURCE"), "\"trx_reference.py\"");
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    if (ref["groups"].contains("left")) {
      EXPECT_EQ(header.property("dpg/left/mean_fa.float32"), "[0.41999998688697815]");
      EXPECT_EQ(header.property("dpg/left/colour.3.uint8"), "[255.0,128.0,0.0]");
    }
  }
}

TEST(TrxReader, reportsProgressUpToTheFileSize) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const std::string path = dir.file("p.trx");
  runReference("make " + path + " --layout stored --streamlines 50 --data");
  auto reader = openTrx(path);
  Tractogram chunk;
  uint64_t previous = reader->bytesRead();
  EXPECT_GT(previous, 0u);  // header and offsets
  while (reader->read(chunk, 40)) {
    EXPECT_GE(reader->bytesRead(), previous);
    previous = reader->bytesRead();
  }
  // Every byte of member data was consumed; only zip headers remain.
  EXPECT_LE(reader->bytesRead(), reader->header().file_bytes);
  EXPECT_GT(reader->bytesRead(), reader->header().file_bytes * 8 / 10);
}

// ---------------------------------------------------------------------------
// Writing: round trips and the reference's view of our files

TEST(TrxRoundTrip, float32ZipIsExactAndReadableByTheReference) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(40, 3, true);
  const std::string path = dir.file("out.trx");
  writeChunked(path, t, likeFor(t), {}, 7);

  TractogramHeader header;
  const Tractogram back = readChunked(path, 100, &header);
  EXPECT_EQ(back.positions, t.positions);
  EXPECT_EQ(back.offsets, t.offsets);
  ASSERT_EQ(back.per_point.size(), 1u);
  EXPECT_EQ(back.per_point[0].values, t.per_point[0].values);
  EXPECT_EQ(back.per_streamline[0].values, t.per_streamline[0].values);
  EXPECT_EQ(header.space.voxel_to_rasmm, likeFor(t).space.voxel_to_rasmm);
  EXPECT_EQ(header.space.voxel_sizes, (std::array<float, 3>{2, 2, 2}));

  const json ref = referenceJson("read " + path);
  expectMatchesReference(back, header, ref);
  EXPECT_EQ(ref["positions_dtype"], "float32");
  EXPECT_EQ(ref["offsets_dtype"], "uint64");
  EXPECT_EQ(ref["offsets_count"], 41);  // the spec's final NB_VERTICES sentinel
  for (const auto& [member, method] : ref["compression"].items()) EXPECT_EQ(method, "stored") << member;
  EXPECT_EQ(ref["header"]["VOXEL_TO_RASMM"][0][3], -100.0);
  EXPECT_EQ(ref["header"]["DIMENSIONS"], json({100, 120, 90}));
}

TEST(TrxRoundTrip, float64DirectoryIsExact) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(25, 4, true);
  WriterOptions options;
  options.trx_position_dtype = "float64";
  options.trx_zip = false;
  const std::string path = dir.file("out.trx");
  writeChunked(path, t, likeFor(t), options, 4);
  ASSERT_TRUE(fs::is_directory(path));
  EXPECT_TRUE(fs::exists(path + "/positions.3.float64"));
  TractogramHeader header;
  const Tractogram back = readChunked(path, 50, &header);
  EXPECT_EQ(back.positions, t.positions);  // float -> double -> float is exact
  EXPECT_EQ(back.offsets, t.offsets);
  const json ref = referenceJson("read " + path);
  EXPECT_EQ(ref["positions_dtype"], "float64");
  expectMatchesReference(back, header, ref);
}

TEST(TrxRoundTrip, float16StaysWithinHalfPrecision) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(30, 5, false);
  WriterOptions options;
  options.trx_position_dtype = "float16";
  const std::string path = dir.file("half.trx");
  writeChunked(path, t, likeFor(t), options, 30);
  const Tractogram back = readChunked(path, 1000);
  EXPECT_EQ(back.offsets, t.offsets);
  ASSERT_EQ(back.positions.size(), t.positions.size());
  for (size_t i = 0; i < t.positions.size(); ++i) {
    // Round to nearest: error at most half a unit in the last place, 2^-11 relative.
    EXPECT_LE(std::abs(back.positions[i] - t.positions[i]), std::abs(t.positions[i]) * std::ldexp(1.0f, -11) + 1e-7f)
        << i;
    EXPECT_EQ(back.positions[i], halfToFloat(floatToHalf(t.positions[i])));
  }
  const json ref = referenceJson("read " + path);
  EXPECT_EQ(ref["positions_dtype"], "float16");
  for (size_t i = 0; i < back.positions.size(); ++i)
    ASSERT_EQ(back.positions[i], static_cast<float>(ref["positions"][i].get<double>()));
}

TEST(TrxRoundTrip, keepsDtypesGroupsDataPerGroupAndHeaderKeys) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const std::string source = dir.file("source.trx");
  const json original = referenceJson("make " + source + " --layout mixed --positions float16 --data --groups --empty");
  TractogramHeader header;
  const Tractogram t = readTractogram(source, &header);
  WriterOptions options;
  options.trx_position_dtype = "float16";
  const std::string copy = dir.file("copy.trx");
  std::vector<std::string> warnings;
  writeTractogram(copy, t, header, options, &warnings);
  EXPECT_TRUE(warnings.empty()) << warnings.front();

  const json ref = referenceJson("read " + copy);
  EXPECT_EQ(ref["positions"], original["positions"]);
  EXPECT_EQ(ref["lengths"], original["lengths"]);
  expectSameArrays(ref["dps"], original["dps"]);
  expectSameArrays(ref["dpv"], original["dpv"]);
  EXPECT_EQ(ref["groups"]["left"]["indices"], original["groups"]["left"]["indices"]);
  EXPECT_EQ(ref["groups"]["left"]["dtype"], "uint32");
  EXPECT_EQ(ref["dpg"], original["dpg"]);
  EXPECT_EQ(ref["header"]["SOURCE"], "trx_reference.py");
  EXPECT_EQ(ref["header"]["VOXEL_TO_RASMM"], original["header"]["VOXEL_TO_RASMM"]);
  EXPECT_EQ(ref["header"]["DIMENSIONS"], original["header"]["DIMENSIONS"]);
}

TEST(TrxRoundTrip, largeArraysSurviveEveryLayout) {
  REQUIRE_NUMPY();
  // 360k points: 1.08 M coordinates, more than one decode step of 2^20
  // values in one chunk; then again in chunks of 123457 points.
  Tractogram t;
  t.per_point.push_back({"fa", 1, "float32", {}});
  std::vector<float> xyz(300);
  for (int s = 0; s < 3600; ++s) {
    for (int i = 0; i < 300; ++i) xyz[i] = static_cast<float>(s) * 0.01f + static_cast<float>(i) * 0.5f;
    t.addStreamline(xyz.data(), 100);
    for (int i = 0; i < 100; ++i) t.per_point[0].values.push_back(static_cast<float>(s * 100 + i));
  }
  test::TempDir dir;
  WriterOptions options;
  options.trx_zip = false;
  writeChunked(dir.file("big_dir.trx"), t, likeFor(t), options, 1500);
  runReference("zip " + dir.file("big_dir.trx") + " " + dir.file("big_deflated.trx") + " --method deflated");
  writeChunked(dir.file("big_stored.trx"), t, likeFor(t), {}, 3600);
  for (const auto& [name, max_points] : std::vector<std::pair<std::string, size_t>>{
           {"big_dir.trx", size_t(1) << 20}, {"big_deflated.trx", size_t(1) << 20}, {"big_stored.trx", 123457}}) {
    const Tractogram back = readChunked(dir.file(name), max_points);
    EXPECT_EQ(back.offsets, t.offsets) << name;
    EXPECT_EQ(back.positions, t.positions) << name;
    EXPECT_EQ(back.per_point[0].values, t.per_point[0].values) << name;
  }
}

TEST(TrxWriter, refusesToOverwriteUnlessAsked) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(5);
  const std::string path = dir.file("exists.trx");
  test::writeBytes(path, "keep me");
  const std::string message = test::errorOf([&] { writeTractogram(path, t, likeFor(t)); });
  expectOneLineError(message, path, "exists");
  EXPECT_EQ(test::readBytes(path), "keep me");
  EXPECT_EQ(listDirectory(dir.path()).size(), 1u);

  WriterOptions options;
  options.overwrite = true;
  writeTractogram(path, t, likeFor(t), options);
  EXPECT_EQ(readTractogram(path).positions, t.positions);
  // A directory replaces the zip, and a zip the directory.
  options.trx_zip = false;
  writeTractogram(path, t, likeFor(t), options);
  EXPECT_TRUE(fs::is_directory(path));
  options.trx_zip = true;
  writeTractogram(path, t, likeFor(t), options);
  EXPECT_TRUE(fs::is_regular_file(path));
  EXPECT_EQ(readTractogram(path).positions, t.positions);
  EXPECT_EQ(listDirectory(dir.path()).size(), 1u);
}

TEST(TrxWriter, leavesNothingBehindWhenAbandonedOrFailing) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(5, 1, true);
  {
    auto writer = createTrxWriter(dir.file("abandoned.trx"), likeFor(t), {});
    writer->write(t);
  }
  EXPECT_TRUE(listDirectory(dir.path()).empty());

  TractogramHeader like = likeFor(t);
  like.groups.push_back({"too_far", {1, 9}});
  const std::string path = dir.file("bad_group.trx");
  expectOneLineError(test::errorOf([&] { writeTractogram(path, t, like); }), path, "streamline 9");
  EXPECT_TRUE(listDirectory(dir.path()).empty());

  like = likeFor(t);
  like.per_point[0].name = "../escape";
  expectOneLineError(test::errorOf([&] { writeTractogram(path, t, like); }), path, "../escape");
  Tractogram huge = t;
  huge.positions[4] = 70000.0f;
  WriterOptions options;
  options.trx_position_dtype = "float16";
  expectOneLineError(test::errorOf([&] { writeTractogram(path, huge, likeFor(t), options); }), path, "float16");
  options.trx_position_dtype = "float8";
  expectOneLineError(test::errorOf([&] { writeTractogram(path, t, likeFor(t), options); }), path, "float8");
  EXPECT_TRUE(listDirectory(dir.path()).empty());
}

// A filter's output knows its groups only once the streamlines are written
// (the viewer's ROI groups): they replace the header's, whose indices (and
// data per group) were the input's.
TEST(TrxWriter, groupsSetAfterTheStreamlinesReplaceTheHeadersOnes) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(6, 3);
  TractogramHeader like = likeFor(t);
  like.format = "trx";
  like.groups.push_back({"input_group", {0, 5}});
  like.properties.push_back({"dpg/input_group/mean.float32", "[1.5]"});
  const std::string path = dir.file("grouped.trx");
  auto writer = createTrxWriter(path, like, {});
  writer->write(t);
  writer->setGroups({{"roi_a", {1, 2, 4}}, {"roi_b", {3}}});
  writer->finish();
  TractogramHeader header;
  EXPECT_EQ(readTractogram(path, &header).positions, t.positions);
  ASSERT_EQ(header.groups.size(), 2u);
  std::sort(header.groups.begin(), header.groups.end(), [](const Group& a, const Group& b) { return a.name < b.name; });
  EXPECT_EQ(header.groups[0].name, "roi_a");
  EXPECT_EQ(header.groups[0].streamlines, (std::vector<uint32_t>{1, 2, 4}));
  EXPECT_EQ(header.groups[1].name, "roi_b");
  EXPECT_EQ(header.groups[1].streamlines, std::vector<uint32_t>{3});
  for (const auto& [key, value] : header.properties) EXPECT_NE(key.rfind("dpg/", 0), 0u) << key;

  // Formats without groups say so.
  auto tck = createTractogramWriter(dir.file("grouped.tck"), likeFor(t));
  tck->write(t);
  tck->setGroups({{"roi_a", {1}}});
  tck->finish();
  ASSERT_FALSE(tck->warnings().empty());
  EXPECT_NE(tck->warnings().back().find("not written"), std::string::npos) << tck->warnings().back();
}

TEST(TrxWriter, coversThePointsWhenNoReferenceSpaceIsKnown) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(10, 2);
  TractogramHeader like;  // space unknown, as from a .tck
  std::vector<std::string> warnings;
  const std::string path = dir.file("nospace.trx");
  writeTractogram(path, t, like, {}, &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("no reference space"), std::string::npos) << warnings[0];
  TractogramHeader header;
  readTractogram(path, &header);
  for (int axis = 0; axis < 3; ++axis) {
    const float origin = header.space.voxel_to_rasmm[axis * 4 + 3];
    EXPECT_EQ(header.space.voxel_to_rasmm[axis * 4 + axis], 1.0f);
    for (size_t p = 0; p < t.pointCount(); ++p) {
      const float voxel = t.point(p)[axis] - origin;
      ASSERT_GE(voxel, 0.0f);
      ASSERT_LE(voxel, header.space.dimensions[axis] - 1.0f);
    }
  }
}

TEST(TrxWriter, storesDataArraysInTheirDtype) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  Tractogram t = test::smallTractogram(4, 9, false);
  t.per_streamline.push_back({"label", 1, "uint8", {1, 2, 300, -4}});
  t.per_streamline.push_back({"rgb", 3, "float16", std::vector<float>(12, 0.25f)});
  TractogramHeader like = likeFor(t);
  std::vector<std::string> warnings;
  writeChunked(dir.file("d.trx"), t, like, {}, 2, &warnings);
  const json ref = referenceJson("read " + dir.file("d.trx"));
  EXPECT_EQ(ref["dps"]["label"]["dtype"], "uint8");
  EXPECT_EQ(ref["dps"]["label"]["values"], json({1.0, 2.0, 255.0, 0.0}));
  EXPECT_EQ(ref["dps"]["rgb"]["components"], 3);
  EXPECT_EQ(ref["dps"]["rgb"]["dtype"], "float16");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("2 values did not fit uint8"), std::string::npos) << warnings[0];
}

// ---------------------------------------------------------------------------
// Malformed input

TEST(TrxMalformed, missingMembersAreNamed) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const std::string pristine = makeReferenceDirectory(dir);
  for (const auto& [member, needle] : std::vector<std::pair<std::string, std::string>>{
           {"header.json", "missing member header.json"},
           {"positions.3.float32", "missing member positions"},
           {"offsets.uint64", "missing member offsets"}}) {
    const std::string trx = copyOf(pristine, dir.file("broken.trx"));
    fs::remove(trx + "/" + member);
    expectOneLineError(readError(trx), trx, needle);
  }
  // The same in a zip (zipped with a top folder, as `zip -r` does).
  fs::remove(dir.file("broken.trx") + "/positions.3.float32");
  runReference("zip " + dir.file("broken.trx") + " " + dir.file("z.trx") + " --top-folder inner");
  expectOneLineError(readError(dir.file("z.trx")), dir.file("z.trx"), "missing member positions");
}

TEST(TrxMalformed, headerProblemsAreReported) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const std::string trx = makeReferenceDirectory(dir);
  const std::string good = test::readBytes(trx + "/header.json");
  auto check = [&](const std::function<void(json&)>& edit, const std::string& needle) {
    test::writeBytes(trx + "/header.json", good);
    rewriteHeader(trx, edit);
    expectOneLineError(readError(trx), trx, needle);
  };
  check([](json& h) { h["NB_VERTICES"] = h["NB_VERTICES"].get<int>() + 1; }, "positions.3.float32: holds");
  check([](json& h) { h["NB_VERTICES"] = h["NB_VERTICES"].get<int>() - 1; }, "expected");
  check([](json& h) { h["NB_STREAMLINES"] = h["NB_STREAMLINES"].get<int>() + 3; }, "offsets.uint64: holds");
  check([](json& h) { h["NB_STREAMLINES"] = "6"; }, "NB_STREAMLINES must be an integer");
  check([](json& h) { h["NB_VERTICES"] = -4; }, "NB_VERTICES must be an integer");
  check([](json& h) { h.erase("DIMENSIONS"); }, "missing key DIMENSIONS");
  check([](json& h) { h["VOXEL_TO_RASMM"] = json::array({json::array({1, 0, 0}), json::array({0, 1, 0})}); },
        "VOXEL_TO_RASMM must be");
  check([](json& h) { h["DIMENSIONS"] = json::array({1, 2}); }, "DIMENSIONS must be");
  check([](json& h) { h = json::array({1, 2}); }, "expected a JSON object");
  check([](json& h) { h["NB_VERTICES"] = 1e30; }, "NB_VERTICES must be an integer");
  test::writeBytes(trx + "/header.json", "{\"NB_STREAMLINES\": 6,, }");
  expectOneLineError(readError(trx), trx, "invalid JSON");
  test::writeBytes(trx + "/header.json", "");
  expectOneLineError(readError(trx), trx, "invalid JSON");
  // A number beyond double's range is nlohmann's out_of_range, not a
  // parse_error: it escaped the reader as a crash once.
  test::writeBytes(trx + "/header.json", "{\"NB_STREAMLINES\": 1e999}");
  expectOneLineError(readError(trx), trx, "invalid JSON");
  test::writeBytes(trx + "/header.json", "{\"a\": " + std::string(100000, '[') + std::string(100000, ']') + "}");
  expectOneLineError(readError(trx), trx, "nests deeper");
}

TEST(TrxMalformed, badOffsetsAreReported) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  {
    const std::string trx = makeReferenceDirectory(dir);
    const auto good = readArray<uint64_t>(trx + "/offsets.uint64");
    auto offsets = good;
    std::swap(offsets[2], offsets[3]);
    writeArray(trx + "/offsets.uint64", offsets);
    expectOneLineError(readError(trx), trx, "offsets decrease");
    offsets = good;
    offsets[0] = 1;
    writeArray(trx + "/offsets.uint64", offsets);
    expectOneLineError(readError(trx), trx, "first offset is 1");
    offsets = good;
    offsets.back() += 1;
    writeArray(trx + "/offsets.uint64", offsets);
    expectOneLineError(readError(trx), trx, "final offset");
    fs::remove_all(trx);
  }
  {
    // Without the sentinel, the last streamline must start inside NB_VERTICES.
    const std::string trx = makeReferenceDirectory(dir, "--no-sentinel --offsets int32");
    auto offsets = readArray<int32_t>(trx + "/offsets.int32");
    const int32_t nb_vertices = json::parse(test::readBytes(trx + "/header.json"))["NB_VERTICES"];
    offsets.back() = nb_vertices + 5;
    writeArray(trx + "/offsets.int32", offsets);
    expectOneLineError(readError(trx), trx, "past NB_VERTICES");
    offsets.back() = -3;
    writeArray(trx + "/offsets.int32", offsets);
    expectOneLineError(readError(trx), trx, "negative");
    fs::remove_all(trx);
  }
}

TEST(TrxMalformed, badArraysAndGroupsAreReported) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const std::string pristine = makeReferenceDirectory(dir);
  auto fresh = [&] { return copyOf(pristine, dir.file("broken.trx")); };
  std::string trx = fresh();
  auto group = readArray<uint32_t>(trx + "/groups/left.uint32");
  group.back() = 6;
  writeArray(trx + "/groups/left.uint32", group);
  expectOneLineError(readError(trx), trx, "out of range (NB_STREAMLINES 6)");

  trx = fresh();
  fs::rename(trx + "/dps/weight.float32", trx + "/dps/weight.float128");
  expectOneLineError(readError(trx), trx, "unknown dtype 'float128'");

  trx = fresh();
  fs::rename(trx + "/positions.3.float32", trx + "/positions.3.complex64");
  expectOneLineError(readError(trx), trx, "unknown dtype 'complex64'");

  trx = fresh();
  fs::rename(trx + "/positions.3.float32", trx + "/positions.3.int32");
  expectOneLineError(readError(trx), trx, "expected positions.3.float16");

  trx = fresh();
  test::writeBytes(trx + "/dpv/fa.float16", test::readBytes(trx + "/dpv/fa.float16") + "xx");
  expectOneLineError(readError(trx), trx, "member dpv/fa.float16: holds");

  trx = fresh();
  test::writeBytes(trx + "/dps/weight.float16", "");
  expectOneLineError(readError(trx), trx, "a second dps array named 'weight'");

  trx = fresh();
  auto positions = readArray<float>(trx + "/positions.3.float32");
  positions[7] = NAN;
  writeArray(trx + "/positions.3.float32", positions);
  expectOneLineError(readError(trx), trx, "vertex 2 has a non-finite coordinate");

  // Unknown extra files are warnings, not errors.
  trx = fresh();
  test::writeBytes(trx + "/README.txt", "hello");
  std::vector<std::string> warnings;
  readChunked(trx, 100, nullptr, &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("README.txt"), std::string::npos);
}

TEST(TrxMalformed, everyTruncatedZipFailsCleanly) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  for (const char* layout : {"stored", "deflated"}) {
    const std::string source = dir.file(std::string(layout) + ".trx");
    runReference("make " + source + " --layout " + layout + " --streamlines 3 --data --groups");
    const std::string bytes = test::readBytes(source);
    const std::string path = dir.file("cut.trx");
    // Every prefix of the stored zip; every 5th of the deflated one (time).
    // The file is written once and cut shorter and shorter.
    const size_t step = std::string(layout) == "stored" ? 1 : 5;
    test::writeBytes(path, bytes);
    for (size_t n = bytes.size() - 1; n < bytes.size(); n -= std::min(n + 1, step)) {
      fs::resize_file(path, n);
      const std::string message = readError(path);
      ASSERT_NE(message, "") << layout << " prefix of " << n << " bytes read without error";
      ASSERT_EQ(message.find('\n'), std::string::npos) << message;
      ASSERT_EQ(message.rfind(path, 0), 0u) << message;
    }
  }
}

TEST(TrxMalformed, corruptDeflatedDataFailsCleanly) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const std::string path = dir.file("d.trx");
  runReference("make " + path + " --layout deflated --streamlines 30 --data");
  std::string bytes = test::readBytes(path);
  // The first occurrence of the name is its local header; the data follows
  // (Python's zipfile writes no local extra field).
  const std::string name = "dpv/dir.3.float64";
  const size_t local = bytes.find(name);
  ASSERT_NE(local, std::string::npos);
  for (size_t delta : {3u, 40u, 200u, 900u}) {
    std::string corrupt = bytes;
    corrupt[local + name.size() + delta] ^= 0x5a;
    test::writeBytes(path, corrupt);
    expectOneLineError(readError(path), path, "member dpv/dir.3.float64");
  }
}

TEST(TrxReader, opensTrxDirectoryWithoutExtension) {
  REQUIRE_NUMPY();
  test::TempDir dir;
  const std::string path = dir.file("tractogram");
  const json ref = referenceJson("make " + path + " --layout dir --streamlines 4");
  TractogramHeader header;
  const Tractogram t = readTractogram(path, &header);
  expectMatchesReference(t, header, ref);
  EXPECT_EQ(header.format, "trx");
}

}  // namespace
}  // namespace fibscope
