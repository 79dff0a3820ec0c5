#include "app/viewer/dissection.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <type_traits>

#include "core/error.h"
#include "render/clip_planes.h"

namespace fibscope {
namespace {

glm::dvec3 vec(const Vec3d& v) { return {v[0], v[1], v[2]}; }

int requireRoi(const RoiSet& set, const std::string& name, const char* command) {
  const int i = findRoi(set, name);
  if (i < 0) throw Error(std::string(command) + ": no ROI named '" + name + "'");
  return i;
}

void checkLengths(double min_mm, double max_mm) {
  if (!std::isnan(min_mm) && !(min_mm >= 0 && std::isfinite(min_mm)))
    throw Error("length: the minimum must be a length >= 0 mm");
  if (!std::isnan(max_mm) && !(max_mm >= 0 && std::isfinite(max_mm)))
    throw Error("length: the maximum must be a length >= 0 mm");
  if (!std::isnan(min_mm) && !std::isnan(max_mm) && min_mm > max_mm)
    throw Error("length: the minimum " + std::to_string(min_mm) + " mm lies above the maximum " +
                std::to_string(max_mm) + " mm");
}

}  // namespace

int findRoi(const RoiSet& set, const std::string& name) {
  for (size_t i = 0; i < set.rois.size(); ++i)
    if (set.rois[i].name == name) return int(i);
  return -1;
}

std::string uniqueRoiName(const RoiSet& set, const std::string& base) {
  for (int n = 1;; ++n) {
    const std::string name = base + "-" + std::to_string(n);
    if (findRoi(set, name) < 0) return name;
  }
}

int findScalarRange(const RoiSet& set, const std::string& name, uint32_t component) {
  for (size_t i = 0; i < set.scalar_ranges.size(); ++i)
    if (set.scalar_ranges[i].range.name == name && set.scalar_ranges[i].range.component == component) return int(i);
  return -1;
}

size_t enabledScalarRanges(const RoiSet& set) {
  return size_t(std::count_if(set.scalar_ranges.begin(), set.scalar_ranges.end(),
                              [](const RoiScalarRange& r) { return r.enabled; }));
}

size_t enabledClipPlanes(const RoiSet& set) {
  return size_t(
      std::count_if(set.clip_planes.begin(), set.clip_planes.end(), [](const RoiClipPlane& p) { return p.enabled; }));
}

size_t enabledCutMeshes(const RoiSet& set) {
  return size_t(
      std::count_if(set.cut_meshes.begin(), set.cut_meshes.end(), [](const RoiCutMesh& m) { return m.enabled; }));
}

void applyDissectionEdit(DissectionState& state, RenderSettings& settings, const DissectionEdit& edit) {
  RoiSet& set = state.set;
  std::visit(
      [&](const auto& e) {
        using E = std::decay_t<decltype(e)>;
        if constexpr (std::is_same_v<E, RoiAddEdit>) {
          if (findRoi(set, e.name) >= 0) throw Error("roi-add: a ROI named '" + e.name + "' exists already");
          set.rois.push_back(Roi{e.name, e.region, e.role, true});
          state.selected = int(set.rois.size()) - 1;
        } else if constexpr (std::is_same_v<E, RoiRemoveEdit>) {
          int i = state.selected;
          if (!e.name.empty()) i = requireRoi(set, e.name, "roi-remove");
          if (i < 0 || i >= int(set.rois.size())) throw Error("roi-remove: no ROI is selected");
          set.rois.erase(set.rois.begin() + i);
          if (state.selected == i)
            state.selected = -1;
          else if (state.selected > i)
            --state.selected;
        } else if constexpr (std::is_same_v<E, RoiEnableEdit>) {
          set.rois[size_t(requireRoi(set, e.name, "roi-enable"))].enabled = e.enabled;
        } else if constexpr (std::is_same_v<E, EndsOnlyEdit>) {
          set.ends_only = e.on;
        } else if constexpr (std::is_same_v<E, LengthEdit>) {
          checkLengths(e.min_mm, e.max_mm);
          set.min_length_mm = e.min_mm;
          set.max_length_mm = e.max_mm;
        } else if constexpr (std::is_same_v<E, ClipPlaneAddEdit>) {
          if (enabledClipPlanes(set) >= kMaxClipPlanes)
            throw Error("clip-plane-add: at most " + std::to_string(kMaxClipPlanes) + " clip planes at once");
          set.clip_planes.push_back(RoiClipPlane{e.plane, true});
        } else if constexpr (std::is_same_v<E, ClipPlaneClearEdit>) {
          set.clip_planes.clear();
        } else if constexpr (std::is_same_v<E, SlabEdit>) {
          if (!(e.thickness_mm >= 0 && std::isfinite(e.thickness_mm)))
            throw Error("slab: expected a thickness >= 0 mm (0: no slab)");
          settings.slab_mm = e.thickness_mm;
        } else if constexpr (std::is_same_v<E, DroppedEdit>) {
          state.dim_dropped = e.dim;
        } else if constexpr (std::is_same_v<E, CutMeshAddEdit>) {
          if (enabledCutMeshes(set) >= kMaxCutMeshes)
            throw Error("cut-mesh-add: at most " + std::to_string(kMaxCutMeshes) + " cut meshes at once");
          set.cut_meshes.push_back(RoiCutMesh{e.cut, true});
        } else if constexpr (std::is_same_v<E, CutMeshClearEdit>) {
          set.cut_meshes.clear();
        } else if constexpr (std::is_same_v<E, FiberScalarEdit>) {
          checkScalarRange(e.range, "fiber-scalar " + scalarRangeArray(e.range));
          const int i = findScalarRange(set, e.range.name, e.range.component);
          const bool was_enabled = i >= 0 && set.scalar_ranges[size_t(i)].enabled;
          if (!was_enabled && enabledScalarRanges(set) >= FiberFilter::kMaxScalarRanges)
            throw Error("fiber-scalar: at most " + std::to_string(FiberFilter::kMaxScalarRanges) +
                        " scalar ranges at once");
          if (i >= 0)
            set.scalar_ranges[size_t(i)] = RoiScalarRange{e.range, true};
          else
            set.scalar_ranges.push_back(RoiScalarRange{e.range, true});
        } else if constexpr (std::is_same_v<E, FiberScalarClearEdit>) {
          set.scalar_ranges.clear();
        }
      },
      edit);
}

FilterCriteria dissectionCriteria(const DissectionState& state) { return filterCriteria(state.set); }

size_t addDissectionCuts(const RoiSet& set, RenderSettings& settings) {
  size_t left_out = 0;
  for (const RoiClipPlane& p : set.clip_planes) {
    if (!p.enabled) continue;
    if (settings.clip_planes.size() >= kMaxClipPlanes) {
      ++left_out;
      continue;
    }
    const glm::vec3& a = p.plane.point;
    const glm::vec3& n = p.plane.normal;
    settings.clip_planes.push_back(planeThrough({a.x, a.y, a.z}, {n.x, n.y, n.z}));
  }
  return left_out;
}

RoiSet roiSetToSave(const DissectionState& state, const RenderSettings& settings, const AnatomyGrid* grid) {
  RoiSet set = state.set;
  const AnatomyGrid ras;
  if (settings.slab_mm > 0)
    set.slab = Slab{settings.slab_mm, settings.slab_follows_slice
                                          ? std::string(sliceAxisView(grid ? *grid : ras, int(settings.active_slice)))
                                          : std::string()};
  else
    set.slab.reset();
  return set;
}

void loadRoiSetIntoState(RoiSet set, DissectionState& state, RenderSettings& settings, const AnatomyGrid* grid) {
  if (enabledClipPlanes(set) > kMaxClipPlanes)
    throw Error("at most " + std::to_string(kMaxClipPlanes) + " clip planes may be enabled at once");
  if (enabledCutMeshes(set) > kMaxCutMeshes)
    throw Error("at most " + std::to_string(kMaxCutMeshes) + " cut meshes may be enabled at once");
  settings.slab_mm = set.slab ? set.slab->thickness_mm : 0.0f;
  const std::string follow = set.slab ? set.slab->follow : "";
  const AnatomyGrid ras;
  const int axis = follow.empty() ? -1 : anatomicalSliceAxis(grid ? *grid : ras, follow);
  settings.slab_follows_slice = axis >= 0;
  if (axis >= 0) settings.active_slice = SliceAxis(axis);
  state.set = std::move(set);
  state.selected = -1;
}

std::vector<RoiClipPlane> clipPlanesFromSettings(const std::vector<std::array<double, 4>>& planes) {
  std::vector<RoiClipPlane> out;
  for (const auto& p : planes) {
    const glm::dvec3 n(p[0], p[1], p[2]);
    const double len = glm::length(n);
    if (!(len > 0)) continue;  // renderSettingsFrom gives unit normals; a zero one keeps nothing to convert
    const glm::dvec3 unit = n / len;
    // (+ 0: no "-0" in a saved set for a plane through the origin.)
    out.push_back(RoiClipPlane{ClipPlane{glm::vec3(-p[3] / len * unit + glm::dvec3(0.0)), glm::vec3(unit)}, true});
  }
  return out;
}

double defaultRoiRadius(const Bounds& scene) {
  const glm::dvec3 diagonal = vec(scene.max) - vec(scene.min);
  const double d = glm::length(diagonal);
  return std::max(0.5, std::isfinite(d) ? 0.03 * d : 0.5);
}

double defaultCutSize(const Bounds& scene) {
  const double d = glm::length(vec(scene.max) - vec(scene.min));
  return std::max(1.0, std::isfinite(d) ? 0.15 * d : 1.0);
}

SphereRegion sphereAt(const glm::dvec3& center, double radius) {
  return SphereRegion{{float(center.x), float(center.y), float(center.z)}, float(radius)};
}

BoxRegion boxAt(const glm::dvec3& center, double half_size) {
  BoxRegion b;
  for (int k = 0; k < 3; ++k) {
    b.min[k] = center[k] - half_size;
    b.max[k] = center[k] + half_size;
  }
  return b;
}

std::optional<glm::dvec3> regionCenter(const Region& region) {
  if (const auto* s = std::get_if<SphereRegion>(&region)) return glm::dvec3(s->center[0], s->center[1], s->center[2]);
  if (const auto* b = std::get_if<BoxRegion>(&region))
    return 0.5 * (glm::dvec3(b->min[0], b->min[1], b->min[2]) + glm::dvec3(b->max[0], b->max[1], b->max[2]));
  if (const auto* o = std::get_if<OrientedBoxRegion>(&region)) return vec(o->center);
  return std::nullopt;
}

Region movedRegion(const Region& region, const glm::dvec3& delta) {
  Region out = region;
  if (auto* s = std::get_if<SphereRegion>(&out)) {
    for (int k = 0; k < 3; ++k) s->center[k] = float(double(s->center[k]) + delta[k]);
  } else if (auto* b = std::get_if<BoxRegion>(&out)) {
    for (int k = 0; k < 3; ++k) {
      b->min[k] += delta[k];
      b->max[k] += delta[k];
    }
  } else if (auto* o = std::get_if<OrientedBoxRegion>(&out)) {
    for (int k = 0; k < 3; ++k) o->center[k] += delta[k];
  }
  return out;
}

Region scaledRegion(const Region& region, double factor) {
  Region out = region;
  if (!(factor > 0) || !std::isfinite(factor)) return out;
  if (auto* s = std::get_if<SphereRegion>(&out)) {
    s->radius = float(double(s->radius) * factor);
  } else if (auto* b = std::get_if<BoxRegion>(&out)) {
    for (int k = 0; k < 3; ++k) {
      const double c = 0.5 * (b->min[k] + b->max[k]), h = 0.5 * (b->max[k] - b->min[k]) * factor;
      b->min[k] = c - h;
      b->max[k] = c + h;
    }
  } else if (auto* o = std::get_if<OrientedBoxRegion>(&out)) {
    for (double& h : o->half) h *= factor;
  }
  return out;
}

OrientedBoxRegion orientedBox(const glm::dvec3& center, const glm::dvec3& size, const glm::dvec3& angles_deg) {
  // Through the spec, so the axes are exactly those parseRegion makes (a
  // saved set reads back to the same box).
  char spec[320];
  std::snprintf(spec, sizeof spec, "obox:%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", center.x, center.y,
                center.z, size.x, size.y, size.z, angles_deg.x, angles_deg.y, angles_deg.z);
  return std::get<OrientedBoxRegion>(parseRegion(spec));
}

ClipPlane planeFacingViewer(const Camera& camera) {
  const glm::dvec3 target = vec(camera.target), eye = vec(camera.eye);
  return makeClipPlane(glm::vec3(target), glm::vec3(eye - target), "clip plane facing the viewer");
}

glm::dvec3 viewPlaneDrag(const Camera& camera, const glm::dvec3& at, double dx_px, double dy_px) {
  const glm::dvec3 eye = vec(camera.eye);
  const glm::dvec3 forward = glm::normalize(vec(camera.target) - eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, vec(camera.up)));
  const glm::dvec3 up = glm::cross(right, forward);
  // World mm per pixel at the point's view depth (the projection's vertical
  // extent 2 depth tan(fov / 2) over the image's height).
  const double depth = std::max(glm::dot(at - eye, forward), 1e-6);
  const double mm_per_px =
      2.0 * depth * std::tan(glm::radians(camera.fov_y_deg) / 2.0) / double(std::max(camera.height, 1u));
  return mm_per_px * (dx_px * right - dy_px * up);
}

}  // namespace fibscope
