// The fiber filter's command-line options, one set for `fibscope filter`,
// `render` and `bench` (the same criteria on the CPU and the GPU):
// --include / --include-ordered / --exclude SPEC (select/region.h),
// --ends-only, --min-length / --max-length MM, --fiber-scalar
// NAME[K]:MIN:MAX (select/scalar_range.h), --roi-set FILE.json
// (select/roi_set.h: its enabled regions come first, the command line's
// after them; the command line's length limits win).
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "select/fiber_filter.h"

namespace CLI {
class App;
}

namespace fibscope {

struct CriteriaCliOptions {
  std::vector<std::string> include, include_ordered, exclude;
  bool ends_only = false;
  double min_length = NAN, max_length = NAN;
  std::string roi_set;
  // --distance-to X,Y,Z (a point) or a sphere/box/obox spec, --max-distance MM.
  std::string distance_to;
  double max_distance = NAN;
  std::vector<std::string> scalar_ranges;  // --fiber-scalar specs (--scalar-range is the colormap's)
};

// The criteria, and a name for each include and exclude region (in the
// criteria's order) for reports: "--include SPEC" or "--roi-set include
// ROI 'NAME' (SPEC) of FILE".
struct CliCriteria {
  FilterCriteria criteria;
  std::vector<std::string> include_names, exclude_names;
};

void addCriteriaCliOptions(CLI::App* cmd, CriteriaCliOptions& options);

// The criteria the options name (the ROI set read). Throws Error (one
// line) naming the option or the file and what is wrong.
CliCriteria criteriaFrom(const CriteriaCliOptions& options);

}  // namespace fibscope
