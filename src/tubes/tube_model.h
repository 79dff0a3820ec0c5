// The tube model of the spline tubes (Salm, "Interactive Rendering of
// Spline Tubes", section 3; issue 15 item 1): from the points of a set of
// fibers, the nodes of one tube per fiber (position, radius, colour and
// their derivatives along the arc), cubic Hermite segments between
// consecutive nodes, and the tubes buffer (shared/tubes.h) that the ray
// caster and the tessellation read: node records and segment records
// holding offsets into them, so all tubes are one dispatch.
//
// Derivatives are per mm of arc (finite differences weighted like
// Catmull-Rom's, made non-uniform: the tangent at a node is the normalised
// sum of the unit chords on both sides, dr/ds and dcolour/ds the central
// difference over the two chords); the Hermite segment of chord L uses
// end derivatives L * tangent, so unevenly spaced nodes (after resampling)
// neither overshoot nor loop.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/tractogram.h"
#include "shared/tubes.h"

namespace fibscope {

// Where a tube's radius comes from. A data value v maps linearly from
// [data_min, data_max] to [radius_min, radius_max], clamped at both ends; a
// NaN or infinite value takes radius_min and is counted
// (TubeBuildStats::invalid_radii).
struct TubeRadius {
  enum class Source { Constant, PerFiber, PerPoint };
  Source source = Source::Constant;
  float radius = 0.5f;  // mm (Constant)
  std::string array;    // per_streamline (PerFiber) or per_point (PerPoint) array, 1 component
  float data_min = 0.0f, data_max = 1.0f;
  float radius_min = 0.2f, radius_max = 1.0f;  // mm
};

// A tube's own colour (TubeNode::color; alpha 0 leaves the colour mode's).
// Sets r.data_min / r.data_max to the smallest and largest finite value of
// `values` (a radius source's data over the fibers drawn); both 0 when
// none is finite (every tube then takes radius_min).
void fitRadiusDataRange(TubeRadius& r, std::span<const float> values);

struct TubeColor {
  enum class Source { None, Constant, PerPoint };
  Source source = Source::None;
  uint32_t rgba = 0xFFFFFFFFu;  // Constant: RGBA8, R in the low byte
  std::string array;            // PerPoint: a per_point array of 3 components
  float scale = 1.0f;           // PerPoint: value * scale is the channel in [0, 1] (255: 8-bit data)
};

struct TubeBuildOptions {
  std::vector<uint32_t> fibers;  // streamline indices, in drawing order; empty: every streamline
  TubeRadius radius;
  TubeColor color;
  // Geometric tolerance of resampling in mm: 0 keeps every point as a node;
  // > 0 drops points while the tube's centre line (the Hermite curve through
  // the kept nodes) stays within the tolerance of the original polyline
  // (resampleTubeNodes).
  float resample_tolerance = 0.0f;
  // Frames: the rotation-minimising frame is propagated in sub-steps along
  // the Hermite curve wherever consecutive tangents turn by more than this.
  float frame_substep_degrees = 20.0f;
};

struct TubeBuildStats {
  size_t tubes = 0;               // tubes made (fibers with at least one point)
  size_t input_points = 0;        // points of the fibers given
  size_t nodes = 0;               // nodes made (= input_points without resampling, + 1 per single-point tube)
  size_t invalid_radii = 0;       // NaN / infinite data values that took radius_min
  size_t single_point_tubes = 0;  // fibers of one distinct point: a sphere (the node twice, a segment of chord 0)
  size_t duplicate_points = 0;    // zero-length steps dropped (a segment needs a direction)
};

struct TubeModel {
  struct Tube {
    uint32_t fiber = 0;       // streamline index in the tractogram
    uint32_t first_node = 0;  // into nodes
    uint32_t node_count = 0;  // segments: node_count - 1, from TubeModel::first segment below
    uint32_t first_segment = 0;
  };
  std::vector<shader::TubeNode> nodes;
  std::vector<shader::TubeSegment> segments;
  std::vector<Tube> tubes;

  size_t subSegmentCount() const { return 2 * segments.size(); }
  // Bytes of the tubes buffer (node and segment records) on the device.
  size_t deviceBytes() const { return nodes.size() * sizeof(nodes[0]) + segments.size() * sizeof(segments[0]); }
};

// Builds one tube per fiber of `options.fibers`. Throws Error for a radius
// <= 0 mm or not finite, radius_max < radius_min, a missing or
// wrong-sized data array, a fiber index out of range, a tolerance < 0 or
// NaN. Fibers of zero points are skipped; a fiber of one point (or whose
// points all coincide) becomes a sphere of its radius: its node twice and
// one segment of chord 0 (TubeBuildStats::single_point_tubes). Safe on any Tractogram that passes
// validate(); cost O(points), memory 48 bytes per node + 16 per segment.
TubeModel buildTubes(const Tractogram& tractogram, const TubeBuildOptions& options, TubeBuildStats* stats = nullptr);

// The Hermite centre line of segment `s` of `model` at u in [0, 1], and its
// derivative d/du.
glm::vec3 tubeSegmentPoint(const TubeModel& model, const shader::TubeSegment& s, float u);
glm::vec3 tubeSegmentDerivative(const TubeModel& model, const shader::TubeSegment& s, float u);
// The cubic Hermite basis on p0, p1 with end derivatives m0, m1 (d/du).
glm::vec3 hermitePoint(const glm::vec3& p0, const glm::vec3& m0, const glm::vec3& p1, const glm::vec3& m1, float u);
glm::vec3 hermiteDerivative(const glm::vec3& p0, const glm::vec3& m0, const glm::vec3& p1, const glm::vec3& m1,
                            float u);

// Point indices (into points[0 .. n)) kept as nodes by resampling with
// tolerance `tolerance` mm: always the first and the last; a run of points
// between two kept ones is dropped when the Hermite curve through the two
// (with the tangents of the full polyline at them) passes within
// `tolerance` of every dropped point at its arc-length parameter, and its
// points halfway between consecutive dropped points lie within
// `tolerance` of the polyline's segment there. Runs are capped at 64
// points. `points`: x y z interleaved; zero-length steps removed.
std::vector<uint32_t> resampleTubeNodes(const float* points, size_t n, float tolerance);

// The unit tangents of a polyline as buildTubes makes them (the normalised
// sum of the unit chords either side; the chord at the ends).
std::vector<glm::vec3> polylineTangents(const float* points, size_t n);

// Octahedral packing of a unit vector (glsl/tangent.glsl's packTangent) and
// its inverse.
uint32_t packUnitVector(const glm::vec3& v);
glm::vec3 unpackUnitVector(uint32_t packed);

}  // namespace fibscope
