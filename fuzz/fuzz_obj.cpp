// libFuzzer target for the OBJ mesh reader (parseObjMesh: tinyobjloader
// behind fibscope's own strict pass over vertex and face lines).
//
// Only fibscope::Error is an accepted outcome, on one line. A mesh that is
// accepted must keep its promises: at least one triangle, every index
// inside the vertex list, every coordinate finite and within
// kMaxObjCoordinateMm. Seeds: fuzz/seeds/obj.sh.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/error.h"
#include "fuzz_support.h"
#include "io/obj_mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const fibscope::TriangleMesh mesh = fibscope::parseObjMesh(text, "input.obj");
    if (mesh.triangles.empty()) std::abort();
    for (const glm::uvec3& t : mesh.triangles)
      if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size()) std::abort();
    for (const glm::vec3& p : mesh.positions)
      for (int k = 0; k < 3; ++k)
        if (!(std::fabs(p[k]) <= fibscope::kMaxObjCoordinateMm)) std::abort();
  } catch (const fibscope::Error& e) {
    fibscope::fuzz::checkMessage(e);
  }
  return 0;
}
