#include "bundling/bundle_reference.h"

#include <algorithm>
#include <cmath>

namespace fibscope {

namespace {

glm::dvec3 pointOf(const Tractogram& t, uint64_t i) { return {t.point(i)[0], t.point(i)[1], t.point(i)[2]}; }

double fiberLength(const Tractogram& t, size_t f) {
  double len = 0;
  for (uint64_t i = t.offsets[f] + 1; i < t.offsets[f + 1]; ++i) len += glm::length(pointOf(t, i) - pointOf(t, i - 1));
  return len;
}

uint32_t sampleFiber(const std::vector<uint32_t>& offsets, size_t i) {
  return uint32_t(std::upper_bound(offsets.begin(), offsets.end(), uint32_t(i)) - offsets.begin() - 1);
}

glm::uvec3 voxelOf(const BundleGrid& g, glm::dvec3 p) {
  const glm::dvec3 q = glm::floor((p - g.origin) / g.voxel);
  return glm::uvec3(glm::clamp(q, glm::dvec3(0.0), glm::dvec3(g.size) - 1.0));
}

}  // namespace

BundleSamples resampleReference(const Tractogram& t, const BundleSetup& setup) {
  BundleSamples samples(setup.sampleCount());
  for (size_t f = 0; f < t.streamlineCount(); ++f) {
    const uint64_t p0 = t.offsets[f], p1 = t.offsets[f + 1];
    const uint32_t s0 = setup.sample_offsets[f], n = setup.sample_offsets[f + 1] - s0;
    if (n == 0 || p1 == p0) continue;
    samples[s0] = pointOf(t, p0);
    if (n == 1) continue;
    const double spacing = fiberLength(t, f) / double(n - 1);
    uint64_t seg = p0;
    double seg_start = 0;
    double seg_len = p1 - p0 > 1 ? glm::length(pointOf(t, p0 + 1) - pointOf(t, p0)) : 0;
    for (uint32_t k = 1; k + 1 < n; ++k) {
      const double target = spacing * k;
      while (seg + 2 < p1 && seg_start + seg_len < target) {
        seg_start += seg_len;
        ++seg;
        seg_len = glm::length(pointOf(t, seg + 1) - pointOf(t, seg));
      }
      const double s = seg_len > 0 ? std::clamp((target - seg_start) / seg_len, 0.0, 1.0) : 0.0;
      samples[s0 + k] = glm::mix(pointOf(t, seg), pointOf(t, seg + 1), s);
    }
    samples[s0 + n - 1] = pointOf(t, p1 - 1);
  }
  return samples;
}

std::vector<double> countReference(const BundleSamples& samples, const BundleGrid& grid) {
  std::vector<double> counts(grid.voxelCount(), 0.0);
  for (const glm::dvec3& p : samples) {
    const glm::uvec3 v = voxelOf(grid, p);
    counts[grid.index(v.x, v.y, v.z)] += 1;
  }
  return counts;
}

std::vector<double> convolveAxisReference(const std::vector<double>& in, const BundleGrid& g, int axis, double radius) {
  std::vector<double> out(in.size(), 0.0);
  const int r = int(std::floor(radius));
  const int n = int(g.size[axis]);
  const uint64_t stride = axis == 0 ? 1 : (axis == 1 ? g.size.x : uint64_t(g.size.x) * g.size.y);
  for (uint32_t z = 0; z < g.size.z; ++z)
    for (uint32_t y = 0; y < g.size.y; ++y)
      for (uint32_t x = 0; x < g.size.x; ++x) {
        const uint64_t index = g.index(x, y, z);
        const int at = int(glm::uvec3(x, y, z)[axis]);
        double sum = 0;
        for (int d = std::max(-r, -at); d <= std::min(r, n - 1 - at); ++d)
          sum += std::max(0.0, 1.0 - double(d) * d / (radius * radius)) *
                 in[uint64_t(int64_t(index) + d * int64_t(stride))];
        out[index] = sum;
      }
  return out;
}

std::vector<double> densitySeparableReference(const std::vector<double>& counts, const BundleGrid& grid,
                                              double radius) {
  return convolveAxisReference(convolveAxisReference(convolveAxisReference(counts, grid, 0, radius), grid, 1, radius),
                               grid, 2, radius);
}

std::vector<double> densityDirectReference(const std::vector<double>& counts, const BundleGrid& g, double radius) {
  const int r = int(std::floor(radius));
  auto k = [&](int d) { return std::max(0.0, 1.0 - double(d) * d / (radius * radius)); };
  std::vector<double> out(counts.size(), 0.0);
  const glm::ivec3 size(g.size);
  for (int z = 0; z < size.z; ++z)
    for (int y = 0; y < size.y; ++y)
      for (int x = 0; x < size.x; ++x) {
        double sum = 0;
        for (int dz = -r; dz <= r; ++dz)
          for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
              const glm::ivec3 q(x + dx, y + dy, z + dz);
              if (glm::any(glm::lessThan(q, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(q, size))) continue;
              sum += k(dx) * k(dy) * k(dz) * counts[g.index(q.x, q.y, q.z)];
            }
        out[g.index(x, y, z)] = sum;
      }
  return out;
}

namespace {

glm::dvec3 fiberDirection(const BundleSamples& samples, size_t i, size_t s0, size_t s1) {
  const glm::dvec3 along = samples[std::min(i + 1, s1 - 1)] - samples[i > s0 ? i - 1 : i];
  const double len = glm::length(along);
  return len > 0 ? along / len : glm::dvec3(0.0);
}

}  // namespace

std::vector<double> splatReference(const BundleSamples& samples, const std::vector<uint32_t>& offsets,
                                   const BundleGrid& g, double ra, double rb, bool quantise) {
  std::vector<double> out(g.voxelCount(), 0.0);
  const glm::dvec3 top = glm::dvec3(g.size) - 1.0;
  for (size_t i = 0; i < samples.size(); ++i) {
    const uint32_t f = sampleFiber(offsets, i);
    const glm::dvec3 d = fiberDirection(samples, i, offsets[f], offsets[f + 1]);
    const glm::dvec3 c = (samples[i] - g.origin) / g.voxel;
    const glm::uvec3 lo(glm::clamp(glm::floor(c - ra), glm::dvec3(0.0), top));
    const glm::uvec3 hi(glm::clamp(glm::floor(c + ra), glm::dvec3(0.0), top));
    for (uint32_t z = lo.z; z <= hi.z; ++z)
      for (uint32_t y = lo.y; y <= hi.y; ++y)
        for (uint32_t x = lo.x; x <= hi.x; ++x) {
          const glm::dvec3 q = glm::dvec3(x, y, z) + 0.5 - c;
          const double a = glm::dot(q, d), b2 = std::max(glm::dot(q, q) - a * a, 0.0);
          const double k = 1 - a * a / (ra * ra) - b2 / (rb * rb);
          if (!(k > 0)) continue;
          const double s = double(shader::kBundleSplatScale);
          out[g.index(x, y, z)] += quantise ? std::floor(k * s + 0.5) / s : k;
        }
  }
  return out;
}

std::vector<glm::dvec3> gradientReference(const std::vector<double>& density, const BundleGrid& g) {
  std::vector<glm::dvec3> out(density.size());
  const uint64_t strides[3] = {1, g.size.x, uint64_t(g.size.x) * g.size.y};
  for (uint32_t z = 0; z < g.size.z; ++z)
    for (uint32_t y = 0; y < g.size.y; ++y)
      for (uint32_t x = 0; x < g.size.x; ++x) {
        const uint64_t index = g.index(x, y, z);
        const glm::uvec3 v(x, y, z);
        glm::dvec3 grad(0.0);
        for (int a = 0; a < 3; ++a) {
          const uint32_t n = g.size[a];
          if (n < 2) continue;
          const uint64_t lo = v[a] > 0 ? index - strides[a] : index;
          const uint64_t hi = v[a] + 1 < n ? index + strides[a] : index;
          const double span = double(int(v[a] > 0) + int(v[a] + 1 < n)) * g.voxel;
          grad[a] = (density[hi] - density[lo]) / span;
        }
        out[index] = grad;
      }
  return out;
}

namespace {

// Trilinear interpolation of a per-voxel field between voxel centres,
// clamped at the faces (the advection's gradient and structure tensor).
template <typename T>
T trilinear(const std::vector<T>& field, const BundleGrid& g, glm::dvec3 p) {
  const glm::dvec3 size(g.size);
  const glm::dvec3 q = (p - g.origin) / g.voxel - 0.5;
  const glm::dvec3 i0 = glm::clamp(glm::floor(q), glm::dvec3(0.0), glm::max(size - 2.0, glm::dvec3(0.0)));
  const glm::dvec3 t = glm::clamp(q - i0, glm::dvec3(0.0), glm::dvec3(1.0));
  const glm::uvec3 a(i0), b(glm::min(i0 + 1.0, size - 1.0));
  auto at = [&](uint32_t x, uint32_t y, uint32_t z) { return field[g.index(x, y, z)]; };
  auto mix = [](const T& u, const T& v, double s) { return u * (1.0 - s) + v * s; };
  const T x00 = mix(at(a.x, a.y, a.z), at(b.x, a.y, a.z), t.x);
  const T x10 = mix(at(a.x, b.y, a.z), at(b.x, b.y, a.z), t.x);
  const T x01 = mix(at(a.x, a.y, b.z), at(b.x, a.y, b.z), t.x);
  const T x11 = mix(at(a.x, b.y, b.z), at(b.x, b.y, b.z), t.x);
  return mix(mix(x00, x10, t.y), mix(x01, x11, t.y), t.z);
}

}  // namespace

glm::dvec3 interpolateGradient(const std::vector<glm::dvec3>& gradient, const BundleGrid& g, glm::dvec3 p) {
  return trilinear(gradient, g, p);
}

BundleTensors structureTensorReference(const std::vector<double>& density, const BundleGrid& g, uint32_t cell) {
  const BundleGrid cells = bundleStructureGrid(g, cell);
  // 1. The density at the tensor's scale: its mean over each cell.
  std::vector<double> mean(cells.voxelCount(), 0.0);
  for (uint32_t cz = 0; cz < cells.size.z; ++cz)
    for (uint32_t cy = 0; cy < cells.size.y; ++cy)
      for (uint32_t cx = 0; cx < cells.size.x; ++cx) {
        const glm::uvec3 lo = glm::uvec3(cx, cy, cz) * cell, hi = glm::min(lo + cell, g.size);
        double sum = 0;
        for (uint32_t z = lo.z; z < hi.z; ++z)
          for (uint32_t y = lo.y; y < hi.y; ++y)
            for (uint32_t x = lo.x; x < hi.x; ++x) sum += density[g.index(x, y, z)];
        const glm::uvec3 n = hi - lo;
        mean[cells.index(cx, cy, cz)] = sum / double(n.x * n.y * n.z);
      }
  // 2. Its gradient between cells (central differences, one-sided at the
  // faces, as gradientReference on the cell grid).
  const std::vector<glm::dvec3> grad = gradientReference(mean, cells);
  // 3. The tensor: the mean of grad grad^T over the cell and its (up to 26)
  // neighbours, so a sheet's middle cell, where the gradient changes sign,
  // still sees the sheet's normal.
  BundleTensors out(cells.voxelCount(), glm::dmat3(0.0));
  for (uint32_t cz = 0; cz < cells.size.z; ++cz)
    for (uint32_t cy = 0; cy < cells.size.y; ++cy)
      for (uint32_t cx = 0; cx < cells.size.x; ++cx) {
        const glm::uvec3 c(cx, cy, cz);
        const glm::uvec3 lo = glm::max(c, glm::uvec3(1)) - 1u, hi = glm::min(c + 2u, cells.size);
        glm::dmat3 sum(0.0);
        for (uint32_t z = lo.z; z < hi.z; ++z)
          for (uint32_t y = lo.y; y < hi.y; ++y)
            for (uint32_t x = lo.x; x < hi.x; ++x) {
              const glm::dvec3 v = grad[cells.index(x, y, z)];
              sum += glm::outerProduct(v, v);
            }
        const glm::uvec3 n = hi - lo;
        out[cells.index(cx, cy, cz)] = sum / double(n.x * n.y * n.z);
      }
  return out;
}

glm::dmat3 interpolateTensor(const BundleTensors& tensors, const BundleGrid& cells, glm::dvec3 p) {
  return trilinear(tensors, cells, p);
}

void symmetricEigenReference(const glm::dmat3& m, glm::dvec3* values, glm::dmat3* vectors) {
  double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[i][j] = 0.5 * (m[j][i] + m[i][j]);
  for (int sweep = 0; sweep < 64; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (!(off > 1e-32 * diag)) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0) continue;
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A P
          const double kp = a[k][p], kq = a[k][q];
          a[k][p] = c * kp - s * kq;
          a[k][q] = s * kp + c * kq;
        }
        for (int k = 0; k < 3; ++k) {  // P^T (A P)
          const double pk = a[p][k], qk = a[q][k];
          a[p][k] = c * pk - s * qk;
          a[q][k] = s * pk + c * qk;
        }
        for (int k = 0; k < 3; ++k) {  // V P
          const double kp = v[k][p], kq = v[k][q];
          v[k][p] = c * kp - s * kq;
          v[k][q] = s * kp + c * kq;
        }
      }
  }
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return a[i][i] > a[j][j]; });
  for (int k = 0; k < 3; ++k) {
    (*values)[k] = a[order[k]][order[k]];
    (*vectors)[k] = glm::dvec3(v[0][order[k]], v[1][order[k]], v[2][order[k]]);
  }
}

glm::dmat3 structureFilterReference(const glm::dmat3& tensor, uint32_t power) {
  glm::dvec3 lambda;
  glm::dmat3 e;
  symmetricEigenReference(tensor, &lambda, &e);
  const double floor = double(shader::kBundleMinGradient) * double(shader::kBundleMinGradient);
  if (!(lambda[0] > floor)) return glm::dmat3(1.0);
  glm::dmat3 out(0.0);
  for (int k = 0; k < 3; ++k)
    out += std::pow(std::max(lambda[k], 0.0) / lambda[0], double(power)) * glm::outerProduct(e[k], e[k]);
  return out;
}

BundleSamples advectReference(const BundleSamples& samples, const std::vector<uint32_t>& offsets,
                              const std::vector<glm::dvec3>& gradient, const BundleGrid& grid, double step_mm,
                              bool anchor_ends, const BundleStructureField* structure) {
  BundleSamples out = samples;
  for (size_t i = 0; i < samples.size(); ++i) {
    const uint32_t f = sampleFiber(offsets, i);
    const size_t s0 = offsets[f], s1 = offsets[f + 1];
    const bool end = i == s0 || i + 1 == s1;
    if (end && anchor_ends) continue;
    const glm::dvec3 along = samples[std::min(i + 1, s1 - 1)] - samples[i > s0 ? i - 1 : i];
    const glm::dvec3 g = interpolateGradient(gradient, grid, samples[i]);
    const double glen = glm::length(g), alen = glm::length(along);
    if (!(glen > double(shader::kBundleMinGradient)) || !(alen > 0)) continue;
    const glm::dvec3 d = along / alen;
    const glm::dvec3 m =
        structure ? structureFilterReference(interpolateTensor(*structure->tensors, structure->cells, samples[i]),
                                             structure->power) *
                        g
                  : g;
    out[i] = samples[i] + (m - d * glm::dot(d, m)) * (step_mm / glen);
  }
  return out;
}

BundleSamples smoothReference(const BundleSamples& samples, const std::vector<uint32_t>& offsets, double phi,
                              uint32_t window, bool anchor_ends) {
  BundleSamples out = samples;
  for (size_t i = 0; i < samples.size(); ++i) {
    const uint32_t f = sampleFiber(offsets, i);
    const size_t s0 = offsets[f], s1 = offsets[f + 1];
    if ((i == s0 || i + 1 == s1) && anchor_ends) continue;
    const size_t m = std::min<size_t>({window, i - s0, s1 - 1 - i});
    const size_t lo = i - m, hi = i + m;
    glm::dvec3 sum(0.0);
    for (size_t j = lo; j <= hi; ++j) sum += samples[j];
    out[i] = samples[i] * (1 - phi) + sum / double(hi - lo + 1) * phi;
  }
  return out;
}

BundleSamples relaxReference(const BundleSamples& original, const BundleSamples& bundled, double alpha) {
  BundleSamples out(bundled.size());
  for (size_t i = 0; i < bundled.size(); ++i) out[i] = original[i] + (bundled[i] - original[i]) * alpha;
  return out;
}

std::vector<float> mapBackReference(const Tractogram& t, const BundleSetup& setup, const BundleSamples& original,
                                    const BundleSamples& bundled) {
  std::vector<float> out(t.positions);
  for (size_t f = 0; f < t.streamlineCount(); ++f) {
    const uint64_t p0 = t.offsets[f], p1 = t.offsets[f + 1];
    const uint32_t s0 = setup.sample_offsets[f], n = setup.sample_offsets[f + 1] - s0;
    if (p1 == p0) continue;
    const double spacing = n > 1 ? fiberLength(t, f) / double(n - 1) : 0.0;
    double arc = 0;
    for (uint64_t i = p0; i < p1; ++i) {
      if (i > p0) arc += glm::length(pointOf(t, i) - pointOf(t, i - 1));
      glm::dvec3 shift;
      if (n == 1 || !(spacing > 0)) {
        shift = bundled[s0] - original[s0];
      } else {
        const double u = i + 1 == p1 ? double(n - 1) : std::clamp(arc / spacing, 0.0, double(n - 1));
        const uint32_t k = std::min(uint32_t(u), n - 2);
        shift = glm::mix(bundled[s0 + k] - original[s0 + k], bundled[s0 + k + 1] - original[s0 + k + 1], u - k);
      }
      const glm::dvec3 moved = pointOf(t, i) + shift;
      for (int a = 0; a < 3; ++a) out[3 * i + a] = float(moved[a]);
    }
  }
  return out;
}

BundleSamples iterateReference(const BundleSamples& samples, const BundleSetup& setup, const BundleParams& params,
                               double radius) {
  const BundleGrid& grid = setup.grid;
  const std::vector<double> density =
      params.mode == BundleMode::Anisotropic
          ? splatReference(samples, setup.sample_offsets, grid, radius, radius * params.anisotropy)
          : densitySeparableReference(countReference(samples, grid), grid, radius);
  const std::vector<glm::dvec3> gradient = gradientReference(density, grid);
  BundleTensors tensors;
  BundleStructureField structure;
  if (params.structure_aware) {
    const uint32_t cell = bundleStructureCell(params);
    tensors = structureTensorReference(density, grid, cell);
    structure = {&tensors, bundleStructureGrid(grid, cell), params.structure_power};
  }
  const BundleSamples advected =
      advectReference(samples, setup.sample_offsets, gradient, grid, bundleAdvectionStep(params, setup, radius),
                      params.anchor_ends, params.structure_aware ? &structure : nullptr);
  return smoothReference(advected, setup.sample_offsets, params.smoothing, bundleSmoothingWindow(params, setup, radius),
                         params.anchor_ends);
}

std::vector<float> bundleReference(const Tractogram& t, const BundleParams& params) {
  const BundleSetup setup = planBundling(t, params);
  const BundleSamples original = resampleReference(t, setup);
  BundleSamples samples = original;
  for (uint32_t it = 0; it < params.iterations; ++it)
    samples = iterateReference(samples, setup, params, bundleRadius(params, it));
  return mapBackReference(t, setup, original, relaxReference(original, samples, params.relaxation));
}

}  // namespace fibscope
