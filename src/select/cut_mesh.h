// Closed triangle meshes as cuts (DESIGN.md section 2, "cuts"): the built-in
// shapes, the closure and orientation checks a cut needs, and the CPU
// references the GPU's front/back depth buffers are tested against.
//
// Orientation: a mesh is outward when every triangle (a, b, c) has its
// normal cross(b - a, c - a) pointing out of the enclosed volume, i.e. its
// vertices counter-clockwise seen from outside; its signed volume is then
// > 0. The built-in meshes are outward; orientOutward() makes a closed,
// consistent one outward.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "io/obj_mesh.h"
#include "select/region.h"

namespace fibscope {

// 8 shared corners, 12 triangles, outward.
TriangleMesh makeBoxMesh(const BoxRegion& box);
TriangleMesh makeBoxMesh(const OrientedBoxRegion& box);

// An icosphere: the icosahedron with every triangle split in 4 for
// `subdivisions` rounds (20 * 4^s triangles, 0 <= s <= kMaxSphereSubdivisions),
// new vertices projected onto the sphere, so every vertex lies ON it and
// the mesh (the convex hull of its vertices) lies INSIDE the analytic
// sphere: between radius r * cos(theta) and r, theta =
// sphereMeshAngle(subdivisions). A point at most r * (1 - cos theta) inside
// the sphere's surface may be outside the mesh; nothing outside the sphere
// is inside it. Outward, closed.
inline constexpr int kMaxSphereSubdivisions = 7;
inline constexpr int kCutSphereSubdivisions = 4;  // the sphere: cut: 5,120 triangles, r (1 - cos theta) < 0.12 % of r
TriangleMesh makeSphereMesh(const glm::vec3& centre, float radius, int subdivisions);
// An upper bound (radians) on the angle, seen from the centre, between a
// face's nearest point and its vertices: for s = 0 the icosahedron's own,
// 37.38 degrees (cos = phi^2 / (sqrt 3 sqrt(phi^2 + 1)), its inradius over its
// circumradius); then 44 / 2^s degrees: measured, the largest angle times
// 2^s grows from 41.8 (s = 1) to 43.8 degrees (s = 7): projecting the
// midpoints makes the faces unequal, so the angle does not quite halve.
double sphereMeshAngle(int subdivisions);

// How the triangles share their edges, with positions welded where they are
// bit-identical (an OBJ that repeats a corner per face is still closed).
// Closed: every undirected edge is used by exactly two triangles that
// traverse it in opposite directions.
struct MeshClosure {
  size_t edges = 0;
  size_t open_edges = 0;            // used by one triangle
  size_t non_manifold_edges = 0;    // used by three or more
  size_t inconsistent_edges = 0;    // by two, in the same direction (one of them is flipped)
  size_t degenerate_triangles = 0;  // two of its corners are one vertex (ignored)
  bool closed() const { return open_edges == 0 && non_manifold_edges == 0 && inconsistent_edges == 0; }
};
MeshClosure checkClosure(const TriangleMesh& mesh);
// "" when closed; else one line: "NAME: not closed (2 open edges, ...): the
// cut may be approximate".
std::string closureWarning(const MeshClosure& closure, const std::string& name);

// The signed enclosed volume (mm^3, divergence theorem): > 0 when outward.
// Meaningful for a closed, consistent mesh only.
double meshVolume(const TriangleMesh& mesh);
// Flips every triangle when the signed volume is < 0; returns whether it did.
bool orientOutward(TriangleMesh& mesh);

// The generalised winding number of the mesh about p (Jacobson et al. 2013:
// the sum of the triangles' signed solid angles / 4 pi, van Oosterom and
// Strackee's formula, in double): 1 inside an outward closed mesh, 0
// outside, -1 inside an inward one, fractional near holes.
double windingNumber(const TriangleMesh& mesh, const glm::vec3& p);
// Whether p lies inside: |winding number| >= 0.5. Chosen over ray parity
// because it needs no ray direction (no ray grazing an edge or a vertex
// counted twice or not at all), works for either global orientation,
// takes the union where closed objects overlap (parity would punch holes),
// and degrades gradually, not along a random ray, where the mesh has a hole
// (closureWarning). Undefined on the surface itself. O(triangles).
bool pointInsideMesh(const TriangleMesh& mesh, const glm::vec3& p);

// Where the ray origin + t * dir (t >= 0) meets the mesh: the distances t
// in mm along normalize(dir), ascending, each with its facing: front when
// the ray enters through the triangle's outward side (dot(normal, dir) < 0),
// back when it leaves. Brute force over every triangle (Moeller-Trumbore in
// double, edges inclusive: a ray through a shared edge or vertex reports
// each triangle, at the same distance; triangles parallel to the ray are
// not hit). The CPU reference of the GPU's front/back depth of a cut mesh.
// dir must be non-zero (an empty list otherwise).
struct MeshHit {
  float distance = 0;
  bool front = false;
};
std::vector<MeshHit> rayMeshHits(const TriangleMesh& mesh, const glm::vec3& origin, const glm::vec3& dir);

// The mesh a --cut-mesh SPEC (without its :inside / :outside) names:
//   box:X0,Y0,Z0,X1,Y1,Z1, obox:CX,...,AZ, sphere:X,Y,Z,R   built in, with
//       region.h's syntax (a sphere of kCutSphereSubdivisions);
//   anything else: the path of an OBJ file (':' allowed; write ./box:x.obj
//       for a file whose name starts like a built-in).
bool isBuiltinMeshSpec(std::string_view spec);
// Throws Error "SPEC: ..." for a bad built-in spec and loadObjMesh's errors
// for a file; the result is oriented outward (orientOutward) when it is
// closed. Safe on untrusted input.
TriangleMesh cutMeshFromSpec(const std::string& spec);

}  // namespace fibscope
