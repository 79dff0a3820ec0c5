// Cuts of the virtual dissection (DESIGN.md section 2): clip planes, a slab
// and closed meshes that hide parts of fibers, as data. The renderer applies
// them (the cull and a per-pixel discard); here are their values, their
// spec text and the exact segment clipping the CPU reference rasteriser uses.
//
// Spec text (the command line; roi_set.h stores the same values in JSON):
//   --clip-plane PX,PY,PZ,NX,NY,NZ   a point on the plane and its normal (mm)
//   --slab T or T:axial|coronal|sagittal
//                                    thickness in mm, optionally following an
//                                    anatomy slice instead of the focal plane
//   --cut-mesh SPEC:inside|outside   cut_mesh.h's SPEC, culling what lies
//                                    inside the mesh or outside it
#pragma once

#include <glm/vec3.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace fibscope {

// A fiber point p is KEPT when dot(p - point, normal) >= 0: the normal
// points into the half-space that stays visible; the plane itself is kept.
struct ClipPlane {
  glm::vec3 point{0};
  glm::vec3 normal{0, 0, 1};  // unit
};
inline constexpr size_t kMaxClipPlanes = 6;  // active at once (the GPU cull's slots)

bool planeKeeps(const ClipPlane& plane, const glm::vec3& p);

// A slab keeps what lies within thickness_mm / 2 of its plane; which plane
// (the view's focal plane, or the anatomy slice it follows) the renderer
// decides.
struct Slab {
  float thickness_mm = 0;  // > 0
  std::string follow;      // "", "axial", "coronal" or "sagittal"
};

// A closed mesh (cut_mesh.h's spec: an OBJ path or a built-in shape) hiding
// what lies inside it (cull_inside) or outside it.
struct MeshCut {
  std::string spec;
  bool cull_inside = true;
};

// The cuts in effect at once (enabled ones only: roi_set.h keeps the rest).
struct CutSet {
  std::vector<ClipPlane> planes;  // at most kMaxClipPlanes
  std::optional<Slab> slab;
  std::vector<MeshCut> meshes;
  bool empty() const { return planes.empty() && !slab && meshes.empty(); }
};

// Each throws Error "SPEC: ..." (one line: what was expected) for anything
// but the syntax above: a wrong number of values, a non-finite one, a zero
// normal, a thickness <= 0, an unknown follow or cull word, a bad built-in
// mesh. parseMeshCut does not open an OBJ file (cutMeshFromSpec does).
// Safe on untrusted text.
ClipPlane parseClipPlane(std::string_view spec);
// A plane from raw values: the normal is normalised; Error "WHERE: ..."
// for a zero or non-finite one.
ClipPlane makeClipPlane(const glm::vec3& point, const glm::vec3& normal, const std::string& where);
Slab parseSlab(std::string_view spec);
bool isSlabFollow(std::string_view follow);
MeshCut parseMeshCut(std::string_view spec);
// The spec text of each (parse gives the value back, to float precision).
std::string clipPlaneSpec(const ClipPlane& plane);
std::string meshCutSpec(const MeshCut& cut);

// The part of segment a -> b that every plane keeps, as parameters
// 0 <= t0 <= t1 <= 1 of a + t (b - a), or nullopt when none of it is kept.
// Exact clipping against each half-space in turn (in double: t = d_a / (d_a
// - d_b) where the signed distances d change sign); a segment lying in a
// plane is kept (boundaries are kept), and t0 == t1 where only one point
// is. No planes: the whole segment.
std::optional<std::pair<float, float>> clipSegment(const glm::vec3& a, const glm::vec3& b,
                                                   const std::vector<ClipPlane>& planes);

}  // namespace fibscope
