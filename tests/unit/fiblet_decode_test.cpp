// Fiblet decoding against an independent double-precision reference built
// from the layout and the frame rules alone, and the shared header compiled
// as GLSL (so that the GPU can include what the CPU runs).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>

#include "codec/codec_params.h"
#include "codec/fiblet_decoder.h"
#include "codec/fiblet_encoder.h"
#include "codec/fiblet_simd.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "shared/fiblet.h"
#include "test_support.h"

namespace fibscope {
namespace {

using D3 = std::array<double, 3>;

D3 sub(D3 a, D3 b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
D3 add(D3 a, D3 b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
D3 mul(D3 a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(D3 a, D3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
D3 cross(D3 a, D3 b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
D3 unit(D3 a) { return mul(a, 1.0 / std::sqrt(dot(a, a))); }

// Rotation as three world-space columns: right, up, forward.
struct Frame {
  D3 right, up, forward;
  D3 apply(D3 l) const { return add(add(mul(right, l[0]), mul(up, l[1])), mul(forward, l[2])); }
};
Frame frameFrom(D3 forward, D3 v) {
  const D3 right = unit(cross(forward, v));
  return {right, cross(right, forward), forward};
}

// Reference decode from the byte layout (DESIGN.md section 5), in double:
// the frame of segment k is the previous frame applied to the local frame
// built from the decoded direction, each point one delta further along the
// new forward axis.
std::vector<D3> referenceDecode(const uint8_t* record, const CodecParams& p) {
  const uint32_t n = p.points_per_fiblet;
  const uint32_t count = record[n + 10] >> 2;
  // The points are floats (q * float(1/65535)); the direction of the first
  // segment depends on their rounding, so the reference starts from them.
  auto coord = [&](int i) {
    const float q = float(record[2 * i] | record[2 * i + 1] << 8);
    return double(q * (1.0f / 65535.0f));
  };
  std::vector<D3> points = {{coord(0), coord(1), coord(2)}};
  if (count == 1) return points;
  points.push_back({coord(3), coord(4), coord(5)});
  const D3 v = {p.v[0], p.v[1], p.v[2]};
  const D3 f = unit(sub(points[1], points[0]));
  // The first frame falls back to a perpendicular of V when f is within 30
  // degrees of V (sin^2 = 0.25); V = +x here, so the fallback is +x cross +y = +z.
  Frame frame = frameFrom(f, dot(cross(f, v), cross(f, v)) >= 0.25 ? v : D3{0, 0, 1});
  for (uint32_t k = 2; k < count; ++k) {
    const shader::vec3 d = decodeDirection(record[12 + k - 2], p.alpha);
    const D3 local = {d.x, d.y, d.z};
    const Frame l = frameFrom(local, v);
    const Frame next = {frame.apply(l.right), frame.apply(l.up), frame.apply(l.forward)};
    points.push_back(add(points.back(), mul(frame.apply(local), p.delta)));
    frame = next;
  }
  return points;
}

TEST(FibletDecode, handBuiltRecordsMatchTheDoublePrecisionReference) {
  CodecParams p;
  p.delta = 0.001f;
  p.alpha = 0.3f;
  std::mt19937 random(5);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<uint8_t> record(p.recordBytes(), 0);
    const uint32_t count = 1 + random() % 60;
    const uint16_t q[6] = {uint16_t(20000 + random() % 20000),
                           uint16_t(20000 + random() % 20000),
                           uint16_t(20000 + random() % 20000),
                           0,
                           0,
                           0};
    uint16_t q1[3];
    for (int c = 0; c < 3; ++c) q1[c] = uint16_t(q[c] + int(random() % 131) - 65);
    for (int c = 0; c < 3; ++c) {
      record[2 * c] = uint8_t(q[c]);
      record[2 * c + 1] = uint8_t(q[c] >> 8);
      record[6 + 2 * c] = uint8_t(q1[c]);
      record[7 + 2 * c] = uint8_t(q1[c] >> 8);
    }
    for (uint32_t k = 2; k < count; ++k) record[12 + k - 2] = uint8_t(random());
    record[70] = uint8_t(shader::fibletFlags(true, true, count));
    const FibletDecoder decoder(p);
    float seq[180], scan[180];
    ASSERT_EQ(decoder.decodeSequential(record.data(), seq), count);
    ASSERT_EQ(decoder.decodeScan(record.data(), scan), count);
    const std::vector<D3> ref = referenceDecode(record.data(), p);
    for (uint32_t k = 0; k < count; ++k) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(seq[3 * k + c], ref[k][c], 2e-6) << "trial " << trial << " point " << k;
        EXPECT_NEAR(scan[3 * k + c], ref[k][c], 2e-6) << "trial " << trial << " point " << k;
      }
    }
    // Consecutive decoded points are one step apart.
    for (uint32_t k = 2; k < count; ++k)
      EXPECT_NEAR(std::sqrt(dot(sub(ref[k], ref[k - 1]), sub(ref[k], ref[k - 1]))), p.delta, 1e-9);
  }
}

TEST(FibletDecode, recordsOfAnyCountOutsideTheRangeDecodeToNothing) {
  CodecParams p;
  p.points_per_fiblet = 8;
  const FibletDecoder decoder(p);
  std::vector<uint8_t> record(p.recordBytes(), 0x55);
  float xyz[24];
  for (uint32_t count : {0u, 9u, 63u}) {
    record[shader::fibletFlagsByte(8)] = uint8_t(count << 2);
    EXPECT_EQ(decoder.decodeSequential(record.data(), xyz), 0u) << count;
    EXPECT_EQ(decoder.decodeScan(record.data(), xyz), 0u) << count;
  }
}

// The scalar decode exactly as the header documents it (shared functions on
// vec3s), sequential and scan, as the references for the vectorised CPU
// decoders: the GPU runs the scalar code, so the vector code must match it
// bit for bit.
void scalarDecode(const FibletDecoder& d, const uint8_t* record, bool scan, std::vector<float>& xyz) {
  const uint32_t n = d.params().points_per_fiblet;
  const uint32_t count = shader::fibletCount(record[shader::fibletFlagsByte(n)]);
  const auto point = [&](int which) {
    float c[3];
    for (int axis = 0; axis < 3; ++axis)
      c[axis] = shader::fibletDequantize(uint32_t(record[6 * which + 2 * axis]) |
                                         uint32_t(record[6 * which + 2 * axis + 1]) << 8);
    return shader::vec3(c[0], c[1], c[2]);
  };
  const shader::vec3 v(d.params().v[0], d.params().v[1], d.params().v[2]);
  xyz.clear();
  const auto push = [&](shader::vec3 p) { xyz.insert(xyz.end(), {p.x, p.y, p.z}); };
  push(point(0));
  if (count == 1) return;
  std::vector<shader::FibletTransform> lane(count - 1);
  lane[0] = shader::fibletInitialTransform(point(0), point(1), v);
  for (uint32_t i = 1; i + 1 < count; ++i) lane[i] = d.localTransform(record[shader::fibletCodeByte(i + 1)]);
  if (scan) {
    for (uint32_t offset = 1; offset < lane.size(); offset *= 2) {
      const auto previous = lane;
      for (uint32_t i = offset; i < lane.size(); ++i)
        lane[i] = shader::fibletCompose(previous[i - offset], previous[i]);
    }
  } else {
    for (uint32_t i = 1; i < lane.size(); ++i) lane[i] = shader::fibletCompose(lane[i - 1], lane[i]);
  }
  for (const auto& w : lane) push(w.t);
}

TEST(FibletDecode, vectorisedDecodersAreBitIdenticalToTheSharedScalarArithmetic) {
  PhantomOptions options;
  options.streamlines = 60;
  options.seed = 4;
  options.threads = 1;
  const Tractogram t = readAllStreamlines(*openPhantom(options));
  for (uint32_t n : {8u, 60u}) {
    CodecParamOptions po;
    po.points_per_fiblet = n;
    const CodecParams params = chooseCodecParams(t, po);
    const EncodedFiblets f = encodeTractogram(t, params);
    const FibletDecoder decoder(params);
    std::vector<float> want;
    std::array<float, 3 * shader::kFibletMaxPoints> got;
    for (size_t i = 0; i < f.fibletCount(); ++i) {
      for (const bool scan : {false, true}) {
        scalarDecode(decoder, f.record(i), scan, want);
        const uint32_t count =
            scan ? decoder.decodeScan(f.record(i), got.data()) : decoder.decodeSequential(f.record(i), got.data());
        ASSERT_EQ(size_t(count) * 3, want.size());
        ASSERT_EQ(std::memcmp(got.data(), want.data(), want.size() * sizeof(float)), 0)
            << "fiblet " << i << (scan ? " scan" : " sequential") << " N " << n;
      }
    }
  }
  // compose4 against fibletCompose on long chains of arbitrary transforms.
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1, 1);
  const auto random = [&] {
    shader::FibletTransform f;
    f.c0 = shader::vec3(u(rng), u(rng), u(rng));
    f.c1 = shader::vec3(u(rng), u(rng), u(rng));
    f.c2 = shader::vec3(u(rng), u(rng), u(rng));
    f.t = shader::vec3(u(rng), u(rng), u(rng));
    return f;
  };
  for (int chain = 0; chain < 100; ++chain) {
    shader::FibletTransform a = random();
    Frame4 b = toFrame4(a);
    for (int step = 0; step < 60; ++step) {
      const shader::FibletTransform l = random();
      a = shader::fibletCompose(a, l);
      b = compose4(b, toFrame4(l));
      const shader::FibletTransform c = toTransform(b);
      ASSERT_EQ(std::memcmp(&a, &c, sizeof a), 0) << "chain " << chain << " step " << step;
    }
  }
}

TEST(FibletShaderHeader, compilesAsGlslForVulkan) {
  if (test::runCommand("command -v glslangValidator").exit_code != 0)
    GTEST_SKIP() << "glslangValidator not installed (Debian package glslang-tools)";
  const test::TempDir dir;
  std::ofstream(dir.file("decode.comp")) << R"(#version 450
#extension GL_GOOGLE_include_directive : require
#include "shared/fiblet.h"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Records { uint words[]; };
layout(std430, binding = 1) readonly buffer Table { vec4 dirs[256]; };
layout(std430, binding = 2) writeonly buffer Out { vec4 points[]; };
shared FibletTransform lanes[64];
void main() {
  uint lane = gl_LocalInvocationID.x;
  uint base = gl_WorkGroupID.x * (fibletRecordBytes(kFibletMaxPoints) / 4u);
  uint w0 = words[base], w1 = words[base + 1u], w2 = words[base + 2u];
  vec3 p0 = vec3(fibletDequantize(fibletCoordOfWords(w0, w1, w2, 0u)),
                 fibletDequantize(fibletCoordOfWords(w0, w1, w2, 1u)),
                 fibletDequantize(fibletCoordOfWords(w0, w1, w2, 2u)));
  vec3 p1 = vec3(fibletDequantize(fibletCoordOfWords(w0, w1, w2, 3u)),
                 fibletDequantize(fibletCoordOfWords(w0, w1, w2, 4u)),
                 fibletDequantize(fibletCoordOfWords(w0, w1, w2, 5u)));
  vec3 v = vec3(1.0f, 0.0f, 0.0f);
  if (lane == 0u) {
    lanes[0] = fibletInitialTransform(p0, p1, v);
  } else {
    uint b = fibletCodeByte(lane + 1u);
    lanes[lane] = fibletLocalTransform(dirs[fibletByteOfWord(words[base + b / 4u], b)].xyz, v, 0.001f);
  }
  barrier();
  for (uint offset = 1u; offset < 64u; offset *= 2u) {
    FibletTransform mine = lanes[lane];
    FibletTransform earlier = lane >= offset ? lanes[lane - offset] : mine;
    barrier();
    if (lane >= offset) lanes[lane] = fibletCompose(earlier, mine);
    barrier();
  }
  uint flags_byte = fibletFlagsByte(kFibletMaxPoints);
  uint count = fibletCount(fibletByteOfWord(words[base + flags_byte / 4u], flags_byte));
  if (lane + 1u < count) points[gl_WorkGroupID.x * 60u + lane + 1u] = vec4(lanes[lane].t, 1.0f);
  if (lane == 0u) points[gl_WorkGroupID.x * 60u] = vec4(p0, fibletOctahedralCell(0u).z);
}
)";
  const std::string shaders = std::string(FIBSCOPE_TEST_TOOLS_DIR) + "/../../shaders";
  const test::CommandResult r =
      test::runCommand("glslangValidator -V --target-env vulkan1.3 -I'" + shaders + "' '" + dir.file("decode.comp") +
                       "' -o '" + dir.file("decode.spv") + "' 2>&1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

}  // namespace
}  // namespace fibscope
