// The cull's per-fiblet tests (DESIGN.md section 6, step 1): bounding
// sphere, clip planes and mesh cuts, dilated frustum, far-view LoD,
// occlusion against the depth pyramid, the fiber filter, and the verdict
// that combines them by mode (fibletCullTarget). Included by the compute
// cull (fiblet_cull.comp: the survivors into lists) and by the mesh
// pipeline's task shader (fiblet_mesh.task: the survivors into its
// payload), so both cull exactly alike. Why each test is conservative:
// fiblet_cull.comp's header and shared/cull_push.h. The includer declares
// nothing of its own for these; FibletCullPush is passed in (its modes,
// addresses, LoD threshold and fiber base).
#ifndef FIBSCOPE_GLSL_FIBLET_CULL_GLSL
#define FIBSCOPE_GLSL_FIBLET_CULL_GLSL

#include "shared/cull_push.h"
#include "glsl/fiblet_record.glsl"

layout(buffer_reference, std430, buffer_reference_align = 4) buffer BitsRef { uint words[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer PyramidRef { float depths[]; };

// Row i of the view-projection matrix (stored as columns).
vec4 matrixRow(CameraBlock cam, int i) {
  return vec4(cam.view_projection[0][i], cam.view_projection[1][i], cam.view_projection[2][i],
              cam.view_projection[3][i]);
}

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer BoundsRef { vec4 spheres[]; };

// False for a fiblet that draws nothing (a single point ending its fiber,
// or a record the raster would refuse).
bool fibletSphere(FibletDataset ds, uint fiblet, out vec3 centre, out float radius) {
  if (ds.fiblet_bounds != 0ul) {
    const vec4 sphere = BoundsRef(ds.fiblet_bounds).spheres[fiblet];
    centre = sphere.xyz;
    radius = sphere.w;
    return sphere.w >= 0.0;
  }
  WordsRef records = WordsRef(ds.records);
  const uint n = ds.points_per_fiblet;
  const uint base = fiblet * ds.record_words;
  const uint flags = fibletRecordByte(records, base, fibletFlagsByte(n));
  const uint count = fibletCount(flags);
  centre = vec3(0.0);
  radius = 0.0;
  if (count < 1u || count > n) return false;
  const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
  const vec3 p0 = fibletRecordPoint(w0, w1, w2, 0u);
  const bool joins = (flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count;
  if (count < 2u && !joins) return false;
  float r = 0.0;
  if (count >= 2u) r = length(fibletRecordPoint(w0, w1, w2, 1u) - p0) + float(count - 2u) * ds.delta;
  if (joins) r = max(r, length(fibletFirstPoint(records, base + ds.record_words) - p0));
  centre = fibletToWorld(ds, p0);
  radius = r * ds.mm_per_unit * (1.0 + kCullRadiusSlack);
  return true;
}

bool sphereOutside(vec4 plane, vec3 c, float r) { return dot(plane.xyz, c) + plane.w < -r * length(plane.xyz); }

// Wholly on the cut side of one of the frame's clip planes (their normals
// are unit): the raster would clip away every one of its segments. The
// sphere holds every segment the fiblet draws, so the test is exact up to
// the rounding the radius's slack absorbs.
bool sphereClipped(CameraBlock cam, vec3 c, float r) {
  const uint planes = uint(cam.cuts.x);
  for (uint i = 0u; i < planes; ++i)
    if (dot(cam.clip_world[i].xyz, c) + cam.clip_world[i].w < -r) return true;
  return false;
}

// The frustum dilated by half the line width plus kCullPixelSlack pixels on
// each side: a sphere entirely outside it cannot bring a pixel centre within
// half the line width of its projection. Near and far are not dilated (the
// raster cuts at the near plane and drops depths beyond the far plane).
bool sphereInFrustum(CameraBlock cam, vec3 c, float r) {
  const vec4 r0 = matrixRow(cam, 0), r1 = matrixRow(cam, 1), r2 = matrixRow(cam, 2), r3 = matrixRow(cam, 3);
  const float margin = 0.5 * cam.viewport.z + kCullPixelSlack;
  // x_w >= -margin  <=>  x_clip >= -w * (1 + 2 margin / width); likewise the others.
  const float kx = 1.0 + 2.0 * margin / cam.viewport.x;
  const float ky = 1.0 + 2.0 * margin / cam.viewport.y;
  return !(sphereOutside(r3 * kx + r0, c, r) || sphereOutside(r3 * kx - r0, c, r) ||
           sphereOutside(r3 * ky + r1, c, r) || sphereOutside(r3 * ky - r1, c, r) || sphereOutside(r2, c, r) ||
           sphereOutside(r3 - r2, c, r));
}

// Far-view LoD: the sphere's projected diameter, measured at its nearest
// view distance, below lod_pixels. With the precomputed sphere the diameter
// is about the fiblet's own extent, so a fiblet becomes one segment when it
// spans fewer than lod_pixels on screen, as the setting says (the fallback
// sphere's diameter is about twice the extent: it switched at half of
// that). The LoD segment runs from p0 to the joining point (or p1), inside
// the sphere, so it stays within the frustum and occlusion bounds too.
bool sphereIsSmall(FibletCullPush p, CameraBlock cam, vec3 c, float r) {
  if (!(p.lod_pixels > 0.0)) return false;
  const vec4 r3 = matrixRow(cam, 3);  // w_clip = view distance along the axis
  const float nearest = dot(r3.xyz, c) + r3.w - r;
  if (!(nearest > cam.depth_range.x)) return false;
  return 2.0 * r * p.focal_px < p.lod_pixels * nearest;
}

// The sphere's screen bounds from the cube around it aligned with the view
// axes: its eight corners bound the sphere's NDC rectangle (perspective
// maps the cube to the hull of the projected corners) and its depths
// (depth grows with view distance, which is linear, so its extremes over
// the cube are at corners). False when the cube reaches past the near plane.
bool sphereScreenBounds(CameraBlock cam, vec3 c, float r, out vec2 lo, out vec2 hi, out float nearest,
                        out float farthest) {
  const vec4 centre = cameraTransformPoint(cam.view_projection, c);
  // View axes in world space (rows of the view rotation), then to clip.
  vec4 axes[3];
  for (int i = 0; i < 3; ++i) {
    const vec3 e = vec3(cam.view[0][i], cam.view[1][i], cam.view[2][i]);
    axes[i] = r * (cam.view_projection[0] * e.x + cam.view_projection[1] * e.y + cam.view_projection[2] * e.z);
  }
  lo = vec2(1e30);
  hi = vec2(-1e30);
  nearest = 1e30;
  farthest = -1e30;
  for (int k = 0; k < 8; ++k) {
    const vec4 q = centre + ((k & 1) != 0 ? axes[0] : -axes[0]) + ((k & 2) != 0 ? axes[1] : -axes[1]) +
                   ((k & 4) != 0 ? axes[2] : -axes[2]);
    if (!(q.z > 0.0) || !(q.w > 0.0)) return false;
    const vec3 ndc = q.xyz / q.w;
    lo = min(lo, ndc.xy);
    hi = max(hi, ndc.xy);
    nearest = min(nearest, ndc.z);
    farthest = max(farthest, ndc.z);
  }
  return true;
}

// Phase 2: true when every pixel the fiblet could cover already holds a
// depth nearer than the sphere's nearest depth. The sphere is enclosed in
// the cube aligned with the view axes; its eight corners bound the sphere's
// screen rectangle (perspective maps the cube to the hull of the projected
// corners) and its nearest depth (depth grows with view distance, which is
// linear, so its minimum over the cube is at a corner). A cube reaching
// past the near plane is never occluded.
bool sphereOccluded(FibletCullPush p, CameraBlock cam, vec3 c, float r) {
  vec2 lo, hi;
  float nearest, farthest;
  if (!sphereScreenBounds(cam, c, r, lo, hi, nearest, farthest)) return false;
  const vec2 size = cam.viewport.xy;
  const float margin = 0.5 * cam.viewport.z + kCullPixelSlack;
  // Pixels whose centre px + 0.5 lies within margin of [lo, hi] in window
  // coordinates, clamped in float before converting.
  const vec2 first = max(ceil((lo + 1.0) * 0.5 * size - margin - 0.5), vec2(0.0));
  const vec2 last = min(floor((hi + 1.0) * 0.5 * size + margin - 0.5), size - 1.0);
  if (first.x > last.x || first.y > last.y) return true;  // no pixel centre at all
  const uvec2 p0 = uvec2(first), p1 = uvec2(last);
  const uint width = uint(size.x), height = uint(size.y);
  // The finest level at which the rectangle spans at most 2 x 2 texels; a
  // level-L texel (x, y) is the max over the level-0 pixels (x << L .. ,
  // y << L ..), so texels p0 >> L .. p1 >> L cover the rectangle.
  const uint levels = pyramidLevelCount(width, height);
  uint level = 0u;
  while (level + 1u < levels && ((p1.x >> level) - (p0.x >> level) > 1u || (p1.y >> level) - (p0.y >> level) > 1u))
    ++level;
  const uint level_width = pyramidLevelSize(width, level);
  const uint offset = pyramidLevelOffset(width, height, level);
  PyramidRef pyramid = PyramidRef(p.pyramid);
  float occluder = 0.0;  // the farthest depth drawn over the rectangle
  for (uint y = p0.y >> level; y <= p1.y >> level; ++y)
    for (uint x = p0.x >> level; x <= p1.x >> level; ++x)
      occluder = max(occluder, pyramid.depths[offset + y * level_width + x]);
  return occluder < nearest - kCullDepthSlack;
}

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer CutTilesRef { CutTile tiles[]; };

// A mesh cut discards every fragment the fiblet could draw: its sphere's
// screen rectangle (sphereOccluded's cube corners, with the line's margin)
// rounded out to tiles, whose summaries already include their neighbours
// (shared/cut_mesh.h). "Cull inside": every tile fully covered and the
// sphere's depths within [max_front, min_back] of all of them; "cull
// outside": no tile covered at all. A cube reaching past the near plane is
// never cut.
bool sphereMeshCut(CameraBlock cam, vec3 c, float r) {
  const CutMeshFrame cuts = cam.mesh_cuts;
  if (cuts.mesh_count == 0u) return false;
  vec2 lo, hi;
  float nearest, farthest;
  if (!sphereScreenBounds(cam, c, r, lo, hi, nearest, farthest)) return false;
  const vec2 size = cam.viewport.xy;
  const float margin = 0.5 * cam.viewport.z + kCullPixelSlack;
  const vec2 first = clamp(floor((lo + 1.0) * 0.5 * size - margin), vec2(0.0), size - 1.0);
  const vec2 last = clamp(ceil((hi + 1.0) * 0.5 * size + margin), vec2(0.0), size - 1.0);
  const uvec2 t0 = uvec2(first) / kCutTileSize, t1 = uvec2(last) / kCutTileSize;
  if ((t1.x - t0.x + 1u) * (t1.y - t0.y + 1u) > 64u) return false;  // large on screen: not worth the loop
  CutTilesRef tiles = CutTilesRef(cuts.tiles);
  const uint per_mesh = cuts.tiles_x * cuts.tiles_y;
  for (uint m = 0u; m < cuts.mesh_count; ++m) {
    const bool cull_inside = ((cuts.inside_bits >> m) & 1u) != 0u;
    bool cut = true;
    for (uint ty = t0.y; ty <= t1.y && cut; ++ty)
      for (uint tx = t0.x; tx <= t1.x && cut; ++tx) {
        const CutTile t = tiles.tiles[m * per_mesh + ty * cuts.tiles_x + tx];
        if (cull_inside)
          cut = (t.flags & kCutTileAllCovered) != 0u && t.max_front <= nearest - kCullDepthSlack &&
                t.min_back >= farthest + kCullDepthSlack;
        else
          cut = (t.flags & kCutTileAnyCovered) == 0u;
      }
    if (cut) return true;
  }
  return false;
}

// The fiber filter kept the fiblet's fiber (or there is no filter). A
// dropped fiber's fiblets are never drawn, so in phase 2 their visible
// bits stay clear and the pyramid holds only kept fibers' depths: culling
// stays exact whatever the filter did between frames.
bool fibletKept(FibletCullPush p, FibletDataset ds, uint fiblet) {
  if (p.kept == 0ul) return true;
  const uint fiber = p.fiber_base + UintsRef(ds.fiblet_fiber).values[fiblet];
  return (BitsRef(p.kept).words[fiber >> 5u] & (1u << (fiber & 31u))) != 0u;
}

// The verdict on `fiblet` of `ds` in mode p.mode: -1 culled, 0 drawn at
// full detail, 1 drawn as one segment (LoD). `visible` is phase 2's new
// visible bit (false in the other modes); the caller writes it back.
int fibletCullTarget(FibletCullPush p, FibletDataset ds, uint fiblet, out bool visible) {
  visible = false;
  vec3 c;
  float r;
  if (fiblet >= ds.fiblet_count || !fibletKept(p, ds, fiblet) || !fibletSphere(ds, fiblet, c, r)) return -1;
  const CameraBlock cam = CameraRef(p.camera).camera;
  // Culled in every mode: nothing of it would be drawn.
  if (sphereClipped(cam, c, r) || sphereMeshCut(cam, c, r)) return -1;
  if (p.mode == kCullKeptOnly) return 0;
  if (!sphereInFrustum(cam, c, r)) return -1;
  bool draw = true;
  if (p.mode == kCullCoverage) {
    draw = !sphereOccluded(p, cam, c, r);
  } else if (p.mode != kCullFrustum) {
    const bool was_visible = (BitsRef(p.visible).words[fiblet >> 5u] & (1u << (fiblet & 31u))) != 0u;
    if (p.mode == kCullPhase1) {
      draw = was_visible;
    } else {
      visible = !sphereOccluded(p, cam, c, r);
      draw = visible && !was_visible;  // phase 1 drew the others
    }
  }
  if (!draw) return -1;
  return sphereIsSmall(p, cam, c, r) ? 1 : 0;
}

#endif
