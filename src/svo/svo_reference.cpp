#include "svo/svo_reference.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>

#include "render/camera.h"
#include "shared/render_config.h"
#include "svo/svo_build.h"

namespace fibscope {

TubeReferenceImage renderBruteForceCapsules(const TubeModel& model, const Camera& camera) {
  const std::array<double, 16> vp = viewProjectionD(camera);  // validates the camera
  TubeReferenceImage img = TubeReferenceImage::empty(camera);
  for (uint32_t py = 0; py < camera.height; ++py)
    for (uint32_t px = 0; px < camera.width; ++px) {
      glm::dvec3 o, d;
      tubePixelRay(camera, px, py, o, d);
      double best = INFINITY;
      size_t best_s = 0;
      for (size_t s = 0; s < model.segments.size(); ++s) {
        const SvoCapsule c = svoCapsule(model, model.segments[s]);
        double t;
        if (intersectCapsule(glm::dvec3(c.a), glm::dvec3(c.b), double(c.radius), o, d, 0.0, t) && t < best) {
          // Within the depth range, as the GPU keeps it.
          const glm::dvec3 p = o + t * d;
          const double cw = vp[3] * p.x + vp[7] * p.y + vp[11] * p.z + vp[15];
          const double cz = vp[2] * p.x + vp[6] * p.y + vp[10] * p.z + vp[14];
          if (!(cw > 0.0) || cz / cw < 0.0 || cz / cw > 1.0) continue;
          best = t;
          best_s = s;
        }
      }
      if (!std::isfinite(best)) continue;
      const size_t i = size_t(py) * camera.width + px;
      const shader::TubeSegment& seg = model.segments[best_s];
      const SvoCapsule c = svoCapsule(model, seg);
      const glm::dvec3 p = o + best * d, a(c.a), b(c.b), ba = b - a;
      const double baba = glm::dot(ba, ba);
      const double u = baba > 0.0 ? std::clamp(glm::dot(p - a, ba) / baba, 0.0, 1.0) : 0.0;
      const double cw = vp[3] * p.x + vp[7] * p.y + vp[11] * p.z + vp[15];
      const double cz = vp[2] * p.x + vp[6] * p.y + vp[10] * p.z + vp[14];
      img.depth[i] = float(cz / cw);
      img.distance[i] = best;
      img.fiber[i] = seg.fiber;
      img.position[i] = float((1.0 - u) * model.nodes[seg.node].point + u * model.nodes[seg.node + 1].point);
      img.normal[i] = glm::vec3(glm::normalize(p - (a + u * ba)));
    }
  return img;
}

}  // namespace fibscope
