// Far-view LoD raster (DESIGN.md section 6, step 1): one invocation per
// fiblet of a LoD list, which draws the fiblet as ONE segment, from its
// first point to the next fiblet's first point when the fiber goes on, else
// to its second point, with the full raster's pixel rule. The payload names
// segment 0 of the fiblet, so the resolve gives the right fiber (and segment
// 0's tangent, a fine approximation at a few pixels).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "shared/workgroup.h"
#include "shared/cull_push.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/raster_segment.glsl"
#include "glsl/tangent.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kLodRasterGroupSize: the finalize pass's items_per_group

layout(push_constant, std430) uniform Push { FibletLodRasterPush pc; };

void main() {
  FibletListRef list = FibletListRef(pc.list);
  const uint index = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
  if (index >= list.header.count) return;
  const uint fiblet = list.fiblets[index];
  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  if (fiblet >= ds.fiblet_count) return;
  WordsRef records = WordsRef(ds.records);
  const uint base = fiblet * ds.record_words;
  const uint flags = fibletRecordByte(records, base, fibletFlagsByte(ds.points_per_fiblet));
  const uint count = fibletCount(flags);
  if (count < 1u || count > ds.points_per_fiblet) return;
  const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
  const vec3 a = fibletRecordPoint(w0, w1, w2, 0u);
  vec3 b;
  if ((flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count) {
    b = fibletFirstPoint(records, base + ds.record_words);
  } else if (count >= 2u) {
    b = fibletRecordPoint(w0, w1, w2, 1u);
  } else {
    return;  // a single point ending its fiber draws nothing
  }
  const CameraBlock cam = CameraRef(pc.camera).camera;
  rasterSegment(VisibilityRef(pc.visibility), cam, fibletToWorld(ds, a), fibletToWorld(ds, b),
                uint64_t(pc.fiblet_base + fiblet) << kKeySegmentBits);
  // Its pixels resolve as segment 0: give that entry this segment's tangent.
  if (pc.tangents != 0ul) UintsOutRef(pc.tangents).values[(pc.fiblet_base + fiblet) * 64u] = packSegmentTangent(b - a);
}
