// The octree file (svo/svo_file.h): a CPU-built tree written and read back
// is the same tree (every member, nodes and decoration byte for byte);
// every truncated prefix, every flipped byte, trailing bytes, another
// version and a checksum-valid tree whose references leave its arrays are
// one-line Errors naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "core/checksum.h"
#include "core/error.h"
#include "svo/svo_build.h"
#include "svo/svo_file.h"
#include "svo_test_scenes.h"
#include "test_support.h"

namespace fibscope {
namespace {

SvoTree smallTree() {
  TubeBuildOptions options;
  options.radius.radius = 0.3f;
  const TubeModel model = buildTubes(test::denseSvoBundle(4), options);
  return buildSvoCpu(model, chooseSvoGrid(model, 0.3f));
}

void expectSameTree(const SvoTree& a, const SvoTree& b) {
  EXPECT_EQ(a.grid.origin.x, b.grid.origin.x);
  EXPECT_EQ(a.grid.origin.y, b.grid.origin.y);
  EXPECT_EQ(a.grid.origin.z, b.grid.origin.z);
  EXPECT_EQ(a.grid.voxel, b.grid.voxel);
  EXPECT_EQ(a.grid.levels, b.grid.levels);
  EXPECT_EQ(a.grid.curved, b.grid.curved);
  EXPECT_EQ(a.leaves, b.leaves);
  EXPECT_EQ(a.leaves_over_4, b.leaves_over_4);
  EXPECT_EQ(a.max_segments_per_leaf, b.max_segments_per_leaf);
  EXPECT_EQ(a.references, b.references);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodeBytes()), 0);
  EXPECT_EQ(a.decoration, b.decoration);
  EXPECT_EQ(a.lod, b.lod);
}

// Rewrites the trailing CRC of `bytes` so that only the content's checks
// can reject it.
void fixChecksum(std::string& bytes) {
  const uint32_t crc = crc32c(bytes.data(), bytes.size() - 4);
  std::memcpy(bytes.data() + bytes.size() - 4, &crc, 4);
}

TEST(SvoFile, aTreeWrittenAndReadBackIsTheSameTree) {
  test::TempDir dir;
  for (const bool curved : {false, true}) {
    SvoTree tree = smallTree();
    tree.grid.curved = curved;
    ASSERT_GT(tree.leaves, 0u);
    const std::string path = dir.file(curved ? "c.svo" : "s.svo");
    writeSvoTree(path, tree);
    expectSameTree(readSvoTree(path), tree);
  }
}

TEST(SvoFile, readRejectsEveryTruncatedPrefixNamingTheFile) {
  test::TempDir dir;
  const std::string path = dir.file("t.svo");
  writeSvoTree(path, smallTree());
  const std::string whole = test::readBytes(path);
  const std::string cut = dir.file("cut.svo");
  // Every prefix through the header and the first records, then ~100 more.
  for (size_t n = 0; n < whole.size(); n += (n < 160 ? 1 : whole.size() / 100 + 1)) {
    test::writeBytes(cut, whole.substr(0, n));
    const std::string e = test::errorOf([&] { readSvoTree(cut); });
    EXPECT_NE(e.find(cut), std::string::npos) << n << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(SvoFile, readRejectsFlippedBytesTrailingBytesAndAnotherVersion) {
  test::TempDir dir;
  const std::string path = dir.file("t.svo");
  writeSvoTree(path, smallTree());
  const std::string whole = test::readBytes(path);
  const std::string bad = dir.file("bad.svo");
  for (size_t i = 0; i < whole.size(); i += (i < 160 ? 1 : whole.size() / 100 + 1)) {
    std::string b = whole;
    b[i] = char(b[i] ^ 0x10);
    test::writeBytes(bad, b);
    EXPECT_NE(test::errorOf([&] { readSvoTree(bad); }).find(bad), std::string::npos) << "byte " << i;
  }
  test::writeBytes(bad, whole + std::string(1, '\0'));
  EXPECT_NE(test::errorOf([&] { readSvoTree(bad); }), "");
  std::string v = whole;
  v[8] = char(kSvoFileVersion + 1);
  fixChecksum(v);
  test::writeBytes(bad, v);
  EXPECT_NE(test::errorOf([&] { readSvoTree(bad); }).find("version"), std::string::npos);
  EXPECT_NE(test::errorOf([&] { readSvoTree(dir.file("missing.svo")); }).find("missing.svo"), std::string::npos);
}

// A tree whose checksum matches but whose references leave its arrays (a
// buggy writer, or a crafted file): the tracer would read out of bounds.
TEST(SvoFile, readRejectsReferencesOutsideTheTree) {
  test::TempDir dir;
  SvoTree tree = smallTree();
  const std::string bad = dir.file("refs.svo");
  SvoTree child = tree;
  child.nodes[0].ref = shader::kSvoNodeInternal | uint32_t(child.nodes.size());
  writeSvoTree(bad, child);
  EXPECT_NE(test::errorOf([&] { readSvoTree(bad); }).find("node 0"), std::string::npos);
  SvoTree list = tree;
  for (shader::SvoNode& n : list.nodes)
    if ((n.ref & shader::kSvoNodeTypeMask) == shader::kSvoNodeLeaf) {
      n.ref = shader::kSvoNodeLeaf | uint32_t(list.decoration.size());
      break;
    }
  writeSvoTree(bad, list);
  EXPECT_NE(test::errorOf([&] { readSvoTree(bad); }).find("decoration"), std::string::npos);
  SvoTree count = tree;
  count.leaves += 1;
  writeSvoTree(bad, count);
  EXPECT_NE(test::errorOf([&] { readSvoTree(bad); }).find("leaves"), std::string::npos);
  SvoTree lod = tree;
  ASSERT_FALSE(lod.lod.empty());
  lod.lod.pop_back();
  writeSvoTree(bad, lod);
  EXPECT_NE(test::errorOf([&] { readSvoTree(bad); }).find("level-of-detail"), std::string::npos);
  // Segment indices against the tubes it is traced with: the tree's own
  // largest index passes, one segment fewer is refused by name.
  const std::string good = dir.file("good.svo");
  writeSvoTree(good, tree);
  uint32_t largest = 0;
  for (const uint32_t s : tree.lod) largest = std::max(largest, s);
  for (const shader::SvoNode& n : tree.nodes)
    if ((n.ref & shader::kSvoNodeTypeMask) == shader::kSvoNodeLeaf) {
      const uint32_t at = n.ref & shader::kSvoNodeIndexMask;
      for (uint32_t k = 1; k <= tree.decoration[at]; ++k) largest = std::max(largest, tree.decoration[at + k]);
    }
  EXPECT_EQ(test::errorOf([&] { readSvoTree(good, uint64_t(largest) + 1); }), "");
  const std::string e = test::errorOf([&] { readSvoTree(good, largest); });
  EXPECT_NE(e.find("past the tubes' " + std::to_string(largest) + " segments"), std::string::npos) << e;
}

}  // namespace
}  // namespace fibscope
