// Buffer-reference types of the render passes (GLSL only; the structs come
// from shaders/shared/). Requires GL_EXT_buffer_reference and
// GL_EXT_shader_explicit_arithmetic_types_int64 in the including shader.
#ifndef FIBSCOPE_GLSL_RENDER_BUFFERS_GLSL
#define FIBSCOPE_GLSL_RENDER_BUFFERS_GLSL

#include "shared/camera.h"
#include "shared/fiblet_dataset.h"
#include "shared/fiblet_list.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer CameraRef { CameraBlock camera; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer DatasetRef { FibletDataset ds; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer WordsRef { uint words[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer UintsRef { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer UintsOutRef { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer FloatsRef { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer DirectionsRef { vec4 directions[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer VisibilityRef { uint64_t keys[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer GBufferRef { GBufferTexel texels[]; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer FibletListRef {
  FibletListHeader header;
  uint fiblets[];
};
// The same layout listing screen tiles (tile_classify.comp).
layout(buffer_reference, std430, buffer_reference_align = 4) buffer TileListRef {
  FibletListHeader header;
  uint tiles[];
};

#endif
