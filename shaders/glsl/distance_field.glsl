// Helpers of the distance-field passes (df_ao.comp, df_shadow.comp;
// shared/distance_field.h): the field's trilinear sample, and a covered
// pixel's world position and normal from the G-buffer (and the surface
// target). CPU twins: src/svo/distance_field.h.
#ifndef FIBSCOPE_GLSL_DISTANCE_FIELD_GLSL
#define FIBSCOPE_GLSL_DISTANCE_FIELD_GLSL

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer DfFieldRef { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer DfSurfaceRef { SurfaceTexel texels[]; };

float dfValue(DfFieldRef field, DfGrid grid, ivec3 v) {
  v = clamp(v, ivec3(0), ivec3(grid.size_x, grid.size_y, grid.size_z) - 1);
  return field.values[(uint(v.z) * grid.size_y + uint(v.y)) * grid.size_x + uint(v.x)];
}

bool dfInside(DfGrid grid, vec3 p) {
  const vec3 lo = vec3(grid.origin_x, grid.origin_y, grid.origin_z);
  const vec3 hi = lo + vec3(grid.size_x, grid.size_y, grid.size_z) * grid.voxel;
  return all(greaterThanEqual(p, lo)) && all(lessThan(p, hi));
}

// The field at p (shared/distance_field.h: trilinear, the band outside).
float dfSample(uint64_t field_address, DfGrid grid, vec3 p) {
  if (!dfInside(grid, p)) return grid.band;
  DfFieldRef field = DfFieldRef(field_address);
  const vec3 g = (p - vec3(grid.origin_x, grid.origin_y, grid.origin_z)) / grid.voxel - 0.5;
  const vec3 i0 = floor(g);
  const vec3 f = g - i0;
  const ivec3 v = ivec3(i0);
  return dfTrilinear(dfValue(field, grid, v), dfValue(field, grid, v + ivec3(1, 0, 0)),
                     dfValue(field, grid, v + ivec3(0, 1, 0)), dfValue(field, grid, v + ivec3(1, 1, 0)),
                     dfValue(field, grid, v + ivec3(0, 0, 1)), dfValue(field, grid, v + ivec3(1, 0, 1)),
                     dfValue(field, grid, v + ivec3(0, 1, 1)), dfValue(field, grid, v + ivec3(1, 1, 1)), f.x, f.y,
                     f.z);
}

// The world position seen at pixel p at clip depth `depth` (the G-buffer's)
// and the unit normal there: a surface's from the surface target (turned
// towards the eye, as shade.comp does), a line's the view-facing normal in
// the plane of its tangent and the eye ray. False for pixels that take no
// distance-field shading: empty ones and anatomical slices.
bool dfPixelPoint(CameraBlock cam, uint64_t gbuffer, uint64_t surface, uvec2 p, uint width, out vec3 position,
                  out vec3 normal) {
  position = vec3(0.0);
  normal = vec3(0.0, 0.0, 1.0);
  const uint index = p.y * width + p.x;
  const GBufferTexel texel = GBufferRef(gbuffer).texels[index];
  if (texel.fiber == kNoFiberId || texel.fiber == kNoFiberObject) return false;
  const vec3 to_eye = pixelToEye(cam, p);
  // viewDistance is along the view axis: the ray's length is that over
  // the ray's cosine with the axis.
  const float z = viewDistance(cam, texel.depth);
  position = cam.eye.xyz - to_eye * (z / dot(to_eye, cameraBack(cam)));
  if (surface != 0ul && (texel.segment & kGBufferSurface) != 0u) {
    const SurfaceTexel s = DfSurfaceRef(surface).texels[index];
    if (s.source == kSurfaceSourceSlice) return false;
    normal = unpackTangent(s.normal);
    if (dot(normal, to_eye) < 0.0) normal = -normal;
  } else {
    const vec3 t = unpackTangent(texel.tangent);
    const vec3 towards = to_eye - dot(to_eye, t) * t;
    const float len = length(towards);
    normal = len > kShadeNormalParallelEps ? towards / len : to_eye;
  }
  return true;
}

#endif
