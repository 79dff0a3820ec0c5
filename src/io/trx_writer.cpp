// TRX writer, streamed.
//
// Chunks are appended as they come to one file per array in a temporary
// directory next to the output (".NAME.tmpdir-PID-N"): positions, offsets,
// dps/ and dpv/. finish() adds the final offset (the spec's sentinel equal
// to NB_VERTICES), the groups, data per group and header.json, then either
// zips the directory with every member stored (no compression, so readers
// can map the arrays in place) into ".NAME.tmp-PID-N" and renames that onto
// the output, or renames the directory itself into place. Until then
// nothing exists under the output name, and the destructor removes what
// was written.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zip.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/byte_order.h"
#include "core/error.h"
#include "core/interrupt_cleanup.h"
#include "core/output_file.h"
#include "io/trx_format.h"
#include "io/writer.h"

namespace fibscope {
namespace {

namespace fs = std::filesystem;

// A hidden name next to `path` that no other writer uses: ".NAME.TAG-PID-N".
std::string hiddenSibling(const std::string& path, const std::string& tag) {
  static std::atomic<unsigned> counter{0};
  const fs::path p(path);
  const std::string dir = p.has_parent_path() ? p.parent_path().string() + "/" : std::string();
  return dir + "." + p.filename().string() + "." + tag + "-" + std::to_string(::getpid()) + "-" +
         std::to_string(counter++);
}

// A path removed (with its contents) on destruction unless released.
class ScopedPath {
 public:
  ScopedPath() = default;
  // Register before creating the path (core/interrupt_cleanup.h).
  explicit ScopedPath(std::string path) : path_(std::move(path)) { registerTemporaryPath(path_); }
  ~ScopedPath() {
    std::error_code ec;
    if (path_.empty()) return;
    fs::remove_all(path_, ec);
    unregisterTemporaryPath(path_);
  }
  ScopedPath(const ScopedPath&) = delete;
  ScopedPath& operator=(const ScopedPath&) = delete;
  ScopedPath& operator=(ScopedPath&& other) noexcept {
    std::swap(path_, other.path_);
    return *this;
  }
  const std::string& path() const { return path_; }
  // The path was renamed into place: nothing to remove any more.
  void release() {
    if (!path_.empty()) unregisterTemporaryPath(path_);
    path_.clear();
  }

 private:
  std::string path_;
};

// Renames `from` onto `to`. A file replaces a file atomically; when either is
// a directory the old one is first moved aside, then removed.
void replacePath(const std::string& from, const std::string& to) {
  std::error_code ec;
  const bool to_exists = fs::exists(fs::symlink_status(to, ec));
  if (to_exists && (fs::is_directory(from, ec) || fs::is_directory(fs::symlink_status(to, ec)))) {
    const std::string aside = hiddenSibling(to, "old");
    if (::rename(to.c_str(), aside.c_str()) != 0) failErrno(to, "cannot move the existing output aside");
    if (::rename(from.c_str(), to.c_str()) != 0) {
      const int saved = errno;
      (void)::rename(aside.c_str(), to.c_str());
      errno = saved;
      failErrno(to, "cannot rename the temporary output into place");
    }
    fs::remove_all(aside, ec);
    return;
  }
  if (::rename(from.c_str(), to.c_str()) != 0) failErrno(to, "cannot rename the temporary output into place");
}

void fsyncPath(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) failErrno(path, "cannot open for fsync");
  const int r = ::fsync(fd);
  ::close(fd);
  if (r != 0) failErrno(path, "fsync failed");
}

// JSON number for a float: its shortest decimal form ("0.1", not the
// double expansion 0.10000000149011612).
double shortestDouble(float v) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, v);
  return std::strtod(std::string(text, result.ptr).c_str(), nullptr);
}

struct ArrayOut {
  std::string name;
  uint32_t components = 1;
  trx::DType dtype = trx::DType::kFloat32;
  std::string member;  // "dps/weight.float32"
  std::unique_ptr<OutputFile> file;
  uint64_t unfit = 0;  // values saturated because the dtype cannot hold them
};

class TrxWriter final : public TractogramWriter {
 public:
  TrxWriter(const std::string& path, const TractogramHeader& like, const WriterOptions& options);
  void write(const Tractogram& chunk) override;
  void finish() override;
  void setGroups(std::vector<Group> groups) override;
  void renumberGroups(std::vector<Group> groups) override;

 private:
  std::unique_ptr<OutputFile> createMember(const std::string& member);
  void setUpArrays(const std::vector<DataArray>& declared, const char* folder, std::vector<ArrayOut>& out);
  void checkArrays(const std::vector<DataArray>& given, const std::vector<ArrayOut>& expected, const char* what) const;
  void appendValues(ArrayOut& out, const std::vector<float>& values);
  void writePositions(const std::vector<float>& positions);
  void writeGroups();
  void writeDataPerGroup();
  void writeHeader();
  void zipInto(const std::string& zip_path) const;

  std::string path_;
  TractogramHeader like_;
  WriterOptions options_;
  trx::DType position_dtype_ = trx::DType::kFloat32;
  // Declared before the files so that it is destroyed after them.
  ScopedPath temp_;
  std::vector<std::string> members_;  // files in temp_, in the order they go into the zip
  std::unique_ptr<OutputFile> positions_;
  std::unique_ptr<OutputFile> offsets_;
  std::vector<ArrayOut> per_streamline_;
  std::vector<ArrayOut> per_point_;
  uint64_t streamlines_ = 0;
  uint64_t points_ = 0;
  std::array<float, 3> low_ = {INFINITY, INFINITY, INFINITY};
  std::array<float, 3> high_ = {-INFINITY, -INFINITY, -INFINITY};
  std::vector<uint8_t> scratch_;
  bool finished_ = false;
};

TrxWriter::TrxWriter(const std::string& path, const TractogramHeader& like, const WriterOptions& options)
    : path_(path), like_(like), options_(options) {
  while (path_.size() > 1 && path_.back() == '/') path_.pop_back();
  if (path_.empty()) fail(path, "empty output path");
  checkOverwrite(path_, options_.overwrite);
  const auto dtype = trx::parseDType(options_.trx_position_dtype);
  if (!dtype || !trx::isFloat(*dtype))
    fail(path_, "TRX positions must be float16, float32 or float64, not '" + options_.trx_position_dtype + "'");
  position_dtype_ = *dtype;

  const std::string temp = hiddenSibling(path_, "tmpdir");
  ScopedPath dir(temp);
  if (::mkdir(temp.c_str(), 0755) != 0) {
    dir.release();  // not ours to remove
    failErrno(path_, "cannot create temporary directory " + temp);
  }
  temp_ = std::move(dir);

  offsets_ = createMember("offsets.uint64");
  positions_ = createMember(trx::memberFileName("positions", 3, position_dtype_));
  setUpArrays(like_.per_streamline, "dps", per_streamline_);
  setUpArrays(like_.per_point, "dpv", per_point_);
}

std::unique_ptr<OutputFile> TrxWriter::createMember(const std::string& member) {
  const size_t slash = member.rfind('/');
  if (slash != std::string::npos) {
    std::error_code ec;
    fs::create_directories(temp_.path() + "/" + member.substr(0, slash), ec);
    if (ec) fail(path_, "cannot create temporary folder for " + member + ": " + ec.message());
  }
  members_.push_back(member);
  return std::make_unique<OutputFile>(temp_.path() + "/" + member, false);
}

void TrxWriter::setUpArrays(const std::vector<DataArray>& declared, const char* folder, std::vector<ArrayOut>& out) {
  for (const DataArray& array : declared) {
    if (!trx::isValidArrayName(array.name))
      fail(path_, std::string(folder) + " array name '" + array.name + "' cannot be a TRX member name");
    if (array.components == 0) fail(path_, std::string(folder) + " array '" + array.name + "' has 0 components");
    for (const ArrayOut& other : out)
      if (other.name == array.name) fail(path_, std::string("two ") + folder + " arrays are named '" + array.name + "'");
    ArrayOut a;
    a.name = array.name;
    a.components = array.components;
    const auto dtype = trx::parseDType(array.dtype);
    if (dtype) {
      a.dtype = *dtype;
    } else {
      warn(path_ + ": " + folder + " array '" + array.name + "' has dtype '" + array.dtype +
           "', which TRX lacks; stored as float32");
    }
    a.member = std::string(folder) + "/" + trx::memberFileName(a.name, a.components, a.dtype);
    a.file = createMember(a.member);
    out.push_back(std::move(a));
  }
}

void TrxWriter::checkArrays(const std::vector<DataArray>& given, const std::vector<ArrayOut>& expected,
                            const char* what) const {
  bool same = given.size() == expected.size();
  for (size_t i = 0; same && i < given.size(); ++i)
    same = given[i].name == expected[i].name && given[i].components == expected[i].components;
  if (!same)
    fail(path_, std::string("chunk's ") + what + " arrays (" + std::to_string(given.size()) +
                    ") differ from those the writer was created with (" + std::to_string(expected.size()) + ")");
}

void TrxWriter::appendValues(ArrayOut& out, const std::vector<float>& values) {
  scratch_.resize(values.size() * trx::dtypeSize(out.dtype));
  out.unfit += trx::encodeFromFloat(out.dtype, values.data(), values.size(), scratch_.data());
  out.file->write(scratch_.data(), scratch_.size());
}

void TrxWriter::writePositions(const std::vector<float>& positions) {
  for (size_t i = 0; i < positions.size(); ++i) {
    const float v = positions[i];
    if (!std::isfinite(v))
      fail(path_, "vertex " + std::to_string(points_ + i / 3) + " has a non-finite coordinate, which TRX cannot hold");
    low_[i % 3] = std::min(low_[i % 3], v);
    high_[i % 3] = std::max(high_[i % 3], v);
  }
  if (position_dtype_ == trx::DType::kFloat32 && kHostIsLittleEndian) {
    positions_->write(positions.data(), positions.size() * sizeof(float));
    return;
  }
  scratch_.resize(positions.size() * trx::dtypeSize(position_dtype_));
  if (trx::encodeFromFloat(position_dtype_, positions.data(), positions.size(), scratch_.data()) != 0)
    fail(path_, "a coordinate exceeds float16's range (±65504 mm); write float32 positions instead");
  positions_->write(scratch_.data(), scratch_.size());
}

void TrxWriter::write(const Tractogram& chunk) {
  if (finished_) fail(path_, "internal error: write() after finish()");
  const std::string invalid = chunk.validate();
  if (!invalid.empty()) fail(path_, "internal error: inconsistent chunk: " + invalid);
  // An empty chunk carries no values, so it need not hold the header's arrays.
  if (chunk.streamlineCount() == 0) return;
  checkArrays(chunk.per_streamline, per_streamline_, "per-streamline");
  checkArrays(chunk.per_point, per_point_, "per-point");

  writePositions(chunk.positions);
  // Offsets are global: this chunk's start plus the points written before it.
  const size_t n = chunk.streamlineCount();
  scratch_.resize(n * sizeof(uint64_t));
  for (size_t i = 0; i < n; ++i) storeUnaligned<uint64_t>(scratch_.data() + 8 * i, points_ + chunk.offsets[i], !kHostIsLittleEndian);
  offsets_->write(scratch_.data(), scratch_.size());
  for (size_t a = 0; a < per_streamline_.size(); ++a) appendValues(per_streamline_[a], chunk.per_streamline[a].values);
  for (size_t a = 0; a < per_point_.size(); ++a) appendValues(per_point_[a], chunk.per_point[a].values);
  streamlines_ += n;
  points_ += chunk.pointCount();
}

void TrxWriter::setGroups(std::vector<Group> groups) {
  if (finished_) fail(path_, "internal error: setGroups() after finish()");
  // The data per group of the header's groups goes with them.
  std::erase_if(like_.properties, [](const auto& kv) { return kv.first.rfind("dpg/", 0) == 0; });
  like_.groups = std::move(groups);
}

void TrxWriter::renumberGroups(std::vector<Group> groups) {
  if (finished_) fail(path_, "internal error: renumberGroups() after finish()");
  // The data per group of the groups dropped goes with them.
  std::erase_if(like_.properties, [&](const auto& kv) {
    if (kv.first.rfind("dpg/", 0) != 0) return false;
    const size_t slash = kv.first.find('/', 4);
    const std::string group = kv.first.substr(4, slash == std::string::npos ? std::string::npos : slash - 4);
    return std::none_of(groups.begin(), groups.end(), [&](const Group& g) { return g.name == group; });
  });
  like_.groups = std::move(groups);
}

void TrxWriter::writeGroups() {
  for (const Group& group : like_.groups) {
    if (!trx::isValidArrayName(group.name)) fail(path_, "group name '" + group.name + "' cannot be a TRX member name");
    scratch_.resize(group.streamlines.size() * sizeof(uint32_t));
    for (size_t i = 0; i < group.streamlines.size(); ++i) {
      if (group.streamlines[i] >= streamlines_)
        fail(path_, "group '" + group.name + "' lists streamline " + std::to_string(group.streamlines[i]) +
                        ", but only " + std::to_string(streamlines_) + " were written");
      storeUnaligned<uint32_t>(scratch_.data() + 4 * i, group.streamlines[i], !kHostIsLittleEndian);
    }
    auto file = createMember("groups/" + trx::memberFileName(group.name, 1, trx::DType::kUint32));
    file->write(scratch_.data(), scratch_.size());
    file->commit();
  }
}

// Data per group comes from a TRX reader as properties "dpg/GROUP/FILE"
// holding a JSON list of values; anything malformed is dropped with a warning.
void TrxWriter::writeDataPerGroup() {
  if (like_.format != "trx") return;
  for (const auto& [key, value] : like_.properties) {
    if (key.rfind("dpg/", 0) != 0) continue;
    const size_t slash = key.find('/', 4);
    const std::string group = slash == std::string::npos ? std::string() : key.substr(4, slash - 4);
    const std::string file_name = slash == std::string::npos ? std::string() : key.substr(slash + 1);
    const bool group_written = std::any_of(like_.groups.begin(), like_.groups.end(),
                                           [&](const Group& g) { return g.name == group; });
    const auto parsed = trx::parseMemberName(file_name, nullptr);
    const nlohmann::json values = nlohmann::json::parse(value, nullptr, false);
    bool numbers = values.is_array();
    for (size_t i = 0; numbers && i < values.size(); ++i) numbers = values[i].is_number();
    if (!group_written || !trx::isValidArrayName(file_name) || !parsed || !numbers ||
        values.size() % parsed->components != 0) {
      warn(path_ + ": dropped data per group '" + key + "' (malformed, or its group is not written)");
      continue;
    }
    std::vector<float> floats;
    for (const auto& v : values) floats.push_back(v.get<float>());
    scratch_.resize(floats.size() * trx::dtypeSize(parsed->dtype));
    trx::encodeFromFloat(parsed->dtype, floats.data(), floats.size(), scratch_.data());
    auto file = createMember(key);
    file->write(scratch_.data(), scratch_.size());
    file->commit();
  }
}

void TrxWriter::writeHeader() {
  nlohmann::ordered_json header;
  std::array<float, 16> affine = like_.space.voxel_to_rasmm;
  std::array<int64_t, 3> dimensions = {like_.space.dimensions[0], like_.space.dimensions[1], like_.space.dimensions[2]};
  if (!like_.space.known) {
    // No reference image: a 1 mm grid, axes along RAS, whose voxel 0 lies
    // at the floor of the points' minimum and which covers all points, so
    // tools that check streamlines against the volume keep them.
    affine = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    dimensions = {1, 1, 1};
    if (points_ > 0) {
      for (int axis = 0; axis < 3; ++axis) {
        const double origin = std::floor(static_cast<double>(low_[axis]));
        affine[axis * 4 + 3] = static_cast<float>(origin);
        dimensions[axis] = std::min<int64_t>(65535, static_cast<int64_t>(std::ceil(high_[axis] - origin)) + 1);
      }
    }
    warn(path_ + ": no reference space known; header.json gets a 1 mm RAS grid covering the points (origin " +
         std::to_string(affine[3]) + ", " + std::to_string(affine[7]) + ", " + std::to_string(affine[11]) +
         " mm, DIMENSIONS " + std::to_string(dimensions[0]) + " x " + std::to_string(dimensions[1]) + " x " +
         std::to_string(dimensions[2]) + ")");
  }
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (int r = 0; r < 4; ++r) {
    nlohmann::ordered_json row = nlohmann::ordered_json::array();
    for (int c = 0; c < 4; ++c) row.push_back(shortestDouble(affine[r * 4 + c]));
    rows.push_back(row);
  }
  header["VOXEL_TO_RASMM"] = rows;
  header["DIMENSIONS"] = dimensions;
  header["NB_VERTICES"] = points_;
  header["NB_STREAMLINES"] = streamlines_;
  // Keys of a TRX header we do not interpret go back as they came.
  if (like_.format == "trx") {
    for (const auto& [key, value] : like_.properties) {
      if (key.rfind("dpg/", 0) == 0 || header.contains(key)) continue;
      const auto parsed = nlohmann::ordered_json::parse(value, nullptr, false);
      header[key] = parsed.is_discarded() ? nlohmann::ordered_json(value) : parsed;
    }
  }
  members_.insert(members_.begin(), "header.json");
  OutputFile file(temp_.path() + "/header.json", false);
  file.write(header.dump(2) + "\n");
  file.commit();
}

void TrxWriter::zipInto(const std::string& zip_path) const {
  int code = 0;
  zip_t* archive = zip_open(zip_path.c_str(), ZIP_CREATE | ZIP_EXCL, &code);
  if (!archive) {
    zip_error_t error;
    zip_error_init_with_code(&error, code);
    const std::string message = zip_error_strerror(&error);
    zip_error_fini(&error);
    fail(path_, "cannot create zip archive " + zip_path + ": " + message);
  }
  auto abandon = [&](const std::string& what) {
    const std::string message = zip_strerror(archive);
    zip_discard(archive);
    fail(path_, what + ": " + message);
  };
  for (const std::string& member : members_) {
    zip_source_t* source = zip_source_file(archive, (temp_.path() + "/" + member).c_str(), 0, -1);
    if (!source) abandon("cannot read temporary member " + member);
    const zip_int64_t index = zip_file_add(archive, member.c_str(), source, ZIP_FL_ENC_UTF_8);
    if (index < 0) {
      zip_source_free(source);
      abandon("cannot add member " + member);
    }
    // Stored, not deflated: readers map stored members in place.
    if (zip_set_file_compression(archive, static_cast<zip_uint64_t>(index), ZIP_CM_STORE, 0) != 0)
      abandon("cannot store member " + member);
  }
  if (zip_close(archive) != 0) abandon("cannot write zip archive");
}

void TrxWriter::finish() {
  if (finished_) fail(path_, "internal error: finish() called twice");
  finished_ = true;
  uint8_t sentinel[8];
  storeUnaligned<uint64_t>(sentinel, points_, !kHostIsLittleEndian);
  offsets_->write(sentinel, sizeof sentinel);
  offsets_->commit();
  positions_->commit();
  for (auto* arrays : {&per_streamline_, &per_point_}) {
    for (ArrayOut& a : *arrays) {
      a.file->commit();
      if (a.unfit > 0)
        warn(path_ + ": " + a.member + ": " + std::to_string(a.unfit) + " values did not fit " +
             trx::dtypeName(a.dtype) + " and were saturated");
    }
  }
  writeGroups();
  writeDataPerGroup();
  writeHeader();

  checkOverwrite(path_, options_.overwrite);
  if (options_.trx_zip) {
    ScopedPath zip_file(hiddenSibling(path_, "tmp"));
    zipInto(zip_file.path());
    fsyncPath(zip_file.path());
    replacePath(zip_file.path(), path_);
    zip_file.release();
  } else {
    replacePath(temp_.path(), path_);
    temp_.release();
  }
}

}  // namespace

std::unique_ptr<TractogramWriter> createTrxWriter(const std::string& path, const TractogramHeader& like,
                                                  const WriterOptions& options) {
  return std::make_unique<TrxWriter>(path, like, options);
}

}  // namespace fibscope
