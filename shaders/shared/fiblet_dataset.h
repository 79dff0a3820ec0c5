// The description of a dataset on the GPU (render/gpu/dataset.h uploads
// it), shared by the shaders and the C++ that fills it.
//
// It lives in a small device-local buffer of its own, and a pass receives
// only that buffer's device address in its push constants (8 bytes). As a
// push constant the block would take 96 of the 128 bytes Vulkan guarantees,
// leaving too little for a pass's own outputs and camera; read through a
// buffer reference it costs one uniform, cached load per workgroup.
//
// Buffers are device addresses (uint64_t; the shader casts them to buffer
// references). Counts are uint32: the uploader refuses datasets of 2^32 - 1
// fiblets or fibers or more (fiber_first_fiblet's last entry is the fiblet
// count).
#ifndef FIBSCOPE_SHADERS_SHARED_FIBLET_DATASET_H
#define FIBSCOPE_SHADERS_SHARED_FIBLET_DATASET_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#include <cstddef>
#endif

SHADER_NAMESPACE_BEGIN

// std430 and C++ agree: the uint64_t members first, then 4-byte scalars
// only (no vec3/vec4, whose GLSL alignment differs), 96 bytes in all.
struct FibletDataset {
  // uint words, record_words per fiblet: the .fbl "fiblets" section as is.
  uint64_t records;
  // uint per fiblet: the index of the fiber the fiblet belongs to (derived
  // from fiber_first_fiblet on the CPU; the resolve pass maps fiblet ->
  // fiber -> per-fiber colour and length).
  uint64_t fiblet_fiber;
  // vec4[256]: the unit direction of each code in the local frame (w = 0),
  // buildDirectionTable(alpha); then vec4[3 * 256]: each code's local
  // transform L_c = fibletLocalTransform(direction, V, delta) as 12 floats
  // (c0, c1, c2, t) in 3 vec4 (fibletTableTransform in
  // shaders/glsl/fiblet_record.glsl reads it).
  uint64_t directions;
  // uint x (fiber_count + 1): the first fiblet of each fiber, then
  // fiblet_count (fiber f owns fiblets [first[f], first[f + 1])).
  uint64_t fiber_first_fiblet;
  // float per fiber: its length in mm (the length filter).
  uint64_t fiber_length_mm;
  // vec4 per fiblet, or 0 (none): each fiblet's bounding sphere in world mm
  // (xyz centre, w radius; w < 0: the fiblet draws nothing), computed on the
  // device after the upload by fiblet_bounds.comp (render/gpu/fiblet_bounds.h).
  // The cull uses it when present, else a looser bound from the record.
  uint64_t fiblet_bounds;
  uint fiber_count;
  uint fiblet_count;
  uint record_words;       // uint words per fiblet record: fibletRecordBytes(N) / 4
  uint points_per_fiblet;  // N
  // Normalised -> world (RAS+ mm): p_mm = translation + mm_per_unit * p_n
  // (mm_per_unit = 1 / CodecParams::scale, rounded once from double).
  float translation_x;
  float translation_y;
  float translation_z;
  float mm_per_unit;
  float delta;  // the step in normalised units (CodecParams::delta)
  float v_x;    // the constant vector V of the local frames
  float v_y;
  float v_z;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::FibletDataset) == 96, "the dataset block is 96 bytes in std430");
static_assert(offsetof(fibscope::shader::FibletDataset, fiblet_bounds) == 40, "the bounds follow the tables");
static_assert(offsetof(fibscope::shader::FibletDataset, fiber_count) == 48, "scalars follow the six addresses");
static_assert(offsetof(fibscope::shader::FibletDataset, translation_x) == 64, "floats follow the four uints");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_FIBLET_DATASET_H
