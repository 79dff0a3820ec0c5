// libFuzzer target for the dissection's spec parsers: the text of
// --include/--exclude (parseRegion), --clip-plane, --slab, --cut-mesh and
// --fiber-scalar, which also arrive from ROI-set files and viewer scripts.
//
// The first byte picks the parser, the rest is the spec. Only
// fibscope::Error on one line is an accepted failure. What is accepted must
// keep its promises: finite values, a unit normal, a positive thickness,
// MIN <= MAX, and a spec printed back that parses to a value printed the
// same (one trip may round to the printed digits; a second may not change
// anything). A built-in cut mesh is built and checked as fuzz_obj checks a
// file's. Mask regions and OBJ paths name files: they are not opened here
// (fuzz_nifti and fuzz_obj read those), so no run depends on the disk.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "core/error.h"
#include "fuzz_support.h"
#include "select/cut_mesh.h"
#include "select/cuts.h"
#include "select/region.h"
#include "select/scalar_range.h"

namespace {

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void checkRegion(std::string_view spec) {
  const fibscope::Region r = fibscope::parseRegion(spec);
  const std::string printed = fibscope::regionSpec(r);
  if (fibscope::regionSpec(fibscope::parseRegion(printed)) != printed) std::abort();
  if (const auto* s = std::get_if<fibscope::SphereRegion>(&r)) {
    for (float c : s->center)
      if (!std::isfinite(c)) std::abort();
    if (!(s->radius > 0) || !std::isfinite(s->radius)) std::abort();
  }
  if (const auto* b = std::get_if<fibscope::BoxRegion>(&r))
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(b->min[k]) || !std::isfinite(b->max[k]) || !(b->min[k] <= b->max[k])) std::abort();
  if (const auto* o = std::get_if<fibscope::OrientedBoxRegion>(&r))
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(o->center[k]) || !(o->half[k] > 0) || !std::isfinite(o->half[k])) std::abort();
      const auto& a = o->axes[k];
      if (!(std::fabs(a[0] * a[0] + a[1] * a[1] + a[2] * a[2] - 1) < 1e-6)) std::abort();
    }
  // Whatever was accepted can be asked about any point.
  const float p[3] = {0.5f, -1.0f, 2.0f};
  (void)fibscope::regionContains(r, p);
}

void checkClipPlane(std::string_view spec) {
  const fibscope::ClipPlane plane = fibscope::parseClipPlane(spec);
  if (!finite3(plane.point) || !finite3(plane.normal)) std::abort();
  if (!(std::fabs(glm::dot(plane.normal, plane.normal) - 1) < 1e-5f)) std::abort();
  const std::string printed = fibscope::clipPlaneSpec(plane);
  if (fibscope::clipPlaneSpec(fibscope::parseClipPlane(printed)) != printed) std::abort();
  const auto kept = fibscope::clipSegment(glm::vec3(-1e3f), glm::vec3(1e3f), {plane});
  if (kept && !(0 <= kept->first && kept->first <= kept->second && kept->second <= 1)) std::abort();
}

void checkSlab(std::string_view spec) {
  const fibscope::Slab slab = fibscope::parseSlab(spec);
  if (!(slab.thickness_mm > 0) || !std::isfinite(slab.thickness_mm)) std::abort();
  if (!fibscope::isSlabFollow(slab.follow)) std::abort();
}

void checkMeshCut(std::string_view spec) {
  const fibscope::MeshCut cut = fibscope::parseMeshCut(spec);
  const std::string printed = fibscope::meshCutSpec(cut);
  const fibscope::MeshCut again = fibscope::parseMeshCut(printed);
  if (again.cull_inside != cut.cull_inside || fibscope::meshCutSpec(again) != printed) std::abort();
  if (!fibscope::isBuiltinMeshSpec(cut.spec)) return;  // an OBJ path: fuzz_obj's part
  const fibscope::TriangleMesh mesh = fibscope::cutMeshFromSpec(cut.spec);
  if (mesh.triangles.empty()) std::abort();
  for (const glm::uvec3& t : mesh.triangles)
    if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size()) std::abort();
  for (const glm::vec3& v : mesh.positions)
    if (!finite3(v)) std::abort();
}

void checkScalarRange(std::string_view spec) {
  const fibscope::ScalarRange range = fibscope::parseScalarRange(spec);
  if (range.name.empty()) std::abort();
  if (std::isinf(range.min) || std::isinf(range.max)) std::abort();
  if (!std::isnan(range.min) && !std::isnan(range.max) && !(range.min <= range.max)) std::abort();
  const std::string printed = fibscope::scalarRangeSpec(range);
  if (fibscope::scalarRangeSpec(fibscope::parseScalarRange(printed)) != printed) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string_view spec(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 5) {
      case 0:
        if (spec.starts_with("mask:")) return 0;  // names a file
        checkRegion(spec);
        break;
      case 1: checkClipPlane(spec); break;
      case 2: checkSlab(spec); break;
      case 3: checkMeshCut(spec); break;
      case 4: checkScalarRange(spec); break;
    }
  } catch (const fibscope::Error& e) {
    fibscope::fuzz::checkMessage(e);
  }
  return 0;
}
