#include "app/criteria_options.h"

#include <CLI/CLI.hpp>

#include "core/error.h"
#include "select/number_list.h"
#include "select/roi_set.h"
#include "select/scalar_range.h"

namespace fibscope {
namespace {

std::vector<Region> regions(const std::vector<std::string>& specs, const char* option) {
  std::vector<Region> out;
  for (const std::string& spec : specs) {
    try {
      out.push_back(parseRegion(spec));
    } catch (const Error& e) {
      throw Error(std::string(option) + " " + e.what());
    }
  }
  return out;
}

}  // namespace

void addCriteriaCliOptions(CLI::App* cmd, CriteriaCliOptions& o) {
  cmd->add_option("--include", o.include,
                  "A region every kept streamline has a vertex in: sphere:X,Y,Z,R (or X,Y,Z,R), "
                  "box:X0,Y0,Z0,X1,Y1,Z1, obox:CX,CY,CZ,SX,SY,SZ,AX,AY,AZ (mm, degrees) or mask:FILE (a NIfTI "
                  "image: its voxels >= 0.5, as tckedit reads a mask); repeatable");
  cmd->add_option("--include-ordered", o.include_ordered,
                  "Regions a kept streamline enters in the order given (tckedit -include_ordered); repeatable");
  cmd->add_option("--exclude", o.exclude, "A region no kept streamline has a vertex in; repeatable");
  cmd->add_flag("--ends-only", o.ends_only, "Test only the two end vertices against the regions");
  cmd->add_option("--min-length", o.min_length, "Shortest length kept, mm");
  cmd->add_option("--max-length", o.max_length, "Longest length kept, mm");
  cmd->add_option("--distance-to", o.distance_to,
                  "A zone: X,Y,Z (a point) or a sphere:, box: or obox: spec; each fiber's smallest distance to it "
                  "(mm, from any vertex) is measured: a threshold with --max-distance, a colour with --color scalar");
  cmd->add_option("--max-distance", o.max_distance, "Keep the fibers within this distance of --distance-to, mm");
  cmd->add_option("--fiber-scalar", o.scalar_ranges,
                  "NAME:MIN:MAX or NAME[K]:MIN:MAX: keep the streamlines whose per-streamline value NAME (a trk "
                  "property, a TRX dps array; component K, default 0) lies in [MIN, MAX]; MIN or MAX empty for an "
                  "open end (fa_mean:0.3:); a NaN value is dropped; repeatable");
  cmd->add_option("--roi-set", o.roi_set,
                  "A ROI set (JSON, as the viewer saves it): its enabled regions, ends-only flag and length limits "
                  "join the options here (whose regions come after its; whose length limits win)");
}

CliCriteria criteriaFrom(const CriteriaCliOptions& o) {
  CliCriteria out;
  FilterCriteria& criteria = out.criteria;
  criteria.include = regions(o.include, "--include");
  criteria.include_ordered = regions(o.include_ordered, "--include-ordered");
  criteria.exclude = regions(o.exclude, "--exclude");
  criteria.ends_only = o.ends_only;
  for (const auto& [value, name] : {std::pair{o.min_length, "--min-length"}, std::pair{o.max_length, "--max-length"}})
    if (!std::isnan(value) && !(value >= 0 && std::isfinite(value)))
      throw Error(std::string(name) + ": expected a length >= 0 mm");
  criteria.min_length_mm = o.min_length;
  criteria.max_length_mm = o.max_length;
  if (!o.distance_to.empty()) {
    std::vector<double> v;
    if (parseNumberList(o.distance_to, v) && v.size() == 3) {
      criteria.distance_zone = SphereRegion{{float(v[0]), float(v[1]), float(v[2])}, 0.0f};  // a point
    } else {
      try {
        criteria.distance_zone = parseRegion(o.distance_to);
      } catch (const Error& e) {
        throw Error(std::string("--distance-to ") + e.what());
      }
      if (std::holds_alternative<MaskRegion>(*criteria.distance_zone))
        throw Error("--distance-to " + o.distance_to + ": expected a point, a sphere, a box or an oriented box");
    }
  }
  if (!std::isnan(o.max_distance)) {
    if (!(o.max_distance >= 0 && std::isfinite(o.max_distance)))
      throw Error("--max-distance: expected a distance >= 0 mm");
    if (!criteria.distance_zone) throw Error("--max-distance: needs --distance-to");
    criteria.max_distance_mm = o.max_distance;
  }
  for (const std::string& spec : o.scalar_ranges) {
    try {
      criteria.scalar_ranges.push_back(parseScalarRange(spec));
    } catch (const Error& e) {
      throw Error(std::string("--fiber-scalar ") + e.what());
    }
  }
  if (!o.roi_set.empty()) {
    const RoiSet set = loadRoiSet(o.roi_set);
    criteria = mergeCriteria(filterCriteria(set), criteria);
    for (const Roi& roi : set.rois) {
      const std::string name = "ROI '" + roi.name + "' (" + regionSpec(roi.region) + ") of " + o.roi_set;
      if (roi.enabled && roi.role == RoiRole::Include) out.include_names.push_back("--roi-set include " + name);
      if (roi.enabled && roi.role == RoiRole::Exclude) out.exclude_names.push_back("--roi-set exclude " + name);
    }
  }
  for (const std::string& spec : o.include) out.include_names.push_back("--include " + spec);
  for (const std::string& spec : o.exclude) out.exclude_names.push_back("--exclude " + spec);
  return out;
}

}  // namespace fibscope
