// DSI Studio's TinyTrack tract files (.tt.gz, its default since 2020).
//
// The file is a gzip-compressed MATLAB level-4 MAT file: a run of matrices,
// each a 20-byte header (type MOPT, rows, columns, imaginary flag, name
// length), its name and its values. DSI Studio writes "dimension",
// "voxel_size" and "trans_to_mni" (the voxel-to-world affine of its grid)
// first, then the tracts in uint8 matrices "track", "track1", "track2", ...
// of at most 128 MB each. A tract is a 16-byte record header (uint32: its
// coordinate count, three per point; int32 x, y, z: the first point in
// 1/32 voxel) and one int8 step per later coordinate, in 1/32 voxel. Read
// here as DSI Studio's TinyTrack::load_from_file reads it.
//
// World space: DSI Studio puts voxel centres at integer coordinates; the
// .trk files it exports hold voxmm = voxel x voxel size, which nibabel (and
// fibscope's .trk reader) reads half a voxel lower (TrackVis puts the first
// voxel's centre at 0.5). So that a .tt.gz and the .trk DSI Studio exports
// from it open in the same place, a point is trans_to_mni x (v / 32 - 0.5),
// as nibabel-based converters of .tt do.
//
// Streamed: one pass through the compressed file (GzipWindow), a record in
// memory at a time; progress counts compressed bytes. Every count is
// checked against the matrix it lies in before anything is read.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/byte_order.h"
#include "core/error.h"
#include "io/gzip_file.h"
#include "io/reader.h"
#include "io/trk_format.h"

namespace fibscope {
namespace {

constexpr uint64_t kMatHeaderBytes = 20;
constexpr uint32_t kMaxNameBytes = 64;
constexpr uint64_t kMaxSmallMatrixBytes = uint64_t(1) << 20;  // read whole; larger unknown ones are skipped
constexpr uint64_t kSkipStep = uint64_t(1) << 20;
constexpr uint64_t kTractHeaderBytes = 16;

// Bytes of one value of MAT-4 precision P (0 double, 1 single, 2 int32,
// 3 int16, 4 uint16, 5 uint8); 0 for any other.
uint64_t precisionBytes(int p) {
  static constexpr uint64_t bytes[] = {8, 4, 4, 2, 2, 1};
  return p >= 0 && p <= 5 ? bytes[p] : 0;
}

struct MatHeader {
  bool swap = false;  // big-endian values on this little-endian host (or the reverse)
  int precision = 0;
  int kind = 0;       // 0 numeric, 1 text
  uint64_t rows = 0, cols = 0;
  std::string name;
  uint64_t at = 0;     // offset of the header
  uint64_t data = 0;   // offset of the values
  uint64_t bytes = 0;  // of the values (real part; an imaginary part follows)
  uint64_t end = 0;    // offset after the matrix
};

bool isTrackBlock(const std::string& name) {
  if (name.rfind("track", 0) != 0) return false;
  return std::all_of(name.begin() + 5, name.end(), [](char c) { return c >= '0' && c <= '9'; });
}

class TinyTrackReader final : public TractogramReader {
 public:
  explicit TinyTrackReader(const std::string& path);
  bool read(Tractogram& chunk, size_t max_points) override;
  uint64_t bytesRead() const override { return done_ ? header_.file_bytes : window_.file().fileOffset(); }

 private:
  // The matrix header at pos_ (pos_ moves to its values); false at the end
  // of the file.
  bool nextMatrix(MatHeader& m);
  std::vector<double> values(const MatHeader& m);  // of a small numeric matrix; pos_ moves past it
  void skip(const MatHeader& m);                   // pos_ moves past it
  // Moves to the values of the next track block; false at the end of the file.
  bool nextTrackBlock();
  void enterTrackBlock(const MatHeader& m);  // checks it holds uint8 records
  void setAffine(const MatHeader& m, const std::vector<double>& v);
  void decodeTract(Tractogram& chunk, uint32_t count);
  [[noreturn]] void failHere(uint64_t at, const std::string& what) const { failAt(header_.path, at, what); }

  GzipWindow window_;
  uint64_t pos_ = 0;
  uint64_t block_end_ = 0;  // end of the track block being read (0: none)
  bool has_affine_ = false;
  std::array<double, 16> affine_{};  // trans_to_mni, row-major
  uint64_t tracts_ = 0;
  bool done_ = false;
};

TinyTrackReader::TinyTrackReader(const std::string& path) : window_(path) {
  header_.path = path;
  header_.format = "tt";
  header_.file_bytes = window_.file().fileSize();
  std::vector<double> dims, sizes;
  MatHeader m;
  bool tracks = false;
  while (nextMatrix(m)) {
    if (isTrackBlock(m.name)) {
      tracks = true;
      break;
    }
    const bool wanted = m.name == "dimension" || m.name == "voxel_size" || m.name == "trans_to_mni";
    if (!wanted || m.kind != 0 || m.bytes > kMaxSmallMatrixBytes) {
      skip(m);
      continue;
    }
    const std::vector<double> v = values(m);
    if (m.name == "dimension") dims = v;
    if (m.name == "voxel_size") sizes = v;
    if (m.name == "trans_to_mni") setAffine(m, v);
  }
  if (tracks) {
    if (!has_affine_) failHere(m.at, "the tracts come before any trans_to_mni (the voxel-to-world affine)");
    enterTrackBlock(m);
  } else if (has_affine_) {
    done_ = true;  // a file of no tracts (DSI Studio then writes no track matrix)
  } else {
    fail(path, "not a DSI Studio tract file: no trans_to_mni and no track matrix");
  }
  header_.space.known = has_affine_;
  for (int i = 0; i < 16; ++i) header_.space.voxel_to_rasmm[size_t(i)] = float(affine_[size_t(i)]);
  if (dims.size() == 3 && std::all_of(dims.begin(), dims.end(), [](double d) { return d >= 1 && d <= 32767; }))
    for (int k = 0; k < 3; ++k) header_.space.dimensions[size_t(k)] = int32_t(dims[size_t(k)]);
  if (sizes.size() == 3 && std::all_of(sizes.begin(), sizes.end(), [](double s) { return s > 0 && s < 1e6; }))
    for (int k = 0; k < 3; ++k) header_.space.voxel_sizes[size_t(k)] = float(sizes[size_t(k)]);
  if (has_affine_) header_.space.voxel_order = affineAxisCodes(header_.space.voxel_to_rasmm);
}

bool TinyTrackReader::nextMatrix(MatHeader& m) {
  const uint64_t got = window_.ensure(pos_, kMatHeaderBytes);
  if (got == 0) return false;
  if (got < kMatHeaderBytes) failHere(pos_, "the file ends inside a matrix header");
  const uint8_t* p = window_.at(pos_);
  m = MatHeader{};
  m.at = pos_;
  // MOPT as a decimal number in the file's byte order: M = 0 little-endian,
  // 1 big-endian; so it is below 2000 read the right way round.
  int32_t type = loadUnaligned<int32_t>(p, false);
  if (type < 0 || type >= 2000) {
    type = loadUnaligned<int32_t>(p, true);
    m.swap = true;
  }
  if (type < 0 || type >= 2000 || (type / 100) % 10 != 0)
    failHere(pos_, "not a MATLAB level-4 matrix (type " + std::to_string(loadUnaligned<int32_t>(p, false)) + ")");
  if ((type / 1000 == 1) != (m.swap == kHostIsLittleEndian))
    failHere(pos_, "a matrix's byte order disagrees with its type " + std::to_string(type));
  m.precision = (type / 10) % 10;
  m.kind = type % 10;
  if (precisionBytes(m.precision) == 0 || m.kind > 1)
    failHere(pos_, "matrix type " + std::to_string(type) + " is not supported (full numeric or text only)");
  const int32_t rows = loadUnaligned<int32_t>(p + 4, m.swap), cols = loadUnaligned<int32_t>(p + 8, m.swap);
  const int32_t imaginary = loadUnaligned<int32_t>(p + 12, m.swap), name_bytes = loadUnaligned<int32_t>(p + 16, m.swap);
  if (rows < 0 || cols < 0) failHere(pos_, "a matrix of " + std::to_string(rows) + " x " + std::to_string(cols));
  if (name_bytes < 1 || uint32_t(name_bytes) > kMaxNameBytes)
    failHere(pos_, "a matrix name of " + std::to_string(name_bytes) + " bytes (expected 1 to " +
                       std::to_string(kMaxNameBytes) + ")");
  m.rows = uint64_t(rows), m.cols = uint64_t(cols);
  // rows, cols < 2^31: their product fits; a product beyond 2^58 values
  // saturates, so the size check below refuses it without overflow.
  const uint64_t n = m.rows * m.cols;
  m.bytes = n > (uint64_t(1) << 58) ? uint64_t(1) << 61 : n * precisionBytes(m.precision);
  pos_ += kMatHeaderBytes;
  if (window_.ensure(pos_, uint64_t(name_bytes)) < uint64_t(name_bytes)) failHere(pos_, "the file ends inside a matrix name");
  const char* name = reinterpret_cast<const char*>(window_.at(pos_));
  m.name.assign(name, strnlen(name, size_t(name_bytes)));
  pos_ += uint64_t(name_bytes);
  m.data = pos_;
  m.end = m.data + m.bytes * (imaginary ? 2 : 1);
  // A deflate stream cannot hold more than 1032 times its size.
  if (m.end > kMaxGzipInflateRatio * header_.file_bytes + 65536)
    failHere(m.at, "matrix '" + m.name + "' claims " + std::to_string(m.bytes) + " bytes, more than a " +
                       std::to_string(header_.file_bytes) + "-byte gzip file can hold");
  return true;
}

std::vector<double> TinyTrackReader::values(const MatHeader& m) {
  if (window_.ensure(pos_, m.bytes) < m.bytes) failHere(pos_, "the file ends inside matrix '" + m.name + "'");
  const uint8_t* p = window_.at(pos_);
  const uint64_t n = m.rows * m.cols, size = precisionBytes(m.precision);
  std::vector<double> v(n);
  for (uint64_t i = 0; i < n; ++i) {
    const uint8_t* q = p + i * size;
    switch (m.precision) {
      case 0: v[i] = loadUnaligned<double>(q, m.swap); break;
      case 1: v[i] = loadUnaligned<float>(q, m.swap); break;
      case 2: v[i] = loadUnaligned<int32_t>(q, m.swap); break;
      case 3: v[i] = loadUnaligned<int16_t>(q, m.swap); break;
      case 4: v[i] = loadUnaligned<uint16_t>(q, m.swap); break;
      default: v[i] = *q; break;
    }
  }
  skip(m);
  return v;
}

void TinyTrackReader::skip(const MatHeader& m) {
  while (pos_ < m.end) {
    const uint64_t step = std::min(m.end - pos_, kSkipStep);
    if (window_.ensure(pos_, step) < step) failHere(pos_, "the file ends inside matrix '" + m.name + "'");
    pos_ += step;
  }
}

void TinyTrackReader::setAffine(const MatHeader& m, const std::vector<double>& v) {
  if (v.size() != 16) failHere(m.at, "trans_to_mni has " + std::to_string(v.size()) + " values, expected 16");
  // MATLAB stores a 4 x 4 matrix by columns; a 1 x 16 or 16 x 1 one holds
  // DSI Studio's row-major memory as it is. Whichever reading has the
  // affine's last row (0 0 0 1) is taken, the shape's first.
  std::array<double, 16> by_rows, by_cols;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) by_rows[size_t(4 * r + c)] = v[size_t(4 * r + c)], by_cols[size_t(4 * r + c)] = v[size_t(4 * c + r)];
  auto affine = [](const std::array<double, 16>& a) {
    return a[12] == 0 && a[13] == 0 && a[14] == 0 && a[15] == 1 &&
           std::all_of(a.begin(), a.end(), [](double x) { return std::isfinite(x); });
  };
  const bool square = m.rows == 4 && m.cols == 4;
  const std::array<double, 16>& first = square ? by_cols : by_rows;
  const std::array<double, 16>& second = square ? by_rows : by_cols;
  if (affine(first)) affine_ = first;
  else if (affine(second)) affine_ = second;
  else failHere(m.at, "trans_to_mni is not an affine (its last row is not 0 0 0 1, or a value is not finite)");
  const double* a = affine_.data();
  const double det = a[0] * (a[5] * a[10] - a[6] * a[9]) - a[1] * (a[4] * a[10] - a[6] * a[8]) +
                     a[2] * (a[4] * a[9] - a[5] * a[8]);
  if (!(std::fabs(det) > 1e-12)) failHere(m.at, "trans_to_mni is singular");
  has_affine_ = true;
}

void TinyTrackReader::enterTrackBlock(const MatHeader& m) {
  if (m.precision != 5 || m.end != m.data + m.bytes)
    failHere(m.at, "matrix '" + m.name + "' is not real uint8 data (a track block must be)");
  block_end_ = m.end;
}

bool TinyTrackReader::nextTrackBlock() {
  MatHeader m;
  while (nextMatrix(m)) {
    if (isTrackBlock(m.name)) {
      enterTrackBlock(m);
      return true;
    }
    skip(m);
  }
  return false;
}

bool TinyTrackReader::read(Tractogram& chunk, size_t max_points) {
  startChunk(chunk);
  max_points = std::max<size_t>(max_points, 1);
  while (!done_ && chunk.pointCount() < max_points) {
    if (pos_ >= block_end_) {
      if (!nextTrackBlock()) {
        done_ = true;
        break;
      }
      continue;
    }
    const uint64_t left = block_end_ - pos_;
    const std::string tract = "tract " + std::to_string(tracts_);
    if (left < kTractHeaderBytes) failHere(pos_, tract + ": the track block ends inside its 16-byte header");
    if (window_.ensure(pos_, kTractHeaderBytes) < kTractHeaderBytes) failHere(pos_, "the file ends inside " + tract);
    const uint32_t count = loadUnaligned<uint32_t>(window_.at(pos_), !kHostIsLittleEndian);
    if (count == 0 || count % 3 != 0)
      failHere(pos_, tract + ": " + std::to_string(count) + " coordinates, expected a positive multiple of 3");
    const uint64_t need = uint64_t(count) + kTractHeaderBytes - 3;
    if (need > left)
      failHere(pos_, tract + ": " + std::to_string(count / 3) + " points need " + std::to_string(need) +
                         " bytes, its track block has " + std::to_string(left) + " left");
    if (window_.ensure(pos_, need) < need) failHere(pos_, "the file ends inside " + tract);
    decodeTract(chunk, count);
    pos_ += need;
    ++tracts_;
  }
  return chunk.streamlineCount() > 0;
}

void TinyTrackReader::decodeTract(Tractogram& chunk, uint32_t count) {
  const uint8_t* p = window_.at(pos_);
  const bool swap = !kHostIsLittleEndian;  // records are little-endian (DSI Studio's memory on x86)
  // 64-bit sums: a long tract's steps cannot overflow them.
  int64_t v[3] = {loadUnaligned<int32_t>(p + 4, swap), loadUnaligned<int32_t>(p + 8, swap),
                  loadUnaligned<int32_t>(p + 12, swap)};
  const auto* steps = reinterpret_cast<const int8_t*>(p + kTractHeaderBytes);
  const size_t points = count / 3, first = chunk.pointCount();
  chunk.positions.resize(3 * (first + points));
  float* out = chunk.positions.data() + 3 * first;
  const double* a = affine_.data();
  for (size_t j = 0; j < points; ++j) {
    if (j > 0)
      for (int k = 0; k < 3; ++k) v[k] += steps[3 * (j - 1) + size_t(k)];
    const double x = std::ldexp(double(v[0]), -5) - 0.5, y = std::ldexp(double(v[1]), -5) - 0.5,
                 z = std::ldexp(double(v[2]), -5) - 0.5;
    for (int r = 0; r < 3; ++r) {
      const float w = float(a[4 * r] * x + a[4 * r + 1] * y + a[4 * r + 2] * z + a[4 * r + 3]);
      if (!std::isfinite(w)) failHere(pos_, "tract " + std::to_string(tracts_) + ": a point beyond the float range");
      out[3 * j + size_t(r)] = w;
    }
  }
  chunk.offsets.push_back(first + points);
}

}  // namespace

std::unique_ptr<TractogramReader> openTinyTrack(const std::string& path) {
  return std::make_unique<TinyTrackReader>(path);
}

}  // namespace fibscope
