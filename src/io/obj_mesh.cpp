#include "io/obj_mesh.h"

#include <tiny_obj_loader.h>

#include <charconv>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <span>
#include <string_view>

#include "core/error.h"

namespace fibscope {
namespace {

bool isBlank(char c) { return c == ' ' || c == '\t'; }

// The whitespace-separated words of a line after its keyword.
std::vector<std::string_view> words(std::string_view rest) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < rest.size()) {
    while (i < rest.size() && isBlank(rest[i])) ++i;
    const size_t start = i;
    while (i < rest.size() && !isBlank(rest[i])) ++i;
    if (i > start) out.push_back(rest.substr(start, i - start));
  }
  return out;
}

bool parseFiniteNumber(std::string_view word, double& v) {
  if (word.size() > 1 && word[0] == '+') word.remove_prefix(1);  // from_chars refuses a '+'
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  return ec == std::errc() && end == word.data() + word.size() && std::isfinite(v);
}

// tinyobjloader reads what it cannot parse as 0 ("v nan 1,2 x" is the vertex
// 0,1,0; "f 1.5 x 3" the face 1,0,3) and keeps going, so a cut mesh would
// silently lose its shape. This pass over the same lines (split as its
// safeGetline splits them: \n, \r or \r\n) checks every vertex and face line
// strictly first, with line numbers, so that what tinyobjloader returns
// afterwards is what the file says. It also returns the text tinyobjloader
// gets, with the lines a cut mesh ignores made comments: subdivision tags
// ('t', up to 24,576 values each that tinyobjloader copies into every
// shape), skin weights ('vw') and materials.
std::string checkedText(const std::string& text, const std::string& name) {
  std::string out = text;
  size_t line_no = 0, vertices = 0, max_index = 0, max_index_line = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    ++line_no;
    size_t end = pos;
    while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
    const size_t line_start = pos;
    std::string_view line(text.data() + pos, end - pos);
    pos = end + (end < text.size() && text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n' ? 2 : 1);
    line = line.substr(0, line.find('\0'));  // tinyobjloader reads the line as a C string
    size_t lead = 0;
    while (lead < line.size() && isBlank(line[lead])) ++lead;
    line.remove_prefix(lead);
    auto failLine = [&](const std::string& what) { fail(name, "line " + std::to_string(line_no) + ": " + what); };
    auto keyword = [&](std::string_view k) {
      return line.size() > k.size() && line.substr(0, k.size()) == k && isBlank(line[k.size()]);
    };
    if (keyword("v")) {
      const auto values = words(line.substr(2));
      if (values.size() != 3 && values.size() != 4 && values.size() != 6)
        failLine("expected a vertex as 'v X Y Z' (with W or R G B at most), found " + std::to_string(values.size()) +
                 (values.size() == 1 ? " value" : " values"));
      for (size_t k = 0; k < 3; ++k) {
        double v = 0;
        if (!parseFiniteNumber(values[k], v))
          failLine("vertex coordinate '" + std::string(values[k]) + "' is not a finite number");
        if (!(std::fabs(v) <= kMaxObjCoordinateMm))
          failLine("vertex coordinate " + std::string(values[k]) +
                   " is beyond 1e6 mm from the origin (world-space mm expected)");
      }
      for (size_t k = 3; k < values.size(); ++k) {
        double v = 0;
        if (!parseFiniteNumber(values[k], v)) failLine("'" + std::string(values[k]) + "' is not a finite number");
      }
      ++vertices;
    } else if (keyword("f")) {
      const auto corners = words(line.substr(2));
      if (corners.size() < 3) failLine("a face needs at least 3 vertices, found " + std::to_string(corners.size()));
      if (corners.size() > kMaxObjFaceVertices)
        failLine("a face of " + std::to_string(corners.size()) + " vertices (at most " +
                 std::to_string(kMaxObjFaceVertices) + ")");
      for (const std::string_view corner : corners) {
        const std::string_view v = corner.substr(0, corner.find('/'));
        long long index = 0;
        const auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), index);
        if (ec == std::errc::result_out_of_range || (ec == std::errc() && (index > INT_MAX || index < -INT_MAX)))
          failLine("face vertex '" + std::string(corner) + "': an index beyond any vertex count");
        if (ec != std::errc() || p != v.data() + v.size())
          failLine("face vertex '" + std::string(corner) +
                   "' does not start with a vertex index (1, 2, ... or -1, -2, ...)");
        if (index == 0) failLine("face vertex '" + std::string(corner) + "': vertex index 0 (OBJ counts from 1)");
        if (index < 0 && size_t(-index) > vertices)
          failLine("relative vertex index " + std::to_string(index) + " with " + std::to_string(vertices) +
                   " vertices before it");
        // A positive index may name a vertex declared further down.
        if (index > 0 && size_t(index) > max_index) max_index = size_t(index), max_index_line = line_no;
      }
    } else if (keyword("t") || keyword("vw") || keyword("mtllib") || line.substr(0, 6) == "usemtl") {
      out[line_start + lead] = '#';
    }
  }
  if (max_index > vertices)
    fail(name, "line " + std::to_string(max_index_line) + ": vertex index " + std::to_string(max_index) + " with " +
                   std::to_string(vertices) + " vertices in the file");
  return out;
}

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Appends the triangles of one face (vertex indices in the file's order).
// A polygon is ear-clipped in the plane of its Newell normal, so a concave
// one (an L-shaped cap) is covered exactly once with the face's winding; one
// too degenerate to have an ear (self-intersecting, collinear) gets a fan.
void triangulateFace(const std::vector<glm::vec3>& positions, std::span<const uint32_t> face,
                     std::vector<glm::uvec3>& out) {
  if (face.size() == 3) {
    out.emplace_back(face[0], face[1], face[2]);
    return;
  }
  glm::dvec3 normal(0);
  for (size_t k = 0; k < face.size(); ++k) {
    const glm::dvec3 a = positions[face[k]], b = positions[face[(k + 1) % face.size()]];
    normal += glm::cross(a, b);
  }
  std::vector<uint32_t> left(face.begin(), face.end());
  if (glm::length(normal) > 0) {
    normal = glm::normalize(normal);
    // (u, v, normal) right-handed: the face's counter-clockwise turn about
    // its normal is counter-clockwise in (u, v).
    const glm::dvec3 helper = std::fabs(normal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, normal)), v = glm::cross(normal, u);
    auto flat = [&](uint32_t i) {
      const glm::dvec3 p = positions[i];
      return glm::dvec2(glm::dot(p, u), glm::dot(p, v));
    };
    while (left.size() > 3) {
      bool clipped = false;
      for (size_t k = 0; k < left.size() && !clipped; ++k) {
        const size_t kp = (k + left.size() - 1) % left.size(), kn = (k + 1) % left.size();
        const glm::dvec2 a = flat(left[kp]), b = flat(left[k]), c = flat(left[kn]);
        if (!(cross2(b - a, c - b) > 0)) continue;  // reflex or flat corner
        bool empty = true;
        for (size_t j = 0; j < left.size() && empty; ++j) {
          if (j == kp || j == k || j == kn) continue;
          const glm::dvec2 p = flat(left[j]);
          if (p == a || p == b || p == c) continue;  // a repeated vertex does not block
          empty = !(cross2(b - a, p - a) >= 0 && cross2(c - b, p - b) >= 0 && cross2(a - c, p - c) >= 0);
        }
        if (!empty) continue;
        out.emplace_back(left[kp], left[k], left[kn]);
        left.erase(left.begin() + ptrdiff_t(k));
        clipped = true;
      }
      if (!clipped) break;
    }
  }
  for (size_t k = 1; k + 1 < left.size(); ++k) out.emplace_back(left[0], left[k], left[k + 1]);
}

}  // namespace

TriangleMesh parseObjMesh(const std::string& text, const std::string& name) {
  const std::string checked = checkedText(text, name);
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // ours handles concave polygons (and counts nothing in a byte)
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  // tinyobjloader's messages end in newlines, some have several lines: fail()
  // makes them one.
  if (!reader.ParseFromString(checked, "", config)) fail(name, reader.Error());
  if (!reader.Error().empty()) fail(name, reader.Error());

  TriangleMesh mesh;
  const std::vector<tinyobj::real_t>& v = reader.GetAttrib().vertices;
  mesh.positions.reserve(v.size() / 3);
  for (size_t i = 0; i + 2 < v.size(); i += 3) {
    const glm::vec3 p(v[i], v[i + 1], v[i + 2]);
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
      fail(name, "vertex " + std::to_string(i / 3 + 1) + " has a non-finite coordinate");
    mesh.positions.push_back(p);
  }
  std::vector<uint32_t> face;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const std::vector<tinyobj::index_t>& indices = shape.mesh.indices;
    size_t at = 0;
    for (const unsigned char count : shape.mesh.num_face_vertices) {
      if (count < 3 || at + count > indices.size())
        fail(name, "object '" + shape.name + "': face vertex counts do not match its indices");
      face.clear();
      for (size_t k = 0; k < count; ++k) {
        const int index = indices[at + k].vertex_index;
        if (index < 0 || size_t(index) >= mesh.positions.size())
          fail(name, "object '" + shape.name + "': vertex index " + std::to_string(index + 1) + " out of range (" +
                         std::to_string(mesh.positions.size()) + " vertices)");
        face.push_back(uint32_t(index));
      }
      at += count;
      triangulateFace(mesh.positions, face, mesh.triangles);
    }
    if (at != indices.size()) fail(name, "object '" + shape.name + "': face vertex counts do not match its indices");
  }
  if (mesh.triangles.empty()) fail(name, "no faces (a cut mesh needs triangles or polygons: 'f' lines)");
  return mesh;
}

TriangleMesh loadObjMesh(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) fail(path, "no such file");
  if (!std::filesystem::is_regular_file(status)) fail(path, "not a regular file");
  const uint64_t bytes = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  if (bytes > kMaxObjFileBytes)
    fail(path, std::to_string(bytes) + " bytes: larger than a cut mesh can be (" + std::to_string(kMaxObjFileBytes) +
                   " bytes at most)");
  std::ifstream in(path, std::ios::binary);
  if (!in) failErrno(path, "cannot open");
  std::string text(bytes, '\0');
  if (!in.read(text.data(), std::streamsize(bytes)) || in.gcount() != std::streamsize(bytes))
    fail(path, "could not read all of its " + std::to_string(bytes) + " bytes");
  return parseObjMesh(text, path);
}

}  // namespace fibscope
