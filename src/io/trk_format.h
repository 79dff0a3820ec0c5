// TrackVis .trk format: the 1000-byte header, nibabel-style data names and
// the voxmm <-> RAS+ mm affine.
//
// Layout (http://trackvis.org/docs/?subsect=fileformat, versions 1 and 2):
// a 1000-byte header, then per streamline an int32 point count m, m points
// of (x, y, z, scalars...) as float32 and n_properties float32. Points are
// in "voxmm": voxel indices times voxel size, with (0,0,0) at the corner of
// the first voxel, in the axis order named by `voxel_order`. The byte order
// of the whole file is the one in which hdr_size reads 1000.
//
// The conversion to RAS+ mm follows nibabel's get_affine_trackvis_to_rasmm
// (nibabel/streamlines/trk.py) so that fibscope and nibabel agree on every
// file: divide by the voxel size, shift by half a voxel (voxel centres),
// re-orient from the header's voxel_order to the axis order implied by
// vox_to_ras, then apply vox_to_ras.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace fibscope {

constexpr size_t kTrkHeaderBytes = 1000;
constexpr int kTrkMaxNames = 10;        // named scalars / properties
constexpr size_t kTrkNameBytes = 20;    // each name field, NUL padded

// Byte offsets of the header fields (TrackVis spec; nibabel header_2_dtd).
namespace trk_field {
constexpr size_t kIdString = 0;          // char[6] "TRACK\0"
constexpr size_t kDimensions = 6;        // int16[3]
constexpr size_t kVoxelSize = 12;        // float[3]
constexpr size_t kOrigin = 24;           // float[3]
constexpr size_t kScalarCount = 36;      // int16
constexpr size_t kScalarNames = 38;      // char[10][20]
constexpr size_t kPropertyCount = 238;   // int16
constexpr size_t kPropertyNames = 240;   // char[10][20]
constexpr size_t kVoxToRas = 440;        // float[4][4], row-major; v2 only
constexpr size_t kReserved = 504;        // char[444]
constexpr size_t kVoxelOrder = 948;      // char[4]
constexpr size_t kPad2 = 952;            // char[4]
constexpr size_t kImageOrientation = 956;  // float[6]
constexpr size_t kPad1 = 980;            // char[2]
constexpr size_t kInvertSwap = 982;      // invert_x, invert_y, invert_z, swap_xy, swap_yz, swap_zx (1 byte each)
constexpr size_t kCount = 988;           // int32 n_count (0: unknown)
constexpr size_t kVersion = 992;         // int32
constexpr size_t kHeaderSize = 996;      // int32, always 1000
}  // namespace trk_field

// The header as stored, fields in host byte order.
struct TrkHeader {
  std::array<int16_t, 3> dimensions = {1, 1, 1};
  std::array<float, 3> voxel_sizes = {1, 1, 1};
  std::array<float, 3> origin = {0, 0, 0};
  int16_t n_scalars = 0;
  std::array<std::array<char, kTrkNameBytes>, kTrkMaxNames> scalar_names{};
  int16_t n_properties = 0;
  std::array<std::array<char, kTrkNameBytes>, kTrkMaxNames> property_names{};
  std::array<float, 16> vox_to_ras = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // row-major
  std::array<char, 4> voxel_order = {'R', 'A', 'S', 0};
  std::array<float, 6> image_orientation_patient = {0, 0, 0, 0, 0, 0};
  std::array<uint8_t, 6> invert_swap = {0, 0, 0, 0, 0, 0};  // invert_x..z, swap_xy, swap_yz, swap_zx
  int32_t n_count = 0;
  int32_t version = 2;
  bool big_endian = false;  // byte order of the file it came from
};

// Parses the first kTrkHeaderBytes of `bytes` (size >= kTrkHeaderBytes is
// checked). Throws Error naming `path` for a wrong magic string, a hdr_size
// that is 1000 in neither byte order, an unsupported version or negative
// scalar / property counts. Safe on untrusted input.
TrkHeader parseTrkHeader(const uint8_t* bytes, size_t size, const std::string& path);

// Writes `header` as kTrkHeaderBytes little-endian bytes (hdr_size 1000).
void serializeTrkHeader(const TrkHeader& header, uint8_t* out);

// One named run of scalar or property components.
struct TrkNamedRun {
  std::string name;         // UTF-8
  uint32_t first = 0;       // first component within the scalars / properties of a point / streamline
  uint32_t components = 1;
};

// Splits `count` components into named runs using nibabel's convention: a
// name field "fa" names one component, "dir\0003" (name, NUL, decimal count)
// names three; an all-NUL field names none. Components left without a name
// form one run named "<unnamed_prefix>_<its first component>". Names that
// lie (more components than `count`, malformed counts, duplicates) are
// repaired and reported through `warnings`. Names are latin-1 in the file.
std::vector<TrkNamedRun> decodeTrkNames(const std::array<std::array<char, kTrkNameBytes>, kTrkMaxNames>& fields,
                                        int count, const std::string& unnamed_prefix, const std::string& what,
                                        std::vector<std::string>& warnings);

// Encodes `name` with `components` nibabel-style into a 20-byte field.
// Returns false (and shortens the name to fit) when the name was too long.
bool encodeTrkName(const std::string& name, uint32_t components, std::array<char, kTrkNameBytes>& field);

// The voxel grid that defines voxmm: what TrkHeader says, after nibabel's
// fallbacks (identity when vox_to_ras is not recorded, LPS when voxel_order
// is empty).
struct TrkGrid {
  std::array<float, 16> vox_to_ras = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::array<int16_t, 3> dimensions = {1, 1, 1};
  std::array<float, 3> voxel_sizes = {1, 1, 1};
  std::string voxel_order = "RAS";  // three letters from LR, PA, IS
};

// Row-major 4x4 affine in double precision.
using Affine4 = std::array<double, 16>;

// Resolves the grid of a parsed header: version 1 or vox_to_ras[3][3] == 0
// -> identity, empty voxel_order -> "LPS" (TrackVis' default), each with a
// warning as nibabel gives; a voxel_order that is not three distinct axis
// letters -> the affine's own order, with a warning; zero or non-finite
// voxel sizes -> 1 mm, with a warning. Throws Error (naming `path`) when
// vox_to_ras is non-finite or singular (no axis directions).
TrkGrid resolveTrkGrid(const TrkHeader& header, const std::string& path, std::vector<std::string>& warnings);

// True for three distinct axis letters, one from each of LR, PA, IS ("LPS").
bool validTrkVoxelOrder(const std::string& codes);

// Axis codes of the voxel axes of a 4x4 row-major affine ("RAS", "LPS", ...),
// as nibabel.orientations.aff2axcodes; "" when the linear part is singular
// or not finite.
std::string affineAxisCodes(const std::array<float, 16>& affine);

// The affine from voxmm to RAS+ mm, as nibabel's get_affine_trackvis_to_rasmm
// (entries rounded to float32 like nibabel's result). `grid` must have a
// valid voxel_order and non-singular vox_to_ras (resolveTrkGrid ensures it).
Affine4 trkVoxmmToRasmm(const TrkGrid& grid);

// Inverse of an invertible affine (general 4x4, Gauss-Jordan with pivoting).
Affine4 invertAffine(const Affine4& a);

// Header fields kept in TractogramHeader::properties for round trips, as
// "trk.<field>" keys with space-separated values (floats to 9 digits, exact).
std::vector<std::pair<std::string, std::string>> trkProperties(const TrkHeader& header, const TrkGrid& grid);

// Reads back a grid stored by trkProperties ("trk.vox_to_ras",
// "trk.dimensions", "trk.voxel_sizes", "trk.voxel_order"); false when any is
// missing or malformed.
bool trkGridFromProperties(const std::vector<std::pair<std::string, std::string>>& properties, TrkGrid& grid);

// Conversions between latin-1 (trk names) and UTF-8 (fibscope names).
std::string latin1ToUtf8(const std::string& latin1);
std::string utf8ToLatin1(const std::string& utf8);  // characters beyond U+00FF become '?'

}  // namespace fibscope
