// The CPU reference of every bundling stage, in double precision, with the
// formulas of shared/bundling.h (the GPU passes are tested against it,
// stage by stage and for whole iterations). Small models and grids only:
// it is written to be checked by eye, not to be fast (the direct 3-D
// convolution costs (2 floor(R) + 1)^3 per voxel).
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

#include "bundling/bundle_params.h"
#include "bundling/bundle_setup.h"
#include "core/tractogram.h"

namespace fibscope {

using BundleSamples = std::vector<glm::dvec3>;  // setup.sample_offsets order
using BundleTensors = std::vector<glm::dmat3>;   // per cell of a structure grid

// Resample: fiber f's n samples at arc lengths k len / (n - 1), the first
// and the last its end points (n = 1: its first point).
BundleSamples resampleReference(const Tractogram& tractogram, const BundleSetup& setup);

// Count: samples per voxel (the voxel holding each, clamped into the grid).
std::vector<double> countReference(const BundleSamples& samples, const BundleGrid& grid);

// One 1-D pass along `axis` (0, 1, 2): out[v] = sum over |d| <= floor(R)
// of (1 - d^2 / R^2) in[v + d e_axis], voxels outside the grid empty.
std::vector<double> convolveAxisReference(const std::vector<double>& in, const BundleGrid& grid, int axis,
                                          double radius);
// The three passes x, y, z: the convolution with the product kernel
// k(dx) k(dy) k(dz), k(d) = max(0, 1 - d^2 / R^2).
std::vector<double> densitySeparableReference(const std::vector<double>& counts, const BundleGrid& grid, double radius);
// The same product kernel as one direct 3-D sum over the cube |dx|, |dy|,
// |dz| <= floor(R) (mathematically equal to the separable passes).
std::vector<double> densityDirectReference(const std::vector<double>& counts, const BundleGrid& grid, double radius);

// Anisotropic splat: at every voxel centre within Ra (voxels, per axis) of
// each sample, the kernel max(0, 1 - a^2 / Ra^2 - b^2 / Rb^2) with a and b
// the offset's parts along and across the sample's fiber direction (the
// advection's), summed in double; `quantise`: each term rounded to
// 1 / kBundleSplatScale as the GPU's fixed point.
std::vector<double> splatReference(const BundleSamples& samples, const std::vector<uint32_t>& sample_offsets,
                                   const BundleGrid& grid, double radius_along, double radius_across,
                                   bool quantise = true);

// Gradient: central differences / 2h, one-sided / h at the faces (world units).
std::vector<glm::dvec3> gradientReference(const std::vector<double>& density, const BundleGrid& grid);
// The gradient at p, trilinear between voxel centres (clamped at the faces).
glm::dvec3 interpolateGradient(const std::vector<glm::dvec3>& gradient, const BundleGrid& grid, glm::dvec3 p);

// Structure tensor, per cell of `cell` voxels a side (bundleStructureGrid):
// the density averaged over each cell (the tensor's scale, coarse enough
// that the ripple between neighbouring fibers is gone), its gradient
// between cells, and the mean of grad grad^T over the cell and its
// neighbours (the integration scale).
BundleTensors structureTensorReference(const std::vector<double>& density, const BundleGrid& grid, uint32_t cell);
// The tensor at p, trilinear between cell centres (clamped at the faces).
glm::dmat3 interpolateTensor(const BundleTensors& tensors, const BundleGrid& cells, glm::dvec3 p);
// Eigenvalues (descending) and unit eigenvectors (the columns, in the same
// order) of a symmetric matrix, by cyclic Jacobi rotations.
void symmetricEigenReference(const glm::dmat3& m, glm::dvec3* values, glm::dmat3* vectors);
// The structure filter sum_k (lambda_k / lambda_1)^power e_k e_k^T from the
// eigen decomposition (the GPU takes (J / lambda_1)^power by products: the
// same matrix); the identity where lambda_1 <= kBundleMinGradient^2.
glm::dmat3 structureFilterReference(const glm::dmat3& tensor, uint32_t power);

// What structure-aware advection reads: the tensors, their grid, the power.
struct BundleStructureField {
  const BundleTensors* tensors = nullptr;
  BundleGrid cells;
  uint32_t power = 2;
};

// Constrained advection: p += step (g - d (d . g)) / |g| (step = R h mm).
// With `structure`: g in that formula's numerator becomes M g, M the
// structure filter of the tensor at p (|M g| <= |g|, so the step stays at
// most `step` long and orthogonal to the fiber).
BundleSamples advectReference(const BundleSamples& samples, const std::vector<uint32_t>& sample_offsets,
                              const std::vector<glm::dvec3>& gradient, const BundleGrid& grid, double step_mm,
                              bool anchor_ends, const BundleStructureField* structure = nullptr);
// Smoothing: p' = (1 - phi) p + phi mean(p_j, |j - i| <= m), m = min(window,
// i - s0, s1 - 1 - i): symmetric near the ends, which only advection moves.
BundleSamples smoothReference(const BundleSamples& samples, const std::vector<uint32_t>& sample_offsets, double phi,
                              uint32_t window, bool anchor_ends);
// Relaxation: o + alpha (p - o).
BundleSamples relaxReference(const BundleSamples& original, const BundleSamples& bundled, double alpha);
// Map back: each point of `tractogram` moved by its samples' displacement
// (bundled - original) interpolated at its arc length (x y z floats, the
// tractogram's point order).
std::vector<float> mapBackReference(const Tractogram& tractogram, const BundleSetup& setup,
                                    const BundleSamples& original, const BundleSamples& bundled);

// One iteration at kernel radius `radius` (voxels): count, density,
// gradient, (structure tensor,) advection, smoothing.
BundleSamples iterateReference(const BundleSamples& samples, const BundleSetup& setup, const BundleParams& params,
                               double radius);
// A whole run: the bundled positions of every point of `tractogram`.
std::vector<float> bundleReference(const Tractogram& tractogram, const BundleParams& params);

}  // namespace fibscope
