// Streaming TrackVis .trk reader.
//
// The file is memory-mapped and walked front to back: each read() decodes
// whole streamlines straight from the map into the chunk, converting voxmm
// to RAS+ mm with nibabel's affine (io/trk_format.h), and lets the kernel
// drop the pages it has passed. Every length is checked against the bytes
// that remain before anything is read or allocated.
//
// A gzip-compressed file (DSI Studio's .trk.gz; told by its magic, not its
// name) is walked the same way through a forward-only window on the
// decompressed bytes (io/gzip_file.h): offsets in messages are those of the
// decompressed data, progress (bytesRead) counts the compressed file's.
#include <unistd.h>

#include <bit>
#include <cstring>

#include "core/byte_order.h"
#include "core/error.h"
#include "core/mapped_file.h"
#include "io/gzip_file.h"
#include "io/reader.h"
#include "io/trk_format.h"

namespace fibscope {
namespace {

// A streamline whose bytes run past the end of the file is a truncated last
// streamline (interrupted tracking or copy) unless its point count could not
// come from any tracker: above 16.7 M points (200 MB for one streamline) it is
// taken as a corrupt count and reported as an error.
constexpr int64_t kMaxPlausiblePoints = int64_t(1) << 24;

inline bool nonFinite(uint32_t bits) { return (bits & 0x7f800000u) == 0x7f800000u; }

class TrkReader final : public TractogramReader {
 public:
  explicit TrkReader(const std::string& path);
  bool read(Tractogram& chunk, size_t max_points) override;
  uint64_t bytesRead() const override { return gz_ ? (done_ ? header_.file_bytes : gz_->file().fileOffset()) : pos_; }

 private:
  // The bytes [pos_, pos_ + n) of the (decompressed) data where there are:
  // how many (n, fewer only at the end); at() points into them.
  uint64_t available(uint64_t n);
  const uint8_t* at(uint64_t offset) const { return gz_ ? gz_->at(offset) : file_.data() + offset; }
  void decodeStreamline(Tractogram& chunk, uint32_t m, uint64_t offset) const;
  [[noreturn]] void reportNonFinite(uint32_t m, uint64_t start) const;
  void finishFile();

  MappedFile file_;                  // a plain file
  std::unique_ptr<GzipWindow> gz_;   // or a gzip-compressed one
  TrkHeader trk_;
  Affine4 to_ras_{};
  bool swap_ = false;             // file byte order differs from the host's
  uint64_t point_bytes_ = 12;     // (3 + n_scalars) * 4
  uint64_t property_bytes_ = 0;   // n_properties * 4
  std::vector<TrkNamedRun> scalar_runs_;
  std::vector<TrkNamedRun> property_runs_;
  uint64_t pos_ = kTrkHeaderBytes;
  uint64_t released_ = 0;         // page-aligned end of the pages handed back to the kernel
  uint64_t page_bytes_ = 4096;
  uint64_t streamlines_ = 0;
  bool done_ = false;
};

TrkReader::TrkReader(const std::string& path) {
  header_.path = path;
  header_.format = "trk";
  if (isGzipFile(path)) {
    gz_ = std::make_unique<GzipWindow>(path);
    header_.file_bytes = gz_->file().fileSize();
    pos_ = 0;
    const size_t head = size_t(available(kTrkHeaderBytes));  // before at(): it may move the window
    trk_ = parseTrkHeader(gz_->at(0), head, path);
    pos_ = kTrkHeaderBytes;
  } else {
    file_ = MappedFile(path);
    header_.file_bytes = file_.size();
    trk_ = parseTrkHeader(file_.data(), file_.size(), path);
  }
  swap_ = trk_.big_endian == kHostIsLittleEndian;

  std::vector<std::string> notes;
  const TrkGrid grid = resolveTrkGrid(trk_, path, notes);
  scalar_runs_ = decodeTrkNames(trk_.scalar_names, trk_.n_scalars, "scalar", "scalar", notes);
  property_runs_ = decodeTrkNames(trk_.property_names, trk_.n_properties, "property", "property", notes);
  for (const auto& note : notes) warn(note);
  to_ras_ = trkVoxmmToRasmm(grid);
  point_bytes_ = 4 * (3 + uint64_t(trk_.n_scalars));
  property_bytes_ = 4 * uint64_t(trk_.n_properties);

  header_.declared_streamlines = trk_.n_count > 0 ? trk_.n_count : -1;  // 0 means "not recorded"
  header_.space.known = true;
  header_.space.voxel_to_rasmm = grid.vox_to_ras;
  header_.space.dimensions = {grid.dimensions[0], grid.dimensions[1], grid.dimensions[2]};
  header_.space.voxel_sizes = grid.voxel_sizes;
  header_.space.voxel_order = grid.voxel_order;
  header_.properties = trkProperties(trk_, grid);
  for (const auto& run : scalar_runs_) header_.per_point.push_back({run.name, run.components, "float32", {}});
  for (const auto& run : property_runs_) header_.per_streamline.push_back({run.name, run.components, "float32", {}});

  const long page = ::sysconf(_SC_PAGESIZE);
  if (page > 0) page_bytes_ = uint64_t(page);
  if (!gz_) file_.adviseSequential();
}

uint64_t TrkReader::available(uint64_t n) {
  if (gz_) return gz_->ensure(pos_, n);
  return std::min<uint64_t>(n, file_.size() - pos_);
}

bool TrkReader::read(Tractogram& chunk, size_t max_points) {
  startChunk(chunk);
  if (done_) return false;
  while (!done_) {
    const uint64_t head = available(4);
    if (head == 0) {
      finishFile();
      break;
    }
    if (head < 4) {
      warn("byte " + std::to_string(pos_) + ": " + std::to_string(head) +
           " trailing bytes are too few for a point count; ignored");
      finishFile();
      break;
    }
    const int32_t m = loadUnaligned<int32_t>(at(pos_), swap_);
    if (m < 0)
      failAt(header_.path, pos_,
             "streamline " + std::to_string(streamlines_) + ": point count is " + std::to_string(m) + ", expected >= 0");
    const uint64_t need = 4 + uint64_t(m) * point_bytes_ + property_bytes_;
    // Compressed, the bytes that remain are known only by decompressing
    // them: a count no tracker makes is refused before the window grows.
    if (gz_ && m > kMaxPlausiblePoints)
      failAt(header_.path, pos_,
             "streamline " + std::to_string(streamlines_) + ": point count " + std::to_string(m) +
                 " is implausible (above " + std::to_string(kMaxPlausiblePoints) + ")");
    const uint64_t remaining = available(need);
    if (need > remaining) {
      const std::string what = "streamline " + std::to_string(streamlines_) + " has " + std::to_string(m) +
                               " points and needs " + std::to_string(need) + " bytes, but only " +
                               std::to_string(remaining) + " remain";
      if (m > kMaxPlausiblePoints) failAt(header_.path, pos_, what);
      warn("byte " + std::to_string(pos_) + ": file is truncated: " + what + "; it is dropped");
      finishFile();
      break;
    }
    decodeStreamline(chunk, uint32_t(m), pos_ + 4);
    pos_ += need;
    ++streamlines_;
    if (chunk.pointCount() >= max_points) break;
  }
  // Hand the pages behind us back to the kernel: bounded memory on huge files.
  if (!gz_ && pos_ - released_ >= page_bytes_) {
    file_.release(released_, pos_);
    released_ = pos_ / page_bytes_ * page_bytes_;
  }
  return chunk.streamlineCount() > 0;
}

void TrkReader::decodeStreamline(Tractogram& chunk, uint32_t m, uint64_t offset) const {
  const uint8_t* p = at(offset);
  const size_t first_point = chunk.pointCount();
  chunk.positions.resize(3 * (first_point + m));
  float* out = chunk.positions.data() + 3 * first_point;
  const double* a = to_ras_.data();
  uint32_t bad = 0;
  for (uint32_t j = 0; j < m; ++j) {
    const uint8_t* q = p + j * point_bytes_;
    const uint32_t bx = loadUnaligned<uint32_t>(q, swap_);
    const uint32_t by = loadUnaligned<uint32_t>(q + 4, swap_);
    const uint32_t bz = loadUnaligned<uint32_t>(q + 8, swap_);
    bad |= uint32_t(nonFinite(bx)) | uint32_t(nonFinite(by)) | uint32_t(nonFinite(bz));
    const double x = std::bit_cast<float>(bx), y = std::bit_cast<float>(by), z = std::bit_cast<float>(bz);
    out[3 * j + 0] = static_cast<float>(a[0] * x + a[1] * y + a[2] * z + a[3]);
    out[3 * j + 1] = static_cast<float>(a[4] * x + a[5] * y + a[6] * z + a[7]);
    out[3 * j + 2] = static_cast<float>(a[8] * x + a[9] * y + a[10] * z + a[11]);
  }
  if (bad) reportNonFinite(m, offset);

  for (size_t r = 0; r < scalar_runs_.size(); ++r) {
    const TrkNamedRun& run = scalar_runs_[r];
    std::vector<float>& values = chunk.per_point[r].values;
    const size_t base = values.size();
    values.resize(base + size_t(m) * run.components);
    float* v = values.data() + base;
    for (uint32_t j = 0; j < m; ++j) {
      const uint8_t* q = p + j * point_bytes_ + 12 + 4 * uint64_t(run.first);
      for (uint32_t c = 0; c < run.components; ++c) *v++ = loadUnaligned<float>(q + 4 * c, swap_);
    }
  }
  const uint8_t* props = p + uint64_t(m) * point_bytes_;
  for (size_t r = 0; r < property_runs_.size(); ++r) {
    const TrkNamedRun& run = property_runs_[r];
    for (uint32_t c = 0; c < run.components; ++c)
      chunk.per_streamline[r].values.push_back(loadUnaligned<float>(props + 4 * (uint64_t(run.first) + c), swap_));
  }
  chunk.offsets.push_back(first_point + m);
}

void TrkReader::reportNonFinite(uint32_t m, uint64_t start) const {
  const uint8_t* p = at(start);
  for (uint32_t j = 0; j < m; ++j)
    for (int k = 0; k < 3; ++k) {
      const uint64_t offset = start + j * point_bytes_ + 4 * k;
      const uint32_t bits = loadUnaligned<uint32_t>(p + j * point_bytes_ + 4 * k, swap_);
      if (nonFinite(bits))
        failAt(header_.path, offset,
               "streamline " + std::to_string(streamlines_) + ": point " + std::to_string(j) + " coordinate " +
                   std::string(1, "xyz"[k]) + " is " + ((bits & 0x007fffffu) ? "NaN" : "infinite"));
    }
  failAt(header_.path, start, "streamline " + std::to_string(streamlines_) + " has a non-finite coordinate");
}

void TrkReader::finishFile() {
  done_ = true;
  if (trk_.n_count > 0 && streamlines_ != uint64_t(trk_.n_count))
    warn("header n_count says " + std::to_string(trk_.n_count) + " streamlines, the file holds " +
         std::to_string(streamlines_));
}

}  // namespace

std::unique_ptr<TractogramReader> openTrk(const std::string& path) { return std::make_unique<TrkReader>(path); }

}  // namespace fibscope
