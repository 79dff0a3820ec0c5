// Colormaps for ColorMode::Scalar (DESIGN.md section 6, "Shading"): each a
// short list of control points written here (sRGB, evenly spaced, read off the published
// maps to 3 decimals), linearly
// interpolated into a 256-entry RGBA8 table that the shade pass uploads
// once and the shader indexes. The control points approximate the published
// maps; the tables are the single source of truth for GPU and tests.
//   Viridis    matplotlib's viridis (S. van der Walt, N. Smith, 2015), 11 points
//   Magma      matplotlib's magma (same authors), 11 points
//   Grayscale  black to white, 2 points
//   CoolWarm   K. Moreland, "Diverging Color Maps for Scientific
//              Visualization" (ISVC 2009), 5 points of its Msh path
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "render/render_settings.h"

namespace fibscope {

inline constexpr uint32_t kColormapEntries = 256;
inline constexpr uint32_t kColormapCount = 4;  // Colormap's values, 0 .. kColormapCount - 1

// Control points at t = k / (count - 1), k = 0 .. count - 1, sRGB in [0, 1].
std::span<const std::array<float, 3>> colormapControlPoints(Colormap colormap);

// The colour at t (clamped to [0, 1]), linear between control points.
std::array<float, 3> colormapColor(Colormap colormap, float t);

// kColormapEntries colours packed RGBA8 (R in the low byte, A = 255), entry
// i the colour at t = i / (kColormapEntries - 1) rounded to 8 bits.
std::vector<uint32_t> colormapTable(Colormap colormap);

// Every colormap's table, back to back in Colormap order (what the shade
// pass uploads: table c starts at entry c * kColormapEntries).
std::vector<uint32_t> allColormapTables();

// The table entry a scalar maps to: t = (value - min) / (max - min)
// clamped to [0, 1] (NaN maps to 0; max == min maps everything to the
// middle), entry round(t * 255). shade.comp does the same arithmetic.
uint32_t colormapIndex(float value, float scalar_min, float scalar_max);

// The range of the finite values of a per-fiber scalar (ColorMode::Scalar's
// default range): false, leaving lo and hi alone, when none is finite. NaN
// and infinities are skipped so that a damaged table cannot make the range
// NaN.
bool finiteRange(std::span<const float> values, float& lo, float& hi);

}  // namespace fibscope
