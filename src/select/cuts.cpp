#include "select/cuts.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>

#include "core/error.h"
#include "select/number_list.h"
#include "select/cut_mesh.h"

namespace fibscope {
namespace {

// The shortest text that reads back as the same float.
std::string number(float v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, ec == std::errc() ? end : buf);
}

}  // namespace

bool planeKeeps(const ClipPlane& plane, const glm::vec3& p) { return glm::dot(p - plane.point, plane.normal) >= 0; }

ClipPlane makeClipPlane(const glm::vec3& point, const glm::vec3& normal, const std::string& where) {
  const glm::dvec3 n = normal;
  const double length = glm::length(n);
  if (!(std::isfinite(length) && length > 0)) fail(where, "a clip plane's normal must be non-zero and finite");
  if (!(std::isfinite(point.x) && std::isfinite(point.y) && std::isfinite(point.z)))
    fail(where, "a clip plane's point must be finite");
  return {point, glm::vec3(n / length)};
}

ClipPlane parseClipPlane(std::string_view spec) {
  const std::string text(spec);
  std::vector<double> v;
  if (!parseNumberList(spec, v) || v.size() != 6)
    fail(text, "expected a clip plane as PX,PY,PZ,NX,NY,NZ (a point and the normal of the side kept, mm)");
  for (const double x : v)
    if (!std::isfinite(float(x))) fail(text, "a clip plane's values must be finite floats");
  return makeClipPlane({float(v[0]), float(v[1]), float(v[2])}, {float(v[3]), float(v[4]), float(v[5])}, text);
}

bool isSlabFollow(std::string_view follow) {
  return follow.empty() || follow == "axial" || follow == "coronal" || follow == "sagittal";
}

Slab parseSlab(std::string_view spec) {
  const std::string text(spec);
  const size_t colon = spec.find(':');
  const std::string_view value = spec.substr(0, colon);
  Slab slab;
  if (colon != std::string_view::npos) {
    slab.follow = std::string(spec.substr(colon + 1));
    if (slab.follow.empty() || !isSlabFollow(slab.follow))
      fail(text, "a slab follows axial, coronal or sagittal (or nothing: the focal plane), not '" + slab.follow + "'");
  }
  std::vector<double> v;
  if (!parseNumberList(value, v) || v.size() != 1)
    fail(text, "expected a slab as T or T:axial|coronal|sagittal (thickness in mm)");
  if (!(v[0] > 0 && std::isfinite(float(v[0])) && float(v[0]) > 0)) fail(text, "a slab's thickness must be > 0 mm");
  slab.thickness_mm = float(v[0]);
  return slab;
}

MeshCut parseMeshCut(std::string_view spec) {
  const std::string text(spec);
  const size_t colon = spec.rfind(':');
  const std::string_view side = colon == std::string_view::npos ? std::string_view() : spec.substr(colon + 1);
  if (side != "inside" && side != "outside")
    fail(text,
         "expected a mesh cut as SPEC:inside or SPEC:outside (the side culled; SPEC an OBJ file, "
         "box:X0,Y0,Z0,X1,Y1,Z1, obox:CX,CY,CZ,SX,SY,SZ,AX,AY,AZ or sphere:X,Y,Z,R)");
  MeshCut cut{std::string(spec.substr(0, colon)), side == "inside"};
  if (cut.spec.empty()) fail(text, "no mesh before :" + std::string(side));
  // A built-in shape is checked now; a file when it is loaded.
  if (isBuiltinMeshSpec(cut.spec)) {
    try {
      cutMeshFromSpec(cut.spec);
    } catch (const Error& e) {
      fail(text, e.what());
    }
  }
  return cut;
}

std::string clipPlaneSpec(const ClipPlane& p) {
  return number(p.point.x) + "," + number(p.point.y) + "," + number(p.point.z) + "," + number(p.normal.x) + "," +
         number(p.normal.y) + "," + number(p.normal.z);
}

std::string meshCutSpec(const MeshCut& cut) { return cut.spec + (cut.cull_inside ? ":inside" : ":outside"); }

std::optional<std::pair<float, float>> clipSegment(const glm::vec3& a, const glm::vec3& b,
                                                   const std::vector<ClipPlane>& planes) {
  double t0 = 0, t1 = 1;
  for (const ClipPlane& plane : planes) {
    const glm::dvec3 n = plane.normal, q = plane.point;
    const double da = glm::dot(glm::dvec3(a) - q, n), db = glm::dot(glm::dvec3(b) - q, n);
    if (da >= 0 && db >= 0) continue;
    if (da < 0 && db < 0) return std::nullopt;
    const double t = da / (da - db);  // where the signed distance is 0; da != db here
    if (da < 0)
      t0 = std::max(t0, t);  // entering the kept side
    else
      t1 = std::min(t1, t);  // leaving it
    if (t0 > t1) return std::nullopt;
  }
  return std::pair{float(t0), float(t1)};
}

}  // namespace fibscope
