#include "io/trk_format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <unordered_set>

#include "core/byte_order.h"
#include "core/error.h"

namespace fibscope {
namespace {

using Matrix3 = std::array<std::array<double, 3>, 3>;

// Printable rendering of raw header bytes for error messages.
std::string printable(const uint8_t* p, size_t n) {
  std::string s;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = p[i];
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      s += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      s += buf;
    }
  }
  return s;
}

double determinant(const Matrix3& m) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// Inverse transpose of a non-singular 3x3 matrix (cofactors / determinant).
Matrix3 inverseTranspose(const Matrix3& m) {
  const double det = determinant(m);
  Matrix3 c;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      c[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / det;
    }
  return c;
}

// Orthogonal factor of the polar decomposition (Newton's iteration
// X <- (X + X^-T) / 2, quadratic convergence for non-singular X). nibabel
// gets the same matrix from an SVD (io_orientation: R = P Qs).
Matrix3 polarRotation(Matrix3 x) {
  for (int iteration = 0; iteration < 100; ++iteration) {
    const Matrix3 it = inverseTranspose(x);
    double change = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double next = 0.5 * (x[i][j] + it[i][j]);
        change = std::max(change, std::fabs(next - x[i][j]));
        x[i][j] = next;
      }
    if (change < 1e-15) break;
  }
  return x;
}

// (output axis 0..2 = R/A/S, +1 or -1) for one axis letter; axis -1 if invalid.
std::pair<int, int> axisOfCode(char code) {
  switch (code) {
    case 'R': return {0, 1};
    case 'L': return {0, -1};
    case 'A': return {1, 1};
    case 'P': return {1, -1};
    case 'S': return {2, 1};
    case 'I': return {2, -1};
    default: return {-1, 0};
  }
}

}  // namespace

bool validTrkVoxelOrder(const std::string& codes) {
  if (codes.size() != 3) return false;
  bool seen[3] = {false, false, false};
  for (char c : codes) {
    const int axis = axisOfCode(c).first;
    if (axis < 0 || seen[axis]) return false;
    seen[axis] = true;
  }
  return true;
}

namespace {

std::string formatFloats(const float* v, size_t n) {
  std::string s;
  for (size_t i = 0; i < n; ++i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v[i]));
    if (i) s += ' ';
    s += buf;
  }
  return s;
}

template <typename T>
bool parseNumbers(const std::string& text, T* out, size_t n) {
  const char* p = text.data();
  const char* end = p + text.size();
  for (size_t i = 0; i < n; ++i) {
    while (p < end && *p == ' ') ++p;
    const auto [next, ec] = std::from_chars(p, end, out[i]);
    if (ec != std::errc()) return false;
    p = next;
  }
  while (p < end && *p == ' ') ++p;
  return p == end;
}

std::string trimmedField(const char* p, size_t n) {
  std::string s(p, n);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

}  // namespace

TrkHeader parseTrkHeader(const uint8_t* bytes, size_t size, const std::string& path) {
  namespace f = trk_field;
  if (size < kTrkHeaderBytes)
    fail(path, "file is " + std::to_string(size) + " bytes, shorter than the " + std::to_string(kTrkHeaderBytes) +
                   "-byte trk header");
  if (std::memcmp(bytes, "TRACK", 5) != 0)
    failAt(path, 0, "expected the trk magic 'TRACK', found '" + printable(bytes, 6) + "'");

  // hdr_size is 1000 in the file's byte order; that is how the order is told.
  const int32_t size_native = loadUnaligned<int32_t>(bytes + f::kHeaderSize);
  bool swap = false;
  if (size_native != int32_t(kTrkHeaderBytes)) {
    if (loadUnaligned<int32_t>(bytes + f::kHeaderSize, true) != int32_t(kTrkHeaderBytes))
      failAt(path, f::kHeaderSize,
             "hdr_size is " + std::to_string(size_native) + " (byte-swapped " +
                 std::to_string(loadUnaligned<int32_t>(bytes + f::kHeaderSize, true)) + "), expected 1000");
    swap = true;
  }

  TrkHeader h;
  h.big_endian = swap == kHostIsLittleEndian;
  for (int k = 0; k < 3; ++k) {
    h.dimensions[k] = loadUnaligned<int16_t>(bytes + f::kDimensions + 2 * k, swap);
    h.voxel_sizes[k] = loadUnaligned<float>(bytes + f::kVoxelSize + 4 * k, swap);
    h.origin[k] = loadUnaligned<float>(bytes + f::kOrigin + 4 * k, swap);
  }
  h.n_scalars = loadUnaligned<int16_t>(bytes + f::kScalarCount, swap);
  h.n_properties = loadUnaligned<int16_t>(bytes + f::kPropertyCount, swap);
  for (int i = 0; i < kTrkMaxNames; ++i) {
    std::memcpy(h.scalar_names[i].data(), bytes + f::kScalarNames + kTrkNameBytes * i, kTrkNameBytes);
    std::memcpy(h.property_names[i].data(), bytes + f::kPropertyNames + kTrkNameBytes * i, kTrkNameBytes);
  }
  for (int i = 0; i < 16; ++i) h.vox_to_ras[i] = loadUnaligned<float>(bytes + f::kVoxToRas + 4 * i, swap);
  std::memcpy(h.voxel_order.data(), bytes + f::kVoxelOrder, 4);
  for (int i = 0; i < 6; ++i)
    h.image_orientation_patient[i] = loadUnaligned<float>(bytes + f::kImageOrientation + 4 * i, swap);
  std::memcpy(h.invert_swap.data(), bytes + f::kInvertSwap, 6);
  h.n_count = loadUnaligned<int32_t>(bytes + f::kCount, swap);
  h.version = loadUnaligned<int32_t>(bytes + f::kVersion, swap);

  // nibabel reads version 3 as version 2 (with a warning, see resolveTrkGrid).
  if (h.version < 1 || h.version > 3)
    failAt(path, f::kVersion, "unsupported trk version " + std::to_string(h.version) + " (expected 1 or 2)");
  if (h.n_scalars < 0)
    failAt(path, f::kScalarCount, "n_scalars is " + std::to_string(h.n_scalars) + ", expected >= 0");
  if (h.n_properties < 0)
    failAt(path, f::kPropertyCount, "n_properties is " + std::to_string(h.n_properties) + ", expected >= 0");
  if (h.n_count < 0) failAt(path, f::kCount, "n_count is " + std::to_string(h.n_count) + ", expected >= 0");
  return h;
}

void serializeTrkHeader(const TrkHeader& h, uint8_t* out) {
  namespace f = trk_field;
  constexpr bool swap = !kHostIsLittleEndian;  // trk files are written little-endian, as nibabel does
  std::memset(out, 0, kTrkHeaderBytes);
  std::memcpy(out + f::kIdString, "TRACK", 6);
  for (int k = 0; k < 3; ++k) {
    storeUnaligned<int16_t>(out + f::kDimensions + 2 * k, h.dimensions[k], swap);
    storeUnaligned<float>(out + f::kVoxelSize + 4 * k, h.voxel_sizes[k], swap);
    storeUnaligned<float>(out + f::kOrigin + 4 * k, h.origin[k], swap);
  }
  storeUnaligned<int16_t>(out + f::kScalarCount, h.n_scalars, swap);
  storeUnaligned<int16_t>(out + f::kPropertyCount, h.n_properties, swap);
  for (int i = 0; i < kTrkMaxNames; ++i) {
    std::memcpy(out + f::kScalarNames + kTrkNameBytes * i, h.scalar_names[i].data(), kTrkNameBytes);
    std::memcpy(out + f::kPropertyNames + kTrkNameBytes * i, h.property_names[i].data(), kTrkNameBytes);
  }
  for (int i = 0; i < 16; ++i) storeUnaligned<float>(out + f::kVoxToRas + 4 * i, h.vox_to_ras[i], swap);
  std::memcpy(out + f::kVoxelOrder, h.voxel_order.data(), 4);
  for (int i = 0; i < 6; ++i)
    storeUnaligned<float>(out + f::kImageOrientation + 4 * i, h.image_orientation_patient[i], swap);
  std::memcpy(out + f::kInvertSwap, h.invert_swap.data(), 6);
  storeUnaligned<int32_t>(out + f::kCount, h.n_count, swap);
  storeUnaligned<int32_t>(out + f::kVersion, h.version, swap);
  storeUnaligned<int32_t>(out + f::kHeaderSize, int32_t(kTrkHeaderBytes), swap);
}

std::vector<TrkNamedRun> decodeTrkNames(const std::array<std::array<char, kTrkNameBytes>, kTrkMaxNames>& fields,
                                        int count, const std::string& unnamed_prefix, const std::string& what,
                                        std::vector<std::string>& warnings) {
  std::vector<TrkNamedRun> runs;
  if (count <= 0) return runs;
  uint32_t next = 0;
  for (int i = 0; i < kTrkMaxNames; ++i) {
    // nibabel: strip trailing NULs; "" names nothing; "name" one component;
    // "name\0N" N components.
    const std::string raw = trimmedField(fields[i].data(), kTrkNameBytes);
    if (raw.empty()) continue;
    std::vector<std::string> parts;
    size_t start = 0;
    for (;;) {
      const size_t nul = raw.find('\0', start);
      parts.push_back(raw.substr(start, nul == std::string::npos ? std::string::npos : nul - start));
      if (nul == std::string::npos) break;
      start = nul + 1;
    }
    TrkNamedRun run;
    run.name = latin1ToUtf8(parts[0]);
    int64_t components = 1;
    if (parts.size() >= 2) {
      const std::string& digits = parts.back();
      int64_t value = 0;
      const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
      if (parts.size() > 2 || ec != std::errc() || end != digits.data() + digits.size()) {
        warnings.push_back(what + " name " + std::to_string(i) + " ('" + run.name +
                           "') has malformed text after its NUL; taking it as one component");
      } else {
        components = value;
      }
    }
    if (components <= 0) continue;  // "name\0" "0": nibabel skips it too
    if (next >= uint32_t(count)) {
      warnings.push_back(what + " name '" + run.name + "' lies beyond the " + std::to_string(count) +
                         " declared components; ignored");
      continue;
    }
    if (components > int64_t(count) - next) {
      warnings.push_back(what + " name '" + run.name + "' claims " + std::to_string(components) +
                         " components but only " + std::to_string(count - int64_t(next)) + " remain; clipped");
      components = int64_t(count) - next;
    }
    run.first = next;
    run.components = static_cast<uint32_t>(components);
    next += run.components;
    runs.push_back(std::move(run));
  }
  // Components without a name (n_scalars larger than the names account for)
  // form one array, as nibabel does ("scalars" there, "scalar_<first>" here):
  // the number of arrays stays bounded whatever the count says.
  if (next < uint32_t(count))
    runs.push_back({unnamed_prefix + "_" + std::to_string(next), next, uint32_t(count) - next});

  // Empty and duplicate names would be ambiguous downstream.
  std::unordered_set<std::string> used;
  for (TrkNamedRun& run : runs) {
    if (run.name.empty()) run.name = unnamed_prefix + "_" + std::to_string(run.first);
    if (used.count(run.name)) {
      std::string renamed = run.name + "_" + std::to_string(run.first);
      while (used.count(renamed)) renamed += "_";
      warnings.push_back(what + " name '" + run.name + "' appears twice; the second is read as '" + renamed + "'");
      run.name = renamed;
    }
    used.insert(run.name);
  }
  return runs;
}

bool encodeTrkName(const std::string& name, uint32_t components, std::array<char, kTrkNameBytes>& field) {
  field.fill('\0');
  std::string latin = utf8ToLatin1(name);
  latin.erase(std::remove(latin.begin(), latin.end(), '\0'), latin.end());
  const std::string suffix = components > 1 ? std::string(1, '\0') + std::to_string(components) : std::string();
  bool fits = true;
  // The field needs no terminating NUL when full (nibabel strips only padding).
  if (latin.size() + suffix.size() > kTrkNameBytes) {
    latin.resize(kTrkNameBytes - suffix.size());
    fits = false;
  }
  const std::string encoded = latin + suffix;
  std::memcpy(field.data(), encoded.data(), encoded.size());
  return fits;
}

std::string affineAxisCodes(const std::array<float, 16>& affine) {
  // nibabel io_orientation: normalise the columns of the linear part, take
  // the nearest orthogonal matrix, then give each voxel axis the world axis
  // it moves along most, removing taken world axes as it goes.
  Matrix3 rs;
  for (int j = 0; j < 3; ++j) {
    double norm = 0;
    for (int i = 0; i < 3; ++i) {
      const double v = affine[4 * i + j];
      if (!std::isfinite(v)) return {};
      norm += v * v;
    }
    norm = std::sqrt(norm);
    if (norm == 0) norm = 1;
    for (int i = 0; i < 3; ++i) rs[i][j] = affine[4 * i + j] / norm;
  }
  // Unit columns bound |det| by 1; below 1e-6 the axes are (nearly) coplanar
  // and nibabel's SVD drops a direction, leaving an axis without a code.
  if (!(std::fabs(determinant(rs)) >= 1e-6)) return {};
  Matrix3 r = polarRotation(rs);
  std::string codes;
  for (int in_axis = 0; in_axis < 3; ++in_axis) {
    int out_axis = -1;
    double best = 1e-8;  // np.allclose(col, 0)
    for (int i = 0; i < 3; ++i)
      if (std::fabs(r[i][in_axis]) > best) {
        best = std::fabs(r[i][in_axis]);
        out_axis = i;
      }
    if (out_axis < 0) return {};
    const bool positive = r[out_axis][in_axis] > 0;
    codes += positive ? "RAS"[out_axis] : "LPI"[out_axis];
    for (int j = 0; j < 3; ++j) r[out_axis][j] = 0;
  }
  return codes;
}

TrkGrid resolveTrkGrid(const TrkHeader& h, const std::string& path, std::vector<std::string>& warnings) {
  TrkGrid g;
  g.dimensions = h.dimensions;
  if (h.version == 3) warnings.push_back("trk version 3 is read as version 2");

  if (h.version == 1) {
    warnings.push_back("trk version 1 has no vox_to_ras; assuming the identity (voxmm scaled by voxel size only)");
  } else if (h.vox_to_ras[15] == 0) {
    warnings.push_back("vox_to_ras is not recorded (element [3][3] is 0); assuming the identity");
  } else {
    for (int i = 0; i < 16; ++i)
      if (!std::isfinite(h.vox_to_ras[i]))
        failAt(path, trk_field::kVoxToRas + 4 * i, "vox_to_ras element [" + std::to_string(i / 4) + "][" +
                                                      std::to_string(i % 4) + "] is not finite");
    g.vox_to_ras = h.vox_to_ras;
  }
  const std::string affine_codes = affineAxisCodes(g.vox_to_ras);
  if (affine_codes.empty())
    failAt(path, trk_field::kVoxToRas, "vox_to_ras is singular: its voxel axes have no RAS directions");

  for (int k = 0; k < 3; ++k) {
    g.voxel_sizes[k] = h.voxel_sizes[k];
    if (!std::isfinite(h.voxel_sizes[k]) || h.voxel_sizes[k] == 0) {
      warnings.push_back("voxel size " + std::to_string(k) + " is " + formatFloats(&h.voxel_sizes[k], 1) +
                         "; assuming 1 mm");
      g.voxel_sizes[k] = 1;
    }
  }

  std::string order = trimmedField(h.voxel_order.data(), 4);
  for (char& c : order) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (order.empty()) {
    warnings.push_back("voxel_order is empty; assuming LPS (TrackVis' default)");
    order = "LPS";
  } else if (!validTrkVoxelOrder(order)) {
    warnings.push_back("voxel_order '" + printable(reinterpret_cast<const uint8_t*>(order.data()), order.size()) +
                       "' is not three distinct axis letters; using vox_to_ras' own order " + affine_codes);
    order = affine_codes;
  }
  g.voxel_order = order;
  return g;
}

Affine4 trkVoxmmToRasmm(const TrkGrid& g) {
  // Steps as in nibabel get_affine_trackvis_to_rasmm, right to left:
  // A = vox_to_ras * M (re-orientation) * shift(-0.5) * scale(1 / voxel size).
  const std::string affine_codes = affineAxisCodes(g.vox_to_ras);
  std::array<std::pair<int, int>, 3> header_ornt, affine_ornt;
  for (int i = 0; i < 3; ++i) {
    header_ornt[i] = axisOfCode(g.voxel_order.size() == 3 ? g.voxel_order[i] : "RAS"[i]);
    affine_ornt[i] = axisOfCode(affine_codes.size() == 3 ? affine_codes[i] : "RAS"[i]);
  }
  // ornt_transform(header, affine): header axis i becomes affine axis j
  // (same world axis), flipped when the two directions differ; a flipped
  // axis maps index x to (dim - 1) - x (inv_ornt_aff).
  double m[3][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      if (header_ornt[i].first == affine_ornt[j].first) {
        const double flip = header_ornt[i].second == affine_ornt[j].second ? 1.0 : -1.0;
        m[i][j] = flip;
        m[i][3] = flip < 0 ? double(g.dimensions[i]) - 1.0 : 0.0;
        break;
      }
  // M * shift * scale: column j of the linear part is M[:, j] / size_j, the
  // translation is M[:, 3] - 0.5 * sum_j M[:, j].
  double inner[3][4];
  for (int i = 0; i < 3; ++i) {
    inner[i][3] = m[i][3];
    for (int j = 0; j < 3; ++j) {
      inner[i][j] = m[i][j] / double(g.voxel_sizes[j]);
      inner[i][3] -= 0.5 * m[i][j];
    }
  }
  Affine4 a{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) {
      double v = j == 3 ? double(g.vox_to_ras[4 * i + 3]) : 0.0;
      for (int k = 0; k < 3; ++k) v += double(g.vox_to_ras[4 * i + k]) * inner[k][j];
      a[4 * i + j] = static_cast<double>(static_cast<float>(v));  // nibabel returns float32
    }
  // Row 3 of vox_to_ras is (0 0 0 1) in any valid file; nibabel keeps what is there.
  for (int j = 0; j < 4; ++j) {
    double v = j == 3 ? double(g.vox_to_ras[15]) : 0.0;
    for (int k = 0; k < 3; ++k) v += double(g.vox_to_ras[12 + k]) * inner[k][j];
    a[12 + j] = static_cast<double>(static_cast<float>(v));
  }
  return a;
}

Affine4 invertAffine(const Affine4& a) {
  double m[4][8];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 8; ++j) m[i][j] = j < 4 ? a[4 * i + j] : (j - 4 == i ? 1.0 : 0.0);
  for (int col = 0; col < 4; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 4; ++r)
      if (std::fabs(m[r][col]) > std::fabs(m[pivot][col])) pivot = r;
    if (pivot != col)
      for (int j = 0; j < 8; ++j) std::swap(m[pivot][j], m[col][j]);
    const double p = m[col][col];
    for (int j = 0; j < 8; ++j) m[col][j] /= p;
    for (int r = 0; r < 4; ++r)
      if (r != col && m[r][col] != 0) {
        const double factor = m[r][col];
        for (int j = 0; j < 8; ++j) m[r][j] -= factor * m[col][j];
      }
  }
  Affine4 inv;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) inv[4 * i + j] = m[i][4 + j];
  return inv;
}

std::vector<std::pair<std::string, std::string>> trkProperties(const TrkHeader& h, const TrkGrid& g) {
  std::vector<std::pair<std::string, std::string>> p;
  const std::array<float, 3> dims = {float(g.dimensions[0]), float(g.dimensions[1]), float(g.dimensions[2])};
  p.emplace_back("trk.version", std::to_string(h.version));
  p.emplace_back("trk.byte_order", h.big_endian ? "big" : "little");
  p.emplace_back("trk.dimensions", formatFloats(dims.data(), 3));
  p.emplace_back("trk.voxel_sizes", formatFloats(g.voxel_sizes.data(), 3));
  p.emplace_back("trk.vox_to_ras", formatFloats(g.vox_to_ras.data(), 16));
  p.emplace_back("trk.voxel_order", g.voxel_order);
  p.emplace_back("trk.origin", formatFloats(h.origin.data(), 3));
  p.emplace_back("trk.image_orientation_patient", formatFloats(h.image_orientation_patient.data(), 6));
  static const char* kFlagNames[6] = {"invert_x", "invert_y", "invert_z", "swap_xy", "swap_yz", "swap_zx"};
  for (int i = 0; i < 6; ++i) p.emplace_back(std::string("trk.") + kFlagNames[i], std::to_string(h.invert_swap[i]));
  return p;
}

bool trkGridFromProperties(const std::vector<std::pair<std::string, std::string>>& properties, TrkGrid& grid) {
  auto find = [&](const char* key) -> const std::string* {
    for (const auto& [k, v] : properties)
      if (k == key) return &v;
    return nullptr;
  };
  const std::string* dims = find("trk.dimensions");
  const std::string* sizes = find("trk.voxel_sizes");
  const std::string* affine = find("trk.vox_to_ras");
  const std::string* order = find("trk.voxel_order");
  if (!dims || !sizes || !affine || !order) return false;
  TrkGrid g;
  int d[3];
  if (!parseNumbers(*dims, d, 3) || !parseNumbers(*sizes, g.voxel_sizes.data(), 3) ||
      !parseNumbers(*affine, g.vox_to_ras.data(), 16))
    return false;
  for (int k = 0; k < 3; ++k) {
    if (d[k] < -32768 || d[k] > 32767 || !std::isfinite(g.voxel_sizes[k]) || g.voxel_sizes[k] == 0) return false;
    g.dimensions[k] = static_cast<int16_t>(d[k]);
  }
  g.voxel_order = *order;
  if (!validTrkVoxelOrder(g.voxel_order) || affineAxisCodes(g.vox_to_ras).empty()) return false;
  grid = g;
  return true;
}

std::string latin1ToUtf8(const std::string& latin1) {
  std::string out;
  out.reserve(latin1.size());
  for (unsigned char c : latin1) {
    if (c < 0x80) {
      out += static_cast<char>(c);
    } else {
      out += static_cast<char>(0xC0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  return out;
}

std::string utf8ToLatin1(const std::string& utf8) {
  std::string out;
  for (size_t i = 0; i < utf8.size();) {
    const unsigned char c = utf8[i];
    if (c < 0x80) {
      out += static_cast<char>(c);
      ++i;
      continue;
    }
    // Length of the sequence from its lead byte; invalid leads count as one byte.
    const size_t length = (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 1;
    bool valid = length > 1 && i + length <= utf8.size();
    for (size_t k = 1; valid && k < length; ++k) valid = (static_cast<unsigned char>(utf8[i + k]) & 0xC0) == 0x80;
    if (valid && length == 2 && c >= 0xC2 && c <= 0xC3) {
      out += static_cast<char>(((c & 0x1F) << 6) | (static_cast<unsigned char>(utf8[i + 1]) & 0x3F));
    } else {
      out += '?';
    }
    i += valid ? length : 1;
  }
  return out;
}

}  // namespace fibscope
