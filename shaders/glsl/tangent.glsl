// Unit tangents packed into one uint: octahedral mapping to [-1, 1]^2, then
// packSnorm2x16 (about 0.003 degrees of error). src/render/gbuffer_tangent.h
// is the C++ mirror the tests use.
#ifndef FIBSCOPE_GLSL_TANGENT_GLSL
#define FIBSCOPE_GLSL_TANGENT_GLSL

uint packTangent(vec3 t) {
  const float l1 = abs(t.x) + abs(t.y) + abs(t.z);
  if (!(l1 > 0.0)) return packSnorm2x16(vec2(0.0));  // zero tangent -> (0, 0, 1) side, flagged by l1 == 0 upstream
  vec2 p = t.xy / l1;
  if (t.z < 0.0) p = (1.0 - abs(p.yx)) * vec2(p.x >= 0.0 ? 1.0 : -1.0, p.y >= 0.0 ? 1.0 : -1.0);
  return packSnorm2x16(p);
}

// The packed unit tangent of a segment's direction (zero: 0, as the
// resolve writes for a zero-length segment).
uint packSegmentTangent(vec3 d) {
  return dot(d, d) > 0.0 ? packTangent(normalize(d)) : 0u;
}

vec3 unpackTangent(uint packed) {
  const vec2 p = unpackSnorm2x16(packed);
  vec3 t = vec3(p, 1.0 - abs(p.x) - abs(p.y));
  if (t.z < 0.0) t.xy = (1.0 - abs(t.yx)) * vec2(t.x >= 0.0 ? 1.0 : -1.0, t.y >= 0.0 ? 1.0 : -1.0);
  return normalize(t);
}

#endif
