#include "render/fiber_selection.h"

#include <algorithm>
#include <array>
#include <functional>

#include "codec/fbl_codec.h"
#include "codec/fbl_reader.h"
#include "codec/fiblet_decoder.h"
#include "core/error.h"
#include "io/writer.h"
#include "shared/fiblet.h"

namespace fibscope {
namespace {

std::string str(uint64_t v) { return std::to_string(v); }

// Points written per chunk of the .tck writer (bounds memory for a huge
// selection).
constexpr size_t kExportChunkPoints = size_t(1) << 20;

}  // namespace

void FiberSelection::select(uint32_t fiber) {
  fibers_.assign(1, fiber);
  ++revision_;
}

void FiberSelection::toggle(uint32_t fiber) {
  const auto it = std::find(fibers_.begin(), fibers_.end(), fiber);
  if (it == fibers_.end())
    fibers_.push_back(fiber);
  else
    fibers_.erase(it);
  ++revision_;
}

void FiberSelection::add(uint32_t fiber) {
  if (contains(fiber)) return;
  fibers_.push_back(fiber);
  ++revision_;
}

void FiberSelection::remove(uint32_t fiber) {
  const auto it = std::find(fibers_.begin(), fibers_.end(), fiber);
  if (it == fibers_.end()) return;
  fibers_.erase(it);
  ++revision_;
}

void FiberSelection::clear() {
  if (fibers_.empty()) return;
  fibers_.clear();
  ++revision_;
}

bool FiberSelection::contains(uint32_t fiber) const {
  // A selection is a handful of clicked fibers: a linear scan beats a set.
  return std::find(fibers_.begin(), fibers_.end(), fiber) != fibers_.end();
}

std::vector<uint32_t> FiberSelection::bitWords(uint64_t fiber_count) const {
  std::vector<uint32_t> words(size_t((fiber_count + 31) / 32), 0u);
  for (const uint32_t f : fibers_)
    if (f < fiber_count) words[f / 32] |= 1u << (f % 32);
  return words;
}

void decodeFibers(const FblFile& file, std::span<const uint32_t> fibers, size_t chunk_points,
                  const std::function<void(const Tractogram&)>& sink) {
  const std::string& path = file.path();
  const FblHeaderFields& h = file.header();
  const CodecParams params = codecParamsFromFbl(h, path);
  const FibletDecoder decoder(params);
  const uint32_t n = params.points_per_fiblet;
  const uint32_t record_bytes = params.recordBytes();

  const auto require = [&](std::string_view name, FblDType dtype) -> const FblSection& {
    const FblSection* s = file.find(name);
    if (!s) fail(path, "no section '" + std::string(name) + "' (a .fbl tractogram needs it)");
    if (s->dtype != dtype || s->components != 1)
      fail(path, "section '" + std::string(name) + "': holds " + fblDTypeName(s->dtype) + " x " + str(s->components) +
                     ", expected " + fblDTypeName(dtype) + " x 1");
    return *s;
  };
  const auto words = file.array<uint32_t>(require(kFblSectionFiblets, FblDType::kUint32));
  const std::span<const uint8_t> records(reinterpret_cast<const uint8_t*>(words.data()), words.size() * 4);
  const auto first_fiblet = file.array<uint64_t>(require(kFblSectionFiberFirstFiblet, FblDType::kUint64));
  // FblFile::open checked both sizes against the header's counts; recheck
  // what the indexing below relies on.
  const uint64_t fiblet_count = records.size() / record_bytes;
  if (first_fiblet.size() != h.fiber_count + 1)
    fail(path, "section 'fiber_first_fiblet': " + str(first_fiblet.size()) + " entries, expected " +
                   str(h.fiber_count + 1));

  // Same checks and arithmetic as the .fbl reader (fbl_reader.cpp), per
  // fiber: the table entries, every fiblet's count and begins/ends flags.
  const uint32_t flags_byte = shader::fibletFlagsByte(n);
  const auto checkFiber = [&](uint64_t fiber) {
    const uint64_t first = first_fiblet[fiber], last = first_fiblet[fiber + 1];
    const std::string where = "section 'fiber_first_fiblet': fiber " + str(fiber);
    if (last < first || last > fiblet_count)
      fail(path, where + " spans fiblets " + str(first) + ".." + str(last) + ", outside the " + str(fiblet_count) +
                     " fiblets or reversed");
    if (last == first) fail(path, where + " has no fiblets");
    if (last - first > kFblMaxFiberPoints) fail(path, where + " has " + str(last - first) + " fiblets, too many");
    uint64_t points = 0;
    for (uint64_t i = first; i < last; ++i) {
      const uint32_t flags = records[i * record_bytes + flags_byte];
      const uint32_t count = shader::fibletCount(flags);
      const std::string at = "section 'fiblets': fiblet " + str(i) + " (fiber " + str(fiber) + "): ";
      if (count < 1 || count > n) fail(path, at + "point count " + str(count) + " outside [1, " + str(n) + "]");
      if (((flags & shader::kFibletFlagBegins) != 0) != (i == first))
        fail(path, at + "begins-fiber flag does not match the fiber's first fiblet");
      if (((flags & shader::kFibletFlagEnds) != 0) != (i + 1 == last))
        fail(path, at + "ends-fiber flag does not match the fiber's last fiblet");
      points += count;
    }
    if (points > kFblMaxFiberPoints) fail(path, where + " has " + str(points) + " points, too many");
  };
  // Every id and fiber is checked before the output is created.
  for (const uint32_t f : fibers) {
    if (f >= h.fiber_count)
      fail(path, "fiber " + str(f) + " does not exist (the file has " + str(h.fiber_count) + " fibers)");
    checkFiber(f);
  }

  Tractogram chunk;
  std::vector<float> xyz_world;
  std::array<float, 3 * shader::kFibletMaxPoints> xyz;
  for (const uint32_t f : fibers) {
    xyz_world.clear();
    for (uint64_t i = first_fiblet[f]; i < first_fiblet[f + 1]; ++i) {
      // checkFiber validated the count, so decode returns it (never 0).
      const uint32_t count = decoder.decode(records.data() + i * record_bytes, xyz.data(), DecodeOrder::Sequential);
      for (uint32_t k = 0; k < count; ++k) {
        // As the .fbl reader and FibletDecoder::decodeAll: world mm in
        // double, rounded to float.
        const auto w = decoder.toWorld(&xyz[3 * k]);
        for (int c = 0; c < 3; ++c) xyz_world.push_back(float(w[c]));
      }
    }
    chunk.addStreamline(xyz_world.data(), xyz_world.size() / 3);
    if (chunk.pointCount() >= chunk_points) {
      sink(chunk);
      chunk.clear();
    }
  }
  if (chunk.streamlineCount() > 0) sink(chunk);
}

void exportFibers(const FblFile& file, std::span<const uint32_t> fibers, const std::string& tck_path,
                  bool overwrite) {
  if (fibers.empty()) fail(tck_path, "no fibers to export (the selection is empty)");
  TractogramHeader like;
  like.format = "tck";
  WriterOptions options;
  options.overwrite = overwrite;
  // The checks run before the first chunk, so a bad id leaves no file.
  std::unique_ptr<TractogramWriter> writer;
  decodeFibers(file, fibers, kExportChunkPoints, [&](const Tractogram& chunk) {
    if (!writer) writer = createTckWriter(tck_path, like, options);
    writer->write(chunk);
  });
  writer->finish();
}

std::optional<float> fiberLengthMm(const FblFile& file, uint64_t fiber) {
  if (fiber >= file.header().fiber_count)
    fail(file.path(), "fiber " + str(fiber) + " does not exist (the file has " + str(file.header().fiber_count) +
                          " fibers)");
  const FblSection* s = file.find(kFblSectionFiberLength);
  if (!s || s->dtype != FblDType::kFloat32 || s->components != 1 || s->element_count != file.header().fiber_count)
    return std::nullopt;
  return file.array<float>(*s)[fiber];
}

}  // namespace fibscope
