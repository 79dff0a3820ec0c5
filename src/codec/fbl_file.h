// The .fbl container: a versioned header and named, checksummed,
// 64-byte-aligned sections (layout in codec/fbl_format.h and
// docs/FBL_FORMAT.md).
//
// The container knows nothing of the fiblet encoding: the codec stores its
// parameters in FblHeaderFields and its arrays as opaque typed sections.
// Standard section names (kFblSection*) are listed here so that writer and
// viewer agree on them.
//
// FblWriter streams: a section is appended chunk by chunk, its checksum
// computed on the fly, so a 100 GB fiblet section never sits in memory. The
// file is written under a temporary name, fsynced and renamed on finish();
// an exception or an abandoned writer leaves nothing behind.
//
// FblFile maps the file read-only. open() validates the header and the
// section table completely (safe on untrusted input); each section's
// checksum is verified on its first data() access or by verify(). Every
// problem is a one-line fibscope::Error naming the path, and the section
// and byte offset where there is one.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/mapped_file.h"
#include "core/output_file.h"

namespace fibscope {

// Element types of a section (values are the on-disk codes).
enum class FblDType : uint32_t {
  kUint8 = 1,
  kUint16 = 2,
  kUint32 = 3,
  kUint64 = 4,
  kInt8 = 5,
  kInt16 = 6,
  kInt32 = 7,
  kInt64 = 8,
  kFloat32 = 9,
  kFloat64 = 10,
  kUtf8 = 11,  // text, one byte per element, no terminator
};

// Bytes of one component; 0 for an unknown code.
uint32_t fblDTypeBytes(FblDType dtype);
// "uint32", "float32", "utf8", ... ("dtype 42" for an unknown code).
std::string fblDTypeName(FblDType dtype);

// Standard section names.
inline constexpr std::string_view kFblSectionFiblets = "fiblets";                      // uint32 words of fiblet records
inline constexpr std::string_view kFblSectionFiberFirstFiblet = "fiber_first_fiblet";  // uint64 x (fibers + 1)
inline constexpr std::string_view kFblSectionFiberLength = "fiber_length_mm";          // float32 per fiber
inline constexpr std::string_view kFblSectionDpsPrefix = "dps/";  // "dps/<name>": float32 x components per fiber
// Per-point data (optional; both or neither): "dpv/<name>" float32 x
// components per encoded point, in the fibers' order, and the index of each
// fiber's first point in them.
inline constexpr std::string_view kFblSectionDpvPrefix = "dpv/";
inline constexpr std::string_view kFblSectionFiberFirstPoint = "fiber_first_point";  // uint64 x (fibers + 1)
inline constexpr std::string_view kFblSectionSource = "source";   // utf8 JSON: input path, format, header

// Header fields owned by the codec; the container stores them verbatim.
// Normalisation: p_mm = translation + scale * p_normalised.
struct FblHeaderFields {
  uint32_t codec_version = 0;
  uint32_t flags = 0;  // must be 0 in format version 1
  uint64_t fiber_count = 0;
  uint64_t fiblet_count = 0;
  uint64_t point_count = 0;
  uint32_t points_per_fiblet = 0;    // N
  uint32_t fiblet_record_bytes = 0;  // bytes of one fiblet record
  double translation[3] = {0, 0, 0};
  double scale = 1;
  double delta = 0;     // step in normalised units
  double delta_mm = 0;  // the same step in mm
  double alpha = 0;     // maximum turn between segments, radians
  float v[3] = {0, 0, 0};  // the frame vector V
};

struct FblSectionSpec {
  std::string name;  // 1..47 bytes, no control characters, unique in the file
  FblDType dtype = FblDType::kUint8;
  uint32_t components = 1;
};

struct FblSection {
  std::string name;
  FblDType dtype = FblDType::kUint8;
  uint32_t components = 1;
  uint64_t element_count = 0;
  uint64_t offset = 0;  // byte offset in the file, multiple of 64
  uint64_t bytes = 0;
  uint32_t checksum = 0;  // CRC-32C of the bytes
};

inline constexpr uint32_t kFblDefaultSectionCapacity = 64;

class FblWriter {
 public:
  // Creates the temporary file; fails if `path` exists and !overwrite.
  // `section_capacity` entries are reserved for the section table, which
  // sits right after the header so that a reader learns every section from
  // the first pages (and can name the section a truncation cut).
  FblWriter(const std::string& path, const FblHeaderFields& fields, bool overwrite,
            uint32_t section_capacity = kFblDefaultSectionCapacity);
  FblWriter(const FblWriter&) = delete;
  FblWriter& operator=(const FblWriter&) = delete;

  // Counts known only at the end of a streamed encode may be set up to finish().
  FblHeaderFields& fields() { return fields_; }

  void beginSection(const FblSectionSpec& spec);
  void beginSection(const std::string& name, FblDType dtype, uint32_t components = 1) {
    beginSection(FblSectionSpec{name, dtype, components});
  }
  void append(const void* data, size_t bytes);
  // Fails if the bytes appended are not a whole number of elements.
  void endSection();
  // beginSection + append + endSection.
  void writeSection(const FblSectionSpec& spec, const void* data, size_t bytes);
  // Writes header and table, fsyncs, renames into place.
  void finish();

  const std::vector<FblSection>& sections() const { return sections_; }
  const std::string& path() const { return file_.path(); }

 private:
  void pad();
  OutputFile file_;
  FblHeaderFields fields_;
  uint32_t capacity_;
  std::vector<FblSection> sections_;
  bool in_section_ = false;
  bool finished_ = false;
};

class FblFile {
 public:
  FblFile() = default;
  FblFile(FblFile&&) noexcept = default;
  FblFile& operator=(FblFile&&) noexcept = default;

  // Maps and validates header and section table; safe on untrusted input.
  static FblFile open(const std::string& path);

  const std::string& path() const { return map_.path(); }
  uint32_t formatVersion() const { return version_; }
  const FblHeaderFields& header() const { return fields_; }
  const std::vector<FblSection>& sections() const { return sections_; }
  uint64_t fileBytes() const { return map_.size(); }
  // nullptr when there is no section of that name.
  const FblSection* find(std::string_view name) const;

  // The section's bytes, checksum verified on the first access (throws on
  // mismatch). The span is 64-byte aligned in memory and valid while this
  // FblFile lives.
  std::span<const uint8_t> data(const FblSection& section) const;
  // Typed view; fails if the section's dtype is not T's.
  template <typename T>
  std::span<const T> array(const FblSection& section) const;
  // The named section's bytes; fails naming the file if it is missing.
  std::span<const uint8_t> data(std::string_view name) const;

  // Checks every section's checksum (or one), throwing on the first mismatch.
  void verify() const;
  void verify(std::string_view name) const;

 private:
  void verifySection(size_t index) const;
  const FblSection& require(std::string_view name) const;
  void checkDType(const FblSection& section, FblDType expected) const;

  MappedFile map_;
  uint32_t version_ = 0;
  FblHeaderFields fields_;
  std::vector<FblSection> sections_;
  // One flag per section; atomic so concurrent readers may verify at once.
  std::unique_ptr<std::atomic<bool>[]> verified_;
};

template <typename T>
constexpr FblDType fblDTypeOf() {
  if constexpr (std::is_same_v<T, uint8_t>) return FblDType::kUint8;
  else if constexpr (std::is_same_v<T, uint16_t>) return FblDType::kUint16;
  else if constexpr (std::is_same_v<T, uint32_t>) return FblDType::kUint32;
  else if constexpr (std::is_same_v<T, uint64_t>) return FblDType::kUint64;
  else if constexpr (std::is_same_v<T, int8_t>) return FblDType::kInt8;
  else if constexpr (std::is_same_v<T, int16_t>) return FblDType::kInt16;
  else if constexpr (std::is_same_v<T, int32_t>) return FblDType::kInt32;
  else if constexpr (std::is_same_v<T, int64_t>) return FblDType::kInt64;
  else if constexpr (std::is_same_v<T, float>) return FblDType::kFloat32;
  else if constexpr (std::is_same_v<T, double>) return FblDType::kFloat64;
  else static_assert(sizeof(T) == 0, "no .fbl dtype for this type");
}

template <typename T>
std::span<const T> FblFile::array(const FblSection& section) const {
  checkDType(section, fblDTypeOf<T>());
  const auto bytes = data(section);
  // Sections start 64-byte aligned in a page-aligned map: the cast is aligned.
  return {reinterpret_cast<const T*>(bytes.data()), bytes.size() / sizeof(T)};
}

}  // namespace fibscope
