// The orientation overlay (orientation_overlay.comp), stamped over the
// final RGBA8 image after FXAA, as mrview draws it: at the middle of each
// image edge the anatomical direction (RAS+: R = +x, A = +y, S = +z) of the
// world axis most aligned with the screen direction towards that edge
// (render/orientation_labels.h chooses them), and an axis triad in the
// bottom-right corner: each world axis's direction in the view, x red, y
// green, z blue, the one nearer the viewer on top.
//
// Layout, in pixels, s = scale (1 to 4, by the image size):
//   a glyph is 5 x 7 cells of s x s pixels in a box of 7 x 9 cells (one
//   cell of outline around it); its set cells take kOrientationLabelColor,
//   the unset cells next to a set one (8-neighbours) are darkened to a
//   quarter (the outline that keeps the letter legible on white);
//   margin m = 4 s from the edge: left box at (m, (h - 9 s) / 2), right at
//   (w - m - 7 s, same), top at ((w - 7 s) / 2, max(m, kOrientationTopMargin)),
//   bottom at (same, h - m - 9 s) (integer division);
//   triad: centre (w - m - 13 s, h - m - 13 s), each axis a segment of 12 s px
//   from the centre towards (right . axis, -(up . axis)) times 12 s, drawn
//   where a pixel centre lies within 0.5 s + 0.5 px of it.
#ifndef FIBSCOPE_SHADERS_SHARED_ORIENTATION_OVERLAY_H
#define FIBSCOPE_SHADERS_SHARED_ORIENTATION_OVERLAY_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define OVERLAY_CONST inline constexpr
#define OVERLAY_ARRAY(type, name, n) inline constexpr type name[n] = {
#define OVERLAY_ARRAY_END }
#else
#define OVERLAY_CONST const
#define OVERLAY_ARRAY(type, name, n) const type name[n] = type[n](
#define OVERLAY_ARRAY_END )
#endif

SHADER_NAMESPACE_BEGIN

// Glyph g = 2 * axis + (1 for the positive direction): L R P A I S.
OVERLAY_CONST uint kOrientationGlyphs = 6u;
OVERLAY_CONST uint kOrientationGlyphWidth = 5u;
OVERLAY_CONST uint kOrientationGlyphHeight = 7u;
// Row r (0 = top) of glyph g is kOrientationGlyphRows[7 g + r]; bit 4 is
// the leftmost column.
OVERLAY_ARRAY(uint, kOrientationGlyphRows, 42)
    0x10u, 0x10u, 0x10u, 0x10u, 0x10u, 0x10u, 0x1Fu,  // L
    0x1Eu, 0x11u, 0x11u, 0x1Eu, 0x14u, 0x12u, 0x11u,  // R
    0x1Eu, 0x11u, 0x11u, 0x1Eu, 0x10u, 0x10u, 0x10u,  // P
    0x0Eu, 0x11u, 0x11u, 0x1Fu, 0x11u, 0x11u, 0x11u,  // A
    0x0Eu, 0x04u, 0x04u, 0x04u, 0x04u, 0x04u, 0x0Eu,  // I
    0x0Fu, 0x10u, 0x10u, 0x0Eu, 0x01u, 0x01u, 0x1Eu   // S
OVERLAY_ARRAY_END;

// RGBA8, R in the low byte.
OVERLAY_CONST uint kOrientationLabelColor = 0xFF78F0FFu;  // pale yellow (255, 240, 120)
OVERLAY_CONST uint kOrientationAxisXColor = 0xFF3C3CF0u;  // red (240, 60, 60)
OVERLAY_CONST uint kOrientationAxisYColor = 0xFF3CD23Cu;  // green (60, 210, 60)
OVERLAY_CONST uint kOrientationAxisZColor = 0xFFFF8C50u;  // blue, light enough on black (80, 140, 255)
// The top label's least distance from the top (px): below the viewer's
// menu bar (about 20 px), where the corners hold its panels and status line.
OVERLAY_CONST int kOrientationTopMargin = 24;
// Boxes of one dispatch (the z of the grid): the four labels, the triad.
OVERLAY_CONST uint kOrientationBoxes = 5u;

// orientation_overlay.comp: the grid covers the largest box (the triad's
// 26 s + 2 px square); z picks the box: 0 left, 1 right, 2 top, 3 bottom
// label, 4 the triad. Writes `color` in place.
struct OrientationOverlayPush {
  // Each world axis (x, y, z) in view space: .x towards the image's right,
  // .y towards its top, .z towards the viewer; w: 0.
  vec4 axis[3];
  uint64_t color;  // uint per pixel, RGBA8 (read and written)
  uint width;
  uint height;
  uint glyphs;  // the glyph of box b (left, right, top, bottom) in bits 8 b .. 8 b + 7
  uint scale;   // s, 1 .. 4
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::OrientationOverlayPush) == 72, "");
static_assert(offsetof(fibscope::shader::OrientationOverlayPush, color) == 48, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_ORIENTATION_OVERLAY_H
