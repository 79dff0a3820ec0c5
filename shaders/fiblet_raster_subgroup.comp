// The decode + raster pass of fiblet_raster.comp with the scan of the runs
// done by subgroup shuffles (no shared memory, no barriers), for devices
// whose subgroup size is a multiple of the lanes per fiblet and that support
// KHR_shader_subgroup_shuffle_relative in compute shaders: a subgroup holds
// subgroup size / LANES fiblets (lavapipe: 8 lanes, one fiblet per subgroup;
// NVIDIA: 8 lanes, four fiblets per 32-wide subgroup). Chosen by
// createFibletPasses.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_shuffle_relative : require

#define FIBLET_SUBGROUP_SCAN 1
#include "glsl/fiblet_raster_body.glsl"
