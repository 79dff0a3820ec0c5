// libFuzzer target for ROI-set files (select/roi_set.h): the JSON a user
// saves from the viewer and hands to `fibscope filter --roi-set`, `render`
// and `bench`, and may receive from somebody else.
//
// Only fibscope::Error on one line is an accepted failure (nlohmann's own
// exceptions escaping would be a defect). A set that is accepted must keep
// its promises: its criteria and cuts can be built and a filter made of
// them judges fibers, at most kMaxClipPlanes
// enabled planes with unit normals, a positive slab; and the JSON saved
// for it must load again to a set that saves the same text (a fixed point
// after one trip, whose numbers may round to the printed digits).
// The file lies in a folder that does not exist, so relative mask, mesh and
// anatomy paths resolve to nothing on the disk. Seeds: fuzz/seeds/roiset.sh.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/error.h"
#include "fuzz_support.h"
#include "select/fiber_filter.h"
#include "select/roi_set.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string path = "/nonexistent-fibscope-fuzz/set.json";
  try {
    const fibscope::RoiSet set = fibscope::parseRoiSet(text, path);
    const fibscope::CutSet cuts = fibscope::cutSet(set);
    if (cuts.planes.size() > fibscope::kMaxClipPlanes) std::abort();
    for (const fibscope::ClipPlane& p : cuts.planes)
      if (!(std::fabs(glm::dot(p.normal, p.normal) - 1) < 1e-5f)) std::abort();
    if (cuts.slab && !(cuts.slab->thickness_mm > 0)) std::abort();
    // The filter built from it judges a fiber; one value per scalar range.
    const fibscope::FiberFilter filter(fibscope::filterCriteria(set));
    const float xyz[12] = {0, 0, 0, 10, 0, 0, 10, 10, 0, 10, 10, 10};
    const std::vector<float> scalars(filter.criteria().scalar_ranges.size(), 0.5f);
    for (size_t n : {size_t(0), size_t(1), size_t(4)}) (void)filter.evaluate(xyz, n, scalars);
    for (const double mm : {set.min_length_mm, set.max_length_mm})
      if (!std::isnan(mm) && !(mm >= 0 && std::isfinite(mm))) std::abort();
    const std::string saved = fibscope::roiSetJson(set, path);
    const std::string again = fibscope::roiSetJson(fibscope::parseRoiSet(saved, path), path);
    if (fibscope::roiSetJson(fibscope::parseRoiSet(again, path), path) != again) std::abort();
  } catch (const fibscope::Error& e) {
    fibscope::fuzz::checkMessage(e);
  }
  return 0;
}
