// The fiber filter's command-line options, one set for `fibscope filter`,
// `render` and `bench` (the same criteria on the CPU and the GPU):
// --include / --include-ordered / --exclude SPEC (select/region.h),
// --ends-only, --min-length / --max-length MM.
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
};

void addCriteriaCliOptions(CLI::App* cmd, CriteriaCliOptions& options);

// The criteria the options name. Throws Error (one line) naming the option
// and what is wrong with its value.
FilterCriteria criteriaFrom(const CriteriaCliOptions& options);

}  // namespace fibscope
