#include "select/cut_mesh.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/trigonometric.hpp>
#include <map>
#include <unordered_map>

#include "core/error.h"

namespace fibscope {
namespace {

glm::dvec3 toVec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

// A box from its centre and three half-extent vectors: one quad per side,
// each wound so that its normal points away from the centre.
TriangleMesh boxMesh(const glm::dvec3& centre, const glm::dvec3 (&half)[3]) {
  TriangleMesh mesh;
  for (int corner = 0; corner < 8; ++corner) {  // bit k: + or - along axis k
    glm::dvec3 p = centre;
    for (int k = 0; k < 3; ++k) p += ((corner >> k) & 1 ? 1.0 : -1.0) * half[k];
    mesh.positions.emplace_back(p);
  }
  for (int k = 0; k < 3; ++k) {
    const int i = 1 << ((k + 1) % 3), j = 1 << ((k + 2) % 3);
    for (const int side : {0, 1 << k}) {
      uint32_t quad[4] = {uint32_t(side), uint32_t(side | i), uint32_t(side | i | j), uint32_t(side | j)};
      const glm::dvec3 a = mesh.positions[quad[0]], b = mesh.positions[quad[1]], c = mesh.positions[quad[2]];
      const glm::dvec3 out = (side ? 1.0 : -1.0) * half[k];
      if (glm::dot(glm::cross(b - a, c - a), out) < 0) std::swap(quad[1], quad[3]);
      mesh.triangles.emplace_back(quad[0], quad[1], quad[2]);
      mesh.triangles.emplace_back(quad[0], quad[2], quad[3]);
    }
  }
  return mesh;
}

// The solid angle of triangle (a, b, c) seen from the origin (van Oosterom
// and Strackee 1983), signed: > 0 when its normal cross(b - a, c - a)
// points away from the origin (a . (b x c) is a . that normal), as the
// triangles of an outward mesh do seen from inside.
double solidAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double num = glm::dot(a, glm::cross(b, c));
  const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return 2 * std::atan2(num, den);
}

std::string plural(size_t n, const char* what) { return std::to_string(n) + " " + what + (n == 1 ? "" : "s"); }

}  // namespace

TriangleMesh makeBoxMesh(const BoxRegion& box) {
  const glm::dvec3 lo = toVec(box.min), hi = toVec(box.max), h = (hi - lo) / 2.0;
  const glm::dvec3 half[3] = {{h.x, 0, 0}, {0, h.y, 0}, {0, 0, h.z}};
  return boxMesh((lo + hi) / 2.0, half);
}

TriangleMesh makeBoxMesh(const OrientedBoxRegion& box) {
  glm::dvec3 half[3];
  for (int k = 0; k < 3; ++k) half[k] = box.half[k] * toVec(box.axes[k]);
  return boxMesh(toVec(box.center), half);
}

TriangleMesh makeSphereMesh(const glm::vec3& centre, float radius, int subdivisions) {
  assert(subdivisions >= 0 && subdivisions <= kMaxSphereSubdivisions && radius > 0);
  // The icosahedron: the cyclic permutations of (0, +-1, +-phi).
  const double phi = (1 + std::sqrt(5.0)) / 2;
  std::vector<glm::dvec3> unit = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0},
                                  {0, -1, phi}, {0, 1, phi}, {0, -1, -phi}, {0, 1, -phi},
                                  {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  for (glm::dvec3& p : unit) p = glm::normalize(p);
  std::vector<glm::uvec3> faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                   {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    // One midpoint per edge, shared by its two triangles: the mesh stays closed.
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoint;
    auto mid = [&](uint32_t i, uint32_t j) {
      const auto key = std::minmax(i, j);
      const auto [it, added] = midpoint.try_emplace(key, uint32_t(unit.size()));
      if (added) unit.push_back(glm::normalize(unit[i] + unit[j]));
      return it->second;
    };
    std::vector<glm::uvec3> next;
    next.reserve(faces.size() * 4);
    for (const glm::uvec3& f : faces) {
      const uint32_t ab = mid(f.x, f.y), bc = mid(f.y, f.z), ca = mid(f.z, f.x);
      next.insert(next.end(), {{f.x, ab, ca}, {f.y, bc, ab}, {f.z, ca, bc}, {ab, bc, ca}});
    }
    faces.swap(next);
  }
  TriangleMesh mesh;
  mesh.positions.reserve(unit.size());
  for (const glm::dvec3& u : unit) mesh.positions.emplace_back(glm::dvec3(centre) + double(radius) * u);
  mesh.triangles = std::move(faces);
  return mesh;
}

double sphereMeshAngle(int subdivisions) {
  if (subdivisions == 0) {
    const double phi2 = (3 + std::sqrt(5.0)) / 2;  // phi^2 = phi + 1
    return std::acos(phi2 / (std::sqrt(3.0) * std::sqrt(phi2 + 1)));
  }
  return glm::radians(44.0) / std::ldexp(1.0, subdivisions);
}

MeshClosure checkClosure(const TriangleMesh& mesh) {
  // Weld bit-identical positions (+0 and -0 alike) to one id.
  struct Bits {
    uint32_t x, y, z;
    bool operator==(const Bits&) const = default;
  };
  struct BitsHash {
    size_t operator()(const Bits& b) const {
      return size_t((uint64_t(b.x) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(b.y) * 0xC2B2AE3D27D4EB4Full) ^ b.z);
    }
  };
  std::unordered_map<Bits, uint32_t, BitsHash> welded;
  std::vector<uint32_t> id(mesh.positions.size());
  for (uint32_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::vec3 p = mesh.positions[v] + glm::vec3(0.0f);  // -0 + 0 = +0
    id[v] =
        welded
            .try_emplace({std::bit_cast<uint32_t>(p.x), std::bit_cast<uint32_t>(p.y), std::bit_cast<uint32_t>(p.z)}, v)
            .first->second;
  }
  // Per undirected edge (lo, hi): how often it is traversed lo -> hi and hi -> lo.
  std::unordered_map<uint64_t, std::pair<uint32_t, uint32_t>> edges;
  MeshClosure c;
  for (const glm::uvec3& t : mesh.triangles) {
    const uint32_t v[3] = {id[t.x], id[t.y], id[t.z]};
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
      ++c.degenerate_triangles;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = v[k], b = v[(k + 1) % 3];
      auto& count = edges[(uint64_t(std::min(a, b)) << 32) | std::max(a, b)];
      (a < b ? count.first : count.second) += 1;
    }
  }
  c.edges = edges.size();
  for (const auto& [key, count] : edges) {
    const uint32_t uses = count.first + count.second;
    if (uses == 1)
      ++c.open_edges;
    else if (uses > 2)
      ++c.non_manifold_edges;
    else if (count.first != 1)
      ++c.inconsistent_edges;
  }
  return c;
}

std::string closureWarning(const MeshClosure& c, const std::string& name) {
  if (c.closed()) return "";
  std::string what;
  auto add = [&](size_t n, const char* label) {
    if (n) what += (what.empty() ? "" : ", ") + plural(n, label);
  };
  add(c.open_edges, "open edge");
  add(c.non_manifold_edges, "edge shared by 3+ triangles");
  add(c.inconsistent_edges, "edge with inconsistent orientation");
  return name + ": not closed (" + what + "): the cut may be approximate";
}

double meshVolume(const TriangleMesh& mesh) {
  double six_v = 0;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    six_v += glm::dot(a, glm::cross(b, c));
  }
  return six_v / 6;
}

bool orientOutward(TriangleMesh& mesh) {
  if (!(meshVolume(mesh) < 0)) return false;
  for (glm::uvec3& t : mesh.triangles) std::swap(t.y, t.z);
  return true;
}

double windingNumber(const TriangleMesh& mesh, const glm::vec3& p) {
  const glm::dvec3 o = p;
  double sum = 0;
  for (const glm::uvec3& t : mesh.triangles)
    sum += solidAngle(glm::dvec3(mesh.positions[t.x]) - o, glm::dvec3(mesh.positions[t.y]) - o,
                      glm::dvec3(mesh.positions[t.z]) - o);
  return sum / (4 * glm::pi<double>());
}

bool pointInsideMesh(const TriangleMesh& mesh, const glm::vec3& p) { return std::fabs(windingNumber(mesh, p)) >= 0.5; }

std::vector<MeshHit> rayMeshHits(const TriangleMesh& mesh, const glm::vec3& origin, const glm::vec3& dir) {
  std::vector<MeshHit> hits;
  const glm::dvec3 o = origin, d0 = dir;
  if (!(glm::length(d0) > 0)) return hits;
  const glm::dvec3 d = glm::normalize(d0);
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    const glm::dvec3 e1 = b - a, e2 = c - a, q = glm::cross(d, e2);
    const double det = glm::dot(e1, q);
    if (det == 0) continue;  // parallel to the ray (or degenerate)
    const glm::dvec3 s = o - a;
    const double u = glm::dot(s, q) / det;
    if (u < 0 || u > 1) continue;
    const glm::dvec3 r = glm::cross(s, e1);
    const double v = glm::dot(d, r) / det, dist = glm::dot(e2, r) / det;
    if (v < 0 || u + v > 1 || dist < 0) continue;
    hits.push_back({float(dist), glm::dot(glm::cross(e1, e2), d) < 0});
  }
  std::stable_sort(hits.begin(), hits.end(),
                   [](const MeshHit& x, const MeshHit& y) { return x.distance < y.distance; });
  return hits;
}

bool isBuiltinMeshSpec(std::string_view spec) {
  return spec.starts_with("box:") || spec.starts_with("obox:") || spec.starts_with("sphere:");
}

TriangleMesh cutMeshFromSpec(const std::string& spec) {
  TriangleMesh mesh;
  if (isBuiltinMeshSpec(spec)) {
    const Region region = parseRegion(spec);
    if (const auto* b = std::get_if<BoxRegion>(&region)) return makeBoxMesh(*b);
    if (const auto* o = std::get_if<OrientedBoxRegion>(&region)) return makeBoxMesh(*o);
    if (const auto* s = std::get_if<SphereRegion>(&region))
      return makeSphereMesh({s->center[0], s->center[1], s->center[2]}, s->radius, kCutSphereSubdivisions);
    fail(spec, "not a mesh (expected box:, obox:, sphere: or an OBJ file)");
  }
  mesh = loadObjMesh(spec);
  if (checkClosure(mesh).closed()) orientOutward(mesh);
  return mesh;
}

}  // namespace fibscope
