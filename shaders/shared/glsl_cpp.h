// Preamble that lets one header compile as both GLSL and C++.
//
// Headers under shaders/shared/ are written in the common subset of GLSL 4.50
// and C++20: structs, plain functions that take and return values, float
// arithmetic with explicit `f` literals, uint with `u` literals. Under
// __cplusplus this file supplies the GLSL types and built-ins they use; under
// GLSL it only defines the hook macros.
//
// Rules for shared code (so CPU and GPU give the same bits):
//   - only +, -, * on floats (Vulkan makes these correctly rounded); no
//     division, sqrt, normalize, trig or built-in matrix products, whose
//     precision is implementation-defined on GPUs;
//   - every float temporary is declared SHADER_PRECISE (GLSL `precise`: no
//     reassociation, no FMA contraction; C++ gets -ffp-contract=off from the
//     build);
//   - functions are declared SHADER_FN (inline in C++, forced: the encoder
//     calls them per point, and out-of-line calls passed 48-byte transforms
//     through the stack at a third of the encoder's time);
//   - float literals carry `f` (in C++ a bare 1.0 is double and would change
//     the arithmetic).
#ifndef FIBSCOPE_SHADERS_SHARED_GLSL_CPP_H
#define FIBSCOPE_SHADERS_SHARED_GLSL_CPP_H

#ifdef __cplusplus

#include <bit>
#include <cmath>
#include <cstdint>

#define SHADER_PRECISE
#if defined(__GNUC__)
#define SHADER_FN [[gnu::always_inline]] inline
#else
#define SHADER_FN inline
#endif
#define SHADER_NAMESPACE_BEGIN namespace fibscope::shader {
#define SHADER_NAMESPACE_END }

namespace fibscope::shader {

using uint = uint32_t;

struct vec3 {
  float x = 0, y = 0, z = 0;
  constexpr vec3() = default;
  constexpr explicit vec3(float s) : x(s), y(s), z(s) {}
  constexpr vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};
struct vec4 {
  float x = 0, y = 0, z = 0, w = 0;
  constexpr vec4() = default;
  constexpr vec4(float x_, float y_, float z_, float w_) : x(x_), y(y_), z(z_), w(w_) {}
  constexpr vec4(vec3 v, float w_) : x(v.x), y(v.y), z(v.z), w(w_) {}
};
struct uvec3 {
  uint x = 0, y = 0, z = 0;
};

// Component-wise operators, evaluated x, y, z as GLSL does.
constexpr vec3 operator+(vec3 a, vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
constexpr vec3 operator-(vec3 a, vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
constexpr vec3 operator-(vec3 a) { return {-a.x, -a.y, -a.z}; }
constexpr vec3 operator*(vec3 a, vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
constexpr vec3 operator*(vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
constexpr vec3 operator*(float s, vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
constexpr bool operator==(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// GLSL defines dot and cross exactly like this, but leaves the evaluation
// order to the compiler; shared code spells them out (see fiblet.h) where
// bits matter. These are for C++-side convenience.
constexpr float dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr vec3 cross(vec3 a, vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

inline float abs(float v) { return std::fabs(v); }
inline float floor(float v) { return std::floor(v); }
inline float trunc(float v) { return std::trunc(v); }
inline float min(float a, float b) { return a < b ? a : b; }
inline float max(float a, float b) { return a > b ? a : b; }
inline float clamp(float v, float lo, float hi) { return min(max(v, lo), hi); }
inline uint min(uint a, uint b) { return a < b ? a : b; }
inline uint floatBitsToUint(float v) { return std::bit_cast<uint>(v); }
inline float uintBitsToFloat(uint v) { return std::bit_cast<float>(v); }

}  // namespace fibscope::shader

#else  // GLSL

#define SHADER_PRECISE precise
#define SHADER_FN
#define SHADER_NAMESPACE_BEGIN
#define SHADER_NAMESPACE_END

#endif

#endif  // FIBSCOPE_SHADERS_SHARED_GLSL_CPP_H
