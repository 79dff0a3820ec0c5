// Pixel metrics that compare two renderings of the same frame (DESIGN.md
// section 8): coverage agreement, and how far a disagreeing pixel lies from
// the nearest pixel covered in the other image. Images are compared within
// one run (GPU against the CPU reference, culling on against off), never
// against golden files.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fibscope {

struct CoverageComparison {
  uint32_t width = 0, height = 0;
  size_t covered_a = 0;     // pixels covered in A
  size_t covered_b = 0;     // pixels covered in B
  size_t covered_both = 0;  // in A and in B
  // |A and B| / |A or B|; 1 when neither image covers anything.
  double agreement = 1.0;
  // Largest Euclidean distance (px, between pixel centres) from a pixel
  // covered in A but not in B to the nearest pixel covered in B; 0 when
  // there is no such pixel, infinity when B covers nothing. b_to_a likewise.
  double max_distance_a_to_b = 0.0;
  double max_distance_b_to_a = 0.0;
  // The larger of the two.
  double maxDistance() const;
  // One line for test messages, e.g. "A 1200 px, B 1210 px, both 1195 px,
  // agreement 0.9876, max distance 1.41 px (A->B 1.00, B->A 1.41)".
  std::string summary() const;
};

// Masks are row-major width * height bytes, non-zero = covered. Throws Error
// when a mask's size is not width * height. Distances are exact (a
// separable Euclidean distance transform), linear in the pixel count.
CoverageComparison compareCoverage(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b,
                                   uint32_t width, uint32_t height);

// Squared Euclidean distance (px^2) from every pixel to the nearest covered
// pixel of `mask` (0 on covered pixels; infinity everywhere when nothing is
// covered). Exposed for tests.
std::vector<double> squaredDistanceToCovered(const std::vector<uint8_t>& mask, uint32_t width, uint32_t height);

}  // namespace fibscope
