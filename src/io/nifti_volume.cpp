#include "io/nifti_volume.h"


#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <memory>
#include <nifti1.h>

#include "core/byte_order.h"
#include "core/error.h"
#include "io/gzip_file.h"
#include "io/nifti_header.h"

namespace fibscope {
namespace {

// Bytes read at a time: a multiple of every voxel size.
constexpr size_t kChunkBytes = size_t(1) << 20;

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The .img that holds the voxels of a .hdr (gzipped or not, as it exists).
std::string imagePathOf(const std::string& path) {
  std::string stem;
  if (endsWith(path, ".hdr")) stem = path.substr(0, path.size() - 4);
  else if (endsWith(path, ".hdr.gz")) stem = path.substr(0, path.size() - 7);
  else fail(path, "its magic says the voxels are in a separate .img file, but it is not a .hdr");
  std::error_code ec;
  for (const char* suffix : {".img", ".img.gz"})
    if (std::filesystem::exists(stem + suffix, ec)) return stem + suffix;
  fail(path, "the voxels should be in " + stem + ".img (or .img.gz), which does not exist");
}

struct Conversion {
  bool swap = false, scaled = false;
  double slope = 1, inter = 0;
  NiftiValues mode = NiftiValues::Scaled;
};

// Converts n stored values of type T to out[0..n).
template <typename T>
void convert(const unsigned char* raw, size_t n, const Conversion& c, float* out) {
  for (size_t i = 0; i < n; ++i) {
    double x = double(loadUnaligned<T>(raw + i * sizeof(T), c.swap));
    // nibabel: stored * slope + inter in float64; MRtrix3: offset + scale *
    // stored in double, the same two roundings.
    if (c.scaled) x = x * c.slope + c.inter;
    if (c.mode == NiftiValues::Scaled) out[i] = float(x);
    else out[i] = std::isfinite(x) && std::round(x) != 0 ? 1.0f : 0.0f;  // MRtrix3's round_func<bool>
  }
}

void convertChunk(int datatype, const unsigned char* raw, size_t n, const Conversion& c, float* out) {
  switch (datatype) {
    case DT_UINT8: return convert<uint8_t>(raw, n, c, out);
    case DT_INT8: return convert<int8_t>(raw, n, c, out);
    case DT_INT16: return convert<int16_t>(raw, n, c, out);
    case DT_UINT16: return convert<uint16_t>(raw, n, c, out);
    case DT_INT32: return convert<int32_t>(raw, n, c, out);
    case DT_UINT32: return convert<uint32_t>(raw, n, c, out);
    case DT_INT64: return convert<int64_t>(raw, n, c, out);
    case DT_UINT64: return convert<uint64_t>(raw, n, c, out);
    case DT_FLOAT32: return convert<float>(raw, n, c, out);
    case DT_FLOAT64: return convert<double>(raw, n, c, out);
    default: throw Error("convertChunk: datatype " + std::to_string(datatype));  // parseNiftiHeader refused it
  }
}

std::string describe(const NiftiHeader& h) {
  std::string s = std::to_string(h.dim[1]) + " x " + std::to_string(h.dim[2]) + " x " + std::to_string(h.dim[3]);
  if (h.volumes() > 1) s += " x " + std::to_string(h.volumes()) + " volumes";
  return s + " " + niftiDatatypeName(h.datatype);
}

}  // namespace

NiftiVolume loadNiftiVolume(const std::string& path, NiftiValues mode, const NiftiVoxelLimit& limit) {
  GzipFile file(path);
  unsigned char header_bytes[540];
  // sizeof_hdr first: a NIfTI-1 header is followed by data from byte 352 on,
  // so 540 bytes cannot be read blindly.
  size_t got = file.read(header_bytes, 4);
  if (got == 4) {
    const int32_t size = loadUnaligned<int32_t>(header_bytes);
    const bool v2 = size == 540 || loadUnaligned<int32_t>(header_bytes, true) == 540;
    got += file.read(header_bytes + 4, (v2 ? 540 : 348) - 4);
  }
  const NiftiHeader h = parseNiftiHeader(path, header_bytes, got);
  if (limit.max_voxels > 0 && h.voxelsPerVolume() > limit.max_voxels)
    fail(path, std::to_string(h.dim[1]) + " x " + std::to_string(h.dim[2]) + " x " + std::to_string(h.dim[3]) +
                   " voxels, more than the " + std::to_string(limit.max_voxels) + " of " + std::string(limit.what));

  NiftiVolume v;
  v.path = path;
  v.nifti_version = h.version;
  v.datatype = niftiDatatypeName(h.datatype);
  v.dims = glm::ivec3(int(h.dim[1]), int(h.dim[2]), int(h.dim[3]));
  v.voxel_size_mm = glm::dvec3(std::fabs(h.pixdim[1]), std::fabs(h.pixdim[2]), std::fabs(h.pixdim[3]));
  v.voxel_to_world = niftiAffine(path, h, &v.affine_source);
  v.world_to_voxel = glm::inverse(v.voxel_to_world);
  v.volumes = h.volumes();

  // The voxels: in this file after the header (and its extensions, skipped),
  // or from the start of a separate .img.
  std::unique_ptr<GzipFile> image;
  std::string data_path = path;
  if (h.separate_image) {
    data_path = imagePathOf(path);
    image = std::make_unique<GzipFile>(data_path);
  }
  GzipFile& data = image ? *image : file;
  std::vector<unsigned char> buffer(kChunkBytes);
  const uint64_t start = uint64_t(h.vox_offset);  // >= the header's end in a single file
  const uint64_t before = start - data.offset();
  if (data.skip(before, buffer) < before)
    fail(data_path, "truncated: the voxels should start at byte " + std::to_string(start) + ", the file ends before");

  const uint64_t volume_bytes = h.voxelsPerVolume() * h.bytes_per_voxel;
  const uint64_t total_bytes = volume_bytes * h.volumes();  // < 2^62 (nifti_header.h's limits)
  if (!data.compressed()) {
    if (data.fileSize() < start || data.fileSize() - start < total_bytes)
      fail(data_path, "truncated: the header's " + describe(h) + " voxels need " + std::to_string(total_bytes) +
                          " bytes from byte " + std::to_string(start) + ", the file has " +
                          std::to_string(data.fileSize()) + " bytes");
  } else if (double(start) + double(total_bytes) > double(kMaxGzipInflateRatio) * double(data.fileSize()) + 65536.0) {
    fail(data_path, "truncated: the header's " + describe(h) + " voxels need " + std::to_string(total_bytes) +
                        " bytes, more than a gzip file of " + std::to_string(data.fileSize()) + " bytes can hold");
  }

  // The first volume, a chunk at a time, so that memory follows what the
  // file really holds (a gzip file is only known to be short at its end).
  Conversion c;
  c.swap = h.swap;
  c.scaled = h.scaled();
  c.slope = c.scaled ? h.scl_slope : 1.0;
  c.inter = c.scaled ? h.scl_inter : 0.0;
  c.mode = mode;
  if (!data.compressed()) v.values.reserve(size_t(h.voxelsPerVolume()));
  uint64_t done = 0;
  while (done < volume_bytes) {
    const size_t want = size_t(std::min<uint64_t>(volume_bytes - done, buffer.size()));
    const size_t n = data.read(buffer.data(), want);
    if (n < want)
      fail(data_path, "truncated: the header's " + describe(h) + " voxels need " + std::to_string(total_bytes) +
                          " bytes from byte " + std::to_string(start) + ", the data end after " +
                          std::to_string(done + n));
    const size_t first = v.values.size();
    v.values.resize(first + n / h.bytes_per_voxel);
    convertChunk(h.datatype, buffer.data(), n / h.bytes_per_voxel, c, v.values.data() + first);
    done += n;
  }
  // The other volumes must be there too (a header that disagrees with its
  // data is an error). A gzip file is read to its end: zlib checks the CRC
  // and length of everything only there, and a corrupt stream may as well
  // inflate to more bytes than the header says as to fewer. Bytes after the
  // voxels are allowed (and ignored), as nibabel allows them.
  if (data.compressed()) {
    const uint64_t rest = total_bytes - volume_bytes;
    if (data.skip(rest, buffer) < rest)
      fail(data_path, "truncated: the header's " + describe(h) + " voxels need " + std::to_string(total_bytes) +
                          " bytes from byte " + std::to_string(start) + ", the data end before");
    data.skip(UINT64_MAX, buffer);
  }

  for (const float x : v.values) {
    if (!std::isfinite(x)) continue;
    if (!(x >= v.min)) v.min = x;  // NaN at first
    if (!(x <= v.max)) v.max = x;
  }
  return v;
}

}  // namespace fibscope
