// The mesh-shader fiblet pipelines (DESIGN.md section 6 "mesh"; fiblets
// paper 3.3 and its table 2's "mesh (1 thread)"): VK_EXT_mesh_shader only.
//   fiblet_mesh.task         one invocation per fiblet, kMeshTaskGroupSize
//                            per workgroup: the compute cull's tests
//                            (glsl/fiblet_cull.glsl), the survivors
//                            compacted into the payload, one mesh
//                            workgroup each (EmitMeshTasksEXT);
//   fiblet_mesh.mesh         one workgroup of kMeshLanes per surviving
//                            fiblet: each invocation the local transforms of
//                            kMeshRun points, the shared-memory log-step
//                            prefix composing them (paper 3.3.2, as
//                            fiblet_raster.comp), a line-list meshlet out;
//   fiblet_mesh_serial.mesh  one invocation decodes the fiblet front to back
//                            (the geometry shader's serial decode);
//   fiblet_lines.frag        the geometry pipeline's fragment shader.
// The meshlet: vertices = points 0..used (used = count - 1) and, unless the
// fiblet ends its fiber, the next fiblet's first point; primitives = line k
// from vertex k to k + 1, so at most kFibletMaxPoints + 1 = 61 vertices and
// kFibletMaxPoints = 60 lines (the EXT guarantees 256 of each). Vertex k is
// line k's provoking vertex (a mesh line list's first index) and carries its
// flat values, as in the geometry pipeline.
#ifndef FIBSCOPE_SHADERS_SHARED_FIBLET_MESH_H
#define FIBSCOPE_SHADERS_SHARED_FIBLET_MESH_H

#include "shared/cull_push.h"
#include "shared/fiblet.h"
#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define MESH_CONST inline constexpr
#else
#define MESH_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// Fiblets per task workgroup: one word of the two-phase visible bits, so
// phase 2 rewrites its word without atomics (datasets' bit regions are
// whole kCullGroupSize = 64 fiblets, so whole words too).
MESH_CONST uint kMeshTaskGroupSize = 32u;
// Invocations of a parallel mesh workgroup (NVIDIA's
// maxPreferredMeshWorkGroupInvocations; the EXT guarantees 128), each
// composing kMeshRun transforms of the 64 slots (>= kFibletMaxPoints).
MESH_CONST uint kMeshLanes = 32u;
MESH_CONST uint kMeshRun = 64u / kMeshLanes;
// The meshlet's declared sizes (max_vertices, max_primitives).
MESH_CONST uint kMeshMaxVertices = 64u;
MESH_CONST uint kMeshMaxPrimitives = 64u;
// A payload entry: the fiblet, with this bit for far-view LoD (one segment).
MESH_CONST uint kMeshLodFlag = 0x80000000u;

// The task payload: the workgroup's surviving fiblets, compacted; mesh
// workgroup i draws entry i.
struct FibletMeshPayload {
  uint fiblets[32];  // kMeshTaskGroupSize
};

// Push constants of all three stages (and fiblet_lines.frag, which reads
// its FibletDrawPush's camera at offset 8: the cull push's camera).
struct FibletMeshPush {
  // The compute cull's push as its tests read it (mode, camera, visible
  // bits, pyramid, filter, LoD, fiber base); `list` and `lod_list`, when
  // not 0, are FibletLists whose counts the task shader adds its full and
  // LoD survivors to (the statistics: the lists themselves stay empty).
  FibletCullPush cull;
  // 1: no test at all, every fiblet drawn (CullingMode::None without a
  // filter); cull.mode is then ignored.
  uint draw_all;
  uint pad;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::FibletMeshPush) == 80, "");
static_assert(offsetof(fibscope::shader::FibletMeshPush, cull) == 0, "dataset at 0, camera at 8");
static_assert(sizeof(fibscope::shader::FibletMeshPayload) == 4 * fibscope::shader::kMeshTaskGroupSize, "");
static_assert(fibscope::shader::kMeshMaxVertices >= fibscope::shader::kFibletMaxPoints + 1, "");
static_assert(fibscope::shader::kMeshMaxPrimitives >= fibscope::shader::kFibletMaxPoints, "");
static_assert(fibscope::shader::kMeshLanes * fibscope::shader::kMeshRun >= fibscope::shader::kFibletMaxPoints, "");
static_assert(fibscope::shader::kMeshTaskGroupSize == 32, "one visible-bit word per task workgroup");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_FIBLET_MESH_H
