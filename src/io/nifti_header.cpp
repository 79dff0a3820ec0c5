#include "io/nifti_header.h"

#include <nifti1.h>
#include <nifti2.h>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

#include "core/byte_order.h"
#include "core/error.h"

namespace fibscope {
namespace {

static_assert(sizeof(nifti_1_header) == 348 && sizeof(nifti_2_header) == 540);

// A field of type Stored at `offset`, in the header's byte order.
template <typename Stored>
Stored field(const unsigned char* bytes, size_t offset, bool swap) {
  return loadUnaligned<Stored>(bytes + offset, swap);
}

// The header's fields, whose types differ between the versions: NIfTI-1
// stores shorts and floats, NIfTI-2 64-bit integers and doubles.
template <typename Header, typename Dim, typename Real, typename Code>
void readFields(const unsigned char* b, bool swap, NiftiHeader& h) {
  h.datatype = field<int16_t>(b, offsetof(Header, datatype), swap);
  for (int i = 0; i < 8; ++i) {
    h.dim[i] = field<Dim>(b, offsetof(Header, dim) + i * sizeof(Dim), swap);
    h.pixdim[i] = field<Real>(b, offsetof(Header, pixdim) + i * sizeof(Real), swap);
  }
  h.scl_slope = field<Real>(b, offsetof(Header, scl_slope), swap);
  h.scl_inter = field<Real>(b, offsetof(Header, scl_inter), swap);
  h.qform_code = field<Code>(b, offsetof(Header, qform_code), swap);
  h.sform_code = field<Code>(b, offsetof(Header, sform_code), swap);
  const size_t quatern[3] = {offsetof(Header, quatern_b), offsetof(Header, quatern_c), offsetof(Header, quatern_d)};
  const size_t qoffset[3] = {offsetof(Header, qoffset_x), offsetof(Header, qoffset_y), offsetof(Header, qoffset_z)};
  const size_t srow[3] = {offsetof(Header, srow_x), offsetof(Header, srow_y), offsetof(Header, srow_z)};
  for (int i = 0; i < 3; ++i) {
    h.quatern[i] = field<Real>(b, quatern[i], swap);
    h.qoffset[i] = field<Real>(b, qoffset[i], swap);
    for (int j = 0; j < 4; ++j) h.srow[i][j] = field<Real>(b, srow[i] + j * sizeof(Real), swap);
  }
}

size_t bytesPerVoxel(int datatype) {
  switch (datatype) {
    case DT_UINT8: case DT_INT8: return 1;
    case DT_INT16: case DT_UINT16: return 2;
    case DT_INT32: case DT_UINT32: case DT_FLOAT32: return 4;
    case DT_INT64: case DT_UINT64: case DT_FLOAT64: return 8;
    default: return 0;  // not one fibscope reads
  }
}

// Printable text for bytes of a magic string.
std::string printable(const unsigned char* p, size_t n) {
  std::string out;
  for (size_t i = 0; i < n; ++i) {
    if (p[i] >= 0x20 && p[i] < 0x7f) {
      out += char(p[i]);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", p[i]);
      out += buf;
    }
  }
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// nibabel's quaternions.quat2mat: the rotation of (w, x, y, z), normalised
// by its squared norm; identity when that is ~0.
glm::dmat3 quaternionMatrix(double w, double x, double y, double z) {
  const double nq = w * w + x * x + y * y + z * z;
  if (nq < std::numeric_limits<double>::epsilon()) return glm::dmat3(1.0);
  const double s = 2.0 / nq;
  const double X = x * s, Y = y * s, Z = z * s;
  const double wX = w * X, wY = w * Y, wZ = w * Z;
  const double xX = x * X, xY = x * Y, xZ = x * Z;
  const double yY = y * Y, yZ = y * Z, zZ = z * Z;
  glm::dmat3 r;  // glm is column-major: r[column][row]
  r[0] = {1.0 - (yY + zZ), xY + wZ, xZ - wY};
  r[1] = {xY - wZ, 1.0 - (xX + zZ), yZ + wX};
  r[2] = {xZ + wY, yZ - wX, 1.0 - (xX + yY)};
  return r;
}

}  // namespace

uint64_t NiftiHeader::volumes() const {
  uint64_t n = 1;
  for (int i = 4; i <= 7; ++i) n *= uint64_t(dim[i]);  // <= kNiftiMaxVolumes (parseNiftiHeader)
  return n;
}

std::string niftiDatatypeName(int datatype) {
  switch (datatype) {
    case DT_UINT8: return "uint8";
    case DT_INT8: return "int8";
    case DT_INT16: return "int16";
    case DT_UINT16: return "uint16";
    case DT_INT32: return "int32";
    case DT_UINT32: return "uint32";
    case DT_INT64: return "int64";
    case DT_UINT64: return "uint64";
    case DT_FLOAT32: return "float32";
    case DT_FLOAT64: return "float64";
    // The others the spec defines, which fibscope does not read.
    case DT_BINARY: return "binary (1 bit)";
    case DT_COMPLEX64: return "complex64";
    case DT_COMPLEX128: return "complex128";
    case DT_COMPLEX256: return "complex256";
    case DT_FLOAT128: return "float128";
    case DT_RGB24: return "RGB24";
    case DT_RGBA32: return "RGBA32";
    default: return "code " + std::to_string(datatype);
  }
}

NiftiHeader parseNiftiHeader(const std::string& path, const unsigned char* b, size_t size) {
  NiftiHeader h;
  if (size < 4) fail(path, "not a NIfTI file: " + std::to_string(size) + " bytes, shorter than any NIfTI header");
  const int32_t sizeof_hdr = loadUnaligned<int32_t>(b);
  const int32_t swapped = loadUnaligned<int32_t>(b, true);
  if (sizeof_hdr == 348 || swapped == 348) {
    h.version = 1;
  } else if (sizeof_hdr == 540 || swapped == 540) {
    h.version = 2;
  } else {
    fail(path, "not a NIfTI file: sizeof_hdr is " + std::to_string(sizeof_hdr) +
                   " (expected 348 for NIfTI-1 or 540 for NIfTI-2)");
  }
  h.swap = sizeof_hdr != 348 && sizeof_hdr != 540;
  h.header_bytes = h.version == 1 ? 348 : 540;
  if (size < h.header_bytes)
    fail(path, "truncated NIfTI-" + std::to_string(h.version) + " header: the file ends after " +
                   std::to_string(size) + " of its " + std::to_string(h.header_bytes) + " bytes");

  const unsigned char* magic = b + (h.version == 1 ? offsetof(nifti_1_header, magic) : offsetof(nifti_2_header, magic));
  const char* single = h.version == 1 ? "n+1" : "n+2";
  const char* pair = h.version == 1 ? "ni1" : "ni2";
  if (std::memcmp(magic, single, 4) == 0) {
    h.separate_image = false;
  } else if (std::memcmp(magic, pair, 4) == 0) {
    h.separate_image = true;
  } else {
    fail(path, "not a NIfTI-" + std::to_string(h.version) + " file: magic is \"" + printable(magic, 4) +
                   "\" (expected \"" + single + "\" or \"" + pair + "\")");
  }

  int64_t vox_offset = 0;
  if (h.version == 1) {
    readFields<nifti_1_header, int16_t, float, int16_t>(b, h.swap, h);
    const double v = field<float>(b, offsetof(nifti_1_header, vox_offset), h.swap);
    if (!(v >= 0 && v < 1e15 && v == std::floor(v)))
      fail(path, "vox_offset " + number(v) + " is not a byte offset");
    vox_offset = int64_t(v);
  } else {
    readFields<nifti_2_header, int64_t, double, int32_t>(b, h.swap, h);
    vox_offset = field<int64_t>(b, offsetof(nifti_2_header, vox_offset), h.swap);
    if (vox_offset < 0) fail(path, "vox_offset " + std::to_string(vox_offset) + " is negative");
  }
  // The spec's minimum for one-file images: the header and the 4-byte
  // extension flag come first.
  const int64_t first = h.separate_image ? 0 : int64_t(h.header_bytes) + 4;
  if (vox_offset < first)
    fail(path, "vox_offset " + std::to_string(vox_offset) + " is inside the header (the voxels of a single-file NIfTI-" +
                   std::to_string(h.version) + " start at byte " + std::to_string(first) + " or later)");
  h.vox_offset = vox_offset;

  h.bytes_per_voxel = bytesPerVoxel(h.datatype);
  if (h.bytes_per_voxel == 0)
    fail(path, "unsupported datatype " + niftiDatatypeName(h.datatype) +
                   " (fibscope reads uint8, int8, int16, uint16, int32, uint32, int64, uint64, float32 and float64)");

  h.ndim = int(h.dim[0]);
  if (h.dim[0] < 1 || h.dim[0] > 7)
    fail(path, "dim[0] is " + std::to_string(h.dim[0]) + " (expected 1 to 7 dimensions)");
  for (int i = 1; i <= 7; ++i) {
    if (i > h.ndim) {
      h.dim[i] = 1;
      continue;
    }
    if (h.dim[i] < 1) fail(path, "dim[" + std::to_string(i) + "] is " + std::to_string(h.dim[i]) + " (must be >= 1)");
    if (h.dim[i] > kNiftiMaxDim)
      fail(path, "absurd dimensions: dim[" + std::to_string(i) + "] is " + std::to_string(h.dim[i]) + " (at most " +
                     std::to_string(kNiftiMaxDim) + ")");
  }
  // Each dim is <= 2^24: a volume fits 72 bits only in theory, so test the
  // partial products (2^48 at most) before multiplying on.
  const uint64_t plane = uint64_t(h.dim[1]) * uint64_t(h.dim[2]);
  if (plane > kNiftiMaxVolumeVoxels || plane * uint64_t(h.dim[3]) > kNiftiMaxVolumeVoxels)
    fail(path, "absurd dimensions " + std::to_string(h.dim[1]) + " x " + std::to_string(h.dim[2]) + " x " +
                   std::to_string(h.dim[3]) + " (more than " + std::to_string(kNiftiMaxVolumeVoxels) +
                   " voxels in a volume)");
  uint64_t volumes = 1;
  for (int i = 4; i <= 7; ++i) {
    volumes *= uint64_t(h.dim[i]);
    if (volumes > kNiftiMaxVolumes)
      fail(path, "absurd dimensions: more than " + std::to_string(kNiftiMaxVolumes) + " volumes");
  }

  for (int i = 1; i <= 3; ++i)
    if (!std::isfinite(h.pixdim[i])) fail(path, "pixdim[" + std::to_string(i) + "] is not finite");
  if (h.scaled() && !std::isfinite(h.scl_inter))
    fail(path, "scl_inter is not finite while scl_slope " + number(h.scl_slope) + " is in use");
  return h;
}

glm::dmat4 niftiAffine(const std::string& path, const NiftiHeader& h, std::string* source) {
  glm::dmat4 a(1.0);  // column-major: a[column][row]
  std::string from;
  // nibabel takes |pixdim| (its header check fixes negative ones on load).
  const double zoom[3] = {std::fabs(h.pixdim[1]), std::fabs(h.pixdim[2]), std::fabs(h.pixdim[3])};
  if (h.sform_code != 0) {
    from = "sform";
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) a[c][r] = h.srow[r][c];
  } else if (h.qform_code != 0) {
    from = "qform";
    const double x = h.quatern[0], y = h.quatern[1], z = h.quatern[2];
    // nibabel's fillpositive: w from the unit norm, in the widest float;
    // a slightly negative w² (rounding of the stored b, c, d) is 0.
    const long double w2 = 1.0L - ((long double)x * x + (long double)y * y + (long double)z * z);
    const double threshold = 3 * (h.version == 1 ? double(std::numeric_limits<float>::epsilon())
                                                 : std::numeric_limits<double>::epsilon());
    if (!std::isfinite(double(w2))) fail(path, "the qform quaternion is not finite");
    if (w2 < -threshold) fail(path, "the qform quaternion (b, c, d) has a norm above 1");
    const double w = w2 < 0 ? 0.0 : double(std::sqrt(w2));
    const glm::dmat3 rotation = quaternionMatrix(w, x, y, z);
    const double qfac = h.pixdim[0] == -1.0 ? -1.0 : 1.0;
    const double scale[3] = {zoom[0], zoom[1], zoom[2] * qfac};
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) a[c][r] = rotation[c][r] * scale[c];
    a[3] = {h.qoffset[0], h.qoffset[1], h.qoffset[2], 1.0};
  } else {
    from = "pixdim";
    // nibabel's shape_zoom_affine(x_flip=True): an image of fewer than three
    // dimensions gets size 1 and zoom 1 on the missing axes.
    for (int i = 0; i < 3; ++i) {
      const bool used = i < h.ndim;
      const double n = used ? double(h.dim[i + 1]) : 1.0;
      const double zi = (used ? zoom[i] : 1.0) * (i == 0 ? -1.0 : 1.0);
      a[i][i] = zi;
      a[3][i] = -((n - 1) / 2.0) * zi;
    }
  }
  if (source) *source = from;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r)
      if (!std::isfinite(a[c][r])) fail(path, "the " + from + " affine is not finite");
  const glm::dmat3 linear(a);
  const double n0 = glm::length(linear[0]), n1 = glm::length(linear[1]), n2 = glm::length(linear[2]);
  const double det = glm::determinant(linear);
  // Relative to the column lengths, so that the test does not depend on
  // the voxel size: |det| / (n0 n1 n2) is the volume of the unit cell
  // spanned by the column directions (1 for orthogonal axes).
  if (!(n0 > 0 && n1 > 0 && n2 > 0) || !(std::fabs(det) > 1e-9 * n0 * n1 * n2))
    fail(path, "the " + from + " affine is singular (voxel axes of lengths " + number(n0) + ", " + number(n1) + ", " +
                   number(n2) + " mm, determinant " + number(det) + ")");
  return a;
}

}  // namespace fibscope
