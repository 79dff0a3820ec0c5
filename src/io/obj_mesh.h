// Triangle meshes from Wavefront OBJ files (tinyobjloader), for the mesh
// cuts of the virtual dissection (DESIGN.md section 2, "cuts").
//
// World space as everywhere (RAS+ mm): the file's coordinates are taken as
// they are, no unit or axis conversion.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

namespace fibscope {

// An indexed triangle list. Triangles index `positions`; a triangle's
// vertices in counter-clockwise order seen from the side its normal
// cross(b - a, c - a) points to.
struct TriangleMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
};

// Limits past which a file is refused as absurd rather than read: a cut
// mesh is a surface around a brain region, not a scan of a building.
inline constexpr uint64_t kMaxObjFileBytes = uint64_t(1) << 30;  // 1 GiB of text
inline constexpr double kMaxObjCoordinateMm = 1e6;               // 1 km from the origin
inline constexpr size_t kMaxObjFaceVertices = 255;               // tinyobjloader counts them in a byte

// Every object and group of the file merged into one mesh: its vertex list
// as the file declares it (unused vertices stay), every face triangulated
// (a polygon by ear clipping in its own plane, so concave ones too; a fan
// where the polygon is too degenerate for that), vertex indices only
// (normals, texture coordinates, materials, lines and points are ignored),
// negative indices relative to the vertices declared before the face, as
// OBJ allows.
//
// Safe on untrusted input: throws Error with one line starting with `path`
// for a missing or unreadable file, a file over kMaxObjFileBytes, a vertex
// line that is not 3 finite numbers (or 4 with w, or 6 with a colour), a
// coordinate beyond kMaxObjCoordinateMm, a face of fewer than 3 or more
// than kMaxObjFaceVertices vertices, an index of 0 or out of range, any
// other parse error of tinyobjloader (its message on one line), and a file
// with no face at all. The line number is given where one is known.
TriangleMesh loadObjMesh(const std::string& path);

// The same for OBJ text in memory; `name` stands for the path in messages.
TriangleMesh parseObjMesh(const std::string& text, const std::string& name);

}  // namespace fibscope
