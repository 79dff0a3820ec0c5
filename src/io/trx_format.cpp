#include "io/trx_format.h"

#include <zip.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <type_traits>

#include "core/byte_order.h"
#include "core/error.h"
#include "core/half.h"

namespace fibscope::trx {
namespace {

struct DTypeInfo {
  DType dtype;
  const char* name;
  size_t size;
};

constexpr std::array<DTypeInfo, 12> kDTypes = {{
    {DType::kInt8, "int8", 1},
    {DType::kInt16, "int16", 2},
    {DType::kInt32, "int32", 4},
    {DType::kInt64, "int64", 8},
    {DType::kUint8, "uint8", 1},
    {DType::kUint16, "uint16", 2},
    {DType::kUint32, "uint32", 4},
    {DType::kUint64, "uint64", 8},
    {DType::kFloat16, "float16", 2},
    {DType::kFloat32, "float32", 4},
    {DType::kFloat64, "float64", 8},
    {DType::kBit, "bit", 1},
}};

// A component count above this is a corrupt name, not an array.
constexpr uint64_t kMaxComponents = 1u << 20;

constexpr bool kSwap = !kHostIsLittleEndian;

bool allDigits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

template <typename T>
void decodeAs(const uint8_t* src, size_t count, float* dst) {
  for (size_t i = 0; i < count; ++i) dst[i] = static_cast<float>(loadUnaligned<T>(src + i * sizeof(T), kSwap));
}

// Rounds to nearest (ties to even, the default rounding mode) and saturates
// to T's range; NaN becomes 0.
template <typename T>
size_t encodeInteger(const float* src, size_t count, uint8_t* dst) {
  // Both bounds are exact in double: min is 0 or -2^(bits-1); max + 1 is a power of two.
  constexpr double kLow = static_cast<double>(std::numeric_limits<T>::min());
  constexpr double kHighExclusive = static_cast<double>(std::numeric_limits<T>::max() / 2 + 1) * 2.0;
  size_t bad = 0;
  for (size_t i = 0; i < count; ++i) {
    const double v = std::nearbyint(static_cast<double>(src[i]));
    T out;
    if (std::isnan(v)) {
      out = 0;
      ++bad;
    } else if (v < kLow) {
      out = std::numeric_limits<T>::min();
      ++bad;
    } else if (v >= kHighExclusive) {
      out = std::numeric_limits<T>::max();
      ++bad;
    } else {
      out = static_cast<T>(v);
    }
    storeUnaligned<T>(dst + i * sizeof(T), out, kSwap);
  }
  return bad;
}

template <typename T>
size_t decodeIndicesAs(const uint8_t* src, size_t count, uint64_t* dst) {
  for (size_t i = 0; i < count; ++i) {
    const T v = loadUnaligned<T>(src + i * sizeof(T), kSwap);
    if constexpr (std::is_signed_v<T>) {
      if (v < 0) return i;
    }
    dst[i] = static_cast<uint64_t>(v);
  }
  return count;
}

// Member names go into one-line messages: control bytes are shown as \xNN.
std::string printable(std::string_view name) {
  std::string out;
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[u >> 4];
      out += hex[u & 15];
    } else {
      out += c;
    }
  }
  return out;
}

uint16_t le16(const uint8_t* p) { return loadUnaligned<uint16_t>(p, kSwap); }
uint32_t le32(const uint8_t* p) { return loadUnaligned<uint32_t>(p, kSwap); }
uint64_t le64(const uint8_t* p) { return loadUnaligned<uint64_t>(p, kSwap); }

// Zip record signatures and fixed sizes (APPNOTE.TXT 4.3).
constexpr uint32_t kLocalHeaderSignature = 0x04034b50;
constexpr uint32_t kCentralHeaderSignature = 0x02014b50;
constexpr uint32_t kEndOfCentralDirSignature = 0x06054b50;
constexpr uint32_t kZip64EndOfCentralDirSignature = 0x06064b50;
constexpr uint32_t kZip64LocatorSignature = 0x07064b50;
constexpr uint64_t kLocalHeaderBytes = 30;
constexpr uint64_t kCentralHeaderBytes = 46;
constexpr uint64_t kEndOfCentralDirBytes = 22;
constexpr uint64_t kZip64EndOfCentralDirBytes = 56;
constexpr uint64_t kZip64LocatorBytes = 20;
constexpr uint16_t kZip64ExtraId = 0x0001;

// Consumed pages of an in-place member are dropped from the process in
// steps of this size, so reading a 100 GB member keeps resident memory small.
constexpr uint64_t kReleaseStep = uint64_t(64) << 20;

}  // namespace

std::optional<DType> parseDType(std::string_view text) {
  for (const auto& info : kDTypes)
    if (text == info.name) return info.dtype;
  return std::nullopt;
}

std::string dtypeName(DType dtype) { return kDTypes[static_cast<size_t>(dtype)].name; }
size_t dtypeSize(DType dtype) { return kDTypes[static_cast<size_t>(dtype)].size; }
bool isFloat(DType dtype) { return dtype == DType::kFloat16 || dtype == DType::kFloat32 || dtype == DType::kFloat64; }
bool isInteger(DType dtype) { return !isFloat(dtype) && dtype != DType::kBit; }

std::optional<MemberName> parseMemberName(std::string_view file_name, std::string* why) {
  auto reject = [&](const std::string& reason) -> std::optional<MemberName> {
    if (why) *why = reason;
    return std::nullopt;
  };
  const size_t last_dot = file_name.rfind('.');
  if (last_dot == std::string_view::npos) return reject("no dtype extension (expected NAME[.NCOMP].DTYPE)");
  const std::string_view dtype_text = file_name.substr(last_dot + 1);
  const auto dtype = parseDType(dtype_text);
  if (!dtype) return reject("unknown dtype '" + std::string(dtype_text) + "'");
  MemberName parsed;
  parsed.dtype = *dtype;
  std::string_view rest = file_name.substr(0, last_dot);
  const size_t dot = rest.rfind('.');
  if (dot != std::string_view::npos && allDigits(rest.substr(dot + 1))) {
    const std::string_view digits = rest.substr(dot + 1);
    if (digits.size() > 7) return reject("absurd component count '" + std::string(digits) + "'");
    const uint64_t components = std::stoull(std::string(digits));
    if (components == 0 || components > kMaxComponents)
      return reject("component count " + std::to_string(components) + " is not in 1.." + std::to_string(kMaxComponents));
    parsed.components = static_cast<uint32_t>(components);
    rest = rest.substr(0, dot);
  }
  if (rest.empty()) return reject("empty array name");
  parsed.name = std::string(rest);
  return parsed;
}

std::string memberFileName(const std::string& name, uint32_t components, DType dtype) {
  const size_t dot = name.rfind('.');
  const bool name_ends_in_number = dot != std::string::npos && allDigits(std::string_view(name).substr(dot + 1));
  std::string file = name;
  if (components != 1 || name_ends_in_number) (file += '.') += std::to_string(components);
  (file += '.') += dtypeName(dtype);
  return file;
}

bool isValidArrayName(std::string_view name) {
  if (name.empty() || name == "." || name == "..") return false;
  return std::none_of(name.begin(), name.end(),
                      [](char c) { return c == '/' || c == '\\' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
}

void decodeToFloat(DType dtype, const uint8_t* src, size_t count, float* dst) {
  switch (dtype) {
    case DType::kInt8: return decodeAs<int8_t>(src, count, dst);
    case DType::kInt16: return decodeAs<int16_t>(src, count, dst);
    case DType::kInt32: return decodeAs<int32_t>(src, count, dst);
    case DType::kInt64: return decodeAs<int64_t>(src, count, dst);
    case DType::kUint8: return decodeAs<uint8_t>(src, count, dst);
    case DType::kUint16: return decodeAs<uint16_t>(src, count, dst);
    case DType::kUint32: return decodeAs<uint32_t>(src, count, dst);
    case DType::kUint64: return decodeAs<uint64_t>(src, count, dst);
    case DType::kFloat16:
      for (size_t i = 0; i < count; ++i) dst[i] = halfToFloat(loadUnaligned<uint16_t>(src + 2 * i, kSwap));
      return;
    case DType::kFloat32:
      if constexpr (kHostIsLittleEndian) {
        if (count) std::memcpy(dst, src, count * sizeof(float));
      } else {
        decodeAs<float>(src, count, dst);
      }
      return;
    case DType::kFloat64: return decodeAs<double>(src, count, dst);
    case DType::kBit:
      for (size_t i = 0; i < count; ++i) dst[i] = src[i] != 0 ? 1.0f : 0.0f;
      return;
  }
}

size_t encodeFromFloat(DType dtype, const float* src, size_t count, uint8_t* dst) {
  switch (dtype) {
    case DType::kInt8: return encodeInteger<int8_t>(src, count, dst);
    case DType::kInt16: return encodeInteger<int16_t>(src, count, dst);
    case DType::kInt32: return encodeInteger<int32_t>(src, count, dst);
    case DType::kInt64: return encodeInteger<int64_t>(src, count, dst);
    case DType::kUint8: return encodeInteger<uint8_t>(src, count, dst);
    case DType::kUint16: return encodeInteger<uint16_t>(src, count, dst);
    case DType::kUint32: return encodeInteger<uint32_t>(src, count, dst);
    case DType::kUint64: return encodeInteger<uint64_t>(src, count, dst);
    case DType::kFloat16: {
      size_t bad = 0;
      for (size_t i = 0; i < count; ++i) {
        const uint16_t h = floatToHalf(src[i]);
        // A finite float that became infinity did not fit in ±65504.
        if ((h & 0x7c00u) == 0x7c00u && std::isfinite(src[i])) ++bad;
        storeUnaligned<uint16_t>(dst + 2 * i, h, kSwap);
      }
      return bad;
    }
    case DType::kFloat32:
      if constexpr (kHostIsLittleEndian) {
        if (count) std::memcpy(dst, src, count * sizeof(float));
      } else {
        for (size_t i = 0; i < count; ++i) storeUnaligned<float>(dst + 4 * i, src[i], kSwap);
      }
      return 0;
    case DType::kFloat64:
      for (size_t i = 0; i < count; ++i) storeUnaligned<double>(dst + 8 * i, static_cast<double>(src[i]), kSwap);
      return 0;
    case DType::kBit: {
      size_t bad = 0;
      for (size_t i = 0; i < count; ++i) {
        const float v = src[i];
        if (v != 0.0f && v != 1.0f) ++bad;
        dst[i] = (v != 0.0f && !std::isnan(v)) ? 1 : 0;
      }
      return bad;
    }
  }
  return 0;
}

size_t decodeIndices(DType dtype, const uint8_t* src, size_t count, uint64_t* dst) {
  switch (dtype) {
    case DType::kInt8: return decodeIndicesAs<int8_t>(src, count, dst);
    case DType::kInt16: return decodeIndicesAs<int16_t>(src, count, dst);
    case DType::kInt32: return decodeIndicesAs<int32_t>(src, count, dst);
    case DType::kInt64: return decodeIndicesAs<int64_t>(src, count, dst);
    case DType::kUint8: return decodeIndicesAs<uint8_t>(src, count, dst);
    case DType::kUint16: return decodeIndicesAs<uint16_t>(src, count, dst);
    case DType::kUint32: return decodeIndicesAs<uint32_t>(src, count, dst);
    case DType::kUint64: return decodeIndicesAs<uint64_t>(src, count, dst);
    default: return 0;  // not an integer type: callers check isInteger() first
  }
}

// ---------------------------------------------------------------------------
// Archive

Archive::Archive(const std::string& path) : path_(path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) fail(path, "does not exist");
  if (std::filesystem::is_directory(status)) {
    is_directory_ = true;
    listDirectory();
  } else {
    map_ = MappedFile(path);
    map_.adviseSequential();  // members are read front to back (several at once: that is fine)
    file_bytes_ = map_.size();
    listZip();
    stripTopFolder();
  }
  std::sort(members_.begin(), members_.end(), [](const Member& a, const Member& b) { return a.name < b.name; });
  for (size_t i = 1; i < members_.size(); ++i)
    if (members_[i].name == members_[i - 1].name) fail(path_, "member " + members_[i].name + " appears twice");
}

Archive::~Archive() {
  if (zip_) zip_discard(zip_);
}

void Archive::listDirectory() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path root(path_);
  fs::recursive_directory_iterator it(root, fs::directory_options::none, ec);
  if (ec) fail(path_, "cannot list directory: " + ec.message());
  for (; it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) fail(path_, "cannot list directory: " + ec.message());
    const fs::directory_entry& entry = *it;
    const std::string raw_name = entry.path().lexically_relative(root).generic_string();
    const std::string name = printable(raw_name);
    std::error_code kind_ec;
    if (entry.is_directory(kind_ec)) continue;
    if (!entry.is_regular_file(kind_ec) || name != raw_name) {
      notes_.push_back("ignored " + name + (name != raw_name ? " (control characters in its name)" : " (not a regular file)"));
      continue;
    }
    Member m;
    m.name = name;
    m.size = entry.file_size(kind_ec);
    if (kind_ec) fail(path_, "cannot stat " + name + ": " + kind_ec.message());
    m.stored_size = m.size;
    m.in_place = true;
    m.file_path = entry.path().string();
    file_bytes_ += m.size;
    members_.push_back(std::move(m));
  }
}

void Archive::listZip() {
  const uint8_t* d = map_.data();
  const uint64_t n = map_.size();
  if (n < kEndOfCentralDirBytes)
    fail(path_, "is not a zip archive (" + std::to_string(n) + " bytes, too short for an end of central directory record)");

  // The end of central directory record is the last one in the file; a zip
  // comment of up to 65535 bytes may follow it.
  uint64_t eocd = UINT64_MAX;
  const uint64_t lowest = n > kEndOfCentralDirBytes + 0xffff ? n - kEndOfCentralDirBytes - 0xffff : 0;
  for (uint64_t p = n - kEndOfCentralDirBytes + 1; p-- > lowest;) {
    if (le32(d + p) == kEndOfCentralDirSignature && p + kEndOfCentralDirBytes + le16(d + p + 20) <= n) {
      eocd = p;
      break;
    }
  }
  if (eocd == UINT64_MAX) fail(path_, "no zip end of central directory record (not a zip archive, or truncated)");

  uint64_t disk = le16(d + eocd + 4);
  uint64_t directory_disk = le16(d + eocd + 6);
  uint64_t entries = le16(d + eocd + 10);
  uint64_t directory_size = le32(d + eocd + 12);
  uint64_t directory_offset = le32(d + eocd + 16);
  uint64_t directory_limit = eocd;  // the central directory ends before this
  if (entries == 0xffff || directory_size == 0xffffffff || directory_offset == 0xffffffff) {
    // ZIP64 (APPNOTE 4.3.14-15): a locator right before the record points at
    // the zip64 end of central directory record with 64-bit fields.
    if (eocd < kZip64LocatorBytes || le32(d + eocd - kZip64LocatorBytes) != kZip64LocatorSignature)
      failAt(path_, eocd, "zip end of central directory asks for zip64 but no zip64 locator precedes it");
    const uint64_t locator = eocd - kZip64LocatorBytes;
    const uint64_t record = le64(d + locator + 8);
    if (record > locator || locator - record < kZip64EndOfCentralDirBytes ||
        le32(d + record) != kZip64EndOfCentralDirSignature)
      failAt(path_, locator, "zip64 locator points to byte " + std::to_string(record) +
                                 ", where there is no zip64 end of central directory record");
    disk = le32(d + record + 16);
    directory_disk = le32(d + record + 20);
    entries = le64(d + record + 32);
    directory_size = le64(d + record + 40);
    directory_offset = le64(d + record + 48);
    directory_limit = record;
  }
  if (disk != 0 || directory_disk != 0) fail(path_, "multi-disk zip archives are not supported");
  if (directory_offset > directory_limit || directory_size > directory_limit - directory_offset)
    failAt(path_, eocd, "zip central directory (" + std::to_string(directory_size) + " bytes at byte " +
                            std::to_string(directory_offset) + ") lies outside the file (truncated?)");
  if (entries > directory_size / kCentralHeaderBytes)
    failAt(path_, eocd, "zip central directory of " + std::to_string(directory_size) + " bytes cannot hold " +
                            std::to_string(entries) + " entries");

  members_.reserve(static_cast<size_t>(entries));
  const uint64_t end = directory_offset + directory_size;
  uint64_t p = directory_offset;
  for (uint64_t index = 0; index < entries; ++index) {
    if (end - p < kCentralHeaderBytes || le32(d + p) != kCentralHeaderSignature)
      failAt(path_, p, "expected zip central directory entry " + std::to_string(index) + " of " +
                           std::to_string(entries));
    const uint16_t flags = le16(d + p + 8);
    const uint16_t method = le16(d + p + 10);
    uint64_t compressed = le32(d + p + 20);
    uint64_t size = le32(d + p + 24);
    const uint64_t name_length = le16(d + p + 28);
    const uint64_t extra_length = le16(d + p + 30);
    const uint64_t comment_length = le16(d + p + 32);
    const uint16_t start_disk = le16(d + p + 34);
    uint64_t local = le32(d + p + 42);
    const uint64_t entry_bytes = kCentralHeaderBytes + name_length + extra_length + comment_length;
    if (entry_bytes > end - p)
      failAt(path_, p, "zip central directory entry " + std::to_string(index) + " runs past the central directory");
    const std::string raw_name(reinterpret_cast<const char*>(d + p + kCentralHeaderBytes), name_length);
    const std::string name = printable(raw_name);

    // The zip64 extra field holds, in this order, whichever of the sizes and
    // the local header offset are 0xffffffff in the fixed fields.
    uint64_t q = p + kCentralHeaderBytes + name_length;
    const uint64_t extra_end = q + extra_length;
    while (extra_end - q >= 4) {
      const uint16_t id = le16(d + q);
      const uint64_t length = le16(d + q + 2);
      if (length > extra_end - q - 4) failAt(path_, q, "zip extra field of member " + name + " runs past its entry");
      if (id == kZip64ExtraId) {
        uint64_t r = q + 4;
        const uint64_t r_end = r + length;
        auto take = [&](uint64_t& value) {
          if (r_end - r < 8) failAt(path_, r, "zip64 extra field of member " + name + " is too short");
          value = le64(d + r);
          r += 8;
        };
        if (size == 0xffffffff) take(size);
        if (compressed == 0xffffffff) take(compressed);
        if (local == 0xffffffff) take(local);
      }
      q += 4 + length;
    }
    p += entry_bytes;
    if (start_disk != 0 && start_disk != 0xffff) fail(path_, "multi-disk zip archives are not supported");
    if (name.empty() || name.back() == '/') continue;  // folder entry
    if (name != raw_name) {
      notes_.push_back("ignored member " + name + " (control characters in its name)");
      continue;
    }

    // The local header repeats the name and has its own extra field; the
    // data follows it and must end before the central directory.
    if (local > directory_offset || directory_offset - local < kLocalHeaderBytes)
      failAt(path_, p - entry_bytes, "member " + name + ": local header offset " + std::to_string(local) +
                                         " is outside the archive data");
    if (le32(d + local) != kLocalHeaderSignature)
      failAt(path_, local, "member " + name + ": no local file header signature");
    const uint64_t local_name_length = le16(d + local + 26);
    const uint64_t local_extra_length = le16(d + local + 28);
    const uint64_t data = local + kLocalHeaderBytes + local_name_length + local_extra_length;
    if (data > directory_offset || compressed > directory_offset - data)
      failAt(path_, local, "member " + name + ": " + std::to_string(compressed) + " bytes of data from byte " +
                               std::to_string(data) + " run past the start of the central directory (truncated?)");
    if (local_name_length != name_length || std::memcmp(d + local + kLocalHeaderBytes, name.data(), name_length) != 0)
      failAt(path_, local, "member " + name + ": local file header holds a different name");
    if (method == 0 && compressed != size)
      failAt(path_, local, "stored member " + name + ": compressed size " + std::to_string(compressed) +
                               " differs from size " + std::to_string(size));
    Member m;
    m.name = name;
    m.size = size;
    m.stored_size = compressed;
    m.method = method;
    m.encrypted = (flags & 1u) != 0;
    m.in_place = method == 0 && !m.encrypted;
    m.data_offset = data;
    m.zip_index = static_cast<int64_t>(index);
    members_.push_back(std::move(m));
  }
}

void Archive::stripTopFolder() {
  if (find("header.json")) return;
  std::string folder;
  int candidates = 0;
  for (const Member& m : members_) {
    const size_t slash = m.name.find('/');
    if (slash == std::string::npos || m.name.substr(slash + 1) != "header.json") continue;
    if (m.name.substr(0, slash) == "__MACOSX") continue;  // resource forks added by macOS' zip
    folder = m.name.substr(0, slash + 1);
    ++candidates;
  }
  if (candidates != 1) return;  // the reader reports the missing (or ambiguous) header.json
  std::vector<Member> kept;
  for (Member& m : members_) {
    if (m.name.compare(0, folder.size(), folder) == 0) {
      m.name.erase(0, folder.size());
      kept.push_back(std::move(m));
    } else {
      notes_.push_back("ignored member " + m.name + " (outside the TRX folder " + folder + ")");
    }
  }
  members_ = std::move(kept);
}

const Member* Archive::find(std::string_view name) const {
  for (const Member& m : members_)
    if (m.name == name) return &m;
  return nullptr;
}

std::string Archive::readWhole(const Member& member, uint64_t max_bytes) {
  if (member.size > max_bytes)
    fail(path_, "member " + member.name + " holds " + std::to_string(member.size) + " bytes, more than the " +
                    std::to_string(max_bytes) + " expected at most");
  auto reader = open(member);
  const uint8_t* p = reader->next(static_cast<size_t>(member.size));
  std::string bytes(reinterpret_cast<const char*>(p), static_cast<size_t>(member.size));
  reader->finish();
  return bytes;
}

zip* Archive::libzip() {
  if (zip_) return zip_;
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* source = zip_source_buffer_create(map_.data(), map_.size(), 0, &error);
  zip_t* z = source ? zip_open_from_source(source, ZIP_RDONLY, &error) : nullptr;
  if (!z) {
    if (source) zip_source_free(source);
    const std::string message = zip_error_strerror(&error);
    zip_error_fini(&error);
    fail(path_, "libzip cannot open the archive: " + message);
  }
  zip_error_fini(&error);
  // libzip numbers entries in central directory order, as listZip() does;
  // check that both read the same directory before trusting the indices.
  const zip_int64_t count = zip_get_num_entries(z, 0);
  for (const Member& m : members_) {
    zip_stat_t st;
    zip_stat_init(&st);
    if (m.zip_index >= count || zip_stat_index(z, static_cast<zip_uint64_t>(m.zip_index), ZIP_FL_ENC_RAW, &st) != 0 ||
        !(st.valid & ZIP_STAT_NAME) || !std::string_view(st.name).ends_with(m.name) || st.size != m.size ||
        st.comp_size != m.stored_size) {
      zip_discard(z);
      fail(path_, "libzip reads member " + m.name + " differently from the zip central directory");
    }
  }
  zip_ = z;
  return zip_;
}

std::unique_ptr<MemberReader> Archive::open(const Member& member) {
  std::unique_ptr<MemberReader> reader(new MemberReader(path_, member));
  if (member.encrypted) reader->failMember("encrypted zip members are not supported");
  if (is_directory_) {
    reader->own_map_ = MappedFile(member.file_path);
    if (reader->own_map_.size() != member.size) reader->failMember("file changed size while being read");
    reader->own_map_.adviseSequential();
    reader->base_ = reader->own_map_.data();
    reader->map_ = &reader->own_map_;
    reader->map_offset_ = 0;
  } else if (member.in_place) {
    reader->base_ = map_.data() + member.data_offset;
    reader->map_ = &map_;
    reader->map_offset_ = member.data_offset;
  } else {
    zip* z = libzip();
    reader->file_ = zip_fopen_index(z, static_cast<zip_uint64_t>(member.zip_index), 0);
    if (!reader->file_)
      reader->failMember("cannot open (compression method " + std::to_string(member.method) + "): " + zip_strerror(z));
  }
  return reader;
}

// ---------------------------------------------------------------------------
// MemberReader

MemberReader::~MemberReader() {
  if (file_) zip_fclose(file_);
}

void MemberReader::failMember(const std::string& message) const {
  fail(archive_path_, "member " + member_.name + ": " + message);
}

const uint8_t* MemberReader::next(size_t bytes) {
  static const uint8_t kNothing = 0;
  if (bytes > member_.size - consumed_)
    failMember("holds " + std::to_string(member_.size) + " bytes, cannot read " + std::to_string(bytes) +
               " more from byte " + std::to_string(consumed_));
  if (bytes == 0) return &kNothing;
  if (map_) {
    // The bytes before this call are done with; drop them from the process
    // now and then (the returned range stays mapped).
    if (consumed_ - released_up_to_ >= kReleaseStep) {
      map_->release(map_offset_ + released_up_to_, map_offset_ + consumed_);
      released_up_to_ = consumed_;
    }
    const uint8_t* p = base_ + consumed_;
    consumed_ += bytes;
    return p;
  }
  if (buffer_.size() < bytes) buffer_.resize(bytes);
  size_t got = 0;
  while (got < bytes) {
    const zip_int64_t r = zip_fread(file_, buffer_.data() + got, bytes - got);
    if (r < 0) failMember(std::string("cannot inflate: ") + zip_file_strerror(file_));
    if (r == 0)
      failMember("data ends after " + std::to_string(consumed_ + got) + " bytes, the zip directory says " +
                 std::to_string(member_.size));
    got += static_cast<size_t>(r);
  }
  consumed_ += bytes;
  return buffer_.data();
}

void MemberReader::finish() {
  if (!file_ || consumed_ != member_.size) return;
  // Reading at the end makes libzip compare the CRC-32 of what it inflated.
  uint8_t extra = 0;
  const zip_int64_t r = zip_fread(file_, &extra, 1);
  if (r < 0) failMember(std::string("corrupt data: ") + zip_file_strerror(file_));
  if (r > 0) failMember("holds more than the " + std::to_string(member_.size) + " bytes the zip directory says");
}

uint64_t MemberReader::fileBytesConsumed() const {
  if (member_.size == 0) return 0;
  return static_cast<uint64_t>(static_cast<long double>(consumed_) * member_.stored_size / member_.size);
}

}  // namespace fibscope::trx
