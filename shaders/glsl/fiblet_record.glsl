// Reading fiblet records (shared/fiblet.h layout) through a dataset block.
#ifndef FIBSCOPE_GLSL_FIBLET_RECORD_GLSL
#define FIBSCOPE_GLSL_FIBLET_RECORD_GLSL

#include "shared/fiblet.h"
#include "glsl/render_buffers.glsl"

uint fibletRecordByte(WordsRef records, uint base, uint byte_index) {
  return fibletByteOfWord(records.words[base + byte_index / 4u], byte_index);
}

// Point 0 or 1 of a record (16-bit coordinates), normalised units.
vec3 fibletRecordPoint(uint w0, uint w1, uint w2, uint which) {
  return vec3(fibletDequantize(fibletCoordOfWords(w0, w1, w2, 3u * which)),
              fibletDequantize(fibletCoordOfWords(w0, w1, w2, 3u * which + 1u)),
              fibletDequantize(fibletCoordOfWords(w0, w1, w2, 3u * which + 2u)));
}

vec3 fibletFirstPoint(WordsRef records, uint base) {
  return fibletRecordPoint(records.words[base], records.words[base + 1u], records.words[base + 2u], 0u);
}

// L_code from the dataset's table (fiblet_dataset.h: after the 256
// directions), bit for bit fibletLocalTransform(direction, V, delta).
FibletTransform fibletTableTransform(DirectionsRef table, uint code) {
  const vec4 a = table.directions[256u + 3u * code];
  const vec4 b = table.directions[256u + 3u * code + 1u];
  const vec4 c = table.directions[256u + 3u * code + 2u];
  FibletTransform l;
  l.c0 = a.xyz;
  l.c1 = vec3(a.w, b.xy);
  l.c2 = vec3(b.zw, c.x);
  l.t = c.yzw;
  return l;
}

// One step of the serial decode: W_{k+1} = W_k L_{k+1} (k >= 1), from
// W_1 = fibletInitialTransform(p0, p1, V); the translation of W_k is point
// k. The order of composition every serial decoder (rasters, bounds,
// resolve) shares, so their points agree bit for bit.
FibletTransform fibletNextTransform(FibletTransform w, DirectionsRef table, WordsRef records, uint base, uint k) {
  return fibletCompose(w, fibletTableTransform(table, fibletRecordByte(records, base, fibletCodeByte(k + 1u))));
}

// Normalised -> world mm (FibletDataset: p_mm = translation + mm_per_unit * p_n).
vec3 fibletToWorld(FibletDataset ds, vec3 p) {
  return vec3(ds.translation_x, ds.translation_y, ds.translation_z) + ds.mm_per_unit * p;
}

#endif
