// An SvoTree on disk (the viewer's octree cache, issue 16 item 5): every
// member of the tree, so a tree read back is the tree written, nodes and
// decoration byte for byte.
//
// Layout (little-endian): the magic "FSVOTREE", the format version (u32),
// then the tree's members in the order of svoTreeFields (svo_file.cpp; the
// reader and the writer share that one list, so a new member of SvoTree is
// added there once and kSvoFileVersion bumped), arrays as a u64 element
// count then the elements, and last the CRC-32C (u32) of every byte before
// it. Written under a temporary name and renamed (OutputFile), so a crash
// never leaves a half file under the final name.
#pragma once

#include <cstdint>
#include <string>

#include "svo/svo_build.h"

namespace fibscope {

inline constexpr char kSvoFileMagic[8] = {'F', 'S', 'V', 'O', 'T', 'R', 'E', 'E'};
// Bump when svoTreeFields or the meaning of a member changes.
// 2: the level-of-detail segments (SvoTree::lod).
inline constexpr uint32_t kSvoFileVersion = 2;

// Writes `tree` to `path` atomically (replacing a file there). Throws Error
// naming the path when it cannot be written.
void writeSvoTree(const std::string& path, const SvoTree& tree);

// Reads a tree writeSvoTree wrote. Safe on untrusted input: throws one
// Error naming `path` (and the byte offset where it applies) for a short
// or long file, a wrong magic or version, counts beyond the file, a
// checksum mismatch, or a tree whose node references leave its arrays
// (node or decoration index out of range, a leaf list running past the
// decoration, more than kSvoMaxLevels levels, a voxel not > 0, a
// level-of-detail entry per child block), and for segment indices (lists,
// level of detail) at or past `segment_count`: the tubes the tree is
// traced with (UINT64_MAX: not checked).
SvoTree readSvoTree(const std::string& path, uint64_t segment_count = UINT64_MAX);

}  // namespace fibscope
