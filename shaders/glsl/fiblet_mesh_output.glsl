// The meshlet both mesh shaders write (shared/fiblet_mesh.h): the output
// declarations and the writes, and what a payload entry draws. The
// per-vertex outputs are those of fiblet_lines.geom (gl_Position, the cuts'
// gl_ClipDistance, three flat words at locations 0-2), which
// fiblet_lines.frag reads; vertex k carries line k's values (it is that
// line's provoking vertex).
#ifndef FIBSCOPE_GLSL_FIBLET_MESH_OUTPUT_GLSL
#define FIBSCOPE_GLSL_FIBLET_MESH_OUTPUT_GLSL

#include "shared/fiblet_mesh.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/tangent.glsl"

layout(lines, max_vertices = 64, max_primitives = 64) out;  // kMeshMaxVertices, kMeshMaxPrimitives

layout(push_constant, std430) uniform Push { FibletMeshPush pc; };

taskPayloadSharedEXT FibletMeshPayload payload;

out gl_MeshPerVertexEXT {
  vec4 gl_Position;
  float gl_ClipDistance[kMaxFrameClipPlanes];
} gl_MeshVerticesEXT[];

layout(location = 0) flat out uint out_fiber[];
layout(location = 1) flat out uint out_segment[];
layout(location = 2) flat out uint out_tangent[];

// Vertex v's position (world mm) and its distances to the cuts' planes.
void meshVertex(CameraBlock cam, uint v, vec3 p) {
  gl_MeshVerticesEXT[v].gl_Position = cameraTransformPoint(cam.view_projection, p);
  const uint planes = uint(cam.cuts.x);
  for (uint i = 0u; i < kMaxFrameClipPlanes; ++i)
    gl_MeshVerticesEXT[v].gl_ClipDistance[i] = i < planes ? dot(cam.clip_world[i].xyz, p) + cam.clip_world[i].w : 1.0;
}

// Vertex v's flat values: line v's segment index and tangent (the last
// vertex provokes no line: 0, 0).
void meshVertexFlat(uint v, uint fiber, uint segment, uint tangent) {
  out_fiber[v] = fiber;
  out_segment[v] = segment;
  out_tangent[v] = tangent;
}

void meshLine(uint k) { gl_PrimitiveLineIndicesEXT[k] = uvec2(k, k + 1u); }

// What one payload entry draws, from its record alone (no decode).
struct MeshFiblet {
  uint fiblet;
  bool lod;       // one segment: p0 to the joining point, else to p1
  uint base;      // its first record word
  uint used;      // count - 1: the segments within the fiblet
  bool joins;     // the segment to the next fiblet's first point
  vec3 p0, p1;    // normalised units
  uint vertices;  // SetMeshOutputsEXT's counts (0, 0: nothing to draw)
  uint lines;
};

MeshFiblet meshFiblet(FibletDataset ds, uint entry) {
  MeshFiblet f;
  f.fiblet = entry & ~kMeshLodFlag;
  f.lod = (entry & kMeshLodFlag) != 0u;
  f.base = f.fiblet * ds.record_words;
  f.used = 0u;
  f.joins = false;
  f.p0 = vec3(0.0);
  f.p1 = vec3(0.0);
  f.vertices = 0u;
  f.lines = 0u;
  if (f.fiblet >= ds.fiblet_count) return f;
  WordsRef records = WordsRef(ds.records);
  const uint n = ds.points_per_fiblet;
  const uint flags = fibletRecordByte(records, f.base, fibletFlagsByte(n));
  const uint count = fibletCount(flags);
  if (count < 1u || count > n) return f;  // the uploader validated the records; never draw garbage
  f.used = count - 1u;
  f.joins = (flags & kFibletFlagEnds) == 0u && f.fiblet + 1u < ds.fiblet_count;
  const uint w0 = records.words[f.base], w1 = records.words[f.base + 1u], w2 = records.words[f.base + 2u];
  f.p0 = fibletRecordPoint(w0, w1, w2, 0u);
  f.p1 = fibletRecordPoint(w0, w1, w2, 1u);
  if (f.used == 0u && !f.joins) return f;  // a lone point draws nothing, as in the compute rasters
  if (f.lod) {
    f.vertices = 2u;
    f.lines = 1u;
  } else {
    f.lines = f.used + (f.joins ? 1u : 0u);
    f.vertices = f.lines + 1u;
  }
  return f;
}

// A LoD entry's one segment (fiblet_lod_raster.comp's: segment 0, from p0
// to the joining point, else to p1), written by one invocation.
void meshLodSegment(FibletDataset ds, CameraBlock cam, MeshFiblet f, uint fiber) {
  const vec3 a = fibletToWorld(ds, f.p0);
  const vec3 b = fibletToWorld(ds, f.joins ? fibletFirstPoint(WordsRef(ds.records), f.base + ds.record_words) : f.p1);
  meshVertex(cam, 0u, a);
  meshVertex(cam, 1u, b);
  meshVertexFlat(0u, fiber, 0u, packSegmentTangent(b - a));
  meshVertexFlat(1u, fiber, 0u, 0u);
  meshLine(0u);
}

#endif
