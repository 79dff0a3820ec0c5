// TRX (tee-ar-ex) building blocks shared by the reader and the writer.
//
// A TRX is a zip archive (members stored or deflated) or a plain directory.
// Every array is one member named "NAME[.NCOMP].DTYPE": the base name is the
// array's name, NCOMP its number of components (omitted means 1) and DTYPE
// its element type; all arrays are C-ordered and little-endian.
//
// This file holds the dtype table, member-name parsing and value
// conversions, and read access to the members of an archive or directory:
// stored zip members and directory files are read in place from a memory
// map; compressed members are inflated by libzip, sequentially.
//
// Everything here is safe on untrusted input: the zip directory is parsed
// with every field checked against the end of the file, and errors are one
// line naming the file and the member.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/mapped_file.h"

struct zip;
struct zip_file;

namespace fibscope::trx {

// Element types of TRX arrays. kBit is the spec's "bit": numpy bool, one
// byte per value (0 or 1).
enum class DType : uint8_t {
  kInt8, kInt16, kInt32, kInt64,
  kUint8, kUint16, kUint32, kUint64,
  kFloat16, kFloat32, kFloat64,
  kBit,
};

// "float32" -> kFloat32; nullopt for anything else (names are exact, lower case).
std::optional<DType> parseDType(std::string_view text);
std::string dtypeName(DType dtype);
size_t dtypeSize(DType dtype);
bool isFloat(DType dtype);
// Signed or unsigned integer (not bit, not float): what offsets and groups may use.
bool isInteger(DType dtype);

// One array member's file name, parsed.
struct MemberName {
  std::string name;         // "fa", "commit_weights", "positions"
  uint32_t components = 1;  // NCOMP; 1 when omitted
  DType dtype = DType::kFloat32;
};

// Parses the last path component of a member, "NAME.DTYPE" or
// "NAME.NCOMP.DTYPE". NAME may itself contain dots ("fa.mean.float32" is the
// array "fa.mean"). Returns nullopt with the reason in *why when the dtype is
// unknown, NCOMP is 0 or absurd, or NAME is empty.
std::optional<MemberName> parseMemberName(std::string_view file_name, std::string* why);

// The file name the writer uses for an array. NCOMP is written when it is
// not 1, and also when NAME ends in ".<digits>", so that the name parses
// back to the same NAME and NCOMP.
std::string memberFileName(const std::string& name, uint32_t components, DType dtype);

// True when `name` can be an array or group name: a non-empty single path
// component without '/', NUL or control characters, and not "." or "..".
bool isValidArrayName(std::string_view name);

// Converts `count` little-endian values of `dtype` to float (float64 and
// 64-bit integers lose precision beyond float's 24 bits, as DataArray says).
void decodeToFloat(DType dtype, const uint8_t* src, size_t count, float* dst);

// Stores `count` floats as little-endian `dtype`. Integer types round to
// nearest and saturate; bit stores value != 0. Returns how many values did
// not fit (NaN, out of range, or beyond float16's ±65504) so the caller can
// warn; those are saturated (NaN becomes 0 for integers).
size_t encodeFromFloat(DType dtype, const float* src, size_t count, uint8_t* dst);

// Decodes `count` little-endian integers of an integer `dtype` (offsets,
// group indices) to uint64. Returns the index of the first negative value,
// or `count` when all are non-negative (the rest of dst is then valid).
size_t decodeIndices(DType dtype, const uint8_t* src, size_t count, uint64_t* dst);

// One member of a TRX archive or directory.
struct Member {
  std::string name;              // relative to the TRX root, '/'-separated ("dpv/fa.float32")
  uint64_t size = 0;             // uncompressed bytes
  uint64_t stored_size = 0;      // bytes it occupies in the file (compressed size for zip members)
  bool in_place = false;         // stored zip member or directory file: read straight from a map
  uint64_t data_offset = 0;      // zip: where the (stored) data starts in the archive
  int64_t zip_index = -1;        // zip: index in the central directory (= libzip's index)
  uint16_t method = 0;           // zip: compression method (0 stored, 8 deflate, ...)
  bool encrypted = false;
  std::string file_path;         // directory: the file on disk
};

class MemberReader;

// A TRX zip archive or directory, opened for reading.
class Archive {
 public:
  // Opens `path`: a directory, or a file holding a zip archive. Lists the
  // members; when the archive has no root header.json but exactly one
  // "FOLDER/header.json" (a zipped TRX directory), FOLDER/ is stripped from
  // every member name. Throws Error for unreadable paths and malformed zips.
  explicit Archive(const std::string& path);
  ~Archive();
  Archive(const Archive&) = delete;
  Archive& operator=(const Archive&) = delete;

  const std::string& path() const { return path_; }
  bool isDirectory() const { return is_directory_; }
  // Size of the zip file, or the sum of the directory's member sizes.
  uint64_t fileBytes() const { return file_bytes_; }
  // Members sorted by name (zip and directory order are arbitrary).
  const std::vector<Member>& members() const { return members_; }
  const Member* find(std::string_view name) const;
  // Entries that were skipped (folders outside the TRX root, ...), for warnings.
  const std::vector<std::string>& notes() const { return notes_; }

  // Reads a whole member; Error if it is larger than `max_bytes`.
  std::string readWhole(const Member& member, uint64_t max_bytes);
  // Opens a member for sequential reading. The Archive must outlive it.
  std::unique_ptr<MemberReader> open(const Member& member);

 private:
  void listDirectory();
  void listZip();
  void stripTopFolder();
  zip* libzip();  // opened on first use, over the same memory map

  std::string path_;
  bool is_directory_ = false;
  uint64_t file_bytes_ = 0;
  MappedFile map_;  // the zip archive (empty for a directory)
  std::vector<Member> members_;
  std::vector<std::string> notes_;
  zip* zip_ = nullptr;
};

// Sequential reader of one member.
class MemberReader {
 public:
  MemberReader(const MemberReader&) = delete;
  MemberReader& operator=(const MemberReader&) = delete;
  ~MemberReader();

  // Returns a pointer to the next `bytes` bytes of the member, valid until the
  // next call. Throws Error naming the member when fewer bytes remain or the
  // data cannot be inflated.
  const uint8_t* next(size_t bytes);
  // Checks that the member holds nothing more (for compressed members this
  // makes libzip verify the CRC-32).
  void finish();
  uint64_t consumed() const { return consumed_; }
  const Member& member() const { return member_; }
  // Bytes of the file behind what was consumed (compressed bytes for a
  // compressed member), for progress.
  uint64_t fileBytesConsumed() const;

 private:
  friend class Archive;
  MemberReader(std::string archive_path, Member member) : archive_path_(std::move(archive_path)), member_(std::move(member)) {}
  [[noreturn]] void failMember(const std::string& message) const;

  std::string archive_path_;
  Member member_;
  uint64_t consumed_ = 0;
  // In place: a view of the bytes (the archive's map or our own map of a directory file).
  const uint8_t* base_ = nullptr;
  const MappedFile* map_ = nullptr;  // for releasing consumed pages
  uint64_t map_offset_ = 0;          // where the member starts in *map_
  MappedFile own_map_;
  uint64_t released_up_to_ = 0;
  // Compressed: a libzip stream and a buffer.
  zip_file* file_ = nullptr;
  std::vector<uint8_t> buffer_;
};

}  // namespace fibscope::trx
