#include "codec/fbl_file.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <unordered_set>

#include "codec/fbl_format.h"
#include "core/byte_order.h"
#include "core/checksum.h"
#include "core/error.h"

namespace fibscope {

static_assert(kHostIsLittleEndian, ".fbl sections are mapped in place: a big-endian host needs byte swapping");

namespace {

constexpr uint64_t alignUp(uint64_t v) { return (v + fbl::kAlignment - 1) / fbl::kAlignment * fbl::kAlignment; }

std::string hex32(uint32_t v) {
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "0x%08x", v);
  return buffer;
}

// Printable rendering of untrusted bytes for messages (never a line break).
std::string printable(const uint8_t* p, size_t n) {
  std::string out;
  for (size_t i = 0; i < n; ++i) {
    if (p[i] >= 0x20 && p[i] < 0x7F && p[i] != '\\') {
      out += static_cast<char>(p[i]);
    } else {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\x%02x", p[i]);
      out += buffer;
    }
  }
  return out;
}

std::string quoted(const std::string& name) {
  std::string out = "'";
  out += printable(reinterpret_cast<const uint8_t*>(name.data()), name.size());
  return out += '\'';
}

bool allZero(const uint8_t* p, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (p[i] != 0) return false;
  return true;
}

// Why a section name cannot be stored, or "" if it can.
std::string nameProblem(std::string_view name) {
  if (name.empty()) return "is empty";
  if (name.size() >= fbl::kSectionNameBytes)
    return "is " + std::to_string(name.size()) + " bytes, at most " + std::to_string(fbl::kSectionNameBytes - 1) +
           " fit";
  for (const char c : name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) return "contains a control character";
  return {};
}

void encodeHeader(uint8_t* h, const FblHeaderFields& f, uint32_t section_count, uint32_t capacity,
                  uint32_t table_checksum, uint64_t file_bytes) {
  namespace H = fbl::header;
  std::memset(h, 0, fbl::kHeaderBytes);
  std::memcpy(h + H::kMagic, fbl::kMagic, sizeof fbl::kMagic);
  storeUnaligned<uint32_t>(h + H::kVersion, fbl::kFormatVersion);
  storeUnaligned<uint32_t>(h + H::kHeaderBytes, fbl::kHeaderBytes);
  storeUnaligned<uint32_t>(h + H::kFlags, f.flags);
  storeUnaligned<uint32_t>(h + H::kCodecVersion, f.codec_version);
  storeUnaligned<uint64_t>(h + H::kFiberCount, f.fiber_count);
  storeUnaligned<uint64_t>(h + H::kFibletCount, f.fiblet_count);
  storeUnaligned<uint64_t>(h + H::kPointCount, f.point_count);
  storeUnaligned<uint32_t>(h + H::kPointsPerFiblet, f.points_per_fiblet);
  storeUnaligned<uint32_t>(h + H::kFibletRecordBytes, f.fiblet_record_bytes);
  for (int i = 0; i < 3; ++i) storeUnaligned<double>(h + H::kTranslation + 8 * i, f.translation[i]);
  storeUnaligned<double>(h + H::kScale, f.scale);
  storeUnaligned<double>(h + H::kDelta, f.delta);
  storeUnaligned<double>(h + H::kDeltaMm, f.delta_mm);
  storeUnaligned<double>(h + H::kAlpha, f.alpha);
  for (int i = 0; i < 3; ++i) storeUnaligned<float>(h + H::kV + 4 * i, f.v[i]);
  storeUnaligned<uint32_t>(h + H::kSectionCount, section_count);
  storeUnaligned<uint64_t>(h + H::kTableOffset, fbl::kHeaderBytes);
  storeUnaligned<uint32_t>(h + H::kTableCapacity, capacity);
  storeUnaligned<uint32_t>(h + H::kTableChecksum, table_checksum);
  storeUnaligned<uint64_t>(h + H::kFileBytes, file_bytes);
  storeUnaligned<uint32_t>(h + H::kHeaderChecksum, crc32c(h, H::kHeaderChecksum));
}

void decodeHeaderFields(const uint8_t* h, FblHeaderFields& f) {
  namespace H = fbl::header;
  f.flags = loadUnaligned<uint32_t>(h + H::kFlags);
  f.codec_version = loadUnaligned<uint32_t>(h + H::kCodecVersion);
  f.fiber_count = loadUnaligned<uint64_t>(h + H::kFiberCount);
  f.fiblet_count = loadUnaligned<uint64_t>(h + H::kFibletCount);
  f.point_count = loadUnaligned<uint64_t>(h + H::kPointCount);
  f.points_per_fiblet = loadUnaligned<uint32_t>(h + H::kPointsPerFiblet);
  f.fiblet_record_bytes = loadUnaligned<uint32_t>(h + H::kFibletRecordBytes);
  for (int i = 0; i < 3; ++i) f.translation[i] = loadUnaligned<double>(h + H::kTranslation + 8 * i);
  f.scale = loadUnaligned<double>(h + H::kScale);
  f.delta = loadUnaligned<double>(h + H::kDelta);
  f.delta_mm = loadUnaligned<double>(h + H::kDeltaMm);
  f.alpha = loadUnaligned<double>(h + H::kAlpha);
  for (int i = 0; i < 3; ++i) f.v[i] = loadUnaligned<float>(h + H::kV + 4 * i);
}

void encodeEntry(uint8_t* e, const FblSection& s) {
  namespace E = fbl::entry;
  std::memset(e, 0, fbl::kSectionEntryBytes);
  std::memcpy(e + E::kName, s.name.data(), s.name.size());
  storeUnaligned<uint32_t>(e + E::kDType, static_cast<uint32_t>(s.dtype));
  storeUnaligned<uint32_t>(e + E::kComponents, s.components);
  storeUnaligned<uint64_t>(e + E::kElementCount, s.element_count);
  storeUnaligned<uint64_t>(e + E::kOffset, s.offset);
  storeUnaligned<uint64_t>(e + E::kBytes, s.bytes);
  storeUnaligned<uint32_t>(e + E::kChecksum, s.checksum);
}

}  // namespace

uint32_t fblDTypeBytes(FblDType dtype) {
  switch (dtype) {
    case FblDType::kUint8:
    case FblDType::kInt8:
    case FblDType::kUtf8: return 1;
    case FblDType::kUint16:
    case FblDType::kInt16: return 2;
    case FblDType::kUint32:
    case FblDType::kInt32:
    case FblDType::kFloat32: return 4;
    case FblDType::kUint64:
    case FblDType::kInt64:
    case FblDType::kFloat64: return 8;
  }
  return 0;
}

std::string fblDTypeName(FblDType dtype) {
  switch (dtype) {
    case FblDType::kUint8: return "uint8";
    case FblDType::kUint16: return "uint16";
    case FblDType::kUint32: return "uint32";
    case FblDType::kUint64: return "uint64";
    case FblDType::kInt8: return "int8";
    case FblDType::kInt16: return "int16";
    case FblDType::kInt32: return "int32";
    case FblDType::kInt64: return "int64";
    case FblDType::kFloat32: return "float32";
    case FblDType::kFloat64: return "float64";
    case FblDType::kUtf8: return "utf8";
  }
  return "dtype " + std::to_string(static_cast<uint32_t>(dtype));
}

// --- writer -------------------------------------------------------------------

FblWriter::FblWriter(const std::string& path, const FblHeaderFields& fields, bool overwrite,
                     uint32_t section_capacity)
    : file_(path, overwrite), fields_(fields), capacity_(section_capacity) {
  // Header and table are placeholders until finish(): a reader of a file
  // left half-written (impossible under the final name anyway) sees zeros,
  // not a valid magic.
  const uint64_t table_end = fbl::kHeaderBytes + uint64_t(capacity_) * fbl::kSectionEntryBytes;
  const std::vector<uint8_t> zeros(static_cast<size_t>(alignUp(table_end)), 0);
  file_.write(zeros.data(), zeros.size());
}

void FblWriter::beginSection(const FblSectionSpec& spec) {
  const std::string& path = file_.path();
  if (finished_) fail(path, "internal error: section " + quoted(spec.name) + " begun after finish()");
  if (in_section_) fail(path, "internal error: section " + quoted(spec.name) + " begun inside section " + quoted(sections_.back().name));
  if (const std::string problem = nameProblem(spec.name); !problem.empty())
    fail(path, "section name " + quoted(spec.name) + " " + problem);
  for (const FblSection& s : sections_)
    if (s.name == spec.name) fail(path, "section " + quoted(spec.name) + " written twice");
  if (fblDTypeBytes(spec.dtype) == 0) fail(path, "section " + quoted(spec.name) + ": unknown " + fblDTypeName(spec.dtype));
  if (spec.components == 0) fail(path, "section " + quoted(spec.name) + ": 0 components");
  if (sections_.size() >= capacity_)
    fail(path, "section " + quoted(spec.name) + ": more than the " + std::to_string(capacity_) +
                   " sections reserved when the writer was created");
  FblSection s;
  s.name = spec.name;
  s.dtype = spec.dtype;
  s.components = spec.components;
  s.offset = file_.size();  // aligned: the table and every section are padded
  sections_.push_back(std::move(s));
  in_section_ = true;
}

void FblWriter::append(const void* data, size_t bytes) {
  if (!in_section_) fail(file_.path(), "internal error: append() outside a section");
  if (bytes == 0) return;
  FblSection& s = sections_.back();
  s.checksum = crc32c(data, bytes, s.checksum);
  s.bytes += bytes;
  file_.write(data, bytes);
}

void FblWriter::endSection() {
  if (!in_section_) fail(file_.path(), "internal error: endSection() outside a section");
  FblSection& s = sections_.back();
  const uint64_t element_bytes = uint64_t(fblDTypeBytes(s.dtype)) * s.components;
  if (s.bytes % element_bytes != 0)
    fail(file_.path(), "section " + quoted(s.name) + ": " + std::to_string(s.bytes) + " bytes is not a whole number of " +
                           std::to_string(s.components) + " x " + fblDTypeName(s.dtype) + " elements");
  s.element_count = s.bytes / element_bytes;
  in_section_ = false;
  pad();
}

void FblWriter::writeSection(const FblSectionSpec& spec, const void* data, size_t bytes) {
  beginSection(spec);
  append(data, bytes);
  endSection();
}

void FblWriter::pad() {
  static constexpr uint8_t kZeros[fbl::kAlignment] = {};
  const uint64_t size = file_.size();
  file_.write(kZeros, static_cast<size_t>(alignUp(size) - size));
}

void FblWriter::finish() {
  if (finished_) fail(file_.path(), "internal error: finish() called twice");
  if (in_section_) fail(file_.path(), "internal error: finish() inside section " + quoted(sections_.back().name));
  std::vector<uint8_t> table(sections_.size() * fbl::kSectionEntryBytes);
  for (size_t i = 0; i < sections_.size(); ++i) encodeEntry(table.data() + i * fbl::kSectionEntryBytes, sections_[i]);
  uint8_t header[fbl::kHeaderBytes];
  encodeHeader(header, fields_, static_cast<uint32_t>(sections_.size()), capacity_,
               crc32c(table.data(), table.size()), file_.size());
  if (!table.empty()) file_.writeAt(fbl::kHeaderBytes, table.data(), table.size());
  file_.writeAt(0, header, sizeof header);
  file_.commit();
  finished_ = true;
}

// --- reader -------------------------------------------------------------------

FblFile FblFile::open(const std::string& path) {
  namespace H = fbl::header;
  namespace E = fbl::entry;
  FblFile f;
  f.map_ = MappedFile(path);
  const uint8_t* p = f.map_.data();
  const uint64_t size = f.map_.size();

  if (size < sizeof fbl::kMagic || std::memcmp(p, fbl::kMagic, sizeof fbl::kMagic) != 0)
    fail(path, "not a .fbl file (magic \"" + printable(p, std::min<uint64_t>(size, 8)) + "\", expected \"FIBLETS\\x00\")");
  if (size < 16)
    fail(path, "truncated: the header ends at byte " + std::to_string(fbl::kHeaderBytes) + " but the file has " +
                   std::to_string(size) + " bytes");
  const uint32_t version = loadUnaligned<uint32_t>(p + H::kVersion);
  const uint32_t header_bytes = loadUnaligned<uint32_t>(p + H::kHeaderBytes);
  if (version != fbl::kFormatVersion || header_bytes != fbl::kHeaderBytes) {
    // Every version keeps its header checksum in the header's last 4 bytes,
    // which tells a newer file from a corrupt one.
    const bool plausible = header_bytes >= 16 && header_bytes % 4 == 0 && header_bytes <= size;
    if (plausible && crc32c(p, header_bytes - 4) == loadUnaligned<uint32_t>(p + header_bytes - 4)) {
      if (version > fbl::kFormatVersion)
        fail(path, ".fbl version " + std::to_string(version) + " is newer than this fibscope (" +
                       std::to_string(fbl::kFormatVersion) + ")");
      fail(path, "header: .fbl version " + std::to_string(version) + " with a " + std::to_string(header_bytes) +
                     "-byte header is not a valid combination");
    }
    fail(path, "header (byte 0): version " + std::to_string(version) + ", header size " + std::to_string(header_bytes) +
                   ", checksum mismatch, file is corrupt");
  }
  if (size < fbl::kHeaderBytes)
    fail(path, "truncated: the header ends at byte " + std::to_string(fbl::kHeaderBytes) + " but the file has " +
                   std::to_string(size) + " bytes");
  const uint32_t stored_header_crc = loadUnaligned<uint32_t>(p + H::kHeaderChecksum);
  const uint32_t header_crc = crc32c(p, H::kHeaderChecksum);
  if (stored_header_crc != header_crc)
    fail(path, "header (byte 0): checksum mismatch (stored " + hex32(stored_header_crc) + ", computed " +
                   hex32(header_crc) + "), file is corrupt");

  // The checksum matched: what follows are writer bugs or foreign writers.
  f.version_ = version;
  decodeHeaderFields(p, f.fields_);
  if (f.fields_.flags != 0) fail(path, "header: flags " + hex32(f.fields_.flags) + " unknown to .fbl version 1");
  if (!allZero(p + H::kReserved, H::kHeaderChecksum - H::kReserved))
    failAt(path, H::kReserved, "header: reserved bytes are not zero");
  const uint32_t count = loadUnaligned<uint32_t>(p + H::kSectionCount);
  const uint64_t table_offset = loadUnaligned<uint64_t>(p + H::kTableOffset);
  const uint32_t capacity = loadUnaligned<uint32_t>(p + H::kTableCapacity);
  const uint64_t file_bytes = loadUnaligned<uint64_t>(p + H::kFileBytes);
  if (table_offset != fbl::kHeaderBytes)
    fail(path, "header: section table at byte " + std::to_string(table_offset) + ", expected " +
                   std::to_string(fbl::kHeaderBytes));
  if (count > capacity)
    fail(path, "header: " + std::to_string(count) + " sections but room for " + std::to_string(capacity) +
                   " in the section table");
  const uint64_t table_end = table_offset + uint64_t(capacity) * fbl::kSectionEntryBytes;  // < 2^39, no overflow
  if (file_bytes % fbl::kAlignment != 0 || file_bytes < alignUp(table_end))
    fail(path, "header: file size " + std::to_string(file_bytes) + " is not a multiple of 64 at or after the section table end (" +
                   std::to_string(alignUp(table_end)) + ")");
  if (size < table_end)
    fail(path, "truncated: the section table ends at byte " + std::to_string(table_end) + " but the file has " +
                   std::to_string(size) + " bytes");
  const uint8_t* table = p + table_offset;
  const uint64_t used_bytes = uint64_t(count) * fbl::kSectionEntryBytes;
  const uint32_t stored_table_crc = loadUnaligned<uint32_t>(p + H::kTableChecksum);
  const uint32_t table_crc = crc32c(table, used_bytes);
  if (stored_table_crc != table_crc)
    fail(path, "section table (byte " + std::to_string(table_offset) + "): checksum mismatch (stored " +
                   hex32(stored_table_crc) + ", computed " + hex32(table_crc) + "), file is corrupt");
  if (!allZero(table + used_bytes, table_end - table_offset - used_bytes))
    failAt(path, table_offset + used_bytes, "section table: unused entries are not zero, file is corrupt");

  // Sections follow the table in order, each at the first 64-byte boundary
  // after the previous one: that canonical layout makes every byte of the
  // file covered by a checksum or required to be zero.
  std::unordered_set<std::string> names;
  uint64_t cursor = table_end;  // end of the previous section (or the table)
  std::string previous = "the section table";
  for (uint32_t i = 0; i < count; ++i) {
    const uint8_t* e = table + uint64_t(i) * fbl::kSectionEntryBytes;
    const uint64_t entry_offset = table_offset + uint64_t(i) * fbl::kSectionEntryBytes;
    const size_t name_length = strnlen(reinterpret_cast<const char*>(e + E::kName), fbl::kSectionNameBytes);
    FblSection s;
    s.name.assign(reinterpret_cast<const char*>(e + E::kName), name_length);
    const std::string where = "section table entry " + std::to_string(i) + " (" + quoted(s.name) + ")";
    if (name_length == fbl::kSectionNameBytes || !allZero(e + E::kName + name_length, fbl::kSectionNameBytes - name_length))
      failAt(path, entry_offset, where + ": name is not NUL-terminated and zero-padded");
    if (const std::string problem = nameProblem(s.name); !problem.empty())
      failAt(path, entry_offset, where + ": name " + problem);
    if (!names.insert(s.name).second) failAt(path, entry_offset, where + ": a second section of that name");
    s.dtype = static_cast<FblDType>(loadUnaligned<uint32_t>(e + E::kDType));
    s.components = loadUnaligned<uint32_t>(e + E::kComponents);
    s.element_count = loadUnaligned<uint64_t>(e + E::kElementCount);
    s.offset = loadUnaligned<uint64_t>(e + E::kOffset);
    s.bytes = loadUnaligned<uint64_t>(e + E::kBytes);
    s.checksum = loadUnaligned<uint32_t>(e + E::kChecksum);
    if (!allZero(e + E::kReserved, fbl::kSectionEntryBytes - E::kReserved))
      failAt(path, entry_offset + E::kReserved, where + ": reserved bytes are not zero");
    const uint32_t dtype_bytes = fblDTypeBytes(s.dtype);
    if (dtype_bytes == 0) failAt(path, entry_offset + E::kDType, where + ": unknown " + fblDTypeName(s.dtype));
    if (s.components == 0) failAt(path, entry_offset + E::kComponents, where + ": 0 components");
    // element_count * components * dtype_bytes must equal bytes, without overflow.
    const uint64_t element_bytes = uint64_t(dtype_bytes) * s.components;
    if (s.bytes % element_bytes != 0 || s.bytes / element_bytes != s.element_count)
      failAt(path, entry_offset, where + ": " + std::to_string(s.element_count) + " elements of " +
                                     std::to_string(s.components) + " x " + fblDTypeName(s.dtype) + " do not make " +
                                     std::to_string(s.bytes) + " bytes");
    if (s.offset < cursor)
      failAt(path, entry_offset, where + ": starts at byte " + std::to_string(s.offset) + ", inside " + previous +
                                     " (which ends at byte " + std::to_string(cursor) + ")");
    if (s.offset != alignUp(cursor))
      failAt(path, entry_offset, where + ": starts at byte " + std::to_string(s.offset) + ", expected " +
                                     std::to_string(alignUp(cursor)) + " (the 64-byte boundary after " + previous + ")");
    if (s.bytes > file_bytes || s.offset > file_bytes - s.bytes)
      failAt(path, entry_offset, where + ": bytes " + std::to_string(s.offset) + "+" + std::to_string(s.bytes) +
                                     " run past the end of the file recorded in the header (byte " +
                                     std::to_string(file_bytes) + ")");
    cursor = s.offset + s.bytes;
    previous = "section " + quoted(s.name);
    f.sections_.push_back(std::move(s));
  }
  if (alignUp(cursor) != file_bytes)
    fail(path, "header: file size " + std::to_string(file_bytes) + " but " + previous + " ends at byte " +
                   std::to_string(cursor) + " (expected " + std::to_string(alignUp(cursor)) + ")");
  if (size < file_bytes) {
    for (const FblSection& s : f.sections_)
      if (s.offset + s.bytes > size)
        fail(path, "truncated: section " + quoted(s.name) + " ends at byte " + std::to_string(s.offset + s.bytes) +
                       " but the file has " + std::to_string(size) + " bytes");
    fail(path, "truncated: the padding after " + previous + " ends at byte " + std::to_string(file_bytes) +
                   " but the file has " + std::to_string(size) + " bytes");
  }
  if (size > file_bytes)
    fail(path, std::to_string(size - file_bytes) + " unexpected bytes after the end of the file recorded in the header (byte " +
                   std::to_string(file_bytes) + ")");

  // Padding between sections is zero (a few bytes each: cheap to check now).
  uint64_t end = table_end;
  previous = "the section table";
  for (const FblSection& s : f.sections_) {
    if (!allZero(p + end, s.offset - end))
      failAt(path, end, "padding after " + previous + " is not zero, file is corrupt");
    end = s.offset + s.bytes;
    previous = "section " + quoted(s.name);
  }
  if (!allZero(p + end, file_bytes - end)) failAt(path, end, "padding after " + previous + " is not zero, file is corrupt");

  // Standard sections must agree with the header counts.
  auto checkCount = [&](const FblSection& s, uint64_t expected, const char* what) {
    if (s.element_count != expected)
      fail(path, "section " + quoted(s.name) + " (byte " + std::to_string(s.offset) + "): " +
                     std::to_string(s.element_count) + " elements, expected " + std::to_string(expected) + " (" + what + ")");
  };
  for (const FblSection& s : f.sections_) {
    const std::string_view name = s.name;
    if (name == kFblSectionFiberFirstFiblet || name == kFblSectionFiberFirstPoint) {
      if (f.fields_.fiber_count == UINT64_MAX) fail(path, "header: fiber count 2^64-1 is not possible");
      checkCount(s, f.fields_.fiber_count + 1, "fiber count + 1");
    } else if (name.starts_with(kFblSectionDpvPrefix)) {
      checkCount(s, f.fields_.point_count, "one per point");
    } else if (name == kFblSectionFiberLength || name.starts_with(kFblSectionDpsPrefix)) {
      checkCount(s, f.fields_.fiber_count, "one per fiber");
    } else if (name == kFblSectionFiblets) {
      const uint64_t record = f.fields_.fiblet_record_bytes;
      if (record == 0 || s.bytes % record != 0 || s.bytes / record != f.fields_.fiblet_count)
        fail(path, "section " + quoted(s.name) + " (byte " + std::to_string(s.offset) + "): " + std::to_string(s.bytes) +
                       " bytes is not " + std::to_string(f.fields_.fiblet_count) + " fiblets of " +
                       std::to_string(record) + " bytes (header)");
    }
  }
  f.verified_ = std::make_unique<std::atomic<bool>[]>(f.sections_.size());
  return f;
}

const FblSection* FblFile::find(std::string_view name) const {
  for (const FblSection& s : sections_)
    if (s.name == name) return &s;
  return nullptr;
}

const FblSection& FblFile::require(std::string_view name) const {
  const FblSection* s = find(name);
  if (!s) fail(path(), "no section '" + std::string(name) + "' in this .fbl file");
  return *s;
}

void FblFile::checkDType(const FblSection& section, FblDType expected) const {
  if (section.dtype != expected)
    fail(path(), "section " + quoted(section.name) + " (byte " + std::to_string(section.offset) + "): holds " +
                     fblDTypeName(section.dtype) + ", expected " + fblDTypeName(expected));
}

void FblFile::verifySection(size_t index) const {
  if (verified_[index].load(std::memory_order_acquire)) return;
  const FblSection& s = sections_[index];
  const uint32_t computed = crc32c(map_.data() + s.offset, static_cast<size_t>(s.bytes));
  if (computed != s.checksum)
    fail(path(), "section " + quoted(s.name) + " (byte " + std::to_string(s.offset) + "): checksum mismatch (stored " +
                     hex32(s.checksum) + ", computed " + hex32(computed) + "), file is corrupt");
  verified_[index].store(true, std::memory_order_release);
}

std::span<const uint8_t> FblFile::data(const FblSection& section) const {
  size_t index = 0;
  while (index < sections_.size() && &sections_[index] != &section) ++index;
  if (index == sections_.size())
    fail(path(), "internal error: section " + quoted(section.name) + " does not belong to this file");
  verifySection(index);
  return {map_.data() + section.offset, static_cast<size_t>(section.bytes)};
}

std::span<const uint8_t> FblFile::data(std::string_view name) const { return data(require(name)); }

void FblFile::verify() const {
  for (size_t i = 0; i < sections_.size(); ++i) verifySection(i);
}

void FblFile::verify(std::string_view name) const {
  verifySection(static_cast<size_t>(&require(name) - sections_.data()));
}

}  // namespace fibscope
