// Fiblet decoder (CPU): the reference for the GPU decode, built on the
// arithmetic of shaders/shared/fiblet.h.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "codec/codec_params.h"
#include "codec/fiblet_simd.h"
#include "core/tractogram.h"
#include "shared/fiblet.h"

namespace fibscope {

// Fiblet records plus the per-fiber tables (8 bytes per fiber).
struct EncodedFiblets {
  uint32_t record_bytes = 0;
  std::vector<uint8_t> bytes;                // records, record_bytes each, little-endian
  std::vector<uint32_t> fiber_first_fiblet;  // per fiber: global index of its first fiblet
  std::vector<uint32_t> fiber_points;        // per fiber: point count
  uint64_t fiblet_base = 0;                  // global index of bytes' first record (chunked encoding)

  size_t fibletCount() const { return record_bytes ? bytes.size() / record_bytes : 0; }
  size_t fiberCount() const { return fiber_points.size(); }
  const uint8_t* record(size_t i) const { return bytes.data() + i * record_bytes; }
  size_t tableBytes() const { return 4 * (fiber_first_fiblet.size() + fiber_points.size()); }
};

// The unit direction of `code` inside the alpha-cap around +z: the
// octahedral cell centre, normalised onto the hemisphere, then mapped
// uniformly from the hemisphere to the cap (theta = theta' * alpha / (pi/2),
// same azimuth). Computed in double, rounded to float.
shader::vec3 decodeDirection(uint32_t code, double alpha);

using FibletDirectionTable = std::array<shader::vec4, shader::kFibletCodeCount>;
// decodeDirection for all 256 codes (w = 0): the table the GPU gets.
FibletDirectionTable buildDirectionTable(float alpha);

// Checks the records and tables against each other and against the
// parameters: every point count in [1, N], the begins/ends flags on each
// fiber's first/last fiblet and nowhere else, first-fiblet indices
// increasing and in range, point counts summing to fiber_points. Returns ""
// when consistent, else one line naming the first problem. Safe on
// untrusted input.
std::string validateFiblets(const EncodedFiblets& fiblets, const CodecParams& params);

// Which composition order decodeAll and the .fbl reader use. Both give the
// same points to within 1e-6 of the scene size (tested), not bit for bit.
//   Sequential: the encoder's own reconstruction (the compression report's
//               error is exactly the error of these points); ~5x cheaper.
//   Scan: the GPU workgroup's log-step order (what the renderer shows).
enum class DecodeOrder : uint8_t { Sequential, Scan };

class FibletDecoder {
 public:
  // Throws Error when the parameters are invalid.
  explicit FibletDecoder(const CodecParams& params);

  const CodecParams& params() const { return params_; }
  const FibletDirectionTable& directionTable() const { return table_; }
  // L for each code (fibletLocalTransform of the table entry).
  const shader::FibletTransform& localTransform(uint32_t code) const { return local_[code & 255u]; }

  // Decodes one record (params().recordBytes() bytes) into normalised
  // points, x,y,z interleaved, and returns the point count; returns 0 and
  // writes nothing when the count is outside [1, N]. `xyz` must hold 3 * N
  // floats. Safe on untrusted records of the right size.
  //   decodeSequential: W_k = W_{k-1} * L_k, one point after the other.
  //   decodeScan: the log-step inclusive scan in the GPU workgroup's order.
  uint32_t decodeSequential(const uint8_t* record, float* xyz) const;
  uint32_t decodeScan(const uint8_t* record, float* xyz) const;

  // Normalised point -> world RAS+ mm (double, for error statistics):
  // translation + (1 / scale) * p, as the .fbl header states it.
  std::array<double, 3> toWorld(const float* normalised) const {
    return {double(normalised[0]) * mm_per_unit_ + double(params_.translation[0]),
            double(normalised[1]) * mm_per_unit_ + double(params_.translation[1]),
            double(normalised[2]) * mm_per_unit_ + double(params_.translation[2])};
  }
  uint32_t decode(const uint8_t* record, float* xyz, DecodeOrder order) const {
    return order == DecodeOrder::Scan ? decodeScan(record, xyz) : decodeSequential(record, xyz);
  }

  // Decodes everything back into a tractogram in world mm (by default in
  // scan order, as the GPU does). Throws Error("fiblets: ...") when
  // validateFiblets fails.
  Tractogram decodeAll(const EncodedFiblets& fiblets, DecodeOrder order = DecodeOrder::Scan) const;

 private:
  CodecParams params_;
  double mm_per_unit_;
  shader::vec3 v_;
  FibletDirectionTable table_;
  std::array<shader::FibletTransform, shader::kFibletCodeCount> local_;
  std::array<Frame4, shader::kFibletCodeCount> local4_;
};

}  // namespace fibscope
