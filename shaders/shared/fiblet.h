// Fiblet record layout and decode arithmetic, shared by the CPU codec and the
// GPU shaders (fiblets paper, Schertzer et al. 2022, section 3.2, 3.3.2 and
// appendices A-B; DESIGN.md section 5).
//
// Record of a codec with N points per fiblet (N a multiple of 4 in [8, 60]),
// little-endian, read by the GPU as uints:
//   bytes 0..11        points 0 and 1, 16-bit unsigned per coordinate of the
//                      normalised [0,1]^3 space: x0 y0 z0 x1 y1 z1
//   bytes 12..N+9      one direction code per point 2..N-1 (unused bytes 0)
//   byte  N+10         flags: bit 0 begins fiber, bit 1 ends fiber,
//                      bits 2..7 point count (1..N)
//   pad to a multiple of 4 bytes (N = 60: 72 bytes, 1.2 bytes per point)
// A fiblet of count 1 stores point 0 twice.
//
// Decoding (all float, only +, -, * so that Vulkan GPUs reproduce it bit
// for bit with `precise`):
//   W_1 = [frame(normalize(p1 - p0)) | p1]
//   L_k = [frameFromForward(d_k, V) | delta * d_k]   k = 2..count-1
//   W_k = W_{k-1} * L_k,   point k = translation of W_k
// where d_k is the code's direction in the local frame of segment k-1 (a
// unit vector within alpha of the forward axis +z), looked up in a 256-entry
// table built on the CPU (trigonometry is not bit-reproducible on GPUs, a
// table lookup is). Composition is associative, so a workgroup composes the
// transforms with a log-step inclusive scan: lane i holds W_1 (i = 0) or
// L_{i+1}; at step s (offset o = 2^s) lane i >= o becomes
// fibletCompose(lane[i - o], lane[i]); after ceil(log2(count - 1)) steps lane
// i holds W_{i+1}. The CPU emulates exactly this order (fiblet_decoder.cpp).
#ifndef FIBSCOPE_SHADERS_SHARED_FIBLET_H
#define FIBSCOPE_SHADERS_SHARED_FIBLET_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define FIBLET_CONST inline constexpr
#else
#define FIBLET_CONST const
#endif

SHADER_NAMESPACE_BEGIN

FIBLET_CONST uint kFibletMaxPoints = 60u;
FIBLET_CONST uint kFibletMinPoints = 8u;
FIBLET_CONST uint kFibletPointBytes = 12u;      // points 0 and 1
FIBLET_CONST uint kFibletCodeCount = 256u;
FIBLET_CONST uint kFibletGridSize = 16u;        // 4 + 4 bits: 16 x 16 octahedral cells
FIBLET_CONST uint kFibletFlagBegins = 1u;
FIBLET_CONST uint kFibletFlagEnds = 2u;
FIBLET_CONST uint kFibletCountShift = 2u;
FIBLET_CONST uint kFibletQuantMax = 65535u;
// 1 / 65535 rounded to float, written out so that no compiler folds a
// division differently (checked against 1.0f / 65535.0f in the tests).
FIBLET_CONST float kFibletInvQuantMax = 1.52590219e-05f;

// Size in bytes of one record for N points per fiblet.
SHADER_FN uint fibletRecordBytes(uint n) { return (n + 11u + 3u) & ~3u; }
// Byte offset of the code of point k (k >= 2).
SHADER_FN uint fibletCodeByte(uint k) { return kFibletPointBytes + k - 2u; }
// Byte offset of the flags byte.
SHADER_FN uint fibletFlagsByte(uint n) { return n + 10u; }

SHADER_FN uint fibletFlags(bool begins, bool ends, uint count) {
  return (begins ? kFibletFlagBegins : 0u) | (ends ? kFibletFlagEnds : 0u) | (count << kFibletCountShift);
}
SHADER_FN uint fibletCount(uint flags) { return flags >> kFibletCountShift; }

// Byte `index` of a record given as uint words.
SHADER_FN uint fibletByteOfWord(uint word, uint index) { return (word >> (8u * (index & 3u))) & 0xffu; }
// 16-bit coordinate c (0..5: x0 y0 z0 x1 y1 z1) from the first three words.
SHADER_FN uint fibletCoordOfWords(uint w0, uint w1, uint w2, uint c) {
  uint w = c < 2u ? w0 : (c < 4u ? w1 : w2);
  return (c & 1u) == 0u ? (w & 0xffffu) : (w >> 16u);
}

SHADER_FN float fibletDequantize(uint q) {
  SHADER_PRECISE float v = float(q) * kFibletInvQuantMax;
  return v;
}

// A rigid transform: rotation columns c0 (right), c1 (up), c2 (forward) and
// translation t.
struct FibletTransform {
  vec3 c0;
  vec3 c1;
  vec3 c2;
  vec3 t;
};

// Dot and cross products in a fixed evaluation order (GLSL's built-ins leave
// it open).
SHADER_FN float fibletDot(vec3 a, vec3 b) {
  SHADER_PRECISE float xx = a.x * b.x;
  SHADER_PRECISE float yy = a.y * b.y;
  SHADER_PRECISE float zz = a.z * b.z;
  SHADER_PRECISE float s = (xx + yy) + zz;
  return s;
}
SHADER_FN vec3 fibletCross(vec3 a, vec3 b) {
  SHADER_PRECISE float x = a.y * b.z - a.z * b.y;
  SHADER_PRECISE float y = a.z * b.x - a.x * b.z;
  SHADER_PRECISE float z = a.x * b.y - a.y * b.x;
  return vec3(x, y, z);
}

// 1/sqrt(x) from the bit-level initial guess and three Newton steps: only
// multiplications and subtractions, so every device gives the same bits
// (GLSL inversesqrt/sqrt/division are not correctly rounded). Relative error
// a few float ulps for normal x > 0; x = 0 gives a large finite value, so
// normalising a zero vector gives zero, never NaN.
SHADER_FN float fibletRsqrt(float x) {
  SHADER_PRECISE float y = uintBitsToFloat(0x5f375a86u - (floatBitsToUint(x) >> 1u));
  SHADER_PRECISE float hx = 0.5f * x;
  y = y * (1.5f - hx * y * y);
  y = y * (1.5f - hx * y * y);
  y = y * (1.5f - hx * y * y);
  return y;
}
SHADER_FN vec3 fibletNormalize(vec3 v) {
  SHADER_PRECISE float r = fibletRsqrt(fibletDot(v, v));
  SHADER_PRECISE vec3 n = v * r;
  return n;
}

// Rotation whose forward column is f (unit), with right = normalize(f x v),
// up = right x f. v must not be collinear with f.
SHADER_FN FibletTransform fibletFrameFromForward(vec3 f, vec3 v) {
  SHADER_PRECISE vec3 right = fibletNormalize(fibletCross(f, v));
  SHADER_PRECISE vec3 up = fibletCross(right, f);
  // Member by member: GLSL's constructor syntax FibletTransform(a, b, c, d)
  // is C++20 parenthesised aggregate initialisation, which clang 14 lacks.
  FibletTransform frame;
  frame.c0 = right;
  frame.c1 = up;
  frame.c2 = f;
  frame.t = vec3(0.0f);
  return frame;
}

// A unit vector perpendicular to v (unit): the fallback constant vector for
// the first frame of a fiblet, whose forward direction is arbitrary.
SHADER_FN vec3 fibletPerpendicular(vec3 v) {
  vec3 axis = abs(v.x) <= abs(v.y) ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f);
  return fibletNormalize(fibletCross(v, axis));
}

// W_1: forward along p1 - p0 (or +z when the two points coincide), frame
// from V unless the forward direction is within 30 degrees of V (then from
// fibletPerpendicular(V), which is at least 60 degrees away), origin p1.
SHADER_FN FibletTransform fibletInitialTransform(vec3 p0, vec3 p1, vec3 v) {
  SHADER_PRECISE vec3 d = p1 - p0;
  SHADER_PRECISE float dd = fibletDot(d, d);
  SHADER_PRECISE vec3 f = dd > 1e-20f ? d * fibletRsqrt(dd) : vec3(0.0f, 0.0f, 1.0f);
  SHADER_PRECISE vec3 c = fibletCross(f, v);
  vec3 axis = fibletDot(c, c) >= 0.25f ? v : fibletPerpendicular(v);
  FibletTransform w = fibletFrameFromForward(f, axis);
  w.t = p1;
  return w;
}

// L_k from the decoded local direction d (unit, within alpha of +z) and the
// normalised step delta.
SHADER_FN FibletTransform fibletLocalTransform(vec3 d, vec3 v, float delta) {
  FibletTransform l = fibletFrameFromForward(d, v);
  l.t = d * delta;
  return l;
}

// Rotation part of a times vector b: c0*b.x + c1*b.y + c2*b.z, in that order.
SHADER_FN vec3 fibletRotate(FibletTransform a, vec3 b) {
  SHADER_PRECISE vec3 r = (a.c0 * b.x + a.c1 * b.y) + a.c2 * b.z;
  return r;
}

// a * b (apply b first, then a): the earlier transform on the left.
SHADER_FN FibletTransform fibletCompose(FibletTransform a, FibletTransform b) {
  FibletTransform r;
  r.c0 = fibletRotate(a, b.c0);
  r.c1 = fibletRotate(a, b.c1);
  r.c2 = fibletRotate(a, b.c2);
  SHADER_PRECISE vec3 t = fibletRotate(a, b.t) + a.t;
  r.t = t;
  return r;
}

#ifdef __cplusplus
static_assert(kFibletMaxPoints <= 63u, "the point count has 6 bits");
static_assert(sizeof(FibletTransform) == 48, "FibletTransform is 12 floats");
static_assert(sizeof(vec4) == 16, "direction table entries are std430 vec4");
#endif

// Octahedral cell centre of a code as an unnormalised upper-hemisphere
// vector: the high nibble indexes u, the low nibble v, (u, v) in [-1, 1]^2
// is the 45-degree rotated upper half of the octahedron: x = (u + v) / 2,
// y = (u - v) / 2, z = 1 - |x| - |y| = 1 - max(|u|, |v|) > 0.
SHADER_FN vec3 fibletOctahedralCell(uint code) {
  SHADER_PRECISE float u = (float(code >> 4u) + 0.5f) * (2.0f / 16.0f) - 1.0f;
  SHADER_PRECISE float v = (float(code & 15u) + 0.5f) * (2.0f / 16.0f) - 1.0f;
  SHADER_PRECISE float x = (u + v) * 0.5f;
  SHADER_PRECISE float y = (u - v) * 0.5f;
  SHADER_PRECISE float z = 1.0f - max(abs(u), abs(v));
  return vec3(x, y, z);
}

SHADER_NAMESPACE_END

#endif  // FIBSCOPE_SHADERS_SHARED_FIBLET_H
