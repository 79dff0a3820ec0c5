#include "svo/svo_file.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <type_traits>
#include <vector>

#include "core/checksum.h"
#include "core/error.h"
#include "core/output_file.h"

namespace fibscope {
namespace {

// The members of SvoTree, in file order, for the writer and the reader
// alike (`io` a Writer or a Reader below): the one place to extend when
// SvoTree grows (bump kSvoFileVersion then).
template <typename IO, typename Tree>
void svoTreeFields(IO& io, Tree& t) {
  io.f32(t.grid.origin.x);
  io.f32(t.grid.origin.y);
  io.f32(t.grid.origin.z);
  io.f32(t.grid.voxel);
  io.u32(t.grid.levels);
  io.flag(t.grid.curved);
  io.size(t.leaves);
  io.size(t.leaves_over_4);
  io.size(t.max_segments_per_leaf);
  io.size(t.references);
  io.array(t.nodes, "nodes");
  io.array(t.decoration, "decoration");
  io.array(t.lod, "lod");
}

struct Writer {
  std::vector<uint8_t> bytes;
  void raw(const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    bytes.insert(bytes.end(), b, b + n);
  }
  void f32(const float& v) { raw(&v, 4); }
  void u32(const uint32_t& v) { raw(&v, 4); }
  void flag(const bool& v) {
    const uint32_t w = v ? 1u : 0u;
    raw(&w, 4);
  }
  void size(const size_t& v) {
    const uint64_t w = v;
    raw(&w, 8);
  }
  template <typename T>
  void array(const std::vector<T>& v, const char*) {
    size(v.size());
    raw(v.data(), v.size() * sizeof(T));
  }
};

struct Reader {
  const std::string& path;
  const std::vector<uint8_t>& bytes;
  size_t at = 0;
  size_t end = 0;  // the CRC's offset
  void raw(void* p, size_t n, const char* what) {
    if (n > end - at)
      failAt(path, at, std::string("truncated: ") + what + " needs " + std::to_string(n) + " bytes, " +
                           std::to_string(end - at) + " left");
    std::memcpy(p, bytes.data() + at, n);
    at += n;
  }
  void f32(float& v) { raw(&v, 4, "a float"); }
  void u32(uint32_t& v) { raw(&v, 4, "a u32"); }
  void flag(bool& v) {
    const size_t offset = at;
    uint32_t w = 0;
    raw(&w, 4, "a flag");
    if (w > 1) failAt(path, offset, "expected a flag 0 or 1, found " + std::to_string(w));
    v = w == 1;
  }
  void size(size_t& v) {
    uint64_t w = 0;
    raw(&w, 8, "a count");
    v = size_t(w);
  }
  template <typename T>
  void array(std::vector<T>& v, const char* what) {
    const size_t offset = at;
    uint64_t n = 0;
    raw(&n, 8, "a count");
    // Checked before allocating: a lying count never allocates.
    if (n > (end - at) / sizeof(T))
      failAt(path, offset, std::string("truncated: ") + std::to_string(n) + " " + what + " of " +
                               std::to_string(sizeof(T)) + " bytes do not fit in the " + std::to_string(end - at) +
                               " bytes left");
    v.resize(size_t(n));
    raw(v.data(), size_t(n) * sizeof(T), what);
  }
};

// The references of a tree read from a file stay inside its arrays (the
// tracer follows them without checks).
void validateTree(const std::string& path, const SvoTree& t, uint64_t segment_count) {
  if (!(t.grid.voxel > 0.0f) || !std::isfinite(t.grid.voxel) || !std::isfinite(t.grid.origin.x) ||
      !std::isfinite(t.grid.origin.y) || !std::isfinite(t.grid.origin.z))
    fail(path, "octree: the grid's voxel must be > 0 and its origin finite");
  if (t.grid.levels > shader::kSvoMaxLevels)
    fail(path, "octree: " + std::to_string(t.grid.levels) + " levels, at most " +
                   std::to_string(shader::kSvoMaxLevels));
  if (t.nodes.empty()) fail(path, "octree: no root node");
  size_t leaves = 0;
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const uint32_t type = t.nodes[i].ref & shader::kSvoNodeTypeMask, index = t.nodes[i].ref & shader::kSvoNodeIndexMask;
    const auto bad = [&](const std::string& why) { fail(path, "octree: node " + std::to_string(i) + ": " + why); };
    if (type == shader::kSvoNodeInternal) {
      if (index <= i || uint64_t(index) + 8 > t.nodes.size()) bad("child block " + std::to_string(index) + " out of range");
    } else if (type == shader::kSvoNodeLeaf) {
      if (index >= t.decoration.size() || uint64_t(t.decoration[index]) + 1 > t.decoration.size() - index)
        bad("list at word " + std::to_string(index) + " runs past the decoration");
      ++leaves;
    } else if (type != shader::kSvoNodeEmpty) {
      bad("unknown node type");
    }
  }
  if (leaves != t.leaves)
    fail(path, "octree: the header counts " + std::to_string(t.leaves) + " leaves, the nodes hold " +
                   std::to_string(leaves));
  // One level-of-detail segment per child block (every node but the root).
  if (t.lod.size() != (t.nodes.size() - 1) / 8)
    fail(path, "octree: " + std::to_string(t.lod.size()) + " level-of-detail entries for " +
                   std::to_string((t.nodes.size() - 1) / 8) + " child blocks");
  // Segment indices the tracer reads from the tubes' buffer.
  for (const uint32_t s : t.lod)
    if (s >= segment_count) fail(path, "octree: level-of-detail segment " + std::to_string(s) + " past the tubes' " +
                                           std::to_string(segment_count) + " segments");
  if (segment_count != UINT64_MAX)
    for (size_t i = 0; i < t.nodes.size(); ++i) {
      if ((t.nodes[i].ref & shader::kSvoNodeTypeMask) != shader::kSvoNodeLeaf) continue;
      const uint32_t at = t.nodes[i].ref & shader::kSvoNodeIndexMask;
      for (uint32_t k = 1; k <= t.decoration[at]; ++k)
        if (t.decoration[at + k] >= segment_count)
          fail(path, "octree: node " + std::to_string(i) + " lists segment " + std::to_string(t.decoration[at + k]) +
                         " past the tubes' " + std::to_string(segment_count) + " segments");
    }
}

}  // namespace

void writeSvoTree(const std::string& path, const SvoTree& tree) {
  Writer w;
  w.raw(kSvoFileMagic, sizeof(kSvoFileMagic));
  w.u32(kSvoFileVersion);
  svoTreeFields(w, tree);
  const uint32_t crc = crc32c(w.bytes.data(), w.bytes.size());
  w.u32(crc);
  OutputFile out(path, /*overwrite=*/true);
  out.write(w.bytes.data(), w.bytes.size());
  out.commit();
}

SvoTree readSvoTree(const std::string& path, uint64_t segment_count) {
  std::ifstream in(path, std::ios::binary);
  if (!in) failErrno(path, "cannot open the octree");
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) failErrno(path, "cannot read the octree");
  constexpr size_t kPrefix = sizeof(kSvoFileMagic) + 4;
  if (bytes.size() < kPrefix + 4)
    fail(path, "truncated octree: " + std::to_string(bytes.size()) + " bytes, no header");
  if (std::memcmp(bytes.data(), kSvoFileMagic, sizeof(kSvoFileMagic)) != 0) fail(path, "not an octree file (magic)");
  uint32_t version = 0;
  std::memcpy(&version, bytes.data() + sizeof(kSvoFileMagic), 4);
  if (version != kSvoFileVersion)
    fail(path, "octree format version " + std::to_string(version) + ", expected " + std::to_string(kSvoFileVersion));
  Reader r{path, bytes, kPrefix, bytes.size() - 4};
  SvoTree tree;
  svoTreeFields(r, tree);
  if (r.at != r.end)
    failAt(path, r.at, std::to_string(r.end - r.at) + " bytes after the octree's last member");
  uint32_t stored = 0;
  std::memcpy(&stored, bytes.data() + r.end, 4);
  if (crc32c(bytes.data(), r.end) != stored) failAt(path, r.end, "octree checksum mismatch (a damaged file)");
  validateTree(path, tree, segment_count);
  return tree;
}

}  // namespace fibscope
