#include "tubes/tube_model.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "core/error.h"
#include "tubes/tube_frames.h"

namespace fibscope {
namespace {

constexpr size_t kMaxResampleRun = 64;

glm::vec3 at(const float* p, size_t i) { return {p[3 * i], p[3 * i + 1], p[3 * i + 2]}; }

const DataArray* findArray(const std::vector<DataArray>& arrays, const std::string& name, uint32_t components,
                           size_t count, const char* what) {
  for (const DataArray& a : arrays) {
    if (a.name != name) continue;
    if (a.components != components || a.values.size() != size_t(components) * count)
      throw Error("tubes: the " + std::string(what) + " array '" + name + "' has " + std::to_string(a.components) +
                  " components and " + std::to_string(a.values.size()) + " values; expected " +
                  std::to_string(components) + " components per entry (" + std::to_string(count) + " entries)");
    return &a;
  }
  throw Error("tubes: no " + std::string(what) + " array named '" + name + "'");
}

void checkOptions(const TubeBuildOptions& o) {
  const TubeRadius& r = o.radius;
  const auto positive = [](float v) { return std::isfinite(v) && v > 0.0f; };
  if (r.source == TubeRadius::Source::Constant) {
    if (!positive(r.radius))
      throw Error("tubes: the radius must be a finite number > 0 mm, got " + std::to_string(r.radius));
  } else {
    if (!positive(r.radius_min) || !positive(r.radius_max) || r.radius_max < r.radius_min)
      throw Error("tubes: the radius range must be finite, > 0 mm and ordered, got [" + std::to_string(r.radius_min) +
                  ", " + std::to_string(r.radius_max) + "]");
    if (!std::isfinite(r.data_min) || !std::isfinite(r.data_max))
      throw Error("tubes: the radius data range must be finite");
  }
  if (!(o.resample_tolerance >= 0.0f) || !std::isfinite(o.resample_tolerance))
    throw Error("tubes: the resampling tolerance must be a finite number >= 0 mm, got " +
                std::to_string(o.resample_tolerance));
}

float mapRadius(const TubeRadius& r, float v, size_t& invalid) {
  if (!std::isfinite(v)) {
    ++invalid;
    return r.radius_min;
  }
  const float span = r.data_max - r.data_min;
  const float f = span != 0.0f ? std::clamp((v - r.data_min) / span, 0.0f, 1.0f) : 0.0f;
  return r.radius_min + f * (r.radius_max - r.radius_min);
}

uint32_t packColor(const glm::vec3& c) {
  const auto byte = [](float v) {
    return uint32_t(std::lround(std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f) * 255.0f));
  };
  return byte(c.x) | byte(c.y) << 8 | byte(c.z) << 16 | 0xFFu << 24;
}

uint32_t packSlope(const glm::vec3& s) {
  // packSnorm4x8 of s / kTubeColorSlopeMax, alpha slope 0.
  const auto snorm = [](float v) {
    const float c = std::clamp(std::isfinite(v) ? v / shader::kTubeColorSlopeMax : 0.0f, -1.0f, 1.0f);
    return uint32_t(uint8_t(int8_t(std::lround(c * 127.0f))));
  };
  return snorm(s.x) | snorm(s.y) << 8 | snorm(s.z) << 16;
}

// Point indices of fiber `f` with zero-length steps removed.
void distinctPoints(const Tractogram& t, size_t f, std::vector<uint32_t>& out, size_t& duplicates) {
  out.clear();
  const size_t first = t.offsets[f], n = t.pointsIn(f);
  for (size_t i = 0; i < n; ++i) {
    const glm::vec3 p = at(t.positions.data(), first + i);
    if (!out.empty() && p == at(t.positions.data(), first + out.back())) {
      ++duplicates;
      continue;
    }
    out.push_back(uint32_t(i));
  }
}

}  // namespace

glm::vec3 hermitePoint(const glm::vec3& p0, const glm::vec3& m0, const glm::vec3& p1, const glm::vec3& m1, float u) {
  const float u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1;
}

glm::vec3 hermiteDerivative(const glm::vec3& p0, const glm::vec3& m0, const glm::vec3& p1, const glm::vec3& m1,
                            float u) {
  const float u2 = u * u;
  return (6 * u2 - 6 * u) * p0 + (3 * u2 - 4 * u + 1) * m0 + (-6 * u2 + 6 * u) * p1 + (3 * u2 - 2 * u) * m1;
}

namespace {
void segmentEnds(const TubeModel& model, const shader::TubeSegment& s, glm::vec3& p0, glm::vec3& m0, glm::vec3& p1,
                 glm::vec3& m1) {
  const shader::TubeNode& a = model.nodes[s.node];
  const shader::TubeNode& b = model.nodes[s.node + 1];
  p0 = {a.position_radius.x, a.position_radius.y, a.position_radius.z};
  p1 = {b.position_radius.x, b.position_radius.y, b.position_radius.z};
  m0 = s.chord * glm::vec3(a.tangent_dradius.x, a.tangent_dradius.y, a.tangent_dradius.z);
  m1 = s.chord * glm::vec3(b.tangent_dradius.x, b.tangent_dradius.y, b.tangent_dradius.z);
}
}  // namespace

glm::vec3 tubeSegmentPoint(const TubeModel& model, const shader::TubeSegment& s, float u) {
  glm::vec3 p0, m0, p1, m1;
  segmentEnds(model, s, p0, m0, p1, m1);
  return hermitePoint(p0, m0, p1, m1, u);
}

glm::vec3 tubeSegmentDerivative(const TubeModel& model, const shader::TubeSegment& s, float u) {
  glm::vec3 p0, m0, p1, m1;
  segmentEnds(model, s, p0, m0, p1, m1);
  return hermiteDerivative(p0, m0, p1, m1, u);
}

std::vector<glm::vec3> polylineTangents(const float* points, size_t n) {
  std::vector<glm::vec3> t(n, glm::vec3(0, 0, 1));
  if (n < 2) return t;
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 sum(0.0f);
    if (i > 0) sum += glm::normalize(at(points, i) - at(points, i - 1));
    if (i + 1 < n) sum += glm::normalize(at(points, i + 1) - at(points, i));
    const float l = glm::length(sum);
    // A full reversal (sum zero): the incoming chord.
    t[i] = l > 1e-6f ? sum / l : glm::normalize(at(points, i) - at(points, i - 1));
  }
  return t;
}

std::vector<uint32_t> resampleTubeNodes(const float* points, size_t n, float tolerance) {
  std::vector<uint32_t> kept;
  if (n == 0) return kept;
  kept.push_back(0);
  if (n == 1) return kept;
  const std::vector<glm::vec3> tangent = polylineTangents(points, n);
  std::vector<float> arc(n, 0.0f);  // cumulative chord length
  for (size_t i = 1; i < n; ++i) arc[i] = arc[i - 1] + glm::distance(at(points, i - 1), at(points, i));
  const auto distanceToSegment = [&](const glm::vec3& q, size_t i) {
    const glm::vec3 a = at(points, i), ab = at(points, i + 1) - a;
    const float h = std::clamp(glm::dot(q - a, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
    return glm::distance(q, a + h * ab);
  };
  // Whether nodes a and b (a < b) may be consecutive.
  const auto fits = [&](size_t a, size_t b) {
    const glm::vec3 p0 = at(points, a), p1 = at(points, b);
    const float chord = glm::distance(p0, p1);
    const glm::vec3 m0 = chord * tangent[a], m1 = chord * tangent[b];
    const float span = arc[b] - arc[a];
    for (size_t k = a; k < b; ++k) {
      const float u0 = (arc[k] - arc[a]) / span, u1 = (arc[k + 1] - arc[a]) / span;
      if (k > a && glm::distance(hermitePoint(p0, m0, p1, m1, u0), at(points, k)) > tolerance) return false;
      // The curve between two original points stays near their segment
      // (quarter points and midpoint).
      for (float w : {0.25f, 0.5f, 0.75f})
        if (distanceToSegment(hermitePoint(p0, m0, p1, m1, u0 + w * (u1 - u0)), k) > tolerance) return false;
    }
    return true;
  };
  size_t a = 0;
  while (a + 1 < n) {
    size_t b = a + 1;
    if (tolerance > 0.0f)
      while (b + 1 < n && b + 1 - a <= kMaxResampleRun && fits(a, b + 1)) ++b;
    kept.push_back(uint32_t(b));
    a = b;
  }
  return kept;
}

uint32_t packUnitVector(const glm::vec3& t) {
  const float l1 = std::fabs(t.x) + std::fabs(t.y) + std::fabs(t.z);
  float x = 0.0f, y = 0.0f;
  if (l1 > 0.0f) {
    x = t.x / l1;
    y = t.y / l1;
    if (t.z < 0.0f) {
      const float ox = x;
      x = (1.0f - std::fabs(y)) * (ox >= 0.0f ? 1.0f : -1.0f);
      y = (1.0f - std::fabs(ox)) * (y >= 0.0f ? 1.0f : -1.0f);
    }
  }
  const auto snorm = [](float v) {
    return uint32_t(uint16_t(int16_t(std::lround(std::clamp(v, -1.0f, 1.0f) * 32767.0f))));
  };
  return snorm(x) | snorm(y) << 16;
}

glm::vec3 unpackUnitVector(uint32_t packed) {
  const auto snorm = [](uint32_t bits) { return std::clamp(float(int16_t(uint16_t(bits))) / 32767.0f, -1.0f, 1.0f); };
  float x = snorm(packed & 0xFFFFu), y = snorm(packed >> 16);
  const float z = 1.0f - std::fabs(x) - std::fabs(y);
  if (z < 0.0f) {
    const float ox = x;
    x = (1.0f - std::fabs(y)) * (ox >= 0.0f ? 1.0f : -1.0f);
    y = (1.0f - std::fabs(ox)) * (y >= 0.0f ? 1.0f : -1.0f);
  }
  return glm::normalize(glm::vec3(x, y, z));
}

void fitRadiusDataRange(TubeRadius& r, std::span<const float> values) {
  r.data_min = INFINITY;
  r.data_max = -INFINITY;
  for (const float v : values)
    if (std::isfinite(v)) r.data_min = std::min(r.data_min, v), r.data_max = std::max(r.data_max, v);
  if (r.data_min > r.data_max) r.data_min = r.data_max = 0.0f;
}

TubeModel buildTubes(const Tractogram& tractogram, const TubeBuildOptions& options, TubeBuildStats* stats_out) {
  checkOptions(options);
  const size_t fibers = tractogram.streamlineCount();
  std::vector<uint32_t> order = options.fibers;
  if (order.empty()) {
    order.resize(fibers);
    for (size_t i = 0; i < fibers; ++i) order[i] = uint32_t(i);
  }
  for (uint32_t f : order)
    if (f >= fibers)
      throw Error("tubes: fiber " + std::to_string(f) + " is out of range (the tractogram has " +
                  std::to_string(fibers) + ")");
  const TubeRadius& rs = options.radius;
  const DataArray* radius_array = nullptr;
  if (rs.source == TubeRadius::Source::PerFiber)
    radius_array = findArray(tractogram.per_streamline, rs.array, 1, fibers, "per-streamline");
  if (rs.source == TubeRadius::Source::PerPoint)
    radius_array = findArray(tractogram.per_point, rs.array, 1, tractogram.pointCount(), "per-point");
  const DataArray* color_array = nullptr;
  if (options.color.source == TubeColor::Source::PerPoint)
    color_array = findArray(tractogram.per_point, options.color.array, 3, tractogram.pointCount(), "per-point");

  TubeBuildStats stats;
  TubeModel model;
  size_t total = 0;
  for (uint32_t f : order) total += tractogram.pointsIn(f);
  stats.input_points = total;
  if (options.resample_tolerance == 0.0f) {
    model.nodes.reserve(total);
    model.segments.reserve(total);
  }
  model.tubes.reserve(order.size());

  std::vector<uint32_t> distinct, kept;
  std::vector<float> xyz, radius;
  std::vector<glm::vec3> color;
  for (uint32_t f : order) {
    distinctPoints(tractogram, f, distinct, stats.duplicate_points);
    if (distinct.empty()) continue;
    const size_t first = tractogram.offsets[f];
    xyz.clear();
    for (uint32_t i : distinct)
      for (int k = 0; k < 3; ++k) xyz.push_back(tractogram.positions[3 * (first + i) + k]);
    const size_t n = distinct.size();
    kept = resampleTubeNodes(xyz.data(), n, options.resample_tolerance);
    const std::vector<glm::vec3> tangent = polylineTangents(xyz.data(), n);

    // Per kept node: radius and colour, then their slopes over the kept
    // nodes' chords.
    const size_t m = kept.size();
    radius.assign(m, rs.source == TubeRadius::Source::PerFiber
                         ? mapRadius(rs, radius_array->values[f], stats.invalid_radii)
                         : rs.radius);
    color.assign(m, glm::vec3(0.0f));
    for (size_t j = 0; j < m; ++j) {
      const size_t point = first + distinct[kept[j]];
      if (rs.source == TubeRadius::Source::PerPoint)
        radius[j] = mapRadius(rs, radius_array->values[point], stats.invalid_radii);
      if (color_array)
        for (int k = 0; k < 3; ++k) color[j][k] = color_array->values[3 * point + k] * options.color.scale;
    }

    TubeModel::Tube tube;
    tube.fiber = f;
    tube.first_node = uint32_t(model.nodes.size());
    tube.node_count = uint32_t(m);
    tube.first_segment = uint32_t(model.segments.size());
    std::vector<float> chord(m > 1 ? m - 1 : 0);
    for (size_t j = 0; j + 1 < m; ++j) chord[j] = glm::distance(at(xyz.data(), kept[j]), at(xyz.data(), kept[j + 1]));
    for (size_t j = 0; j < m; ++j) {
      // Central difference over the chords either side (one-sided at the ends).
      const size_t lo = j > 0 ? j - 1 : j, hi = j + 1 < m ? j + 1 : j;
      float span = 0.0f;
      for (size_t k = lo; k < hi; ++k) span += chord[k];
      const float dr = span > 0.0f ? (radius[hi] - radius[lo]) / span : 0.0f;
      const glm::vec3 dc = span > 0.0f ? (color[hi] - color[lo]) / span : glm::vec3(0.0f);
      const glm::vec3 p = at(xyz.data(), kept[j]), t = tangent[kept[j]];
      shader::TubeNode node{};
      node.position_radius = {p.x, p.y, p.z, radius[j]};
      node.tangent_dradius = {t.x, t.y, t.z, dr};
      node.color = options.color.source == TubeColor::Source::Constant ? options.color.rgba
                   : color_array                                       ? packColor(color[j])
                                                                       : 0u;
      node.color_slope = color_array ? packSlope(dc) : 0u;
      node.point = float(distinct[kept[j]]);
      model.nodes.push_back(node);
    }
    for (size_t j = 0; j + 1 < m; ++j) {
      shader::TubeSegment s{};
      s.node = tube.first_node + uint32_t(j);
      s.fiber = f;
      s.chord = chord[j];
      model.segments.push_back(s);
    }
    if (m == 1) {
      // One point: the node twice and a segment of chord 0 between them,
      // whose sub-segments are the node's sphere (every control point the
      // same), so the ray caster draws it as a sphere.
      ++stats.single_point_tubes;
      model.nodes.push_back(model.nodes.back());
      tube.node_count = 2;
      shader::TubeSegment s{};
      s.node = tube.first_node;
      s.fiber = f;
      s.chord = 0.0f;
      model.segments.push_back(s);
    }
    propagateTubeFrames(model.nodes.data() + tube.first_node, model.segments.data() + tube.first_segment,
                        tube.node_count, options.frame_substep_degrees);
    model.tubes.push_back(tube);
  }
  stats.nodes = model.nodes.size();
  stats.tubes = model.tubes.size();
  if (stats_out) *stats_out = stats;
  return model;
}

}  // namespace fibscope
