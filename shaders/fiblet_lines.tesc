// Tessellation fiblet pipeline, control stage (paper section 4.5, table 2):
// one patch of one control point per fiblet; this stage decodes the fiblet
// and the fixed-function tessellator makes one isoline of `segments`
// segments (gl_TessLevelOuter = {1, segments}, at most 60 < 64, the minimum
// maxTessellationGenerationLevel) whose vertices fiblet_lines.tese places
// on the decoded points.
//
// Why the decode is here and parallel: the evaluation stage runs once per
// generated vertex, so decoding there (from the fiblet's start up to the
// vertex) costs O(n^2) compositions per fiblet. The control stage instead
// runs kLanes = 32 invocations per patch (the output patch size, which the
// pass checks against maxTessellationPatchSize), each owning two of the 64
// transform slots (transform k gives point k + 1), and composes them with
// the paper's log-step parallel prefix (3.3.2), as fiblet_raster.comp does
// across a workgroup: the per-vertex outputs are the shared memory, read
// across invocations after barrier(). GLSL allows barrier() in the control
// stage only at the top level of main (no loops, no branches, no return
// before it), so the five steps (32 = 2^5) are written out and invalid
// fiblets run them on identities. Each invocation then writes its two
// points (world mm) as per-vertex outputs; point 0 and the patch values are
// per-patch. The composition order is the scan's, so the points match the
// compute pipeline's to float rounding (not bit for bit: the serial raster
// composes left to right).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/render_push.h"
#include "glsl/fiblet_record.glsl"

const uint kLanes = 32u;  // two transform slots each: 64 >= kFibletMaxPoints
layout(vertices = 32) out;

layout(push_constant, std430) uniform Push { FibletDrawPush pc; };

layout(location = 0) in uint in_fiblet[];

// The scan's partial products (one transform per invocation).
layout(location = 0) out vec3 scan_c0[];
layout(location = 1) out vec3 scan_c1[];
layout(location = 2) out vec3 scan_c2[];
layout(location = 3) out vec3 scan_t[];
// Points 2 * lane + 1 and 2 * lane + 2 (world mm): the decoded points, and
// the joining point (the next fiblet's first) in the slot after the last.
layout(location = 4) out vec3 point_a[];
layout(location = 5) out vec3 point_b[];
layout(location = 6) patch out vec3 first_point;  // point 0, world mm
layout(location = 7) patch out uint fiber;        // scene-global, as the compute resolve's
layout(location = 8) patch out uint segments;     // decoded segments + the joining one

FibletTransform identityTransform() {
  FibletTransform r;
  r.c0 = vec3(1.0, 0.0, 0.0);
  r.c1 = vec3(0.0, 1.0, 0.0);
  r.c2 = vec3(0.0, 0.0, 1.0);
  r.t = vec3(0.0);
  return r;
}

FibletTransform loadScan(uint i) {
  FibletTransform r;
  r.c0 = scan_c0[i];
  r.c1 = scan_c1[i];
  r.c2 = scan_c2[i];
  r.t = scan_t[i];
  return r;
}

// An invocation writes only its own outputs (GLSL: indexed by gl_InvocationID).
void storeScan(FibletTransform t) {
  scan_c0[gl_InvocationID] = t.c0;
  scan_c1[gl_InvocationID] = t.c1;
  scan_c2[gl_InvocationID] = t.c2;
  scan_t[gl_InvocationID] = t.t;
}

// One step of the inclusive scan: lane i >= o becomes lane[i - o] * lane[i]
// (the earlier transform on the left). Reads before the barrier, writes
// after it, so no lane reads a value of this step.
#define SCAN_STEP(o)                                                  \
  FibletTransform combined##o = s;                                    \
  if (lane >= o) combined##o = fibletCompose(loadScan(lane - o), s);  \
  barrier();                                                          \
  s = combined##o;                                                    \
  storeScan(s);                                                 \
  barrier();

void main() {
  const uint lane = uint(gl_InvocationID);
  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  const uint fiblet = in_fiblet[0];
  bool valid = fiblet < ds.fiblet_count;
  const uint n = ds.points_per_fiblet;
  WordsRef records = WordsRef(ds.records);
  const uint base = valid ? fiblet * ds.record_words : 0u;
  uint flags = 0u, count = 0u;
  if (valid) {
    flags = fibletRecordByte(records, base, fibletFlagsByte(n));
    count = fibletCount(flags);
    valid = count >= 1u && count <= n;  // the uploader validated the records; never draw garbage
  }
  const bool joins = valid && (flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count;
  vec3 p0 = vec3(0.0), p1 = vec3(0.0);
  if (valid) {
    const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
    p0 = fibletRecordPoint(w0, w1, w2, 0u);
    p1 = fibletRecordPoint(w0, w1, w2, 1u);
  }
  const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
  DirectionsRef directions = DirectionsRef(ds.directions);
  const uint used = valid ? count - 1u : 0u;  // transforms (decoded segments)

  // 1. The run's two transforms, their product and local prefixes.
  const uint first = 2u * lane;
  vec3 local[2];
  FibletTransform s = identityTransform();
  for (uint j = 0u; j < 2u; ++j) {
    const uint k = first + j;
    local[j] = vec3(0.0);
    if (k < used) {
      const FibletTransform t =
          k == 0u ? fibletInitialTransform(p0, p1, v)
                  : fibletTableTransform(directions, fibletRecordByte(records, base, fibletCodeByte(k + 1u)));
      s = j == 0u ? t : fibletCompose(s, t);
      local[j] = s.t;
    }
  }
  storeScan(s);
  barrier();
  // 2. Inclusive scan across the 32 lanes: lane i ends with runs 0..i.
  SCAN_STEP(1u)
  SCAN_STEP(2u)
  SCAN_STEP(4u)
  SCAN_STEP(8u)
  SCAN_STEP(16u)
  // 3. The run's points through the exclusive prefix (lane 0's are absolute).
  const FibletTransform e = lane == 0u ? identityTransform() : loadScan(lane - 1u);
  vec3 points[2];
  for (uint j = 0u; j < 2u; ++j) {
    const uint k = first + j;
    points[j] = vec3(0.0);
    if (k < used) {
      points[j] = fibletToWorld(ds, fibletRotate(e, local[j]) + e.t);
    } else if (k == used && joins) {
      points[j] = fibletToWorld(ds, fibletFirstPoint(records, base + ds.record_words));
    }
  }
  point_a[gl_InvocationID] = points[0];
  point_b[gl_InvocationID] = points[1];

  if (lane == 0u) {
    const uint drawn = used + (joins ? 1u : 0u);
    first_point = fibletToWorld(ds, p0);
    fiber = valid ? pc.fiber_base + UintsRef(ds.fiblet_fiber).values[fiblet] : 0u;
    segments = drawn;
    // Level 0 discards the patch (nothing to draw: an invalid fiblet, or a
    // lone point ending its fiber, as the compute rasters skip it).
    gl_TessLevelOuter[0] = drawn > 0u ? 1.0 : 0.0;
    gl_TessLevelOuter[1] = float(drawn);
  }
}
