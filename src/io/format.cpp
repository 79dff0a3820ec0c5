// Format dispatch by file extension.
#include <algorithm>
#include <filesystem>

#include "core/error.h"
#include "core/huge_pages.h"
#include "io/reader.h"
#include "io/writer.h"

namespace fibscope {
namespace {

std::string extensionOf(const std::string& path) {
  std::string p = path;
  while (p.size() > 1 && p.back() == '/') p.pop_back();
  std::string ext = std::filesystem::path(p).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

void TractogramReader::startChunk(Tractogram& chunk) const {
  auto follow = [](std::vector<DataArray>& arrays, const std::vector<DataArray>& declared) {
    bool same = arrays.size() == declared.size();
    for (size_t i = 0; same && i < arrays.size(); ++i)
      same = arrays[i].name == declared[i].name && arrays[i].components == declared[i].components &&
             arrays[i].dtype == declared[i].dtype;
    if (!same) {
      arrays.clear();
      for (const auto& a : declared) arrays.push_back({a.name, a.components, a.dtype, {}});
    }
  };
  follow(chunk.per_streamline, header_.per_streamline);
  follow(chunk.per_point, header_.per_point);
  chunk.clear();
}

std::unique_ptr<TractogramReader> openTractogram(const std::string& path) {
  const std::string ext = extensionOf(path);
  if (ext == ".gz") {
    // DSI Studio saves .trk.gz and .tt.gz; both readers read gzip.
    // The others are mapped or read at offsets: say so rather than fail on
    // the compressed bytes.
    const std::string inner = extensionOf(path.substr(0, path.size() - 3));
    if (inner == ".trk") return openTrk(path);
    if (inner == ".tt") return openTinyTrack(path);  // DSI Studio's own format
    fail(path, "a gzip-compressed '" + inner + "' file is not read (only .trk.gz and .tt.gz are): decompress it first (gunzip -k)");
  }
  if (ext == ".tt") return openTinyTrack(path);
  if (ext == ".tck") return openTck(path);
  if (ext == ".trk") return openTrk(path);
  if (ext == ".trx") return openTrx(path);
  if (ext == ".vtk") return openVtk(path);
  if (ext == ".vtp") return openVtp(path);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec) && std::filesystem::exists(std::filesystem::path(path) / "header.json", ec))
    return openTrx(path);
  fail(path, "unknown tractogram format '" + ext + "' (expected .tck, .trk, .trk.gz, .tt.gz, .trx, .vtk or .vtp)");
}

Tractogram readAllStreamlines(TractogramReader& reader) {
  Tractogram all;
  for (const auto& a : reader.header().per_streamline) all.per_streamline.push_back({a.name, a.components, a.dtype, {}});
  for (const auto& a : reader.header().per_point) all.per_point.push_back({a.name, a.components, a.dtype, {}});
  Tractogram chunk;
  bool reserved = false;
  while (reader.read(chunk)) {
    if (!reserved) {
      // Reserve for the whole file from the first chunk's points per byte
      // (+3 %): growing by doubling would copy the points twice and touch
      // twice the pages (first touches cost ~5 us a page on the VMs
      // measured), a third of the time of reading a large .tck.
      reserved = true;
      std::error_code ec;
      const uint64_t file_bytes = std::filesystem::is_regular_file(reader.header().path, ec)
                                      ? std::filesystem::file_size(reader.header().path, ec)
                                      : 0;
      if (!ec && file_bytes > 0 && reader.bytesRead() > 0 && chunk.pointCount() > 0) {
        const double points_per_byte = double(chunk.pointCount()) / double(reader.bytesRead());
        const double lines_per_byte = double(chunk.streamlineCount()) / double(reader.bytesRead());
        const double scale = double(file_bytes) * 1.03;
        // Never more than the file could hold (12 bytes a point at least
        // in every format read here), so a malformed first chunk cannot
        // make this allocate absurdly.
        const size_t points = size_t(std::min(points_per_byte * scale, double(file_bytes) / 4.0));
        all.positions.reserve(3 * points);
        // Back the points with huge pages where the kernel allows it: one
        // fault per 2 MiB instead of per 4 KiB (the faults were a fifth of
        // reading a 250 MB .tck into memory).
        adviseHugePages(all.positions.data(), all.positions.capacity() * sizeof(float));
        all.offsets.reserve(size_t(std::min(lines_per_byte * scale, double(file_bytes) / 4.0)) + 1);
      }
    }
    all.append(chunk);
  }
  return all;
}

Tractogram readTractogram(const std::string& path, TractogramHeader* header, std::vector<std::string>* warnings) {
  auto reader = openTractogram(path);
  Tractogram all = readAllStreamlines(*reader);
  if (header) *header = reader->header();
  if (warnings) warnings->insert(warnings->end(), reader->warnings().begin(), reader->warnings().end());
  return all;
}

std::unique_ptr<TractogramWriter> createTractogramWriter(const std::string& path, const TractogramHeader& like,
                                                         const WriterOptions& options) {
  const std::string ext = extensionOf(path);
  if (ext == ".tck") return createTckWriter(path, like, options);
  if (ext == ".trk") return createTrkWriter(path, like, options);
  if (ext == ".trx") {
    WriterOptions o = options;
    if (!path.empty() && path.back() == '/') o.trx_zip = false;
    return createTrxWriter(path, like, o);
  }
  fail(path, "cannot write format '" + ext + "' (writable: .tck, .trk, .trx)");
}

void writeTractogram(const std::string& path, const Tractogram& tractogram, const TractogramHeader& like,
                     const WriterOptions& options, std::vector<std::string>* warnings) {
  // The arrays come from the tractogram itself when `like` names none.
  TractogramHeader header = like;
  auto describe = [](const std::vector<DataArray>& arrays) {
    std::vector<DataArray> names;
    for (const auto& a : arrays) names.push_back({a.name, a.components, a.dtype, {}});
    return names;
  };
  if (header.per_streamline.empty()) header.per_streamline = describe(tractogram.per_streamline);
  if (header.per_point.empty()) header.per_point = describe(tractogram.per_point);
  auto writer = createTractogramWriter(path, header, options);
  writer->write(tractogram);
  writer->finish();
  if (warnings) warnings->insert(warnings->end(), writer->warnings().begin(), writer->warnings().end());
}

}  // namespace fibscope
