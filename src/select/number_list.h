// The comma-separated numbers of the dissection's specs (regions, clip
// planes, slabs): "1,2.5,-3" -> {1, 2.5, -3}.
#pragma once

#include <string_view>
#include <vector>

namespace fibscope {

// True when `text` is one or more comma-separated finite numbers (no
// spaces, nothing else); `out` holds them. Safe on untrusted text.
bool parseNumberList(std::string_view text, std::vector<double>& out);

}  // namespace fibscope
