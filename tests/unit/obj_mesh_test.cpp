// OBJ meshes (io/obj_mesh.h): what a file declares becomes one triangle list
// (every object, polygons triangulated, relative indices), and malformed
// files are one-line Errors naming the file, never a crash or a silently
// changed shape.
#include <gtest/gtest.h>

#include <algorithm>
#include <glm/geometric.hpp>
#include <random>
#include <string>

#include "core/error.h"
#include "io/obj_mesh.h"
#include "test_support.h"

namespace fibscope {
namespace {

// Twice the signed area of the triangle's projection on z = const.
float area2z(glm::vec3 a, glm::vec3 b, glm::vec3 c) { return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x); }

TEST(ObjMesh, readsTrianglesQuadsAndConcavePolygonsOfEveryObject) {
  test::TempDir dir;
  const std::string path = dir.file("cut.obj");
  test::writeBytes(path,
                   "# exported by hand\n"
                   "mtllib cut.mtl\n"
                   "o first\n"
                   "v 0 0 0\n"
                   "v 1 0 0\n"
                   "v 0 1 0\n"
                   "vn 0 0 1\n"
                   "vt 0 0\n"
                   "usemtl skin\n"
                   "s off\n"
                   "f 1/1/1 2/1/1 3/1/1\n"
                   "\n"
                   "g quad\n"
                   "v 10 0 1\r\n"  // Windows line ends too
                   "v 12 0 1\r\n"
                   "v 12 3 1\r\n"
                   "v 10 3 1\r\n"
                   "f 4//1 5//1 6//1 7//1\r\n"
                   "o second\n"
                   "  # an L-shaped hexagon in z = 5, starting at a corner that does not see all the others\n"
                   "v 2 1 5\n"
                   "v 1 1 5\n"
                   "v 1 2 5\n"
                   "v 0 2 5\n"
                   "v 0 0 5\n"
                   "v 2 0 5\n"
                   "v 99 99 99\n"  // declared, unused: kept
                   "f -7 -6 -5 -4 -3 -2\n");
  const TriangleMesh mesh = loadObjMesh(path);
  ASSERT_EQ(mesh.positions.size(), 14u);
  EXPECT_EQ(mesh.positions[4], glm::vec3(12, 0, 1));
  EXPECT_EQ(mesh.positions[13], glm::vec3(99, 99, 99));
  ASSERT_EQ(mesh.triangles.size(), 1u + 2u + 4u);
  EXPECT_EQ(mesh.triangles[0], glm::uvec3(0, 1, 2));

  // Each polygon covered exactly: its own vertices only, every triangle wound
  // like the polygon (counter-clockwise about +z), the areas adding up to the
  // polygon's (so none overlaps another), each centroid inside the polygon.
  float quad_area = 0, l_area = 0;
  for (size_t t = 1; t < mesh.triangles.size(); ++t) {
    const glm::uvec3 tri = mesh.triangles[t];
    const glm::vec3 a = mesh.positions[tri.x], b = mesh.positions[tri.y], c = mesh.positions[tri.z];
    const bool quad = t < 3;
    for (const uint32_t v : {tri.x, tri.y, tri.z}) {
      EXPECT_GE(v, quad ? 3u : 7u);
      EXPECT_LE(v, quad ? 6u : 12u);
    }
    EXPECT_GT(area2z(a, b, c), 0) << "triangle " << t << " wound against its polygon";
    (quad ? quad_area : l_area) += area2z(a, b, c) / 2;
    if (!quad) {
      const glm::vec3 centroid = (a + b + c) / 3.0f;
      EXPECT_TRUE(centroid.x < 1 || centroid.y < 1) << "triangle " << t << " covers the L's notch";
    }
  }
  EXPECT_FLOAT_EQ(quad_area, 6);
  EXPECT_FLOAT_EQ(l_area, 3);
}

TEST(ObjMesh, relativeIndicesCountTheVerticesDeclaredBeforeTheFace) {
  test::TempDir dir;
  const std::string path = dir.file("rel.obj");
  // The second face refers back past vertices declared after the first.
  test::writeBytes(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1\nf -4 -2 -1\nf 4 1 -3\n");
  const TriangleMesh mesh = loadObjMesh(path);
  ASSERT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], glm::uvec3(0, 2, 3));
  EXPECT_EQ(mesh.triangles[2], glm::uvec3(3, 0, 1));
}

TEST(ObjMesh, malformedFilesAreOneLineErrorsNamingTheFile) {
  test::TempDir dir;
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const std::string big_face = [] {
    std::string s, f = "f";
    for (int i = 1; i <= 300; ++i) s += "v " + std::to_string(i) + " 0 0\n", f += " " + std::to_string(i);
    return s + f + "\n";
  }();
  const std::pair<const char*, std::string> cases[] = {
      {"empty", ""},
      {"only comments", "# nothing\n\n   \n"},
      {"vertices, no faces", tri},
      {"garbage", "\x01\x02\xff hello world\nxyz\n"},
      {"index out of range", tri + "f 1 2 4\n"},
      {"relative index out of range", tri + "f -4 -2 -1\n"},
      {"index 0", tri + "f 0 1 2\n"},
      {"index not an integer", tri + "f 1.5 2 3\n"},
      {"index missing", tri + "f /1 2 3\n"},
      {"index beyond int", tri + "f 1 2 99999999999\n"},
      {"NaN coordinate", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"infinite coordinate", "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"absurd coordinate", "v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"coordinate with commas", "v 0,0,0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"two coordinates", "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"word for a coordinate", "v 0 0 zero\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"face of two vertices", tri + "f 1 2\n"},
      {"face of 300 vertices", big_face},
      {"line with index 0 (tinyobjloader's own error)", tri + "l 0 1\nf 1 2 3\n"},
  };
  for (const auto& [what, text] : cases) {
    SCOPED_TRACE(what);
    const std::string path = dir.file("bad.obj");
    test::writeBytes(path, text);
    const std::string message = test::errorOf([&] { loadObjMesh(path); });
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // Where a line is at fault, the message says which.
  test::writeBytes(dir.file("nan.obj"), tri + "v 0 nan 0\nf 1 2 4\n");
  EXPECT_NE(test::errorOf([&] { loadObjMesh(dir.file("nan.obj")); }).find("line 4"), std::string::npos);
  test::writeBytes(dir.file("range.obj"), tri + "f 1 2 3\nf 1 2 9\n");
  EXPECT_NE(test::errorOf([&] { loadObjMesh(dir.file("range.obj")); }).find("line 5: vertex index 9"),
            std::string::npos);

  for (const std::string& path : {dir.file("missing.obj"), dir.path()}) {
    const std::string message = test::errorOf([&] { loadObjMesh(path); });
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  }
}

TEST(ObjMesh, everyTruncatedPrefixAndRandomBytesLoadOrFailCleanly) {
  // A valid file cut anywhere is either a (smaller) valid mesh or an Error,
  // and so is noise: never a crash, a hang or another exception.
  const std::string good =
      "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nf 1 4 3 2\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
  size_t loaded = 0;
  for (size_t n = 0; n <= good.size(); ++n) {
    try {
      const TriangleMesh mesh = parseObjMesh(good.substr(0, n), "prefix");
      ++loaded;
      for (const glm::uvec3& t : mesh.triangles) EXPECT_LT(std::max({t.x, t.y, t.z}), mesh.positions.size());
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("prefix: ", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(loaded, 5u);
  EXPECT_EQ(parseObjMesh(good, "whole").triangles.size(), 6u);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    std::string noise(rng() % 400, '\0');
    const char alphabet[] = "vf -/0123456789.e\n\t#og";
    for (char& c : noise) c = trial % 2 ? char(rng()) : alphabet[rng() % (sizeof alphabet - 1)];
    try {
      parseObjMesh(noise, "noise");
    } catch (const Error&) {
    }
  }
}

}  // namespace
}  // namespace fibscope
