// Push constants of shaders/fiblet_decode_test.comp, shared by the shader
// and the C++ test that dispatches it. Buffers are passed as device
// addresses (uint64_t; the shader casts them to buffer references).
#ifndef FIBSCOPE_SHADERS_SHARED_FIBLET_DECODE_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_FIBLET_DECODE_PUSH_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#include <cstddef>
#endif

SHADER_NAMESPACE_BEGIN

// std430: the uint64_t members first so that no padding appears; 56 bytes
// under both languages (scalars only, no vec4 whose GLSL alignment is 16).
struct FibletDecodePush {
  uint64_t records;  // uint words, record_words per fiblet
  uint64_t table;    // vec4[256]: the direction of each code (w unused)
  uint64_t points;   // float[3 * N] per fiblet: the decoded normalised points
  uint64_t counts;   // uint per fiblet: decoded point count (0: invalid record)
  float v_x;         // the constant vector V of the local frames
  float v_y;
  float v_z;
  float delta;             // normalised step
  uint points_per_fiblet;  // N
  uint fiblet_count;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::FibletDecodePush) == 56, "push constants are 56 bytes in std430");
static_assert(offsetof(fibscope::shader::FibletDecodePush, v_x) == 32, "scalars follow the four addresses");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_FIBLET_DECODE_PUSH_H
